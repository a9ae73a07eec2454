//! Constraints that enter the implicit solve through Baraff–Witkin's per-particle filter S and
//! prescribed velocity change z: pinned particles, particles attached to a moving target, and
//! particles whose velocity along a normal a step stage prescribes (contact).

use serde::{Deserialize, Serialize};

use crate::geometry::Vec3;

/// A rigid translation over time, applied to attached particles' anchor positions.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum Trajectory {
    /// No motion: the particles stay where they were pinned.
    Fixed,
    /// Constant velocity (m/s) from t = 0.
    Linear {
        /// Velocity (m/s).
        velocity: [f64; 3],
    },
    /// Piecewise-linear displacement keyframes `(time s, displacement m)`, sorted by time;
    /// held constant before the first and after the last.
    Keyframes(Vec<(f64, [f64; 3])>),
    /// Sinusoidal displacement `amplitude · sin(2π f t)`.
    Oscillation {
        /// Amplitude (m).
        amplitude: [f64; 3],
        /// Frequency (Hz).
        frequency: f64,
    },
}

impl Trajectory {
    /// Displacement from the anchor at time `t`.
    pub fn displacement(&self, t: f64) -> Vec3 {
        match self {
            Trajectory::Fixed => Vec3::zeros(),
            Trajectory::Linear { velocity } => Vec3::from(*velocity) * t,
            Trajectory::Keyframes(k) => {
                if k.is_empty() {
                    return Vec3::zeros();
                }
                if t <= k[0].0 {
                    return Vec3::from(k[0].1);
                }
                for w in k.windows(2) {
                    let ((t0, p0), (t1, p1)) = (w[0], w[1]);
                    if t <= t1 {
                        let s = if t1 > t0 { (t - t0) / (t1 - t0) } else { 1.0 };
                        return Vec3::from(p0) * (1.0 - s) + Vec3::from(p1) * s;
                    }
                }
                Vec3::from(k[k.len() - 1].1)
            }
            Trajectory::Oscillation {
                amplitude,
                frequency,
            } => Vec3::from(*amplitude) * (2.0 * std::f64::consts::PI * frequency * t).sin(),
        }
    }

    /// Checks the numbers are finite and keyframes sorted.
    pub fn validate(&self) -> Result<(), String> {
        let finite3 = |p: &[f64; 3]| p.iter().all(|c| c.is_finite());
        match self {
            Trajectory::Fixed => Ok(()),
            Trajectory::Linear { velocity } if finite3(velocity) => Ok(()),
            Trajectory::Oscillation {
                amplitude,
                frequency,
            } if finite3(amplitude) && frequency.is_finite() => Ok(()),
            Trajectory::Keyframes(k) => {
                if k.iter().any(|(t, p)| !t.is_finite() || !finite3(p)) {
                    return Err("keyframes must be finite".into());
                }
                if k.windows(2).any(|w| w[1].0 < w[0].0) {
                    return Err("keyframe times must be sorted".into());
                }
                Ok(())
            }
            _ => Err("trajectory values must be finite".into()),
        }
    }
}

/// A set of particles moved rigidly along a trajectory: particle k's target at time t is
/// `anchors[k] + trajectory.displacement(t)`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Attachment {
    /// Constrained particles.
    pub particles: Vec<usize>,
    /// Their anchor positions (positions at t = 0 of the trajectory).
    pub anchors: Vec<[f64; 3]>,
    /// How the anchors move.
    pub trajectory: Trajectory,
}

/// What the filter does to one particle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ParticleFilter {
    /// Three free degrees of freedom: S = I.
    Free,
    /// Fully prescribed: S = 0, the particle goes to `target` at the end of the step.
    Fixed {
        /// Position at the end of the step.
        target: Vec3,
    },
    /// Free only along unit `free` (S = f fᵀ); in the two other directions the particle goes
    /// to `target` at the end of the step (a clamp that slides along one axis).
    Axis {
        /// The free unit direction.
        free: Vec3,
        /// Position at the end of the step in the constrained directions.
        target: Vec3,
    },
    /// Velocity along unit `normal` prescribed (contact): S = I − n nᵀ.
    Normal {
        /// Constrained unit direction.
        normal: Vec3,
        /// Velocity along `normal` at the end of the step (m/s).
        velocity: f64,
    },
}

/// Per-particle constraint filter S and velocity change z for one step.
#[derive(Debug, Clone, Default)]
pub struct Filter {
    /// Filter of each particle.
    pub kind: Vec<ParticleFilter>,
    /// True when any particle is constrained.
    pub any: bool,
    /// Particles fixed by a soft hold (a compression release's destination) that yield to
    /// cloth–cloth contact: the self-collision response moves them like free particles, so a
    /// release never carries a particle through another layer (empty: none; indexed like
    /// `kind` up to its length).
    pub yields: Vec<bool>,
}

impl Filter {
    /// A filter of `n` free particles.
    pub fn new(n: usize) -> Self {
        Filter {
            kind: vec![ParticleFilter::Free; n],
            any: false,
            yields: Vec::new(),
        }
    }

    /// Frees every particle.
    pub fn clear(&mut self) {
        self.kind.fill(ParticleFilter::Free);
        self.any = false;
        self.yields.clear();
    }

    /// Fixes particle `i` at `target` by a soft hold that yields to cloth–cloth contact (see
    /// [`Filter::yields`]).
    pub fn hold_yielding(&mut self, i: usize, target: Vec3) {
        self.kind[i] = ParticleFilter::Fixed { target };
        self.any = true;
        if self.yields.len() < self.kind.len() {
            self.yields.resize(self.kind.len(), false);
        }
        self.yields[i] = true;
    }

    /// Whether particle `i` is held by a soft hold that yields to cloth–cloth contact.
    #[inline]
    pub fn is_yielding(&self, i: usize) -> bool {
        self.yields.get(i).copied().unwrap_or(false)
    }

    /// Constrains the velocity of particle `i` along unit `normal` to `velocity`, unless the
    /// particle is already fully fixed. A second normal on the same particle fixes the
    /// particle's velocity along both (approximated by keeping the newer normal).
    pub fn constrain_normal(&mut self, i: usize, normal: Vec3, velocity: f64) {
        if matches!(
            self.kind[i],
            ParticleFilter::Free | ParticleFilter::Normal { .. }
        ) {
            self.kind[i] = ParticleFilter::Normal { normal, velocity };
            self.any = true;
        }
    }

    /// S_i a.
    #[inline]
    pub fn apply(&self, i: usize, a: Vec3) -> Vec3 {
        match self.kind[i] {
            ParticleFilter::Free => a,
            ParticleFilter::Fixed { .. } => Vec3::zeros(),
            ParticleFilter::Axis { free, .. } => free * free.dot(&a),
            ParticleFilter::Normal { normal, .. } => a - normal * normal.dot(&a),
        }
    }

    /// z_i: the velocity change prescribed in the constrained directions, given the particle's
    /// position `x`, velocity `v` and the step `dt`.
    #[inline]
    pub fn z(&self, i: usize, x: &Vec3, v: &Vec3, dt: f64) -> Vec3 {
        match self.kind[i] {
            ParticleFilter::Free => Vec3::zeros(),
            ParticleFilter::Fixed { target } => (target - x) / dt - v,
            ParticleFilter::Axis { free, target } => {
                let w = (target - x) / dt - v;
                w - free * free.dot(&w)
            }
            ParticleFilter::Normal { normal, velocity } => normal * (velocity - normal.dot(v)),
        }
    }
}
