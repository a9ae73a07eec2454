//! Golf metrics of a swing from either source, markers or a joint trajectory, computed by the
//! same code ([`golf_metrics`] on sixteen tracking joints per frame; [`marker_joints`] makes
//! them from a GEARS marker trial).
//!
//! - pelvis and shoulder rotation, X-factor and centre of mass: [`swing_metrics`];
//! - lead (left) wrist speed and club-head speed by frame differences
//!   ([`frame_speeds`]), as the data's README gives its 9.75 m/s peak;
//! - the swing plane: the least-squares plane through the shaft (grip and head points of every
//!   frame the club is seen), or through the lead wrist's path without a club; its
//!   inclination to the ground in degrees and the RMS distance of the points from it.
//!
//! Marker joints ([`marker_joints`]): hips from the mean of the front and back waist markers
//! of each side, shoulders from `ShoulderBack` (`RShoulderTop` is missing in most frames of
//! the GEARS swing), neck `BackTop`, head `HeadTop`, elbows `ElbowOut`, wrists `WristTop`,
//! knees `KneeOut`, ankles `AnkleOut`, pelvis the waist centroid; NaN where a marker is
//! missing.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use super::bvh_export::{io_error, TrackingOutputError};
use super::club::{frame_speeds, peak, ClubFit};
use super::joints::JOINT_COUNT;
use super::swing_metrics::{swing_metrics, SwingMetrics};
use crate::body::MarkerTrial;
use crate::geometry::Vec3;
use crate::render::plot::{write_plot_pair, PlotSpec, Series, SeriesStyle};

const L_WRIST: usize = 6;

/// Marker labels (one, or two averaged) for each tracking joint of the GEARS set, in
/// [`TRACKING_JOINTS`](super::joints::TRACKING_JOINTS) order.
const GEARS_JOINTS: [&[&str]; JOINT_COUNT] = [
    &["WaistLeft", "WaistRight", "WaistLBack", "WaistRBack"],
    &["BackTop"],
    &["BackTop"],
    &["HeadTop"],
    &["LShoulderBack"],
    &["LElbowOut"],
    &["LWristTop"],
    &["RShoulderBack"],
    &["RElbowOut"],
    &["RWristTop"],
    &["WaistLeft", "WaistLBack"],
    &["LKneeOut"],
    &["LAnkleOut"],
    &["WaistRight", "WaistRBack"],
    &["RKneeOut"],
    &["RAnkleOut"],
];

/// Sixteen pseudo-joints per frame from a GEARS marker trial (see the module docs), engine
/// frame; the error names a marker the trial lacks.
pub fn marker_joints(trial: &MarkerTrial) -> Result<Vec<[Vec3; JOINT_COUNT]>, String> {
    let ids: Vec<Vec<usize>> = GEARS_JOINTS
        .iter()
        .map(|labels| {
            labels
                .iter()
                .map(|l| {
                    trial
                        .marker(l)
                        .ok_or_else(|| format!("{}: no marker {l:?}", trial.source))
                })
                .collect()
        })
        .collect::<Result<_, _>>()?;
    Ok((0..trial.frames)
        .map(|f| {
            std::array::from_fn(|j| {
                let p: Option<Vec<Vec3>> = ids[j].iter().map(|&m| trial.world(f, m)).collect();
                p.map_or(Vec3::repeat(f64::NAN), |p| {
                    p.iter().sum::<Vec3>() / p.len() as f64
                })
            })
        })
        .collect())
}

/// A least-squares plane.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SwingPlane {
    /// A point on it (the centroid of the points).
    pub point: Vec3,
    /// Unit normal (z component ≥ 0).
    pub normal: Vec3,
    /// Angle between the plane and the ground, degrees (0 flat, 90 upright).
    pub inclination_deg: f64,
    /// RMS distance of the points from the plane, metres.
    pub rms: f64,
}

/// The least-squares plane through `points` (the smallest-eigenvalue direction of their
/// scatter); `None` with fewer than three finite points.
pub fn fit_plane(points: &[Vec3]) -> Option<SwingPlane> {
    let pts: Vec<Vec3> = points
        .iter()
        .copied()
        .filter(|p| p.iter().all(|v| v.is_finite()))
        .collect();
    if pts.len() < 3 {
        return None;
    }
    let c = pts.iter().sum::<Vec3>() / pts.len() as f64;
    let scatter = pts.iter().fold(nalgebra::Matrix3::zeros(), |s, p| {
        s + (p - c) * (p - c).transpose()
    });
    let eig = scatter.symmetric_eigen();
    let k = eig.eigenvalues.imin();
    let mut n: Vec3 = eig.eigenvectors.column(k).into_owned().normalize();
    if n.z < 0.0 {
        n = -n;
    }
    let rms = (eig.eigenvalues[k].max(0.0) / pts.len() as f64).sqrt();
    Some(SwingPlane {
        point: c,
        normal: n,
        inclination_deg: n.z.clamp(-1.0, 1.0).acos().to_degrees(),
        rms,
    })
}

/// Golf metrics per frame (every vector has one entry per frame) and the swing plane.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct GolfMetrics {
    /// Rotations, X-factor, centre of mass ([`swing_metrics`]).
    pub swing: SwingMetrics,
    /// Lead (left) wrist speed by frame differences, m/s (NaN at frame 0 and gaps).
    pub lead_wrist_speed: Vec<f64>,
    /// Club-head speed by frame differences, m/s (NaN without a club).
    pub clubhead_speed: Vec<f64>,
    /// The swing plane (shaft, or lead wrist path without a club).
    pub plane: Option<SwingPlane>,
}

fn max_finite(v: &[f64]) -> f64 {
    peak(v).map_or(f64::NAN, |p| p.1)
}

impl GolfMetrics {
    /// Peak lead wrist speed, m/s.
    pub fn lead_wrist_peak(&self) -> f64 {
        max_finite(&self.lead_wrist_speed)
    }
    /// Peak club-head speed, m/s (NaN without a club).
    pub fn clubhead_peak(&self) -> f64 {
        max_finite(&self.clubhead_speed)
    }
    /// Largest X-factor magnitude, degrees.
    pub fn x_factor_peak(&self) -> f64 {
        let a: Vec<f64> = self.swing.x_factor_deg.iter().map(|x| x.abs()).collect();
        max_finite(&a)
    }
}

/// The golf metrics of `joints` sampled at `rate` per second, with the club if given (see the
/// module docs).
pub fn golf_metrics(
    joints: &[[Vec3; JOINT_COUNT]],
    rate: f64,
    club: Option<&ClubFit>,
) -> GolfMetrics {
    let finite = |p: Vec3| p.iter().all(|v| v.is_finite()).then_some(p);
    let wrist: Vec<Option<Vec3>> = joints.iter().map(|j| finite(j[L_WRIST])).collect();
    let (clubhead_speed, plane_points) = match club {
        Some(c) => (
            frame_speeds(&c.head, rate),
            c.grip.iter().chain(&c.head).flatten().copied().collect(),
        ),
        None => (
            vec![f64::NAN; joints.len()],
            wrist.iter().flatten().copied().collect::<Vec<Vec3>>(),
        ),
    };
    GolfMetrics {
        swing: swing_metrics(joints, rate),
        lead_wrist_speed: frame_speeds(&wrist, rate),
        clubhead_speed,
        plane: fit_plane(&plane_points),
    }
}

/// The metrics CSV: `time,pelvis_deg,shoulder_deg,x_factor_deg,com_x,com_y,com_z,
/// lead_wrist_speed,clubhead_speed`, one row per frame.
pub fn golf_metrics_csv(m: &GolfMetrics) -> String {
    let mut s = String::from(
        "time,pelvis_deg,shoulder_deg,x_factor_deg,com_x,com_y,com_z,lead_wrist_speed,clubhead_speed\n",
    );
    let get = |v: &[f64], i: usize| v.get(i).copied().unwrap_or(f64::NAN);
    let w = &m.swing;
    for (i, t) in w.time.iter().enumerate() {
        let c = w.com.get(i).copied().unwrap_or(Vec3::repeat(f64::NAN));
        let _ = writeln!(
            s,
            "{t},{},{},{},{},{},{},{},{}",
            get(&w.pelvis_deg, i),
            get(&w.shoulder_deg, i),
            get(&w.x_factor_deg, i),
            c.x,
            c.y,
            c.z,
            get(&m.lead_wrist_speed, i),
            get(&m.clubhead_speed, i)
        );
    }
    s
}

/// A plot series of the finite `values` against `time`.
pub(crate) fn series(name: &str, time: &[f64], values: &[f64], style: SeriesStyle) -> Series {
    Series {
        name: name.to_string(),
        points: time
            .iter()
            .zip(values)
            .filter(|(_, v)| v.is_finite())
            .map(|(&t, &v)| [t, v])
            .collect(),
        style,
    }
}

/// Writes `<dir>/<stem>.csv` ([`golf_metrics_csv`]), `<dir>/<stem>_rotation.png/.svg`
/// (pelvis, shoulders, X-factor) and `<dir>/<stem>_speed.png/.svg` (lead wrist and club
/// head); returns the paths. The directory must exist.
///
/// # Errors
///
/// [`TrackingOutputError`] naming the file that failed, or `InvalidInput` with no frames.
pub fn write_golf_metrics(
    dir: &Path,
    stem: &str,
    m: &GolfMetrics,
) -> Result<Vec<PathBuf>, TrackingOutputError> {
    let t = &m.swing.time;
    if t.is_empty() {
        return Err(TrackingOutputError::InvalidInput(
            "no frames in the golf metrics".to_string(),
        ));
    }
    let csv = dir.join(format!("{stem}.csv"));
    std::fs::write(&csv, golf_metrics_csv(m)).map_err(|e| io_error(&csv, e))?;
    let rotation = PlotSpec {
        title: "Pelvis and shoulder rotation".to_string(),
        x_label: "time (s)".to_string(),
        y_label: "rotation about z (°)".to_string(),
        series: vec![
            series("pelvis", t, &m.swing.pelvis_deg, SeriesStyle::Solid),
            series("shoulders", t, &m.swing.shoulder_deg, SeriesStyle::Solid),
            series("X-factor", t, &m.swing.x_factor_deg, SeriesStyle::Solid),
        ],
    };
    let (rp, rs) = write_plot_pair(&dir.join(format!("{stem}_rotation")), &rotation)?;
    let mut speed = vec![series(
        "lead wrist",
        t,
        &m.lead_wrist_speed,
        SeriesStyle::Solid,
    )];
    if m.clubhead_speed.iter().any(|v| v.is_finite()) {
        speed.push(series(
            "club head",
            t,
            &m.clubhead_speed,
            SeriesStyle::Solid,
        ));
    }
    let speeds = PlotSpec {
        title: "Lead wrist and club-head speed".to_string(),
        x_label: "time (s)".to_string(),
        y_label: "speed (m/s)".to_string(),
        series: speed,
    };
    let (sp, ss) = write_plot_pair(&dir.join(format!("{stem}_speed")), &speeds)?;
    Ok(vec![csv, rp, rs, sp, ss])
}
