//! Static equilibrium of a cloth sample under prescribed particles and external forces, by
//! Newton iterations: backward-Euler solves of the engine's own implicit system (same assembly,
//! filter S/z and modified PCG) with the velocity reset to zero and a step of 1 s, so the mass
//! term only regularises, and a backtracking line search. The virtual rigs (Kawabata tests,
//! the cantilever, the compressed strip) read their forces from it.

use crate::cloth::constraints::{Filter, ParticleFilter};
use crate::cloth::solver::assembly::{Assembly, AssemblyInputs};
use crate::cloth::solver::pcg::{PcgWorkspace, Preconditioner};
use crate::cloth::{ClothError, ClothModel};
use crate::geometry::Vec3;

/// The backward-Euler step used as a Newton step (s).
const H: f64 = 1.0;
/// Newton iterations allowed per increment.
const MAX_NEWTON: usize = 30;

/// Equilibrium solver for a rig sample.
pub(crate) struct QuasiStatic {
    pub model: ClothModel,
    pub asm: Assembly,
    pcg: PcgWorkspace,
    pub filter: Filter,
    pub x: Vec<Vec3>,
    zero: Vec<Vec3>,
    z: Vec<Vec3>,
    dv: Vec<Vec3>,
    pub ext: Vec<Vec3>,
    pub gravity: Vec3,
}

impl QuasiStatic {
    pub fn new(model: ClothModel, gravity: Vec3) -> Self {
        let n = model.particle_count();
        let mut asm = Assembly::new(&model);
        asm.auto_commit = false;
        QuasiStatic {
            asm,
            pcg: PcgWorkspace::new(n),
            filter: Filter::new(n),
            x: model.mesh.positions.clone(),
            zero: vec![Vec3::zeros(); n],
            z: vec![Vec3::zeros(); n],
            dv: vec![Vec3::zeros(); n],
            ext: vec![Vec3::zeros(); n],
            model,
            gravity,
        }
    }

    /// Brings the sample to equilibrium with the current filter targets and external forces.
    /// Returns whether the residual reached the tolerance within the iteration cap.
    pub fn solve(&mut self, what: &str) -> Result<bool, ClothError> {
        let n = self.x.len();
        let inp = AssemblyInputs {
            dt: H,
            gravity: self.gravity,
            matrix: true,
        };
        let mut x_old = self.x.clone();
        let mut converged = false;
        for it in 0..MAX_NEWTON {
            self.asm.assemble(&self.model, &self.x, &self.zero, inp);
            for i in 0..n {
                self.asm.b[i] += self.ext[i] * H;
                self.z[i] = self.filter.z(i, &self.x[i], &self.zero[i], H);
            }
            let (res, scale) = self.residual();
            if it > 0 && res <= 1e-6 * scale {
                converged = true;
                break;
            }
            self.dv.fill(Vec3::zeros());
            self.pcg.solve(
                &self.asm.a,
                &self.asm.b,
                &mut Preconditioner::BlockJacobi(&self.asm.pinv),
                &self.filter,
                &self.z,
                &mut self.dv,
                1e-9,
                5000,
            );
            // backtracking: halve the step while the force residual grows (the friction
            // tangent switches between stick and slip, and the shear-cell tangent is
            // approximate, so full Newton steps can overshoot)
            x_old.copy_from_slice(&self.x);
            let mut alpha = 1.0;
            let mut step: f64 = 0.0;
            for ls in 0..8 {
                step = 0.0;
                for i in 0..n {
                    let d = self.dv[i] * (H * alpha);
                    step = step.max(d.norm());
                    self.x[i] = x_old[i] + d;
                    if !self.x[i].iter().all(|c| c.is_finite()) {
                        return Err(ClothError::Diverged {
                            step: it as u64,
                            time: 0.0,
                            cause: format!("{what}: particle {i} got a non-finite position"),
                        });
                    }
                }
                // constrained directions always go to their targets
                for i in 0..n {
                    if !matches!(self.filter.kind[i], ParticleFilter::Free) {
                        let full = x_old[i] + self.dv[i] * H;
                        let gap = full - self.x[i];
                        self.x[i] += gap - self.filter.apply(i, gap);
                    }
                }
                if it == 0 && ls == 0 {
                    break;
                }
                let (r_try, _) = self.force_residual();
                if r_try <= res * (1.0 - 0.05 * alpha) || ls == 7 {
                    break;
                }
                alpha *= 0.5;
            }
            if step < 1e-11 {
                converged = true;
                break;
            }
        }
        // the committed state is that of the final positions
        self.asm.assemble(&self.model, &self.x, &self.zero, inp);
        self.asm.commit_friction();
        Ok(converged)
    }

    /// (max filtered force, max force) of the assembled right-hand side.
    fn residual(&self) -> (f64, f64) {
        let mut res: f64 = 0.0;
        let mut scale: f64 = 1e-12;
        for i in 0..self.x.len() {
            scale = scale.max(self.asm.b[i].norm());
            res = res.max(self.filter.apply(i, self.asm.b[i]).norm());
        }
        (res, scale)
    }

    /// The residual at the current positions (force-only assembly, scaled like `solve`'s).
    fn force_residual(&mut self) -> (f64, f64) {
        let inp = AssemblyInputs {
            dt: H,
            gravity: self.gravity,
            matrix: false,
        };
        self.asm.assemble(&self.model, &self.x, &self.zero, inp);
        for i in 0..self.x.len() {
            self.asm.b[i] = (self.asm.b[i] + self.ext[i]) * H;
        }
        self.residual()
    }

    /// Internal force (elements + gravity) on every particle at the current positions.
    pub fn forces(&mut self) -> &[Vec3] {
        let inp = AssemblyInputs {
            dt: H,
            gravity: self.gravity,
            matrix: false,
        };
        self.asm.assemble(&self.model, &self.x, &self.zero, inp);
        &self.asm.b
    }
}
