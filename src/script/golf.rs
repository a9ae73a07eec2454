//! Script bindings of the marker-captured golf swing: [`crate::tracking::golf_trial`].

use rhai::{Dynamic, Map, INT};

use super::convert::{rt_err, RResult};
use super::paths::{read_folder, read_folder_opt, read_path, write_folder};
use super::tracking_sequence::{apply_options, number, whole};
use super::{function, modules::ApiBuilder};
use crate::body::Mannequin;
use crate::geometry::files::data_path;
use crate::tracking::club_track::ClubTrackOptions;
use crate::tracking::golf_sequence::{make_golf_sequence, GolfSequenceOptions};
use crate::tracking::golf_track::{golf_report, track_club_in};
use crate::tracking::golf_trial::run_golf_trial;
use crate::tracking::marker_fit::MarkerFitOptions;
use crate::tracking::sequence_dressing::DressingOptions;
use crate::tracking::sequence_files::Sequence;

fn golf(c3d: &str, out: &str, m: &Map) -> RResult<Map> {
    if !std::path::Path::new(c3d).is_file() {
        let mut map = Map::new();
        map.insert("skipped".into(), format!("{c3d} is absent").into());
        return Ok(map);
    }
    let mut o = MarkerFitOptions::default();
    let get = |k: &str| m.get(k).map(|d| whole(d, k)).transpose();
    if let Some(v) = get("stride")? {
        o.calibration_stride = v.clamp(1, 1_000_000) as usize;
    }
    if let Some(v) = get("rounds")? {
        o.rounds = v.clamp(1, 100) as usize;
    }
    if let Some(v) = get("iterations")? {
        o.iterations = v.clamp(1, 1000) as usize;
    }
    let every = get("every")?.unwrap_or(1).clamp(1, 1_000_000) as usize;
    let mh_opt = m.get("makehuman").map(|d| d.to_string());
    let mh = read_folder_opt(mh_opt.as_deref())?.unwrap_or_else(|| data_path("bodies/makehuman"));
    let mannequin = Mannequin::load_makehuman(&mh).map_err(rt_err)?;
    let r = run_golf_trial(
        std::path::Path::new(c3d),
        &mannequin,
        &write_folder(out)?,
        &o,
        every,
    )
    .map_err(rt_err)?;
    let mut map = Map::new();
    let fl = |x: f64| Dynamic::from_float(x);
    map.insert("frames".into(), Dynamic::from_int(r.frames as INT));
    map.insert("residual_rms_mm".into(), fl(r.residual_rms * 1e3));
    map.insert(
        "lead_wrist_peak_mps".into(),
        fl(r.markers.lead_wrist_peak()),
    );
    map.insert("clubhead_peak_mps".into(), fl(r.markers.clubhead_peak()));
    map.insert("xfactor_peak_deg".into(), fl(r.markers.x_factor_peak()));
    map.insert(
        "fitted_lead_wrist_peak_mps".into(),
        fl(r.fitted.lead_wrist_peak()),
    );
    map.insert(
        "fitted_xfactor_peak_deg".into(),
        fl(r.fitted.x_factor_peak()),
    );
    let plane = r.markers.plane.map_or(f64::NAN, |p| p.inclination_deg);
    map.insert("swing_plane_deg".into(), fl(plane));
    map.insert("club_length_m".into(), fl(r.club_length));
    map.insert("grip_rms_mm".into(), fl(r.grip_rms * 1e3));
    map.insert("peak_frame".into(), Dynamic::from_int(r.peak_frame as INT));
    map.insert("files".into(), Dynamic::from_int(r.files.len() as INT));
    Ok(map)
}

/// Option keys of `track::golf_sequence` besides the sequence's own.
const GOLF_KEYS: [&str; 11] = [
    "shutter", "blur", "reshape", "every", "stride", "rounds", "garments", "fabric", "edge",
    "cloth_dt", "lead_in",
];

/// The dressing of `track::golf_sequence`: `garments` (an array of garment-table paths;
/// absent or empty: not dressed), `fabric` (a fabric file, required with garments), `edge`,
/// `cloth_dt`, `lead_in`.
fn dressing_options(m: &Map) -> RResult<Option<DressingOptions>> {
    let garments = match m.get("garments") {
        None => return Ok(None),
        Some(g) => g.clone().into_array().map_err(|t| {
            rt_err(format!(
                "golf_sequence: `garments` must be an array of paths, got {t}"
            ))
        })?,
    };
    if garments.is_empty() {
        return Ok(None);
    }
    let paths = garments
        .into_iter()
        .map(|g| read_path(&g.to_string()))
        .collect::<RResult<Vec<_>>>()?;
    let fabric = m
        .get("fabric")
        .ok_or_else(|| rt_err("golf_sequence: `garments` needs `fabric` (a fabric file)"))?;
    let mut d = DressingOptions::new(paths, read_path(&fabric.to_string())?);
    let get = |k: &str| m.get(k).map(|v| number(v, k)).transpose();
    if let Some(v) = get("edge")? {
        d.edge = v;
    }
    if let Some(v) = get("cloth_dt")? {
        d.dt = v;
    }
    if let Some(v) = get("lead_in")? {
        d.lead_in = v;
    }
    Ok(Some(d))
}

fn golf_sequence(c3d: &str, out: &str, m: &Map) -> RResult<Map> {
    if !std::path::Path::new(c3d).is_file() {
        let mut map = Map::new();
        map.insert("skipped".into(), format!("{c3d} is absent").into());
        return Ok(map);
    }
    if m.contains_key("lbs") {
        return Err(rt_err(
            "golf_sequence: `lbs` does not apply (the golfer is always skinned by linear blending)",
        ));
    }
    let mut o = GolfSequenceOptions::default();
    apply_options(&mut o.sequence, m, "golf_sequence", &GOLF_KEYS)?;
    let get = |k: &str| m.get(k).map(|d| number(d, k)).transpose();
    if let Some(v) = get("shutter")? {
        o.shutter = v;
    }
    if let Some(v) = get("reshape")? {
        o.reshape = v;
    }
    let count = |k: &str| m.get(k).map(|d| whole(d, k)).transpose();
    if let Some(v) = count("blur")? {
        o.blur_samples = v.min(1_000) as usize;
    }
    if let Some(v) = count("every")? {
        o.fit_every = v.min(1_000) as usize;
    }
    if let Some(v) = count("stride")? {
        o.fit.calibration_stride = v.clamp(1, 1_000_000) as usize;
    }
    if let Some(v) = count("rounds")? {
        o.fit.rounds = v.clamp(1, 100) as usize;
    }
    o.dressing = dressing_options(m)?;
    let s =
        make_golf_sequence(std::path::Path::new(c3d), &write_folder(out)?, &o).map_err(rt_err)?;
    let mut map = Map::new();
    let fl = |x: f64| Dynamic::from_float(x);
    let q = &s.sequence;
    map.insert("dir".into(), q.dir.display().to_string().into());
    map.insert("frames".into(), Dynamic::from_int(q.frames as INT));
    map.insert("cameras".into(), Dynamic::from_int(q.cameras as INT));
    map.insert("width".into(), Dynamic::from_int(q.width as INT));
    map.insert("height".into(), Dynamic::from_int(q.height as INT));
    map.insert("seconds".into(), fl(q.seconds));
    map.insert("seconds_per_frame".into(), fl(q.seconds_per_frame));
    map.insert("fit_residual_rms_mm".into(), fl(s.fit_residual_rms * 1e3));
    map.insert("lead_wrist_peak_mps".into(), fl(s.truth.lead_wrist_peak()));
    map.insert("clubhead_peak_mps".into(), fl(s.truth.clubhead_peak()));
    map.insert("xfactor_peak_deg".into(), fl(s.truth.x_factor_peak()));
    let mut props = Map::new();
    for (k, v) in s.proportions.named() {
        props.insert(k.into(), fl(v));
    }
    map.insert("proportions".into(), props.into());
    if let Some(d) = &s.dressing {
        let mut g = Map::new();
        g.insert("garments".into(), d.garments.join(", ").into());
        g.insert("vertices".into(), Dynamic::from_int(d.vertices as INT));
        g.insert("dress_seconds".into(), fl(d.dress_seconds));
        g.insert("motion_seconds".into(), fl(d.motion_seconds));
        g.insert("steps".into(), Dynamic::from_int(d.steps as INT));
        g.insert(
            "checked_frames".into(),
            Dynamic::from_int(d.checked_frames as INT),
        );
        g.insert(
            "worst_penetrating".into(),
            Dynamic::from_int(d.worst_penetrating as INT),
        );
        g.insert("min_distance_mm".into(), fl(d.min_distance * 1e3));
        g.insert("max_distance_mm".into(), fl(d.max_distance * 1e3));
        map.insert("dressing".into(), g.into());
    }
    Ok(map)
}

fn golf_club_map(seq: &str, tracked: &str, m: &Map) -> RResult<Map> {
    let seq = Sequence::open(read_folder(seq)?).map_err(rt_err)?;
    let mut o = ClubTrackOptions::default();
    let get = |k: &str| m.get(k).map(|d| number(d, k)).transpose();
    if let Some(v) = get("directions")? {
        o.directions = v.clamp(10.0, 1e6) as usize;
    }
    if let Some(v) = get("samples")? {
        o.samples = v.clamp(4.0, 1e4) as usize;
    }
    if let Some(v) = get("ridge_px")? {
        o.ridge_px = v.clamp(0.5, 50.0);
    }
    if let Some(v) = get("threshold")? {
        o.threshold = v.clamp(0.0, 1.0);
    }
    if let Some(v) = get("length")? {
        if !(0.3..=2.0).contains(&v) {
            return Err(rt_err(format!(
                "`length` (grip to club-head centre) must be within 0.3..2 m, got {v}"
            )));
        }
        o.length = Some(v);
    }
    let c = track_club_in(&seq, &read_folder(tracked)?, &o).map_err(rt_err)?;
    let mut map = Map::new();
    let fl = |x: f64| Dynamic::from_float(x);
    let n = c.grip.len().max(1) as f64;
    map.insert("frames".into(), Dynamic::from_int(c.grip.len() as INT));
    map.insert("length_m".into(), fl(c.length));
    map.insert("seconds".into(), fl(c.seconds));
    map.insert("s_per_frame".into(), fl(c.seconds / n));
    map.insert("mean_score".into(), fl(c.scores.iter().sum::<f64>() / n));
    Ok(map)
}

fn golf_report_map(seq: &str, tracked: &str) -> RResult<Map> {
    let seq = Sequence::open(read_folder(seq)?).map_err(rt_err)?;
    let r = golf_report(&seq, &read_folder(tracked)?).map_err(rt_err)?;
    let mut map = Map::new();
    let fl = |x: f64| Dynamic::from_float(x);
    map.insert("wrist_speed_err_pct".into(), fl(r.wrist_speed_err_pct()));
    map.insert("xfactor_err_deg".into(), fl(r.xfactor_err_deg()));
    map.insert(
        "clubhead_speed_err_pct".into(),
        fl(r.clubhead_speed_err_pct()),
    );
    map.insert(
        "truth_lead_wrist_peak_mps".into(),
        fl(r.truth.lead_wrist_peak()),
    );
    map.insert(
        "tracked_lead_wrist_peak_mps".into(),
        fl(r.tracked.lead_wrist_peak()),
    );
    map.insert("truth_xfactor_peak_deg".into(), fl(r.truth.x_factor_peak()));
    map.insert(
        "tracked_xfactor_peak_deg".into(),
        fl(r.tracked.x_factor_peak()),
    );
    map.insert(
        "truth_clubhead_peak_mps".into(),
        fl(r.truth.clubhead_peak()),
    );
    map.insert(
        "tracked_clubhead_peak_mps".into(),
        fl(r.tracked.clubhead_peak()),
    );
    map.insert("clubhead_error_mm".into(), fl(1e3 * r.head_error));
    map.insert("files".into(), Dynamic::from_int(r.files.len() as INT));
    Ok(map)
}

/// Registers the golf swing's script functions.
pub fn register(engine: &mut ApiBuilder) {
    function!(
        engine,
        "track::golf_markers",
        ["c3d: String", "out: String", "options: Map", "Map"],
        "Reads a GEARS golf swing (C3D, y up read from the data), fits the MakeHuman puppet to its
body markers (proportions, marker offsets, per-frame inverse kinematics) and the club to its
markers (a rigid body: head = the faster cluster, grip = the lead wrist's place on it), and
writes under `out`: `fit.bvh`, `residuals.csv`, `posed.obj` (the mannequin at peak club-head
speed), `markers_metrics.csv` and `fitted_metrics.csv` (pelvis and shoulder rotation,
X-factor, centre of mass, lead wrist and club-head speed by frame differences) with
`_rotation` and `_speed` plots (PNG, SVG). Options: `every` (fit every n-th frame, default
1), `stride` (calibration frames, default 8), `rounds` (4), `iterations` (LM per frame, 40),
`makehuman` (folder). A missing `c3d` file returns #{skipped: message}. Metrics from the markers always use every frame. Returns #{frames,
residual_rms_mm, lead_wrist_peak_mps, clubhead_peak_mps, xfactor_peak_deg,
fitted_lead_wrist_peak_mps, fitted_xfactor_peak_deg, swing_plane_deg, club_length_m,
grip_rms_mm, peak_frame, files}.",
        |c3d: &str, out: &str, m: Map| golf(c3d, out, &m)
    );
    function!(
        engine,
        "track::golf_sequence",
        ["c3d: String", "out: String", "options: Map", "Map"],
        "Makes a synthetic broadcast sequence of a GEARS golf swing (C3D; or of any BVH clip, without
a club: `c3d` ending in `.bvh`) into folder `out`, in
the layout `track::make_sequence` writes (so `track_body.rhai` tracks it): the puppet fitted
to the markers, every segment length and the girth changed by a seeded factor within
±`reshape` (default 0.1), in clothes-like colours, holding the club fitted to its markers;
filmed by up to 4 broadcast cameras (face-on, down the line, behind, high; 640×480, 50 fps,
the whole swing) in front of real photos, with motion blur (`shutter` seconds, default
1/250, `blur` instants averaged, default 5), changing light and noise. Also writes
`club.csv` (grip and head per frame) and `truth_metrics.csv` with plots (the ground truth's
golf metrics). Options: those of `track::make_sequence` (`cameras` ≤ 4, `width`, `height`,
`fps`, `frames`, `start`, `noise`, `lighting`, `occluder`, `seed`, `backgrounds`,
`makehuman`, `shading`) and `shutter`, `blur`, `reshape`, `every` (fit every n-th
capture frame, default 2), `stride` (calibration frames, 8), `rounds` (3). Dressed with
`garments` (garment tables, e.g. `[\"patterns/aaron.garment.json\",
\"patterns/paco.garment.json\"]`) and `fabric` (a fabric file): each garment is sewn and
draped on the golfer at rest, carried into the swing and simulated through it (`edge`: mesh
edge, default 0.02 m; `cloth_dt`: step, 1/240 s; `lead_in`: swing played before the first
frame, 0.8 s); the result then holds `dressing` #{garments, vertices, dress_seconds,
motion_seconds, steps, checked_frames, worst_penetrating (most garment vertices inside the
body at a frame), min_distance_mm, max_distance_mm}. A missing `c3d`
file returns #{skipped: message}. Returns #{dir, frames, cameras, width, height, seconds,
seconds_per_frame, fit_residual_rms_mm, lead_wrist_peak_mps, clubhead_peak_mps,
xfactor_peak_deg, proportions}.",
        |c3d: &str, out: &str, m: Map| golf_sequence(c3d, out, &m)
    );
    function!(
        engine,
        "track::golf_club",
        ["seq: String", "tracked: String", "options: Map", "Map"],
        "Tracks the golf club in the golf sequence `seq` after the body (`tracked/tracked_joints.csv`,
written by `track::body`): in every frame the straight shaft from the hands whose projections
run along thin foreground lines in all cameras (the grip started at the tracked lead wrist;
every direction tried; the length searched over the first frames). Writes
`tracked/tracked_club.csv` (grip and head per frame, the layout of the sequence's
`club.csv`), which `track::golf_report` then compares with the truth, and draws the club
and its head's path into the broadcast pictures under `tracked/overlay/` and
`tracked/broadcast.png`. Options: `directions`
(tried over the sphere, default 3000), `samples` (points along the shaft per camera, 48),
`ridge_px` (side distance of the line test, 3), `threshold` (evidence a point must carry,
0.15), `length` (the club from the grip point to the head's centre, metres; default a
driver's, 1.10). Returns #{frames, length_m, seconds, s_per_frame, mean_score}.",
        |seq: &str, tracked: &str, m: Map| golf_club_map(seq, tracked, &m)
    );
    function!(
        engine,
        "track::golf_report",
        ["seq: String", "tracked: String", "Map"],
        "Compares the tracked joints in `tracked/tracked_joints.csv` (written by `track::body`)
with the ground truth of the golf sequence `seq` (its `ground_truth.csv` and `club.csv`) on
the frames tracked, and writes under `tracked`: `truth_metrics.csv`, `tracked_metrics.csv`
(with their rotation and speed plots) and `golf_compare_speed`, `golf_compare_xfactor` (PNG,
SVG). The tracked club is read from `tracked/tracked_club.csv` (`track::golf_club`); without
it `clubhead_speed_err_pct` is NaN. Returns #{wrist_speed_err_pct, xfactor_err_deg,
clubhead_speed_err_pct, truth_lead_wrist_peak_mps, tracked_lead_wrist_peak_mps,
truth_xfactor_peak_deg, tracked_xfactor_peak_deg, truth_clubhead_peak_mps,
tracked_clubhead_peak_mps, clubhead_error_mm (mean distance of the tracked head from the
truth's), files}.",
        |seq: &str, tracked: &str| golf_report_map(seq, tracked)
    );
}
