//! Script bindings of the body tracker: tracking a sequence folder and writing its outputs.

use std::io::IsTerminal;

use indicatif::ProgressBar;
use rhai::{Dynamic, Map, INT};

use super::checkpoint::{begin, resumed_file, Plan};
use super::convert::{count, finite, rt_err, RResult};
use super::paths::{read_folder, read_folder_opt, write_folder};
use super::tracking_sequence::flag;
use super::{function, modules::ApiBuilder};
use crate::body::Mannequin;
use crate::geometry::checkpoint::Fingerprint;
use crate::geometry::files::data_path;
use crate::tracking::checkpoint::TrackCheckpoint;
use crate::tracking::loss::FrameStatus;
use crate::tracking::sequence_files::Sequence;
use crate::tracking::sequence_run::track_sequence_from;
use crate::tracking::track_outputs::{arm_joints, write_track_outputs, TrackOutputOptions};
use crate::tracking::tracker::{TrackError, TrackerOptions};

fn options(m: &Map) -> RResult<(TrackerOptions, TrackOutputOptions, Option<String>)> {
    let mut o = TrackerOptions::default();
    let mut out = TrackOutputOptions::default();
    let mut makehuman = None;
    for (k, v) in m {
        match k.as_str() {
            "particles" => o.particles = count(v, "particles")?,
            "layers" => {
                let arr = v
                    .read_lock::<rhai::Array>()
                    .ok_or_else(|| rt_err("`layers` must be an array of pyramid levels"))?;
                o.layers = arr
                    .iter()
                    .map(|d| count(d, "layers[]"))
                    .collect::<RResult<Vec<_>>>()?;
            }
            "passes" => {
                let arr = v
                    .read_lock::<rhai::Array>()
                    .ok_or_else(|| rt_err("`passes` must be an array of spread factors"))?;
                o.passes = arr
                    .iter()
                    .map(|d| finite(d, "passes[]"))
                    .collect::<RResult<Vec<_>>>()?;
            }
            "robust_sigma" => o.robust_sigma = finite(v, "robust_sigma")? as f32,
            "mesh_cell" => o.mesh_cell = finite(v, "mesh_cell")?,
            "lbs" => {
                o.lbs = v
                    .as_bool()
                    .map_err(|_| rt_err("`lbs` must be true or false"))?
            }
            "background_frames" => o.background_frames = count(v, "background_frames")?,
            "prediction" => o.prediction = finite(v, "prediction")?,
            "prior_weight" => o.prior_weight = finite(v, "prior_weight")?,
            "limb_restarts" => {
                o.limb_restarts = v
                    .as_bool()
                    .map_err(|_| rt_err("`limb_restarts` must be true or false"))?
            }
            "seed" => o.seed = count(v, "seed")? as u64,
            "init" => {
                o.auto_start = match v.to_string().as_str() {
                    "auto" => true,
                    "joints" => false,
                    other => {
                        return Err(rt_err(format!(
                            "track_body: `init` is `auto` or `joints`, not `{other}`"
                        )))
                    }
                }
            }
            "recover" => {
                o.recover = v
                    .as_bool()
                    .map_err(|_| rt_err("`recover` must be true or false"))?
            }
            "first_frame" => o.first_frame = count(v, "first_frame")?,
            "adapt_body" => o.adapt_body = flag(v, "adapt_body")?,
            "torso_spread" => o.torso_spread = finite(v, "torso_spread")?,
            "anchor_limbs" => o.anchor_limbs = flag(v, "anchor_limbs")?,
            "hands_apart" => o.hands_apart = Some(finite(v, "hands_apart")?),
            "golf_address" => o.golf_address = flag(v, "golf_address")?,
            "lead_elbow_min" => {
                o.lead_elbow_min = Some(finite(v, "lead_elbow_min")?.to_radians())
            }
            "frames" => o.frames = Some(count(v, "frames")?),
            "overlay_every" => out.overlay_every = count(v, "overlay_every")?,
            "makehuman" => makehuman = Some(v.to_string()),
            other => {
                return Err(rt_err(format!(
                "track_body: unknown option `{other}` (particles, layers, passes, robust_sigma, \
                     mesh_cell, lbs, background_frames, prediction, prior_weight, limb_restarts, seed, \
                     init, recover, first_frame, frames, adapt_body, torso_spread, anchor_limbs, \
                     hands_apart, golf_address, lead_elbow_min, overlay_every, makehuman)"
            )))
            }
        }
    }
    Ok((o, out, makehuman))
}

fn track(seq_dir: &str, out: &str, m: &Map) -> RResult<Map> {
    let (options, out_options, makehuman) = options(m)?;
    let seq = Sequence::open(read_folder(seq_dir)?).map_err(rt_err)?;
    let mh =
        read_folder_opt(makehuman.as_deref())?.unwrap_or_else(|| data_path("bodies/makehuman"));
    let mannequin = Mannequin::load_makehuman(&mh).map_err(rt_err)?;
    let available = seq.frames.saturating_sub(options.first_frame);
    let total = options.frames.map_or(available, |f| f.min(available));
    let bar = std::io::stderr()
        .is_terminal()
        .then(|| ProgressBar::new(total as u64));
    // the call's setup: the sequence, the body model, the options and the frames tracked
    let (call, plan) = begin("track_body", || {
        let mut f = Fingerprint::default();
        f.str(&seq.dir.display().to_string())
            .str(&mh.display().to_string())
            .str(&format!("{options:?}"))
            .u64(total as u64);
        f.value()
    })?;
    let resume = match plan {
        Plan::Run => None,
        Plan::Finished(rec) | Plan::Continue(rec) => Some(
            TrackCheckpoint::decode(&rec.state, &resumed_file())
                .map_err(|e| rt_err(e.to_string()))?,
        ),
    };
    let mut last = None;
    let result = track_sequence_from(&seq, &mannequin, &options, None, resume, |done, _, ck| {
        if let Some(b) = &bar {
            b.set_position(done as u64);
        }
        if call.due(done as u64) && done < total {
            call.save(done as u64, 0.0, ck().encode())
                .map_err(|e| TrackError::Invalid(e.to_string()))?;
        }
        if done == total && call.active() {
            last = Some(ck().encode());
        }
        Ok(())
    })
    .map_err(rt_err)?;
    if let Some(state) = last {
        call.finish(total as u64, 0.0, || Ok(state))?;
    }
    if let Some(b) = bar {
        b.finish_and_clear();
    }
    let files =
        write_track_outputs(&seq, &result, &write_folder(out)?, &out_options).map_err(rt_err)?;
    let mut r = Map::new();
    let f = |x: Option<f64>| x.map_or(Dynamic::UNIT, Dynamic::from_float);
    r.insert(
        "frames".into(),
        Dynamic::from_int(result.joints.len() as INT),
    );
    r.insert("mpjpe_mm".into(), f(result.mpjpe_mm()));
    r.insert(
        "max_frame_mm".into(),
        f(result
            .errors_mm
            .as_ref()
            .map(|e| e.iter().cloned().fold(0.0, f64::max))),
    );
    r.insert("arm_mm".into(), f(result.joints_error_mm(&arm_joints())));
    let frames_with = |s| {
        let v: rhai::Array = result
            .frames_with(s)
            .into_iter()
            .map(|k| Dynamic::from_int(k as INT))
            .collect();
        Dynamic::from_array(v)
    };
    r.insert("lost".into(), frames_with(FrameStatus::Lost));
    r.insert("recovered".into(), frames_with(FrameStatus::Recovered));
    r.insert(
        "s_per_frame".into(),
        Dynamic::from_float(result.seconds_per_frame()),
    );
    let n = result.frame_seconds.len().max(1) as f64;
    let mut stages = Map::new();
    for (k, v) in &result.stage_seconds {
        stages.insert(k.as_str().into(), Dynamic::from_float(v / n));
    }
    stages.insert(
        "images".into(),
        Dynamic::from_float(result.io_seconds / result.joints.len().max(1) as f64),
    );
    r.insert("stage_seconds".into(), stages.into());
    r.insert(
        "start_seconds".into(),
        Dynamic::from_float(result.start_seconds),
    );
    r.insert("files".into(), Dynamic::from_int(files.len() as INT));
    Ok(r)
}

/// Registers the tracker's script functions.
pub fn register(engine: &mut ApiBuilder) {
    function!(
        engine,
        "track::body",
        alias = "track_body",
        ["seq: String", "out: String", "Map"],
        "Tracks the body in a sequence folder (the layout `track::make_sequence` writes: cameras,
images per camera, `init_joints.csv` with an approximate first pose, and
`ground_truth.csv` when known) by analysis-by-synthesis: the textured puppet rendered into
every camera, its joint angles found frame by frame by annealing. Writes under `out`: the
tracked motion (`tracked.bvh`, `tracked_joints.csv`), the broadcast pictures
(`overlay/NNNN.png`), swing metrics (CSV and plots), `errors.csv` and `summary.json`.
Returns #{frames, mpjpe_mm, max_frame_mm, arm_mm (elbows and wrists; () without ground
truth), lost and recovered (the frames the loss detector marked), s_per_frame, stage_seconds
(per frame), start_seconds, files}; `track_status.csv` lists every frame's state.",
        |seq: &str, out: &str| track(seq, out, &Map::new())
    );
    function!(
        engine,
        "track::body",
        alias = "track_body",
        ["seq: String", "out: String", "options: Map", "Map"],
        "As `track::body(seq, out)` with options: `particles` per layer, `layers` (pyramid level
of each annealing layer, coarse first, e.g. [1, 1, 1, 0, 0]), `robust_sigma` (grey levels),
`mesh_cell` (metres), `lbs` (linear blend skinning instead of rigid), `background_frames`,
`prediction` (velocity factor), `prior_weight` (motion prior per squared move spread,
default 0.05), `limb_restarts` (limb stages also start from the previous,
the rest, a half-bent and a straightened limb pose; default true), `seed`, `frames` (track only the first
frames), `init` (`joints`: start from `init_joints.csv`; `auto`: find the person and
the pose from the first frame's images alone), `first_frame` (start there; needs `init: \"auto\"`),
`recover` (notice a lost track and search the body again; default false), `adapt_body`
(fit the puppet's segment lengths and girth to the person's silhouettes at the start;
default false), `torso_spread` (move spread of the pelvis and chest rotations, radians,
default 0.08), `anchor_limbs` (the trunk stage keeps the upper arms and thighs still in
the world; default false), `hands_apart` (metres: both hands hold one club, the arm
stages pay for wrists farther apart; default none), `golf_address` (the automatic start
searches from a golfer's address pose; default false), `lead_elbow_min` (degrees: the left
arm's stage pays for a left elbow bent below it, a golfer's straight lead arm; default
none), `passes` (spread factor of each pass of the stage hierarchy per frame, e.g. [1.0, 0.35]),
`overlay_every` (0: no pictures), `makehuman` (folder of the body model).",
        |seq: &str, out: &str, m: Map| track(seq, out, &m)
    );
}
