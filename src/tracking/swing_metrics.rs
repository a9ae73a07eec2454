//! Sports metrics of a tracked motion (a golf swing, typically): pelvis and shoulder rotation,
//! their difference (the X-factor), the whole-body centre of mass and the hand speeds, per
//! frame; and their CSV and plots.
//!
//! - **Rotations**: the heading of the hip line `r_hip → l_hip` (and of the shoulder line
//!   `r_shoulder → l_shoulder`) about the vertical z axis, `atan2(y, x)` in degrees: 0 when the
//!   line points along +x (the body facing −y), positive counter-clockwise seen from above;
//!   unwrapped over time (no jump of 360°). A line that is vertical has no heading (NaN).
//! - **X-factor**: shoulder rotation minus pelvis rotation, degrees.
//! - **Centre of mass**: the mass-weighted mean of segment centres of mass, with the segment
//!   mass fractions and centre positions of Dempster's cadaver data as tabulated by Winter
//!   (*Biomechanics and Motor Control of Human Movement*, 4th ed., table 4.1), see
//!   [`SEGMENTS`]. Segments are defined by the sixteen tracking joints: the trunk runs from
//!   the mid-hip point to the mid-shoulder point; head and neck from `neck` to `head` (the
//!   crown); upper arm, forearm, thigh and shank between their joints. The tracking joints
//!   carry no hand or foot, so each hand is put at its wrist and each foot at its ankle
//!   (an approximation: both are a few centimetres off).
//! - **Hand speeds**: speed of each wrist, m/s, by central differences (second-order
//!   one-sided differences at the ends; zero with a single frame).

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use super::bvh_export::{io_error, validate_frames, TrackingOutputError};
use super::joints::JOINT_COUNT;
use crate::geometry::Vec3;
use crate::render::plot::{write_plot_pair, PlotSpec, Series, SeriesStyle};

// indices into TRACKING_JOINTS
const NECK: usize = 2;
const HEAD: usize = 3;
const L_SHOULDER: usize = 4;
const L_ELBOW: usize = 5;
const L_WRIST: usize = 6;
const R_SHOULDER: usize = 7;
const R_ELBOW: usize = 8;
const R_WRIST: usize = 9;
const L_HIP: usize = 10;
const L_KNEE: usize = 11;
const L_ANKLE: usize = 12;
const R_HIP: usize = 13;
const R_KNEE: usize = 14;
const R_ANKLE: usize = 15;

/// An end of a body segment: a tracking joint, or the midpoint of two.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SegmentEnd {
    /// A tracking joint (index into [`TRACKING_JOINTS`](super::joints::TRACKING_JOINTS)).
    Joint(usize),
    /// The midpoint of two tracking joints.
    Mid(usize, usize),
}

impl SegmentEnd {
    fn at(self, joints: &[Vec3; JOINT_COUNT]) -> Vec3 {
        match self {
            SegmentEnd::Joint(k) => joints[k],
            SegmentEnd::Mid(a, b) => (joints[a] + joints[b]) * 0.5,
        }
    }
}

/// One body segment for the centre of mass.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Segment {
    /// Segment name.
    pub name: &'static str,
    /// Proximal end.
    pub proximal: SegmentEnd,
    /// Distal end.
    pub distal: SegmentEnd,
    /// Fraction of the total body mass.
    pub mass_fraction: f64,
    /// Position of the segment's centre of mass from the proximal end, as a fraction of the
    /// segment length.
    pub com_from_proximal: f64,
}

const fn seg(
    name: &'static str,
    proximal: SegmentEnd,
    distal: SegmentEnd,
    mass_fraction: f64,
    com_from_proximal: f64,
) -> Segment {
    Segment {
        name,
        proximal,
        distal,
        mass_fraction,
        com_from_proximal,
    }
}

use SegmentEnd::{Joint as J, Mid as M};

/// The segment table (Dempster via Winter, table 4.1; fractions sum to 1):
///
/// | segment        | ends (tracking joints)           | mass  | CoM from proximal |
/// |----------------|----------------------------------|-------|-------------------|
/// | trunk          | mid-hips → mid-shoulders         | 0.497 | 0.50              |
/// | head and neck  | neck → head (crown)              | 0.081 | 0.55 (¹)          |
/// | upper arm ×2   | shoulder → elbow                 | 0.028 | 0.436             |
/// | forearm ×2     | elbow → wrist                    | 0.016 | 0.430             |
/// | hand ×2        | at the wrist (²)                 | 0.006 | —                 |
/// | thigh ×2       | hip → knee                       | 0.100 | 0.433             |
/// | shank ×2       | knee → ankle                     | 0.0465| 0.433             |
/// | foot ×2        | at the ankle (²)                 | 0.0145| —                 |
///
/// (¹) Winter puts the head-and-neck centre at the ear canal; on the neck-base-to-crown line
/// that is a little above the middle. (²) The tracking joints have no hand or foot end.
pub const SEGMENTS: [Segment; 14] = [
    seg(
        "trunk",
        M(L_HIP, R_HIP),
        M(L_SHOULDER, R_SHOULDER),
        0.497,
        0.50,
    ),
    seg("head_neck", J(NECK), J(HEAD), 0.081, 0.55),
    seg("l_upper_arm", J(L_SHOULDER), J(L_ELBOW), 0.028, 0.436),
    seg("r_upper_arm", J(R_SHOULDER), J(R_ELBOW), 0.028, 0.436),
    seg("l_forearm", J(L_ELBOW), J(L_WRIST), 0.016, 0.430),
    seg("r_forearm", J(R_ELBOW), J(R_WRIST), 0.016, 0.430),
    seg("l_hand", J(L_WRIST), J(L_WRIST), 0.006, 0.0),
    seg("r_hand", J(R_WRIST), J(R_WRIST), 0.006, 0.0),
    seg("l_thigh", J(L_HIP), J(L_KNEE), 0.100, 0.433),
    seg("r_thigh", J(R_HIP), J(R_KNEE), 0.100, 0.433),
    seg("l_shank", J(L_KNEE), J(L_ANKLE), 0.0465, 0.433),
    seg("r_shank", J(R_KNEE), J(R_ANKLE), 0.0465, 0.433),
    seg("l_foot", J(L_ANKLE), J(L_ANKLE), 0.0145, 0.0),
    seg("r_foot", J(R_ANKLE), J(R_ANKLE), 0.0145, 0.0),
];

/// Per-frame swing metrics; every vector has one entry per frame.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SwingMetrics {
    /// Time of each frame, seconds (`frame / fps`).
    pub time: Vec<f64>,
    /// Pelvis rotation about z, degrees, unwrapped (NaN where the hip line is vertical).
    pub pelvis_deg: Vec<f64>,
    /// Shoulder rotation about z, degrees, unwrapped (NaN where the shoulder line is vertical).
    pub shoulder_deg: Vec<f64>,
    /// X-factor: shoulder minus pelvis rotation, degrees.
    pub x_factor_deg: Vec<f64>,
    /// Whole-body centre of mass, metres (world, z up).
    pub com: Vec<Vec3>,
    /// Left wrist speed, m/s.
    pub l_hand_speed: Vec<f64>,
    /// Right wrist speed, m/s.
    pub r_hand_speed: Vec<f64>,
}

/// Heading (degrees, `atan2(y, x)`) of the horizontal part of `to − from`; NaN when it has
/// no horizontal part.
fn heading_deg(from: Vec3, to: Vec3) -> f64 {
    let d = to - from;
    if d.x.hypot(d.y) <= 1e-12 * d.norm().max(1e-300) {
        return f64::NAN;
    }
    d.y.atan2(d.x).to_degrees()
}

/// Unwraps angles in degrees so that consecutive finite values differ by at most 180°;
/// NaNs stay NaN and are skipped.
fn unwrap_deg(raw: &[f64]) -> Vec<f64> {
    let mut out = Vec::with_capacity(raw.len());
    let mut prev: Option<f64> = None;
    for &a in raw {
        if !a.is_finite() {
            out.push(f64::NAN);
            continue;
        }
        let v = match prev {
            None => a,
            Some(p) => a + 360.0 * ((p - a) / 360.0).round(),
        };
        prev = Some(v);
        out.push(v);
    }
    out
}

/// Whole-body centre of mass of one frame ([`SEGMENTS`]).
pub fn centre_of_mass(joints: &[Vec3; JOINT_COUNT]) -> Vec3 {
    let mut sum = Vec3::zeros();
    let mut mass = 0.0;
    for s in &SEGMENTS {
        let a = s.proximal.at(joints);
        let b = s.distal.at(joints);
        sum += (a + (b - a) * s.com_from_proximal) * s.mass_fraction;
        mass += s.mass_fraction;
    }
    sum / mass
}

/// Speeds of a point sampled at `dt` intervals: central differences inside, second-order
/// one-sided differences at the ends (first-order with two samples, zero with one).
fn speeds(points: &[Vec3], dt: f64) -> Vec<f64> {
    let n = points.len();
    (0..n)
        .map(|i| {
            let v = if n < 2 {
                Vec3::zeros()
            } else if n == 2 {
                (points[1] - points[0]) / dt
            } else if i == 0 {
                (-3.0 * points[0] + 4.0 * points[1] - points[2]) / (2.0 * dt)
            } else if i == n - 1 {
                (3.0 * points[n - 1] - 4.0 * points[n - 2] + points[n - 3]) / (2.0 * dt)
            } else {
                (points[i + 1] - points[i - 1]) / (2.0 * dt)
            };
            v.norm()
        })
        .collect()
}

/// The swing metrics of `frames` sampled at `fps` (see the [module docs](self)). Bad input
/// (no frames, `fps` not positive) gives empty or NaN series, never a panic; use
/// [`try_swing_metrics`] to get an error instead.
pub fn swing_metrics(frames: &[[Vec3; JOINT_COUNT]], fps: f64) -> SwingMetrics {
    let dt = 1.0 / fps;
    let n = frames.len();
    let time = (0..n).map(|i| i as f64 * dt).collect();
    let pelvis_raw: Vec<f64> = frames
        .iter()
        .map(|f| heading_deg(f[R_HIP], f[L_HIP]))
        .collect();
    let shoulder_raw: Vec<f64> = frames
        .iter()
        .map(|f| heading_deg(f[R_SHOULDER], f[L_SHOULDER]))
        .collect();
    let pelvis_deg = unwrap_deg(&pelvis_raw);
    // the shoulder line starts on the branch nearest the pelvis, so the X-factor is in ±180°
    let mut shoulder_deg = unwrap_deg(&shoulder_raw);
    if let Some(k) = (0..n).find(|&k| pelvis_deg[k].is_finite() && shoulder_deg[k].is_finite()) {
        let shift = 360.0 * ((pelvis_deg[k] - shoulder_deg[k]) / 360.0).round();
        shoulder_deg.iter_mut().for_each(|a| *a += shift);
    }
    let x_factor_deg = shoulder_deg
        .iter()
        .zip(&pelvis_deg)
        .map(|(s, p)| s - p)
        .collect();
    let com = frames.iter().map(centre_of_mass).collect();
    let l: Vec<Vec3> = frames.iter().map(|f| f[L_WRIST]).collect();
    let r: Vec<Vec3> = frames.iter().map(|f| f[R_WRIST]).collect();
    SwingMetrics {
        time,
        pelvis_deg,
        shoulder_deg,
        x_factor_deg,
        com,
        l_hand_speed: speeds(&l, dt),
        r_hand_speed: speeds(&r, dt),
    }
}

/// [`swing_metrics`] after checking the input.
///
/// # Errors
///
/// [`TrackingOutputError::InvalidInput`] for no frames, a non-finite joint (naming frame and
/// joint) or `fps` not positive.
pub fn try_swing_metrics(
    frames: &[[Vec3; JOINT_COUNT]],
    fps: f64,
) -> Result<SwingMetrics, TrackingOutputError> {
    validate_frames(frames, fps)?;
    Ok(swing_metrics(frames, fps))
}

/// The metrics CSV: header `time,pelvis_deg,shoulder_deg,x_factor_deg,com_x,com_y,com_z,
/// l_hand_speed,r_hand_speed`, one row per entry of `m.time` (missing values as NaN).
pub fn swing_metrics_csv(m: &SwingMetrics) -> String {
    let mut s = String::from(
        "time,pelvis_deg,shoulder_deg,x_factor_deg,com_x,com_y,com_z,l_hand_speed,r_hand_speed\n",
    );
    let get = |v: &Vec<f64>, i: usize| v.get(i).copied().unwrap_or(f64::NAN);
    for (i, t) in m.time.iter().enumerate() {
        let c = m.com.get(i).copied().unwrap_or(Vec3::repeat(f64::NAN));
        let _ = writeln!(
            s,
            "{t},{},{},{},{},{},{},{},{}",
            get(&m.pelvis_deg, i),
            get(&m.shoulder_deg, i),
            get(&m.x_factor_deg, i),
            c.x,
            c.y,
            c.z,
            get(&m.l_hand_speed, i),
            get(&m.r_hand_speed, i)
        );
    }
    s
}

fn series(name: &str, time: &[f64], values: &[f64]) -> Series {
    Series {
        name: name.to_string(),
        points: time.iter().zip(values).map(|(&t, &v)| [t, v]).collect(),
        style: SeriesStyle::Solid,
    }
}

/// Writes `<dir>/<stem>.csv` ([`swing_metrics_csv`]), `<dir>/<stem>_rotation.png/.svg`
/// (pelvis, shoulder rotation and X-factor over time) and `<dir>/<stem>_hand_speed.png/.svg`
/// (wrist speeds over time); returns the paths written. The directory must exist.
///
/// # Errors
///
/// [`TrackingOutputError::Io`] or [`TrackingOutputError::Plot`] naming the file that failed;
/// [`TrackingOutputError::InvalidInput`] when `m` has no frames.
pub fn write_swing_metrics(
    dir: &Path,
    stem: &str,
    m: &SwingMetrics,
) -> Result<Vec<PathBuf>, TrackingOutputError> {
    if m.time.is_empty() {
        return Err(TrackingOutputError::InvalidInput(
            "no frames in the swing metrics".to_string(),
        ));
    }
    let csv = dir.join(format!("{stem}.csv"));
    std::fs::write(&csv, swing_metrics_csv(m)).map_err(|e| io_error(&csv, e))?;
    let rotation = PlotSpec {
        title: "Pelvis and shoulder rotation".to_string(),
        x_label: "time (s)".to_string(),
        y_label: "rotation about z (°)".to_string(),
        series: vec![
            series("pelvis", &m.time, &m.pelvis_deg),
            series("shoulders", &m.time, &m.shoulder_deg),
            series("X-factor", &m.time, &m.x_factor_deg),
        ],
    };
    let (rp, rs) = write_plot_pair(&dir.join(format!("{stem}_rotation")), &rotation)?;
    let hands = PlotSpec {
        title: "Hand speeds".to_string(),
        x_label: "time (s)".to_string(),
        y_label: "wrist speed (m/s)".to_string(),
        series: vec![
            series("left wrist", &m.time, &m.l_hand_speed),
            series("right wrist", &m.time, &m.r_hand_speed),
        ],
    };
    let (hp, hs) = write_plot_pair(&dir.join(format!("{stem}_hand_speed")), &hands)?;
    Ok(vec![csv, rp, rs, hp, hs])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fractions_sum_to_one() {
        let total: f64 = SEGMENTS.iter().map(|s| s.mass_fraction).sum();
        assert!((total - 1.0).abs() < 1e-12, "{total}");
    }

    #[test]
    fn unwrap_crosses_180() {
        let u = unwrap_deg(&[170.0, -170.0, f64::NAN, -150.0]);
        assert_eq!(u[1], 190.0);
        assert!(u[2].is_nan());
        assert_eq!(u[3], 210.0);
    }

    #[test]
    fn bad_input_does_not_panic() {
        let m = swing_metrics(&[], 0.0);
        assert!(m.time.is_empty());
        let f = [Vec3::repeat(f64::NAN); JOINT_COUNT];
        let m = swing_metrics(&[f], -1.0);
        assert_eq!(m.time.len(), 1);
    }
}
