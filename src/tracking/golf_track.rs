//! The golf figures of a tracked broadcast sequence ([`golf_report`]): the golf metrics of the
//! tracked joints against those of the sequence's ground truth (joints and club, written by
//! [`super::golf_sequence`]), as the errors the acceptance names (peak lead-wrist
//! speed, peak X-factor, peak club-head speed) and plots of both curves.
//!
//! The tracked club is read from `tracked_club.csv` beside the tracked joints (written by
//! [`super::club_track`], on a tracked folder by [`track_club_in`], which also draws the club
//! into its broadcast pictures); without it the tracked club-head speed is NaN, and so is its
//! error.

use std::path::{Path, PathBuf};

use super::bvh_export::{io_error, TrackingOutputError};
use super::club::ClubFit;
use super::club_track::{track_club, ClubTrackOptions, TrackedClub};
use super::golf_metrics::{golf_metrics, series, write_golf_metrics, GolfMetrics};
use super::joints::JOINT_COUNT;
use super::sequence_files::{read_joints_csv, Sequence};
use super::track_outputs::{write_broadcast, ClubOverlay};
use super::tracker::TrackError;
use crate::geometry::Vec3;
use crate::render::plot::{write_plot_pair, PlotSpec, SeriesStyle};

/// Truth against tracking, for one sequence.
#[derive(Clone, Debug)]
pub struct GolfReport {
    /// Metrics of the ground truth (with the club).
    pub truth: GolfMetrics,
    /// Metrics of the tracked joints (and of the tracked club when there is one).
    pub tracked: GolfMetrics,
    /// Mean distance of the tracked club head from the truth's, metres (NaN without a
    /// tracked club or without the truth's).
    pub head_error: f64,
    /// Files written.
    pub files: Vec<PathBuf>,
}

impl GolfReport {
    /// Error of the tracked peak lead-wrist speed, percent of the truth's.
    pub fn wrist_speed_err_pct(&self) -> f64 {
        pct(self.tracked.lead_wrist_peak(), self.truth.lead_wrist_peak())
    }
    /// Error of the tracked peak X-factor, degrees (absolute).
    pub fn xfactor_err_deg(&self) -> f64 {
        (self.tracked.x_factor_peak() - self.truth.x_factor_peak()).abs()
    }
    /// Error of the tracked peak club-head speed, percent (NaN when the club is not tracked).
    pub fn clubhead_speed_err_pct(&self) -> f64 {
        pct(self.tracked.clubhead_peak(), self.truth.clubhead_peak())
    }
}

fn pct(x: f64, truth: f64) -> f64 {
    100.0 * (x - truth).abs() / truth.abs()
}

/// Tracks the club ([`super::club_track`]) of the golf sequence `seq` on the body tracked into
/// `tracked_dir` (its `tracked_joints.csv`, the frames from the sequence's frame of its first
/// row); writes `tracked_club.csv` there and draws the club into the broadcast pictures
/// found under `overlay/` (and `broadcast.png`).
pub fn track_club_in(
    seq: &Sequence,
    tracked_dir: &Path,
    options: &ClubTrackOptions,
) -> Result<TrackedClub, TrackError> {
    let path = tracked_dir.join("tracked_joints.csv");
    let rows = read_joints_csv(&path)?;
    let first = (rows.first().map_or(0.0, |r| r.1) * seq.fps).round() as usize;
    let joints: Vec<[Vec3; JOINT_COUNT]> = rows.iter().map(|r| r.2).collect();
    let club = track_club(seq, &joints, first, options)?;
    club.write_csv(&tracked_dir.join("tracked_club.csv"))
        .map_err(|e| TrackError::Invalid(e.to_string()))?;
    // the broadcast pictures the body's run wrote, drawn again with the club
    let overlays: Vec<usize> = std::fs::read_dir(tracked_dir.join("overlay"))
        .map(|d| {
            let mut v: Vec<usize> = (d.flatten())
                .filter_map(|e| e.file_name().to_str()?.strip_suffix(".png")?.parse().ok())
                .collect();
            v.sort_unstable();
            v
        })
        .unwrap_or_default();
    if !overlays.is_empty() {
        let overlay = ClubOverlay {
            grip: &club.grip,
            head: &club.head,
        };
        write_broadcast(seq, tracked_dir, first, &joints, &overlays, Some(overlay))
            .map_err(|e| TrackError::Invalid(e.to_string()))?;
    }
    Ok(club)
}

/// Reads `club.csv` (`frame,time,grip_x,grip_y,grip_z,head_x,head_y,head_z`) of a golf
/// sequence; `None` when the file is absent.
fn read_club(path: &Path, rate: f64) -> Result<Option<ClubFit>, TrackingOutputError> {
    if !path.is_file() {
        return Ok(None);
    }
    let text = crate::limits::read_to_string(path).map_err(|e| io_error(path, e))?;
    let (mut grip, mut head) = (Vec::new(), Vec::new());
    for (n, line) in text.lines().enumerate().skip(1) {
        let v: Vec<f64> = line
            .split(',')
            .map(|s| s.trim().parse::<f64>())
            .collect::<Result<_, _>>()
            .map_err(|e| {
                TrackingOutputError::InvalidInput(format!("{}:{}: {e}", path.display(), n + 1))
            })?;
        if v.len() != 8 {
            return Err(TrackingOutputError::InvalidInput(format!(
                "{}:{}: expected 8 values, got {}",
                path.display(),
                n + 1,
                v.len()
            )));
        }
        grip.push(Some(Vec3::new(v[2], v[3], v[4])));
        head.push(Some(Vec3::new(v[5], v[6], v[7])));
    }
    Ok(Some(ClubFit {
        rate,
        head_markers: Vec::new(),
        shaft_markers: Vec::new(),
        head,
        grip,
        length: f64::NAN,
        grip_rms: f64::NAN,
    }))
}

/// Compares the tracked joints in `tracked_dir/tracked_joints.csv` with the ground truth of
/// the golf sequence `seq` (its `ground_truth.csv` and `club.csv`), on the frames tracked
/// (from the sequence's frame of the first tracked row). Writes under `tracked_dir`:
/// `truth_metrics.csv`, `tracked_metrics.csv` (with their plots) and `golf_compare_speed`,
/// `golf_compare_xfactor` (PNG, SVG: truth and tracking on one plot).
pub fn golf_report(seq: &Sequence, tracked_dir: &Path) -> Result<GolfReport, TrackingOutputError> {
    let truth_all = seq.ground_truth.as_ref().ok_or_else(|| {
        TrackingOutputError::InvalidInput(format!(
            "{}: no ground_truth.csv to compare with",
            seq.dir.display()
        ))
    })?;
    let path = tracked_dir.join("tracked_joints.csv");
    let rows =
        read_joints_csv(&path).map_err(|e| TrackingOutputError::InvalidInput(e.to_string()))?;
    let first = (rows.first().map_or(0.0, |r| r.1) * seq.fps).round() as usize;
    let tracked: Vec<[Vec3; JOINT_COUNT]> = rows.iter().map(|r| r.2).collect();
    let n = tracked.len().min(truth_all.len().saturating_sub(first));
    if n < 2 {
        return Err(TrackingOutputError::InvalidInput(format!(
            "{}: {n} tracked frames within the sequence; speeds need at least 2",
            path.display()
        )));
    }
    let truth: Vec<[Vec3; JOINT_COUNT]> = truth_all[first..first + n].to_vec();
    let club = read_club(&seq.dir.join("club.csv"), seq.fps)?.map(|mut c| {
        c.head = c.head.into_iter().skip(first).take(n).collect();
        c.grip = c.grip.into_iter().skip(first).take(n).collect();
        c
    });
    let tracked_club = read_club(&tracked_dir.join("tracked_club.csv"), seq.fps)?.map(|mut c| {
        c.head.truncate(n);
        c.grip.truncate(n);
        c
    });
    let head_error = match (&club, &tracked_club) {
        (Some(t), Some(c)) => {
            let d: Vec<f64> = (t.head.iter().zip(&c.head))
                .filter_map(|(a, b)| Some((a.as_ref()? - b.as_ref()?).norm()))
                .collect();
            d.iter().sum::<f64>() / d.len() as f64
        }
        _ => f64::NAN,
    };
    let mut truth_m = golf_metrics(&truth, seq.fps, club.as_ref());
    let mut tracked_m = golf_metrics(&tracked[..n], seq.fps, tracked_club.as_ref());
    let t0 = first as f64 / seq.fps;
    for m in [&mut truth_m, &mut tracked_m] {
        m.swing.time.iter_mut().for_each(|t| *t += t0);
    }
    let mut files = write_golf_metrics(tracked_dir, "truth_metrics", &truth_m)?;
    files.extend(write_golf_metrics(
        tracked_dir,
        "tracked_metrics",
        &tracked_m,
    )?);
    let t = &truth_m.swing.time;
    let mut speed = PlotSpec {
        title: "Lead wrist and club-head speed: ground truth and tracking".to_string(),
        x_label: "time (s)".to_string(),
        y_label: "speed (m/s)".to_string(),
        series: vec![
            series("truth", t, &truth_m.lead_wrist_speed, SeriesStyle::Markers),
            series(
                "tracked",
                t,
                &tracked_m.lead_wrist_speed,
                SeriesStyle::Solid,
            ),
        ],
    };
    if tracked_club.is_some() {
        speed.series.extend([
            series(
                "club head, truth",
                t,
                &truth_m.clubhead_speed,
                SeriesStyle::Markers,
            ),
            series(
                "club head, tracked",
                t,
                &tracked_m.clubhead_speed,
                SeriesStyle::Dashed,
            ),
        ]);
    }
    let (a, b) = write_plot_pair(&tracked_dir.join("golf_compare_speed"), &speed)?;
    let xf = PlotSpec {
        title: "X-factor: ground truth and tracking".to_string(),
        x_label: "time (s)".to_string(),
        y_label: "shoulders − pelvis about z (°)".to_string(),
        series: vec![
            series(
                "truth",
                t,
                &truth_m.swing.x_factor_deg,
                SeriesStyle::Markers,
            ),
            series(
                "tracked",
                t,
                &tracked_m.swing.x_factor_deg,
                SeriesStyle::Solid,
            ),
        ],
    };
    let (c, d) = write_plot_pair(&tracked_dir.join("golf_compare_xfactor"), &xf)?;
    files.extend([a, b, c, d]);
    Ok(GolfReport {
        truth: truth_m,
        tracked: tracked_m,
        head_error,
        files,
    })
}
