//! Tracking the golf club in a broadcast sequence ([`track_club`]), after the body: the club
//! is a straight shaft held in the lead hand, found in every frame as the 3D segment whose
//! projections run along thin foreground lines in all cameras.
//!
//! **Evidence.** Per camera the colour distance of the image from the background model
//! (lighting gain removed, linear up to `CONTRAST` grey levels) is read at points along
//! the projected shaft, and each point scores how much more it differs from the background
//! than the two points `ridge_px` pixels to either side across the line: a thin foreground
//! line (the shaft, 1–3 pixels wide) scores; the background scores nothing, and so do the
//! body's parts, wider than the test's reach, and the body's edges (one side is as
//! foreground as the centre). In the downswing the shutter smears the shaft into a faint
//! wedge of copies a few pixels apart; the same test then also runs over the band the
//! predicted turn sweeps while the shutter is open (the shutter time is read from the
//! sequence's `golf.shutter`), each point keeping its best. Each point pays a threshold, and
//! the sum is weighed by the segment's length, so the shaft is credited per metre seen.
//!
//! **Search.** The club's length is a driver's ([`DRIVER_LENGTH`], or given; it can also be
//! searched over the first frames). Each frame: grips on a grid around the tracked lead
//! hand and around the grip predicted from the last two frames, times
//! [`ClubTrackOptions::directions`] directions over the whole sphere (the shaft turns up to
//! 40° between frames at 50 fps), scored on a max-pooled evidence pyramid (a line one
//! pixel wide keeps its strength while the search's basin widens); the best few, with the
//! predicted shaft, are refined by a pattern search over grip and direction level by level
//! to full resolution. Weak priors keep the grip `HAND` from the tracked lead wrist and
//! near its prediction, and the turn near the predicted one. Then the path through each
//! frame's refined hypotheses that best trades evidence against acceleration is chosen by
//! dynamic programming (`club_path`), which removes single-frame jumps at impact.
//! The head is the grip plus the length along the shaft.

use std::path::Path;
use std::time::Instant;

use nalgebra::UnitQuaternion;
use rayon::prelude::*;

use super::background_model::background_models;
use super::bvh_export::{io_error, TrackingOutputError};
use super::club::club_csv;
use super::club_evidence::{evidence_pyramid, EvidenceLevel, LEVELS};
use super::club_path::{smoothest_path, MotionWeights, Shaft};
use super::cost::{FrameViews, Robust};
use super::joints::{joint_index, JOINT_COUNT};
use super::sequence_files::Sequence;
use super::tracker::TrackError;
use crate::geometry::Vec3;

/// How far the club's butt stands past the grip point (the hands), metres.
const BUTT: f64 = 0.1;
/// How far the head's centre lies past the end of the shaft's thin line, metres (the
/// engine's club: a head of radius [`super::club_mesh::HEAD_RADIUS`]).
const HEAD_RADIUS: f64 = super::club_mesh::HEAD_RADIUS;
/// A driver's length from the grip point to the head's centre, metres: 45.5 in (1.156 m)
/// overall, less the butt end above the lead hand and the head's centre beyond the shaft.
pub const DRIVER_LENGTH: f64 = 1.10;
/// How far from the lead wrist the hands hold the grip, metres.
const HAND: f64 = 0.1;
/// Radius (metres) of the grips tried around the hands, and their spacing.
const GRIP_REACH: f64 = 0.15;
const GRIP_STEP: f64 = 0.05;
/// Half-widths (full-resolution pixels) of the band tested across the line besides the
/// line itself: a shaft smeared by the shutter in the downswing is a faint wedge, several
/// copies a few pixels apart, which a thin-line test alone does not see.
const BLUR_HALF_WIDTHS: [f64; 3] = [0.0, 3.0, 6.0];
/// Distance from the lead shoulder to the grip, metres: the shaft turns about the
/// shoulders in the downswing, so a point `r` along it sweeps as one `ARM + r` from them.
const ARM: f64 = 0.6;
/// Coarse candidates refined per frame.
const STARTS: usize = 16;

/// Settings of the club tracker.
#[derive(Clone, Debug)]
pub struct ClubTrackOptions {
    /// Directions tried over the sphere in the coarse search.
    pub directions: usize,
    /// Points sampled along the shaft per camera.
    pub samples: usize,
    /// Distance (pixels) of the two side points of the ridge test.
    pub ridge_px: f64,
    /// What each sampled point pays, in ridge units (0..1): the evidence a point must carry
    /// to lengthen the segment.
    pub threshold: f64,
    /// The club's length from the grip point (the lead hand) to the head's centre, metres,
    /// when known: by default a driver's, [`DRIVER_LENGTH`]. `None`: searched over the
    /// first frames (see `length_frames`; measured less steady than the club's standard
    /// length, docs/golf.md).
    pub length: Option<f64>,
    /// Lengths (grip to the end of the shaft's thin line, metres) searched when `length` is
    /// `None`.
    pub length_range: (f64, f64),
    /// Frames at the start over which the length is searched (its median is kept after).
    pub length_frames: usize,
    /// Scale (metres) and weight of the prior pulling the grip to the tracked lead wrist.
    pub wrist_sigma: f64,
    /// Weight of that prior (in score units: a mean ridge per sample summed over cameras).
    pub wrist_weight: f64,
    /// Scale (metres) of the prior pulling the grip to its prediction from the last frames.
    pub motion_sigma: f64,
    /// Weight of that prior.
    pub motion_weight: f64,
    /// Scale (radians) of the prior pulling the shaft's direction to its prediction.
    pub turn_sigma: f64,
    /// Weight of that prior.
    pub turn_weight: f64,
    /// Frames used for the background model (as the body tracker).
    pub background_frames: usize,
}

impl Default for ClubTrackOptions {
    fn default() -> Self {
        ClubTrackOptions {
            directions: 3000,
            samples: 48,
            ridge_px: 3.0,
            threshold: 0.15,
            length: Some(DRIVER_LENGTH),
            length_range: (0.8, 1.4),
            length_frames: 5,
            wrist_sigma: 0.12,
            wrist_weight: 0.15,
            motion_sigma: 0.15,
            motion_weight: 0.15,
            turn_sigma: 0.8,
            turn_weight: 0.15,
            background_frames: 25,
        }
    }
}

/// The club found in each tracked frame.
#[derive(Clone, Debug, Default)]
pub struct TrackedClub {
    /// Frames per second.
    pub rate: f64,
    /// The sequence's frame of the first entry.
    pub first_frame: usize,
    /// Grip point (the hands) per frame, metres, world.
    pub grip: Vec<Vec3>,
    /// Head centre per frame.
    pub head: Vec<Vec3>,
    /// Image evidence of the chosen segment per frame (mean ridge per sample, summed over
    /// cameras, thresholds paid).
    pub scores: Vec<f64>,
    /// Shaft length kept (grip to head centre), metres.
    pub length: f64,
    /// Wall time of the whole pass, seconds.
    pub seconds: f64,
}

impl TrackedClub {
    /// Writes `frame,time,grip_x,grip_y,grip_z,head_x,head_y,head_z` (the layout of a golf
    /// sequence's `club.csv`).
    pub fn write_csv(&self, path: &Path) -> Result<(), TrackingOutputError> {
        let s = club_csv(
            (self.grip.iter().zip(&self.head).enumerate()).map(|(k, (g, h))| {
                let f = self.first_frame + k;
                (f, f as f64 / self.rate, *g, *h)
            }),
        );
        std::fs::write(path, s).map_err(|e| io_error(path, e))
    }
}

/// What a frame's search is pulled toward.
struct Priors {
    /// The tracked lead wrist: the grip is held [`HAND`] from it, in any direction (the
    /// wrist cocks and uncocks through the swing).
    wrist: Vec3,
    /// Where the coarse search centres its grips: the forearm carried on past the wrist.
    hand_guess: Vec3,
    /// The grip predicted from the last two frames.
    predicted: Option<Vec3>,
    /// The shaft's direction predicted from the last two frames (its turn between them,
    /// damped).
    predicted_dir: Option<Vec3>,
    /// How far a point one metre from the shoulders is carried while the shutter is half
    /// open, by the predicted turn (a vector; `None` without a shutter time or a turn).
    sweep: Option<Vec3>,
}

/// Tracks the club through the frames of `seq` from `first_frame`, one per row of `joints`
/// (the tracked body: its lead, left, hand starts the grip). Errors name the sequence.
pub fn track_club(
    seq: &Sequence,
    joints: &[[Vec3; JOINT_COUNT]],
    first_frame: usize,
    options: &ClubTrackOptions,
) -> Result<TrackedClub, TrackError> {
    let t0 = Instant::now();
    if options.directions < 10 || options.samples < 4 {
        return Err(TrackError::Invalid(format!(
            "club tracking: directions ({}) must be at least 10 and samples ({}) at least 4",
            options.directions, options.samples
        )));
    }
    if first_frame + joints.len() > seq.frames {
        return Err(TrackError::Invalid(format!(
            "{}: {} tracked frames from frame {first_frame} run past the sequence's {}",
            seq.dir.display(),
            joints.len(),
            seq.frames
        )));
    }
    let backgrounds = background_models(seq, options.background_frames)?;
    let mut views = FrameViews::new(&seq.cameras, &backgrounds, 1, Robust { sigma: 40.0 });
    let sphere = sphere_directions(options.directions);
    let shutter_frames = shutter_seconds(seq).map(|s| s * seq.fps);
    let [l_elbow, l_wrist] = ["l_elbow", "l_wrist"]
        .map(|n| joint_index(n).unwrap_or_else(|| unreachable!("tracking joint {n}")));
    let mut out = TrackedClub {
        rate: seq.fps,
        first_frame,
        ..TrackedClub::default()
    };
    let mut lengths = Vec::new();
    let mut hypotheses: Vec<Vec<(Shaft, f64)>> = Vec::new();
    let mut images = Vec::new();
    let mut pyramid: Vec<Vec<EvidenceLevel>> = Vec::new();
    for (k, j) in joints.iter().enumerate() {
        seq.frame_images_into(first_frame + k, &mut images)?;
        views.set_frame(&images);
        evidence_pyramid(&views, &mut pyramid);
        let free_length = options.length.is_none() && k < options.length_frames;
        let length = match options.length {
            Some(l) => l - HEAD_RADIUS,
            None if free_length => 0.5 * (options.length_range.0 + options.length_range.1),
            None => out.length,
        };
        out.length = length;
        let predicted = match out.grip.len() {
            0 => None,
            1 => Some(out.grip[0]),
            n => Some(out.grip[n - 1] + 0.7 * (out.grip[n - 1] - out.grip[n - 2])),
        };
        let dirs: Vec<Vec3> = (out.head.iter().zip(&out.grip).rev().take(2))
            .filter_map(|(h, g)| (h - g).try_normalize(1e-9))
            .collect();
        let predicted_dir = match dirs[..] {
            [d1, d2] => {
                Some(UnitQuaternion::rotation_between(&d2, &d1).map_or(d1, |q| q.powf(0.7) * d1))
            }
            [d1] => Some(d1),
            _ => None,
        };
        // the hands: the forearm carried on past the wrist
        let forearm = (j[l_wrist] - j[l_elbow])
            .try_normalize(1e-9)
            .unwrap_or_else(Vec3::zeros);
        let priors = Priors {
            wrist: j[l_wrist],
            hand_guess: j[l_wrist] + HAND * forearm,
            predicted,
            predicted_dir,
            sweep: match (shutter_frames, predicted_dir, dirs.first()) {
                (Some(f), Some(p), Some(d)) => Some((p - d) * 0.5 * f),
                _ => None,
            },
        };
        let frame = FrameSearch {
            pyramid: &pyramid,
            priors: &priors,
            options,
        };
        let (best, found) = frame.search(&sphere, predicted_dir, length, free_length);
        hypotheses.push(found.iter().map(|h| (*h, frame.evidence(h))).collect());
        if free_length {
            lengths.push(best.length);
            out.length = median(&lengths);
        }
        out.scores.push(frame.score(0, &best));
        out.grip.push(best.grip);
        out.head
            .push(best.grip + best.dir * (best.length + HEAD_RADIUS));
    }
    // the smoothest path through each frame's hypotheses, with the length kept
    let weights = MotionWeights {
        turn_sigma: options.turn_sigma,
        turn_weight: options.turn_weight,
        motion_sigma: options.motion_sigma,
        motion_weight: options.motion_weight,
    };
    let path = smoothest_path(&hypotheses, &weights);
    for (k, &i) in path.iter().enumerate() {
        let s = hypotheses[k][i].0;
        out.grip[k] = s.grip;
        out.head[k] = s.grip + s.dir * (out.length + HEAD_RADIUS);
        out.scores[k] = hypotheses[k][i].1;
    }
    out.length += HEAD_RADIUS;
    out.seconds = t0.elapsed().as_secs_f64();
    Ok(out)
}

/// The shutter time of a golf sequence's cameras, from its `sequence.json` (`golf.shutter`).
fn shutter_seconds(seq: &Sequence) -> Option<f64> {
    let text = crate::limits::read_to_string(&seq.dir.join("sequence.json")).ok()?;
    let v: serde_json::Value = serde_json::from_str(&text).ok()?;
    v.get("golf")?
        .get("shutter")?
        .as_f64()
        .filter(|s| s.is_finite() && *s >= 0.0)
}

fn median(v: &[f64]) -> f64 {
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    s[s.len() / 2]
}

/// One frame's search: the evidence pyramid and what the club is pulled toward.
struct FrameSearch<'a> {
    pyramid: &'a [Vec<EvidenceLevel>],
    priors: &'a Priors,
    options: &'a ClubTrackOptions,
}

impl FrameSearch<'_> {
    /// The best shaft: the coarse search over grips × directions (× lengths) at the coarsest
    /// level, then the pattern search from the best few, level by level to full resolution.
    fn search(
        &self,
        sphere: &[Vec3],
        last_dir: Option<Vec3>,
        length: f64,
        free: bool,
    ) -> (Shaft, Vec<Shaft>) {
        let o = self.options;
        let mut dirs: Vec<Vec3> = sphere.to_vec();
        dirs.extend(last_dir);
        let lengths: Vec<f64> = if free {
            let (a, b) = o.length_range;
            (0..4)
                .map(|i| a + (b - a) * (i as f64 + 0.5) / 4.0)
                .collect()
        } else {
            vec![length]
        };
        let mut grips = ball(self.priors.hand_guess, GRIP_REACH, GRIP_STEP);
        if let Some(p) = self.priors.predicted {
            grips.extend(ball(p, 2.0 * GRIP_STEP, GRIP_STEP));
        }
        let coarse = LEVELS - 1;
        let candidates: Vec<Shaft> = grips
            .iter()
            .flat_map(|&grip| {
                let lengths = &lengths;
                dirs.iter().flat_map(move |&dir| {
                    lengths
                        .iter()
                        .map(move |&length| Shaft { grip, dir, length })
                })
            })
            .collect();
        let scored: Vec<f64> = candidates
            .par_iter()
            .map(|s| self.objective(coarse, s))
            .collect();
        let mut order: Vec<usize> = (0..candidates.len()).collect();
        order.sort_by(|&a, &b| scored[b].total_cmp(&scored[a]).then(a.cmp(&b)));
        // the best few, their directions at least 5° apart or their grips 6 cm
        let mut starts: Vec<Shaft> = Vec::new();
        for &i in &order {
            let c = candidates[i];
            if starts
                .iter()
                .all(|s| s.dir.dot(&c.dir) < 0.996 || (s.grip - c.grip).norm() > 0.06)
            {
                starts.push(c);
            }
            if starts.len() == STARTS {
                break;
            }
        }
        if let (Some(grip), Some(dir)) = (self.priors.predicted, last_dir) {
            starts.push(Shaft { grip, dir, length });
        }
        let refined: Vec<(Shaft, f64)> = starts
            .par_iter()
            .map(|s| {
                let mut best = *s;
                for level in (0..LEVELS).rev() {
                    best = self.refine(level, best, free);
                }
                (best, self.objective(0, &best))
            })
            .collect();
        let best = (refined.iter())
            .fold(None::<(Shaft, f64)>, |best, &(s, f)| match best {
                Some((_, bf)) if bf >= f => best,
                _ => Some((s, f)),
            })
            .map_or(starts[0], |(s, _)| s);
        // the distinct ends of the refinements, the hypotheses of the path search
        let mut distinct: Vec<Shaft> = Vec::new();
        for (s, _) in refined {
            if distinct
                .iter()
                .all(|d| d.dir.dot(&s.dir) < 0.9986 || (d.grip - s.grip).norm() > 0.02)
            {
                distinct.push(s);
            }
        }
        (best, distinct)
    }

    /// The image evidence at full resolution with the pull to the tracked hands (no motion
    /// prior: the path search weighs the motion).
    fn evidence(&self, s: &Shaft) -> f64 {
        let w = ((s.grip - self.priors.wrist).norm() - HAND) / self.options.wrist_sigma;
        self.score(0, s) - self.options.wrist_weight * w * w
    }

    /// Pattern search at `level` from `start` over the grip (3), the direction (2 turns)
    /// and, when `free`, the length; steps (sized to the level's pixels) halve when no move
    /// improves.
    fn refine(&self, level: usize, start: Shaft, free: bool) -> Shaft {
        let o = self.options;
        let mut best = start;
        let mut f = self.objective(level, &best);
        let scale = (1u32 << level) as f64;
        let (mut step_g, mut step_d, mut step_l) = (0.01 * scale, 0.01 * scale, 0.01 * scale);
        let stop = 0.4 * step_d;
        while step_d > stop {
            let mut improved = false;
            for m in 0..12 {
                if m >= 10 && !free {
                    break;
                }
                let sign = if m % 2 == 0 { 1.0 } else { -1.0 };
                let mut c = best;
                match m / 2 {
                    0..=2 => c.grip[m / 2] += sign * step_g,
                    3 | 4 => {
                        let (u, v) = perpendiculars(&best.dir);
                        let axis = if m / 2 == 3 { u } else { v };
                        c.dir = (best.dir + sign * step_d * axis).normalize();
                    }
                    _ => {
                        c.length =
                            (c.length + sign * step_l).clamp(o.length_range.0, o.length_range.1)
                    }
                }
                let fc = self.objective(level, &c);
                if fc > f {
                    (best, f, improved) = (c, fc, true);
                }
            }
            if !improved {
                step_g *= 0.5;
                step_d *= 0.5;
                step_l *= 0.5;
            }
        }
        best
    }

    /// Image evidence at `level` minus the priors.
    fn objective(&self, level: usize, s: &Shaft) -> f64 {
        let o = self.options;
        let mut f = self.score(level, s);
        let w = ((s.grip - self.priors.wrist).norm() - HAND) / o.wrist_sigma;
        f -= o.wrist_weight * w * w;
        if let Some(p) = self.priors.predicted {
            let m = (s.grip - p).norm() / o.motion_sigma;
            f -= o.motion_weight * m * m;
        }
        if let Some(d) = self.priors.predicted_dir {
            let a = s.dir.dot(&d).clamp(-1.0, 1.0).acos() / o.turn_sigma;
            f -= o.turn_weight * a * a;
        }
        f
    }

    /// The shaft's image evidence at `level`: over cameras, the mean over its sampled points
    /// (butt to head) of the ridge of the background term across the projected line, less
    /// the threshold.
    fn score(&self, level: usize, s: &Shaft) -> f64 {
        let o = self.options;
        let a = s.grip - s.dir * BUTT;
        let b = s.grip + s.dir * s.length;
        let samples = (o.samples >> level).max(8);
        let ridge = (o.ridge_px / (1u32 << level) as f64).max(1.5);
        let mut total = 0.0;
        for levels in self.pyramid {
            let v = &levels[level];
            let (Some(pa), Some(pb)) = (v.camera.project(&a), v.camera.project(&b)) else {
                continue;
            };
            let (dx, dy) = (pb[0] - pa[0], pb[1] - pa[1]);
            let len = (dx * dx + dy * dy).sqrt();
            if len < 1.0 {
                continue;
            }
            let (nx, ny) = (-dy / len * ridge, dx / len * ridge);
            let mut sum = 0.0;
            for i in 0..samples {
                let t = (i as f64 + 0.5) / samples as f64;
                let Some(p) = v.camera.project(&(a + (b - a) * t)) else {
                    continue;
                };
                let (ux, uy) = (nx / ridge, ny / ridge);
                let mut best = 0.0f32;
                let mut widths = BLUR_HALF_WIDTHS.map(|h| h / (1u32 << level) as f64);
                if let Some(sweep) = self.priors.sweep {
                    // the wedge the shutter smears this point over, from the predicted turn
                    let radius = ARM + t * (BUTT + s.length) - BUTT;
                    let edge = v.camera.project(&(a + (b - a) * t + sweep * radius));
                    widths[2] = edge.map_or(0.0, |e| (e[0] - p[0]).hypot(e[1] - p[1]));
                }
                for h in widths {
                    if h > 0.0 && h < 1.0 {
                        continue;
                    }
                    let c = if h == 0.0 {
                        v.at(p[0], p[1])
                    } else {
                        (-2..=2)
                            .map(|q| {
                                let f = 0.5 * q as f64 * h;
                                v.at(p[0] + f * ux, p[1] + f * uy)
                            })
                            .sum::<f32>()
                            / 5.0
                    };
                    let (sx, sy) = (nx + h * ux, ny + h * uy);
                    let side = v.at(p[0] + sx, p[1] + sy).max(v.at(p[0] - sx, p[1] - sy));
                    best = best.max(c - side);
                }
                sum += best as f64 - o.threshold;
            }
            total += sum * (BUTT + s.length) / samples as f64;
        }
        total
    }
}

/// Points of a cubic grid of spacing `step` within `radius` of `centre`.
fn ball(centre: Vec3, radius: f64, step: f64) -> Vec<Vec3> {
    let n = (radius / step).floor() as i32;
    let mut out = Vec::new();
    for i in -n..=n {
        for j in -n..=n {
            for k in -n..=n {
                let d = Vec3::new(i as f64, j as f64, k as f64) * step;
                if d.norm() <= radius + 1e-9 {
                    out.push(centre + d);
                }
            }
        }
    }
    out
}

/// Two unit vectors perpendicular to `d` and to each other.
fn perpendiculars(d: &Vec3) -> (Vec3, Vec3) {
    let helper = if d.x.abs() < 0.9 {
        Vec3::x()
    } else {
        Vec3::y()
    };
    let u = d.cross(&helper).normalize();
    (u, d.cross(&u))
}

/// `n` unit vectors spread evenly over the sphere (a Fibonacci lattice).
fn sphere_directions(n: usize) -> Vec<Vec3> {
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    (0..n)
        .map(|i| {
            let z = 1.0 - 2.0 * (i as f64 + 0.5) / n as f64;
            let r = (1.0 - z * z).sqrt();
            let phi = golden * i as f64;
            Vec3::new(r * phi.cos(), r * phi.sin(), z)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sphere_directions_are_unit_and_even() {
        let d = sphere_directions(2000);
        assert!(d.iter().all(|v| (v.norm() - 1.0).abs() < 1e-12));
        let mean: Vec3 = d.iter().sum::<Vec3>() / d.len() as f64;
        assert!(mean.norm() < 1e-3, "mean {mean:?}");
        // every direction of a coarse probe set has a lattice point within 5°
        for p in sphere_directions(37) {
            let best = d.iter().map(|q| q.dot(&p)).fold(-1.0, f64::max);
            assert!(best > (5f64).to_radians().cos(), "{p:?}: {best}");
        }
    }
}
