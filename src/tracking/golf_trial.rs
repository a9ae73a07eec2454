//! A marker-captured golf swing end to end ([`run_golf_trial`]): the C3D read, the puppet
//! fitted to the body markers, the club fitted to its markers, the fitted motion written as BVH,
//! the mannequin posed with it (an OBJ at the frame of peak club-head speed), and the golf
//! metrics from the markers and from the fitted joints (CSV and plots of each).

use std::path::{Path, PathBuf};

use super::bvh_export::to_bvh_string;
use super::club::{fit_club, GEARS_CLUB};
use super::golf_metrics::{golf_metrics, marker_joints, write_golf_metrics, GolfMetrics};
use super::marker_fit::{fit_markers, MarkerFit, MarkerFitOptions};
use super::marker_set::MarkerSet;
use crate::body::{read_c3d, Mannequin, Pose};
use crate::geometry::export_frame::ExportFrame;
use crate::geometry::obj::write_obj;

/// What [`run_golf_trial`] measured and wrote.
#[derive(Clone, Debug)]
pub struct GolfTrialReport {
    /// Frames in the trial (all, not only those fitted).
    pub frames: usize,
    /// The marker fit's residual RMS over all valid body-marker samples, metres.
    pub residual_rms: f64,
    /// Metrics from the markers (and the club).
    pub markers: GolfMetrics,
    /// Metrics from the fitted joints (and the club), on the fitted frames.
    pub fitted: GolfMetrics,
    /// Shaft length (grip to head centre), metres.
    pub club_length: f64,
    /// RMS distance of the lead wrist from the grip point, metres.
    pub grip_rms: f64,
    /// Frame of peak club-head speed (the posed OBJ's frame).
    pub peak_frame: usize,
    /// Files written.
    pub files: Vec<PathBuf>,
}

fn io(path: &Path, e: impl std::fmt::Display) -> String {
    format!("{}: {e}", path.display())
}

/// Reads the GEARS swing `c3d`, fits `mannequin`'s puppet with `options` to every `every`-th
/// frame (1: all; the metrics from the markers always use every frame) and the club, and
/// writes under `out` (created): `fit.bvh`, `residuals.csv`, `posed.obj` (the mannequin at
/// the frame of peak club-head speed, +Y up as Blender reads OBJ, metres), `markers_metrics.csv` and
/// `fitted_metrics.csv` with their `_rotation` and `_speed` plots (PNG and SVG). Errors name
/// the file or the step that failed.
pub fn run_golf_trial(
    c3d: &Path,
    mannequin: &Mannequin,
    out: &Path,
    options: &MarkerFitOptions,
    every: usize,
) -> Result<GolfTrialReport, String> {
    let mut trial = read_c3d(c3d).map_err(|e| e.to_string())?;
    trial.up = trial.infer_up();
    std::fs::create_dir_all(out).map_err(|e| io(out, e))?;
    let every = every.max(1);
    let sub = trial.every(every);
    let fit = fit_markers(mannequin, &sub, &MarkerSet::gears(), options)?;
    let (a, b, wrist) = GEARS_CLUB;
    let club = fit_club(&trial, &a, &b, wrist)?;
    let sub_club = fit_club(&sub, &a, &b, wrist)?;
    let joints = fit.joints();
    let mut files = Vec::new();
    let bvh = out.join("fit.bvh");
    let text = to_bvh_string(&joints, sub.rate, Some(&fit.puppet.rest_joints()))
        .map_err(|e| e.to_string())?;
    std::fs::write(&bvh, text).map_err(|e| io(&bvh, e))?;
    let csv = out.join("residuals.csv");
    std::fs::write(&csv, fit.residual_csv()).map_err(|e| io(&csv, e))?;
    files.extend([bvh, csv]);
    let sub_peak = sub_club.head_peak().map_or(0, |p| p.0);
    files.push(write_posed(mannequin, &fit, sub_peak, out)?);
    let from_markers = golf_metrics(&marker_joints(&trial)?, trial.rate, Some(&club));
    let fitted = golf_metrics(&joints, sub.rate, Some(&sub_club));
    for (stem, m) in [
        ("markers_metrics", &from_markers),
        ("fitted_metrics", &fitted),
    ] {
        files.extend(write_golf_metrics(out, stem, m).map_err(|e| e.to_string())?);
    }
    Ok(GolfTrialReport {
        frames: trial.frames,
        residual_rms: fit.rms(),
        markers: from_markers,
        fitted,
        club_length: club.length,
        grip_rms: club.grip_rms,
        peak_frame: sub_peak * every,
        files,
    })
}

/// The fitted puppet's skin at `frame` as `out/posed.obj`.
fn write_posed(
    mannequin: &Mannequin,
    fit: &MarkerFit,
    frame: usize,
    out: &Path,
) -> Result<PathBuf, String> {
    let mut pose = Pose::identity(fit.puppet.bone_count());
    fit.puppet.pose_into(&fit.params[frame], &mut pose);
    let mut skin = Vec::new();
    fit.puppet.skin(&pose, &mut skin);
    let path = out.join("posed.obj");
    let frame = ExportFrame {
        up: crate::geometry::export_frame::UpAxis::Y,
        units: crate::geometry::export_frame::Units::Metres,
    };
    write_obj(&path, &skin, mannequin.triangles(), None, frame).map_err(|e| e.to_string())?;
    Ok(path)
}
