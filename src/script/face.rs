//! Script bindings of the face module: synthetic face sequences and face tracking.

use std::io::IsTerminal;
use std::path::Path;

use indicatif::ProgressBar;
use rhai::{Dynamic, Map, INT};

use super::convert::{rt_err, RResult};
use super::paths::{
    read_folder, read_folder_opt, read_folder_text, read_text, write_folder, write_path,
};
use super::tracking_sequence::{number, whole};
use super::{function, modules::ApiBuilder, register};
use crate::face::adapt::AdaptOptions;
use crate::face::adapt::FaceFit;
use crate::face::blendshapes::write_arkit_glb;
use crate::face::expressions::Expressions;
use crate::face::fap::FapRig;
use crate::face::fit_people::fit_people;
use crate::face::fit_run::{load_photos, write_fit_outputs, FitReport, PhotoSet};
use crate::face::model::FaceMesh;
use crate::face::muscles::MuscleRig;
use crate::face::people::Grouping;
use crate::face::preview::expression_image;
use crate::face::sequence::make_face_sequence;
use crate::face::sequence_files::FaceSequence;
use crate::face::sequence_options::FaceSequenceOptions;
use crate::face::track_run::{track_face_sequence, write_face_track_outputs};
use crate::face::tracker::FaceTrackerOptions;

fn sequence_options(m: &Map) -> RResult<FaceSequenceOptions> {
    let mut o = FaceSequenceOptions::default();
    for (k, v) in m {
        let k = k.as_str();
        match k {
            "frames" => o.frames = whole(v, k)? as usize,
            "fps" => o.fps = number(v, k)?,
            "width" => o.width = whole(v, k)?.min(u32::MAX as u64) as u32,
            "height" => o.height = whole(v, k)?.min(u32::MAX as u64) as u32,
            "cameras" => o.cameras = whole(v, k)? as usize,
            "distance" => o.distance = number(v, k)?,
            "focal" => o.focal = number(v, k)?,
            "yaw_deg" => o.yaw_deg = number(v, k)?,
            "noise" => o.noise = number(v, k)?,
            "light" => o.light = number(v, k)?,
            "texture_size" => o.texture_size = whole(v, k)? as usize,
            "seed" => o.seed = whole(v, k)?,
            "texture" => o.texture = Some(read_text(&v.to_string())?),
            "model" => o.model = Some(read_text(&v.to_string())?),
            "backgrounds" => o.backgrounds = Some(read_folder_text(&v.to_string())?),
            "faps" => {
                let arr = v
                    .read_lock::<rhai::Array>()
                    .ok_or_else(|| rt_err("`faps` must be an array of FAP numbers"))?;
                o.faps = arr
                    .iter()
                    .map(|d| whole(d, "faps[]").map(|n| n.min(255) as u8))
                    .collect::<RResult<Vec<_>>>()?;
            }
            other => {
                return Err(rt_err(format!(
                    "make_face_sequence: unknown option `{other}` (frames, fps, width, height, \
                     cameras, distance, focal, yaw_deg, noise, light, texture_size, seed, \
                     texture, model, backgrounds, faps)"
                )))
            }
        }
    }
    Ok(o)
}

fn make(out: &str, m: &Map) -> RResult<Map> {
    let o = sequence_options(m)?;
    let info = make_face_sequence(&write_folder(out)?, &o).map_err(rt_err)?;
    let mut r = Map::new();
    r.insert("frames".into(), Dynamic::from_int(info.frames as INT));
    r.insert(
        "cameras".into(),
        Dynamic::from_int(info.cameras.len() as INT),
    );
    r.insert(
        "faps".into(),
        Dynamic::from_array(
            info.faps
                .iter()
                .map(|&f| Dynamic::from_int(f as INT))
                .collect(),
        ),
    );
    Ok(r)
}

fn track(seq_dir: &str, out: &str, m: &Map) -> RResult<Map> {
    let mut o = FaceTrackerOptions::default();
    let (mut frames, mut overlay_every) = (None, 1usize);
    for (k, v) in m {
        let k = k.as_str();
        match k {
            "frames" => frames = Some(whole(v, k)? as usize),
            "overlay_every" => overlay_every = whole(v, k)? as usize,
            "sample_grid" => o.sample_grid = whole(v, k)? as usize,
            "gn_coarse" => o.gn_coarse = whole(v, k)? as usize,
            "gn_fine" => o.gn_fine = whole(v, k)? as usize,
            "particles" => o.particles = whole(v, k)? as usize,
            "layers" => o.layers = whole(v, k)? as usize,
            "fap_spread" => o.fap_spread = number(v, k)?,
            "fap_refine" => o.fap_refine = whole(v, k)? as usize,
            "prediction" => o.prediction = number(v, k)?,
            "robust_sigma" => o.robust_sigma = number(v, k)?,
            "seed" => o.seed = whole(v, k)?,
            other => {
                return Err(rt_err(format!(
                    "face_track: unknown option `{other}` (frames, overlay_every, sample_grid, \
                     gn_coarse, gn_fine, particles, layers, fap_spread, fap_refine, \
                     prediction, robust_sigma, seed)"
                )))
            }
        }
    }
    let seq = FaceSequence::open(&read_folder(seq_dir)?).map_err(rt_err)?;
    let total = frames.map_or(seq.info.frames, |f| f.min(seq.info.frames));
    let bar = std::io::stderr()
        .is_terminal()
        .then(|| ProgressBar::new(total as u64));
    let result = track_face_sequence(&seq, &o, frames, |done, _| {
        if let Some(b) = &bar {
            b.set_position(done as u64);
        }
    })
    .map_err(rt_err)?;
    if let Some(b) = bar {
        b.finish_and_clear();
    }
    let files = write_face_track_outputs(&seq, &result, &write_folder(out)?, overlay_every)
        .map_err(rt_err)?;
    let f = |x: Option<f64>| x.map_or(Dynamic::UNIT, Dynamic::from_float);
    let mut r = Map::new();
    r.insert("frames".into(), Dynamic::from_int(result.rows.len() as INT));
    r.insert("pose_err_deg".into(), f(result.mean_pose_err_deg()));
    r.insert("pose_err_max_deg".into(), f(result.max_pose_err_deg()));
    r.insert("fap_err".into(), f(result.mean_fap_err()));
    r.insert("fap_err_max".into(), f(result.max_fap_err()));
    r.insert("fps".into(), Dynamic::from_float(result.fps()));
    r.insert("files".into(), Dynamic::from_int(files.len() as INT));
    Ok(r)
}

/// Creates the folder of `path`.
fn parent_dir(path: &Path) -> RResult<()> {
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir).map_err(|e| rt_err(format!("{}: {e}", dir.display())))?;
    }
    Ok(())
}

fn expression_png(path: &str, m: &Map, yaw_deg: f64) -> RResult<()> {
    let values = m
        .iter()
        .map(|(k, v)| Ok((k.to_string(), number(v, k)?)))
        .collect::<RResult<Vec<_>>>()?;
    let img = expression_image(&values, 512, yaw_deg).map_err(rt_err)?;
    let path = write_path(path)?;
    parent_dir(&path)?;
    img.save(&path)
        .map_err(|e| rt_err(format!("{}: {e}", path.display())))
}

fn arkit(path: &str) -> RResult<()> {
    let mesh = FaceMesh::mediapipe().map_err(rt_err)?;
    let faps = FapRig::new(&mesh).map_err(rt_err)?;
    let muscles = MuscleRig::mediapipe(&mesh).map_err(rt_err)?;
    let path = write_path(path)?;
    parent_dir(&path)?;
    write_arkit_glb(&path, &mesh, &faps, &muscles).map_err(rt_err)
}

fn fit(images: &str, out: &str, m: &Map) -> RResult<Map> {
    let mut options = AdaptOptions::default();
    let (mut pts_dir, mut texture_size) = (None, 1024usize);
    let (mut grouping, mut per_photo) = (Grouping::default(), false);
    for (k, v) in m {
        let k = k.as_str();
        match k {
            "pts" => pts_dir = Some(v.to_string()),
            "texture_size" => texture_size = whole(v, k)? as usize,
            "support_fraction" => options.support_fraction = number(v, k)?,
            "rbf_smoothing" => options.rbf_smoothing = number(v, k)?,
            "contour_iterations" => options.contour_iterations = whole(v, k)? as usize,
            "group" => grouping = Grouping::parse(&v.to_string()).map_err(rt_err)?,
            "per_photo" => {
                per_photo = v
                    .as_bool()
                    .map_err(|t| rt_err(format!("face_fit: `per_photo` must be a bool, not {t}")))?
            }
            other => {
                return Err(rt_err(format!(
                    "face_fit: unknown option `{other}` (pts, group, per_photo, texture_size, \
                     support_fraction, rbf_smoothing, contour_iterations)"
                )))
            }
        }
    }
    if per_photo {
        grouping = Grouping::Photo;
    }
    let people = fit_people(
        &read_folder(images)?,
        read_folder_opt(pts_dir.as_deref())?.as_deref(),
        &write_folder(out)?,
        grouping,
        &options,
        texture_size,
    )
    .map_err(rt_err)?;
    let reports: Vec<&FitReport> = people.iter().map(|p| &p.report).collect();
    let all_errors: Vec<f64> = reports
        .iter()
        .flat_map(|r| r.errors_iod_pct.iter().copied())
        .collect();
    let mut r = fit_report_map(&FitReport {
        names: reports.iter().flat_map(|r| r.names.clone()).collect(),
        errors_iod_pct: all_errors,
        texture_coverage: mean(reports.iter().map(|r| r.texture_coverage)),
        mean_abs_change: mean(reports.iter().map(|r| r.mean_abs_change)),
        files: reports.iter().flat_map(|r| r.files.clone()).collect(),
    });
    let list = people
        .iter()
        .map(|p| {
            let mut m = fit_report_map(&p.report);
            m.insert("name".into(), Dynamic::from(p.name.clone()));
            m.insert("dir".into(), Dynamic::from(p.dir.display().to_string()));
            m.insert(
                "max_landmark_err_iod_pct".into(),
                Dynamic::from_float(p.max_error_iod_pct()),
            );
            Dynamic::from_map(m)
        })
        .collect();
    r.insert("people".into(), Dynamic::from_array(list));
    Ok(r)
}

fn mean(values: impl Iterator<Item = f64>) -> f64 {
    let (sum, n) = values.fold((0.0, 0usize), |(s, n), v| (s + v, n + 1));
    sum / n.max(1) as f64
}

/// A fit report as the map `face::fit` returns: images, landmark_err_iod_pct, errors, names,
/// texture_coverage, mean_abs_change_mm, files.
fn fit_report_map(report: &FitReport) -> Map {
    let mut r = Map::new();
    r.insert(
        "images".into(),
        Dynamic::from_int(report.names.len() as INT),
    );
    r.insert(
        "landmark_err_iod_pct".into(),
        Dynamic::from_float(report.mean_error_iod_pct()),
    );
    r.insert(
        "errors".into(),
        Dynamic::from_array(
            report
                .errors_iod_pct
                .iter()
                .map(|&e| Dynamic::from_float(e))
                .collect(),
        ),
    );
    r.insert(
        "names".into(),
        Dynamic::from_array(
            report
                .names
                .iter()
                .map(|n| Dynamic::from(n.clone()))
                .collect(),
        ),
    );
    r.insert(
        "texture_coverage".into(),
        Dynamic::from_float(report.texture_coverage),
    );
    r.insert(
        "mean_abs_change_mm".into(),
        Dynamic::from_float(report.mean_abs_change * 1000.0),
    );
    r.insert("files".into(), Dynamic::from_int(report.files.len() as INT));
    r
}

/// A face adaptation driven step by step from a script (every step can be undone).
#[derive(Clone)]
pub struct FaceFitSession {
    fit: FaceFit,
    photos: PhotoSet,
}

fn start(images: &str, m: &Map) -> RResult<FaceFitSession> {
    let mut pts_dir = None;
    for (k, v) in m {
        match k.as_str() {
            "pts" => pts_dir = Some(v.to_string()),
            other => {
                return Err(rt_err(format!(
                    "face_fit_start: unknown option `{other}` (pts)"
                )))
            }
        }
    }
    let pts_dir = read_folder_opt(pts_dir.as_deref())?;
    let photos = load_photos(&read_folder(images)?, pts_dir.as_deref()).map_err(rt_err)?;
    let generic = FaceMesh::mediapipe().map_err(rt_err)?;
    let fit = FaceFit::new(&generic, &photos.views, &AdaptOptions::default()).map_err(rt_err)?;
    Ok(FaceFitSession { fit, photos })
}

fn session_error(s: &FaceFitSession) -> f64 {
    let n = s.photos.views.len();
    (0..n).map(|v| s.fit.landmark_error_iod_pct(v)).sum::<f64>() / n.max(1) as f64
}

/// Registers the face functions.
pub fn register(engine: &mut ApiBuilder) {
    function!(
        engine,
        "face::make_sequence",
        alias = "make_face_sequence",
        ["out: String", "options: Map", "Map"],
        "Writes a synthetic face sequence with ground truth under `out`: the neutral model
(`model.obj`), its pose and expression (MPEG-4 FAP values) per frame (`ground_truth.csv`,
`init.csv` for frame 0), cameras (`cameras/camN.json`) and frames (`images/camN/NNNN.png`):
the textured face rendered from several cameras over real photos with lighting change and
noise. Options: `frames` (50), `fps` (25), `width` (640), `height` (480), `cameras` (3),
`distance` (m, 0.6), `focal` (px, 1000), `yaw_deg` (20), `noise` (2), `light` (0.04),
`texture_size` (512), `seed`, `texture` (PNG in the mesh's UV layout), `model` (OBJ in
metres), `backgrounds` (folder of photos), `faps` (array of FAP numbers). Returns
#{frames, cameras, faps}.",
        |out: &str, m: Map| make(out, &m)
    );
    function!(
        engine,
        "face::track",
        alias = "face_track",
        ["seq: String", "out: String", "options: Map", "Map"],
        "Tracks the head pose and expression in a face sequence folder (as `face::make_sequence`
writes: cameras, images, the neutral `model.obj` and `init.csv` with the first frame's pose
and FAPs): the model is textured from the first frame, then each frame's pose is found by
Gauss–Newton on the photometric error and its FAP values by simulated annealing. Writes
`tracked.csv`, `errors.csv` and `summary.json` (with ground truth) and `overlay/NNNN.png`
under `out`. Options: `frames`, `overlay_every` (1; 0: none), `sample_grid`, `gn_coarse`,
`gn_fine`, `particles`, `layers`, `fap_spread`, `fap_refine` (Gauss–Newton iterations
polishing the FAPs after the annealing), `prediction`, `robust_sigma`, `seed`.
Returns #{frames, pose_err_deg, pose_err_max_deg, fap_err, fap_err_max (fractions of each
FAP's range; () without ground truth), fps, files}.",
        |seq: &str, out: &str, m: Map| track(seq, out, &m)
    );
    function!(
        engine,
        "face::sliders",
        alias = "face_sliders",
        ["Array"],
        "Names of the expression sliders of the generic face (the seed's interface sliders such
as `Mouth width` or `Left eyelid`, then the six basic expressions `smile`, `surprise`, `anger`, `sadness`,
`disgust`, `fear`), in order.",
        || -> RResult<rhai::Array> {
            let mesh = FaceMesh::mediapipe().map_err(rt_err)?;
            let ex = Expressions::new(&mesh).map_err(rt_err)?;
            Ok(ex.names().into_iter().map(|n| Dynamic::from(n.to_string())).collect())
        }
    );
    function!(
        engine,
        "face::expression_png",
        alias = "face_expression_png",
        ["path: String", "values: Map", "()"],
        "Renders the generic face (MediaPipe canonical mesh with a procedural skin texture,
shaded, frontal, 512×512) with an expression to a PNG: `values` maps slider names (see
`face::sliders`) and MPEG-4 FAPs written `fap_N` (in FAP units: value / 1024 × FAPU) to their
values, e.g. #{ smile: 1.0 } or #{ fap_3: 800 }.",
        |path: &str, m: Map| expression_png(path, &m, 0.0)
    );
    function!(
        engine,
        "face::expression_png",
        alias = "face_expression_png",
        ["path: String", "values: Map", "yaw_deg: f64", "()"],
        "As `face::expression_png(path, values)`, seen from `yaw_deg` degrees to the side
(positive: from the subject's left).",
        |path: &str, m: Map, yaw: f64| expression_png(path, &m, yaw)
    );
    function!(
        engine,
        "face::export_arkit",
        alias = "face_export_arkit",
        ["path: String", "()"],
        "Writes the generic face as a glTF binary (.glb) with the 52 ARKit-style blendshapes as
named morph targets (`extras.targetNames`, the names Blender, Unity and three.js read), made
from the FAPs and muscles, and beside it a CSV of each shape's largest displacement.",
        |path: &str| arkit(path)
    );
    function!(
        engine,
        "face::fit",
        alias = "face_fit",
        ["images: String", "out: String", "options: Map", "Map"],
        "Adapts the generic face (MediaPipe canonical mesh) to the photos of folder `images` that
have a `.pts` file of the same stem (68 iBUG landmarks, 300-W convention; photos in any of
the formats of `geometry::image::PHOTO_EXTENSIONS`), one face per person. People: each
subfolder is one person; photos directly in `images` named `<person>_<view>` (the stem cut
at its last `_`) are grouped by person; the other photos there are one person named after
the folder. Option `group: \"folder\"` makes every photo of `images` one person (subfolders
ignored); `per_photo: true` (or `group: \"photo\"`) makes every photo a person. Per person:
each photo's camera (pose, focal length) and the 3D characteristic points together, then the
jaw-line contour in every photo, then an RBF deformation of the whole mesh (mouth and eye
regions kept apart), then the cameras again. Writes under `out` (one person) or
`out/<person>/` (several): `face.obj`/`.mtl`/`.png` and `face.glb` textured from that
person's photos, `overlay_NAME.png` per photo (the fitted mesh, given landmarks red, the
model's green), `render_front/left/right.png`, `error_map.png` (adapted vs generic face:
green outside, red inside) and `fit.csv`; and under `out`, `photos.csv` (person, photo,
landmark error) and `people.csv` (a summary row per person). Other options: `pts` (folder
of the .pts files with the same subfolders, default `images`), `texture_size` (1024),
`support_fraction` (RBF support as a fraction of the face width), `rbf_smoothing`,
`contour_iterations`. Returns #{images, landmark_err_iod_pct (mean over all photos, % of
the outer-eye-corner distance), errors, names, texture_coverage and mean_abs_change_mm
(means over people), files, people: [#{name, dir, images, landmark_err_iod_pct,
max_landmark_err_iod_pct, errors, names, texture_coverage, mean_abs_change_mm, files}]}.",
        |images: &str, out: &str, m: Map| fit(images, out, &m)
    );
    engine.register_type_with_name::<FaceFitSession>("FaceFit");
    function!(
        engine,
        "face::fit_start",
        alias = "face_fit_start",
        ["images: String", "options: Map", "FaceFit"],
        "Starts a step-by-step adaptation of the generic face to the photos of `images` that have
a `.pts` file of the same stem (option `pts`: the folder of the .pts files), all taken as
views of one person (subfolders are not looked at). Then call
`calibrate`, `adapt_contours`, `deform` and `refine_cameras` in that order; `undo` returns to
the state before the last step; `write` writes the outputs as `face::fit` does.",
        |images: &str, m: Map| start(images, &m)
    );
    register!(
        engine,
        "calibrate",
        ["fit: FaceFit", "()"],
        "Step 1: each photo's camera (pose and focal length) and the 3D characteristic points,
estimated together (views that see a point frontally count more; central points stay on
the symmetry plane).",
        |s: &mut FaceFitSession| s.fit.calibrate_and_reconstruct().map_err(rt_err)
    );
    register!(
        engine,
        "adapt_contours",
        ["fit: FaceFit", "()"],
        "Step 2: the jaw-line landmarks of every photo are matched to the mesh's silhouette in
that view (sliding contour points) and the mesh follows.",
        |s: &mut FaceFitSession| s.fit.adapt_contours().map_err(rt_err)
    );
    register!(
        engine,
        "deform",
        ["fit: FaceFit", "()"],
        "Step 3: the whole mesh follows the reconstructed points by RBF interpolation (the
compactly supported kernel of the seed's eq. 9), upper and lower lips and eyelids kept apart.",
        |s: &mut FaceFitSession| s.fit.deform().map_err(rt_err)
    );
    register!(
        engine,
        "refine_cameras",
        ["fit: FaceFit", "()"],
        "Step 4: the cameras refined on the deformed mesh.",
        |s: &mut FaceFitSession| s.fit.refine_cameras().map_err(rt_err)
    );
    register!(
        engine,
        "undo",
        ["fit: FaceFit", "String"],
        "Returns the adaptation to its state before the last step (the backup made by that
step) and returns the step's name; an error when there is nothing to undo.",
        |s: &mut FaceFitSession| -> RResult<String> {
            s.fit.undo().map(str::to_string).map_err(rt_err)
        }
    );
    register!(
        engine,
        "history",
        ["fit: FaceFit", "Array"],
        "Names of the steps done so far that `undo` can take back, oldest first.",
        |s: &mut FaceFitSession| -> rhai::Array {
            s.fit
                .history_steps()
                .into_iter()
                .map(|n| Dynamic::from(n.to_string()))
                .collect()
        }
    );
    register!(
        engine,
        "landmark_error",
        ["fit: FaceFit", "f64"],
        "Mean landmark error over the photos, % of each photo's inter-ocular distance (outer
eye corners); NaN before `calibrate`.",
        |s: &mut FaceFitSession| session_error(s)
    );
    register!(
        engine,
        "write",
        ["fit: FaceFit", "out: String", "Map"],
        "Writes the outputs of the adaptation in its current state under `out` (as `face::fit`:
textured OBJ and glb, overlays, renders, error map, fit.csv); returns #{images,
landmark_err_iod_pct, texture_coverage, files}.",
        |s: &mut FaceFitSession, out: &str| -> RResult<Map> {
            let report =
                write_fit_outputs(&s.fit, &s.photos, &write_folder(out)?, 1024).map_err(rt_err)?;
            let mut r = Map::new();
            r.insert(
                "images".into(),
                Dynamic::from_int(report.names.len() as INT),
            );
            r.insert(
                "landmark_err_iod_pct".into(),
                Dynamic::from_float(report.mean_error_iod_pct()),
            );
            r.insert(
                "texture_coverage".into(),
                Dynamic::from_float(report.texture_coverage),
            );
            r.insert("files".into(), Dynamic::from_int(report.files.len() as INT));
            Ok(r)
        }
    );
}
