//! Virtual compression of a strip: Euler buckling and the post-buckling path (the elastica),
//! the maths notes §5.3. A strip along the warp, pinned (its end lines held, free to turn) or
//! clamped (two lines held at each end) is compressed quasi-statically, with the engine's own
//! elements and law, by the static equilibrium solver of the rigs. A lateral load of a
//! thousandth of the critical load at mid-span is the imperfection that picks the buckling
//! direction (+z). Forces are the reactions at the moving end, per width.

use std::sync::Arc;

use super::quasi_static::QuasiStatic;
use crate::cloth::constraints::ParticleFilter;
use crate::cloth::{ClothError, ClothModel, Direction, FabricParameters, MaterialLaw};
use crate::geometry::Vec3;

/// How the strip's ends are held.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StripEnds {
    /// End lines held in place, free to turn (effective length factor K_e = 1).
    Pinned,
    /// Two lines held at each end: no rotation (K_e = 0.5).
    Clamped,
}

/// A compressed strip: `length` (m, the free length between the supports) × `width` (m),
/// `cells` cells along it, made of law `law`.
#[derive(Clone)]
pub struct Strip {
    /// The material law.
    pub law: Arc<dyn MaterialLaw>,
    /// Free length between the supports (m).
    pub length: f64,
    /// Width (m).
    pub width: f64,
    /// Cells along the free length.
    pub cells: usize,
    /// Support.
    pub ends: StripEnds,
}

/// One equilibrium of the strip.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StripState {
    /// End shortening over the free length, Δ/L.
    pub shortening: f64,
    /// Axial load per width (N/m), positive in compression.
    pub load: f64,
    /// Rotation of the strip at the fixed end (rad): the slope of its first free segment.
    pub end_rotation: f64,
    /// Largest deflection over the free length, w/L.
    pub deflection: f64,
    /// Whether the equilibrium iterations converged.
    pub converged: bool,
}

/// The sample: the equilibrium solver, lines along the strip (line a holds particles a and
/// na + a) and the free lines.
struct Rig {
    qs: QuasiStatic,
    na: usize,
    /// First free line index (1 pinned, 2 clamped) and last free line index.
    free: (usize, usize),
}

impl Strip {
    /// The Euler critical load per width, π² B / (K_e L)² (N/m), for bending rigidity `b`
    /// (N·m: moment per width per curvature).
    pub fn euler_load(&self, b: f64) -> f64 {
        let ke = match self.ends {
            StripEnds::Pinned => 1.0,
            StripEnds::Clamped => 0.5,
        };
        std::f64::consts::PI.powi(2) * b / (ke * self.length).powi(2)
    }

    fn rig(&self) -> Result<Rig, ClothError> {
        if !(self.length > 0.0 && self.width > 0.0 && self.cells >= 8) {
            return Err(ClothError::Parameter(format!(
                "strip: length and width must be positive and cells at least 8, got {} m, {} m, {}",
                self.length, self.width, self.cells
            )));
        }
        let d = self.length / self.cells as f64;
        let extra = match self.ends {
            StripEnds::Pinned => 0,
            StripEnds::Clamped => 1,
        };
        let na = self.cells + 1 + 2 * extra;
        let fabric = FabricParameters {
            density: 0.1,
            stretch_damping: 0.0,
            bend_damping: 0.0,
            air_drag: 0.0,
            ..FabricParameters::default()
        };
        let mut model = ClothModel::grid(d * (na - 1) as f64, self.width, na, 2, fabric)?;
        model.set_law(self.law.clone());
        let mut qs = QuasiStatic::new(model, Vec3::zeros());
        qs.filter.any = true;
        Ok(Rig {
            qs,
            na,
            free: (extra + 1, na - 2 - extra),
        })
    }

    /// Particles of line `a` (both edges).
    fn line(na: usize, a: usize) -> [usize; 2] {
        [a, na + a]
    }

    /// Reads the state of the rig: load from the reactions at the moving lines.
    fn read(&self, rig: &mut Rig, moving: &[usize], x0: &[Vec3], converged: bool) -> StripState {
        let (first, last) = rig.free;
        let f = rig.qs.forces().to_vec();
        let x = &rig.qs.x;
        // the moving end pushes the strip back (−x): its reaction is the compressive load
        let load = moving.iter().map(|&i| f[i].x).sum::<f64>() / self.width;
        let span = |x: &[Vec3]| x[last + 1].x - x[first - 1].x;
        let shortening = (span(x0) - span(x)) / self.length;
        let e = x[first] - x[first - 1];
        let deflection = (first..=last).map(|a| x[a].z.abs()).fold(0.0, f64::max) / self.length;
        StripState {
            shortening,
            load,
            end_rotation: e.z.atan2(e.x),
            deflection,
            converged,
        }
    }

    /// Shortens the strip in `steps` increments up to `shortening` (Δ/L), growing
    /// quadratically (Δ_k ∝ k²) so that the first ones follow the strip from straight onto the
    /// buckled branch, and returns the equilibrium after each: the force–shortening path. `b` is the bending rigidity the
    /// imperfection load is scaled by (N·m).
    pub fn compress(
        &self,
        b: f64,
        shortening: f64,
        steps: usize,
    ) -> Result<Vec<StripState>, ClothError> {
        let mut rig = self.rig()?;
        let na = rig.na;
        let (first, last) = rig.free;
        let x0 = rig.qs.x.clone();
        let held: Vec<usize> = (0..first).chain(last + 1..na).collect();
        let moving: Vec<usize> = (last + 1..na).flat_map(|a| Self::line(na, a)).collect();
        self.imperfection(&mut rig, b);
        let mut out = Vec::with_capacity(steps);
        for k in 1..=steps {
            let delta = shortening * self.length * (k as f64 / steps as f64).powi(2);
            for &a in &held {
                for i in Self::line(na, a) {
                    let shift = if a > last { -delta } else { 0.0 };
                    rig.qs.filter.kind[i] = ParticleFilter::Fixed {
                        target: x0[i] + Vec3::x() * shift,
                    };
                }
            }
            let ok = rig.qs.solve("strip compression")?;
            out.push(self.read(&mut rig, &moving, &x0, ok));
        }
        Ok(out)
    }

    /// Loads the strip with an axial force per width `load` (N/m), ramped in `steps`
    /// increments, the moving end free to slide along the axis; returns the final equilibrium
    /// (`converged` false if it was not reached).
    pub fn load(&self, b: f64, load: f64, steps: usize) -> Result<StripState, ClothError> {
        let mut rig = self.rig()?;
        let na = rig.na;
        let (first, last) = rig.free;
        let x0 = rig.qs.x.clone();
        let moving: Vec<usize> = (last + 1..na).flat_map(|a| Self::line(na, a)).collect();
        for a in (0..first).chain(last + 1..na) {
            for i in Self::line(na, a) {
                rig.qs.filter.kind[i] = if a > last {
                    ParticleFilter::Axis {
                        free: Vec3::x(),
                        target: x0[i],
                    }
                } else {
                    ParticleFilter::Fixed { target: x0[i] }
                };
            }
        }
        self.imperfection(&mut rig, b);
        let mut ok = true;
        for k in 1..=steps {
            let p = load * self.width * k as f64 / steps as f64;
            for &i in &moving {
                rig.qs.ext[i] = -Vec3::x() * (p / moving.len() as f64);
            }
            ok = rig.qs.solve("strip loading")?;
        }
        // the stiffness the solver assembles leaves out the destabilising transverse part of
        // compressed springs, so near the critical load Newton converges only linearly: keep
        // iterating at the final load
        for _ in 0..100 {
            if ok {
                break;
            }
            ok = rig.qs.solve("strip loading")?;
        }
        let mut s = self.read(&mut rig, &moving, &x0, ok);
        s.load = load;
        Ok(s)
    }

    /// A lateral (+z) load of 1/1000 of the critical load at mid-span, and a start from a
    /// slightly bowed shape (the first mode, 1/1000 of the length high) so the first Newton
    /// iterations meet the buckled branch.
    fn imperfection(&self, rig: &mut Rig, b: f64) {
        let (first, last) = rig.free;
        let mid = (first + last) / 2;
        for a in first..=last {
            let s = (a - first + 1) as f64 / (last + 2 - first) as f64;
            let w = 1e-3
                * self.length
                * match self.ends {
                    StripEnds::Pinned => (std::f64::consts::PI * s).sin(),
                    StripEnds::Clamped => 0.5 * (1.0 - (2.0 * std::f64::consts::PI * s).cos()),
                };
            for i in Self::line(rig.na, a) {
                rig.qs.x[i].z = w;
            }
        }
        let f = 1e-3 * self.euler_load(b) * self.width;
        for i in Self::line(rig.na, mid) {
            rig.qs.ext[i] = Vec3::z() * (0.5 * f);
        }
    }
}

/// A linear law's warp bending rigidity (N·m), for strips of linear material.
pub fn warp_bending(law: &dyn MaterialLaw) -> f64 {
    let (_, db, _) = law.bending(Direction::Warp, 0.0);
    db
}
