//! Constraints that enter the implicit solve through Baraff–Witkin's per-particle filter S and
//! prescribed velocity change z: pinned particles, particles attached to a moving target, and a
//! hook through which contact handlers constrain particles along a normal.

use serde::{Deserialize, Serialize};

use crate::contact::Body;
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

/// A contact handler: before each step it constrains particles in contact through the filter
/// (normal direction, S = I − n nᵀ, with the normal velocity it wants), after the step it may
/// correct positions. Implemented by obstacles (the floor here, bodies in the contact issue).
pub trait ContactHook: Send + Sync + std::fmt::Debug {
    /// Adds contact constraints for the step from `t` to `t + dt`; `obstacles` are the
    /// simulation's collision bodies, for hooks that must not send particles into them.
    fn constrain(
        &mut self,
        x: &[Vec3],
        v: &[Vec3],
        t: f64,
        dt: f64,
        filter: &mut Filter,
        obstacles: Obstacles<'_>,
    );
    /// Corrects positions and velocities after the step (default: nothing).
    fn correct(&mut self, _x: &mut [Vec3], _v: &mut [Vec3]) {}
}

/// An infinite horizontal floor at `height` (z up): particles closer than `thickness` and
/// moving down get their normal velocity set so they rest at `height + thickness`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Floor {
    /// Floor height (m).
    pub height: f64,
    /// Contact distance kept between cloth and floor (m).
    pub thickness: f64,
}

/// The simulation's collision bodies as a contact hook sees them.
#[derive(Debug, Clone, Copy)]
pub struct Obstacles<'a> {
    /// The bodies.
    pub bodies: &'a [Body],
    /// Distance the cloth keeps from them (m).
    pub clearance: f64,
}

impl Obstacles<'_> {
    /// No bodies.
    pub fn none() -> Obstacles<'static> {
        Obstacles {
            bodies: &[],
            clearance: 0.0,
        }
    }

    /// Whether `p` is at least the clearance away from every body (outside all of them).
    pub fn is_clear(&self, p: &Vec3) -> bool {
        self.bodies
            .iter()
            .all(|b| b.proximity(p, self.clearance).is_none())
    }
}

impl ContactHook for Floor {
    fn constrain(
        &mut self,
        x: &[Vec3],
        v: &[Vec3],
        _t: f64,
        dt: f64,
        filter: &mut Filter,
        _obstacles: Obstacles<'_>,
    ) {
        let rest = self.height + self.thickness;
        for i in 0..x.len() {
            let gap = x[i].z - rest;
            // will it reach the contact distance during this step?
            if gap + v[i].z.min(0.0) * dt <= 0.0 {
                filter.constrain_normal(i, Vec3::z(), (-gap / dt).max(0.0));
            }
        }
    }

    fn correct(&mut self, x: &mut [Vec3], v: &mut [Vec3]) {
        let floor = self.height;
        for i in 0..x.len() {
            if x[i].z < floor {
                x[i].z = floor;
                v[i].z = v[i].z.max(0.0);
            }
        }
    }
}
