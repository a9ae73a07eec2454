//! A golf club as a rigid body (grip, shaft, head) from its two marker clusters, held in the
//! hands ([`fit_club`]).
//!
//! The club's markers are fitted rigidly frame by frame: their positions in a reference frame
//! (the first frame where all are seen) are carried onto each frame's observations by the
//! best rotation and translation (Kabsch, at least three markers seen). The **head** is the
//! centroid of the cluster that moves fastest (the club head reaches ~50 m/s in a drive, the
//! shaft cluster under half that); the **grip** is the lead wrist marker's mean position in
//! the club's frame over the trial (the same closed form as a marker's offset on its bone:
//! the hands hold the grip, so the wrist is nearly fixed in the club's frame; its spread is
//! [`ClubFit::grip_rms`]); the **shaft** runs from grip to head. Speeds are frame
//! differences, `|x[i] − x[i−1]| · rate` ([`frame_speeds`]).

use super::puppet::kabsch;
use crate::body::MarkerTrial;
use crate::geometry::Vec3;

/// Default head cluster and shaft cluster labels of the GEARS set and its lead wrist marker.
pub const GEARS_CLUB: ([&str; 3], [&str; 3], &str) = (
    ["Marker_2:2:1", "Marker_2:2:2", "Marker_2:2:3"],
    ["Marker_3:3:1", "Marker_3:3:2", "Marker_3:3:3"],
    "LWristTop",
);

/// The club fitted over a trial.
#[derive(Clone, Debug)]
pub struct ClubFit {
    /// Samples per second of the trial.
    pub rate: f64,
    /// Trial indices of the head cluster's markers.
    pub head_markers: Vec<usize>,
    /// Trial indices of the shaft cluster's markers.
    pub shaft_markers: Vec<usize>,
    /// Club-head centre per frame (engine frame, metres); `None` where under three club
    /// markers are seen.
    pub head: Vec<Option<Vec3>>,
    /// Grip point (the hands) per frame; `None` as for `head`.
    pub grip: Vec<Option<Vec3>>,
    /// Shaft length, grip to head centre, metres.
    pub length: f64,
    /// RMS distance of the lead wrist marker from the fitted grip point, metres (how firmly
    /// the hands hold the club in the data).
    pub grip_rms: f64,
}

impl ClubFit {
    /// Club-head speed per frame, m/s ([`frame_speeds`]).
    pub fn head_speed(&self) -> Vec<f64> {
        frame_speeds(&self.head, self.rate)
    }

    /// The largest club-head speed and its frame.
    pub fn head_peak(&self) -> Option<(usize, f64)> {
        peak(&self.head_speed())
    }
}

/// The text of a club file (`club.csv` of a golf sequence, `tracked_club.csv` of a tracked
/// one): the header `frame,time,grip_x,grip_y,grip_z,head_x,head_y,head_z`, then one row per
/// `(frame, time, grip, head)`, metres and seconds at full precision.
pub fn club_csv(rows: impl IntoIterator<Item = (usize, f64, Vec3, Vec3)>) -> String {
    let mut csv = String::from("frame,time,grip_x,grip_y,grip_z,head_x,head_y,head_z\n");
    for (k, t, g, h) in rows {
        csv += &format!("{k},{t},{},{},{},{},{},{}\n", g.x, g.y, g.z, h.x, h.y, h.z);
    }
    csv
}

/// Speed per frame from frame differences: `|x[i] − x[i−1]| · rate`, NaN for frame 0 and
/// where either sample is missing.
pub fn frame_speeds(points: &[Option<Vec3>], rate: f64) -> Vec<f64> {
    (0..points.len())
        .map(
            |i| match (i.checked_sub(1).and_then(|j| points[j]), points[i]) {
                (Some(a), Some(b)) => (b - a).norm() * rate,
                _ => f64::NAN,
            },
        )
        .collect()
}

/// The frame and value of the largest finite entry.
pub fn peak(values: &[f64]) -> Option<(usize, f64)> {
    values
        .iter()
        .copied()
        .enumerate()
        .filter(|(_, v)| v.is_finite())
        .max_by(|a, b| a.1.total_cmp(&b.1))
}

/// Fits the club of `trial` from two marker clusters (labels; which one is the head is found
/// from the data: the cluster with the faster peak speed) and the lead wrist marker (see the
/// module docs). The error names the trial and the label missing, or says why no fit exists.
pub fn fit_club(
    trial: &MarkerTrial,
    cluster_a: &[&str],
    cluster_b: &[&str],
    lead_wrist: &str,
) -> Result<ClubFit, String> {
    let find = |labels: &[&str]| -> Result<Vec<usize>, String> {
        labels
            .iter()
            .map(|l| {
                trial
                    .marker(l)
                    .ok_or_else(|| format!("{}: no club marker {l:?}", trial.source))
            })
            .collect()
    };
    let (a, b) = (find(cluster_a)?, find(cluster_b)?);
    let wrist = trial
        .marker(lead_wrist)
        .ok_or_else(|| format!("{}: no lead wrist marker {lead_wrist:?}", trial.source))?;
    if !(trial.rate.is_finite() && trial.rate > 0.0) {
        return Err(format!(
            "{}: rate {} is not positive",
            trial.source, trial.rate
        ));
    }
    let centroid_peak = |ids: &[usize]| {
        let c: Vec<Option<Vec3>> = (0..trial.frames)
            .map(|f| {
                let p: Option<Vec<Vec3>> = ids.iter().map(|&m| trial.world(f, m)).collect();
                p.map(|p| p.iter().sum::<Vec3>() / p.len() as f64)
            })
            .collect();
        peak(&frame_speeds(&c, trial.rate)).map_or(0.0, |p| p.1)
    };
    let (head_markers, shaft_markers) = if centroid_peak(&a) >= centroid_peak(&b) {
        (a, b)
    } else {
        (b, a)
    };
    let all: Vec<usize> = head_markers.iter().chain(&shaft_markers).copied().collect();
    let seen = |f: usize| -> Vec<Option<Vec3>> { all.iter().map(|&m| trial.world(f, m)).collect() };
    let reference: Vec<Vec3> = (0..trial.frames)
        .find_map(|f| seen(f).into_iter().collect::<Option<Vec<Vec3>>>())
        .ok_or_else(|| format!("{}: no frame sees every club marker", trial.source))?;
    let head_ref = reference[..head_markers.len()].iter().sum::<Vec3>() / head_markers.len() as f64;
    // per frame: reference → frame
    let poses: Vec<Option<(nalgebra::UnitQuaternion<f64>, Vec3)>> = (0..trial.frames)
        .map(|f| {
            let pairs: Vec<(Vec3, Vec3)> = reference
                .iter()
                .zip(seen(f))
                .filter_map(|(r, o)| o.map(|o| (*r, o)))
                .collect();
            (pairs.len() >= 3).then(|| kabsch(&pairs)).flatten()
        })
        .collect();
    // the grip: the lead wrist's mean position in the reference frame
    let local: Vec<Vec3> = poses
        .iter()
        .enumerate()
        .filter_map(|(f, p)| {
            let (r, t) = (*p)?;
            Some(r.inverse() * (trial.world(f, wrist)? - t))
        })
        .collect();
    if local.is_empty() {
        return Err(format!(
            "{}: the lead wrist is never seen with the club",
            trial.source
        ));
    }
    let grip_ref = local.iter().sum::<Vec3>() / local.len() as f64;
    let grip_rms = (local
        .iter()
        .map(|l| (l - grip_ref).norm_squared())
        .sum::<f64>()
        / local.len() as f64)
        .sqrt();
    let place = |x: Vec3| -> Vec<Option<Vec3>> {
        poses.iter().map(|p| p.map(|(r, t)| r * x + t)).collect()
    };
    Ok(ClubFit {
        rate: trial.rate,
        head: place(head_ref),
        grip: place(grip_ref),
        length: (head_ref - grip_ref).norm(),
        grip_rms,
        head_markers,
        shaft_markers,
    })
}
