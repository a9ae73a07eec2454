//! Script bindings of the marker-captured golf swing: [`crate::tracking::golf_trial`].

use rhai::{Dynamic, Map, INT};

use super::convert::{rt_err, RResult};
use super::paths::{read_folder_opt, write_folder};
use super::tracking_sequence::whole;
use super::{function, modules::ApiBuilder};
use crate::body::Mannequin;
use crate::geometry::files::data_path;
use crate::tracking::golf_trial::run_golf_trial;
use crate::tracking::marker_fit::MarkerFitOptions;

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
}
