//! The implicit (Baraff–Witkin) step of a [`Simulation`], guarded: one attempt of a (sub)step
//! checks its system, the true residual of its solve and the state it ends in
//! ([`crate::cloth::step_guard`]), and the step is retried split in halves when an attempt
//! fails (down to dt/2^[`MAX_SPLITS`]), or stops with an error saying where and why.

use std::time::Instant;

use super::Simulation;
use crate::cloth::constraints::ParticleFilter;
use crate::cloth::solver::assembly::AssemblyInputs;
use crate::cloth::solver::pcg::{PcgResult, Preconditioner};
use crate::cloth::stage::StepEnd;
use crate::cloth::stats::StepStats;
use crate::cloth::step_guard::{self, EnergyRecord, MAX_SPLITS};
use crate::cloth::ClothError;
use crate::geometry::Vec3;

/// The first solve of a step whose stages may loosen constraints stops at this multiple of the
/// CG tolerance: the impulses that decide which holds pull are judged there, and the solve goes
/// on to the full tolerance after. Judged on a fully converged first solve, a drape spent the
/// last one to two iterations of nearly every substep on a solution the release then
/// perturbed (a few dozen holds pull on most substeps): drape 8.5 → 6.46 iterations per
/// substep at 128² and 8.7 → 6.52 at 64² with 10 (5 and 20 gave about 6.9 and 6.5 at 128²).
const LOOSEN_TOLERANCE_FACTOR: f64 = 10.0;

/// How a solve starts: which part of the preconditioner is built first.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Solve {
    /// Built for the step's system.
    Setup,
    /// Only the filter changed since the last solve: the multigrid rebuilds what that touches.
    Refilter,
    /// Nothing changed since the last solve: the preconditioner is used as it is.
    Continue,
}

/// Why an attempt failed.
pub(super) enum Failure {
    /// This (sub)step failed: retry it smaller.
    This(String),
    /// The energy check at this attempt's start found that the step before it gained energy.
    Previous(EnergyRecord, String),
}

impl Simulation {
    /// Advances the implicit step of `params.dt` from the saved start state (`x_save`,
    /// `v_save`): whole, or, when that fails, split into 2, 4, … 2^[`MAX_SPLITS`] equal
    /// substeps. On failure the state is back at the start of the failing step (for an
    /// energy gain found at this step's start: at the start of the step before).
    pub(super) fn advance_implicit(&mut self) -> Result<StepStats, ClothError> {
        let dt = self.params.dt;
        let t0 = self.state.time;
        let record0 = self.guard.record;
        let mut first_cause = String::new();
        for depth in 0..=MAX_SPLITS {
            if depth > 0 {
                self.restore_start();
                self.guard.record = record0;
            }
            match self.split_attempt(dt, 1 << depth, t0) {
                Ok(mut st) => {
                    st.retries = depth;
                    return Ok(st);
                }
                Err(Failure::Previous(rec, cause)) => return Err(self.rewind(rec, cause)),
                Err(Failure::This(cause)) => {
                    if depth == 0 {
                        first_cause = cause;
                    } else if depth == MAX_SPLITS {
                        self.restore_start();
                        self.guard.forget();
                        return Err(ClothError::Diverged {
                            step: self.state.step,
                            time: t0,
                            cause: format!(
                                "{first_cause}; retried split into 2 to {} substeps, the last \
                                 attempt failed with: {cause}",
                                1u32 << MAX_SPLITS
                            ),
                        });
                    }
                }
            }
        }
        unreachable!("the last split returns")
    }

    /// Puts the state back at the step's start and forgets the warm start.
    fn restore_start(&mut self) {
        self.state.x.copy_from_slice(&self.x_save);
        self.state.v.copy_from_slice(&self.v_save);
        self.dv.fill(Vec3::zeros());
    }

    /// The step of `rec` gained energy: puts the state back at its start (its statistics
    /// and counters removed) and returns the error.
    fn rewind(&mut self, rec: EnergyRecord, cause: String) -> ClothError {
        let note = step_guard::strain_note(&self.model, &self.state.x);
        let back = self.state.step == rec.step + 1
            && self.stats.last().is_some_and(|s| s.step == rec.step);
        if back {
            let st = self.stats.pop().expect("checked");
            self.state.x.copy_from_slice(&self.x_prev);
            self.state.v.copy_from_slice(&self.v_prev);
            self.state.step = st.step;
            self.state.time = st.time;
            self.unconverged_steps -= u64::from(!st.converged);
            self.retried_steps -= u64::from(st.retries > 0);
        } else {
            self.state.x.copy_from_slice(&self.x_save);
            self.state.v.copy_from_slice(&self.v_save);
        }
        self.x_save.copy_from_slice(&self.state.x);
        self.v_save.copy_from_slice(&self.state.v);
        self.dv.fill(Vec3::zeros());
        self.guard.forget();
        ClothError::Diverged {
            step: rec.step,
            time: if back { self.state.time } else { rec.span.0 },
            cause: format!("{cause}{note}"),
        }
    }

    /// The step of `dt` from `t0` as `pieces` equal substeps; statistics of the whole step
    /// (energies at its start, iterations and times summed, the worst residual).
    fn split_attempt(&mut self, dt: f64, pieces: u32, t0: f64) -> Result<StepStats, Failure> {
        let h = dt / pieces as f64;
        let mut total = StepStats::default();
        for j in 0..pieces {
            self.state.time = if j == 0 { t0 } else { t0 + h * j as f64 };
            let st = self.step_implicit(h);
            self.state.time = t0;
            let st = match st {
                Ok(st) => st,
                Err(Failure::Previous(_, cause)) if j > 0 => {
                    return Err(Failure::This(format!("substep {j} of {pieces}: {cause}")))
                }
                Err(Failure::This(cause)) if pieces > 1 => {
                    return Err(Failure::This(format!(
                        "substep {} of {pieces}: {cause}",
                        j + 1
                    )))
                }
                Err(e) => return Err(e),
            };
            if j == 0 {
                total = st;
            } else {
                total.cg_iterations += st.cg_iterations;
                total.residual = total.residual.max(st.residual);
                total.converged &= st.converged;
                total.assemble_ms += st.assemble_ms;
                total.solve_ms += st.solve_ms;
            }
        }
        Ok(total)
    }

    /// One implicit (sub)step of length `h` from the current state at `state.time`.
    fn step_implicit(&mut self, h: f64) -> Result<StepStats, Failure> {
        let t_end = self.state.time + h;
        self.build_filter(t_end, h);
        let (kinetic, gravity) = self.kinetic_gravity();
        let t0 = Instant::now();
        let inp = AssemblyInputs {
            dt: h,
            gravity: self.gravity(),
            matrix: true,
        };
        let elastic = self
            .asm
            .assemble(&self.model, &self.state.x, &self.state.v, inp);
        let total = kinetic + gravity + elastic;
        self.guard
            .check_energy(total, inp.gravity)
            .map_err(|(rec, cause)| Failure::Previous(rec, cause))?;
        for stage in &mut self.stages {
            stage.add_forces(&mut self.asm.b);
        }
        step_guard::check_system(&self.asm.a, &self.asm.b, h).map_err(Failure::This)?;
        if !total.is_finite() {
            return Err(Failure::This(format!(
                "the cloth's energy is not finite ({total:e} J: kinetic {kinetic:e}, gravity \
                 {gravity:e}, elastic {elastic:e})"
            )));
        }
        let t1 = Instant::now();
        for i in 0..self.particle_count() {
            self.z[i] = self.filter.z(i, &self.state.x[i], &self.state.v[i], h);
        }
        if !self.params.warm_start {
            self.dv.fill(Vec3::zeros());
        }
        let tol = self.params.cg_tolerance;
        let mut res;
        if self.stages.iter().any(|s| s.may_loosen()) {
            // a stage may loosen the constraints the solve's impulses work against (a static
            // hold that pulls is let go): the impulses are judged on a first solve to a looser
            // tolerance, then the step is solved to the full tolerance from there, on the
            // loosened constraints where any were
            res = self.solve(inp, Solve::Setup, tol * LOOSEN_TOLERANCE_FACTOR);
            self.constraint_impulses();
            let mut loosened = false;
            for stage in &mut self.stages {
                loosened |= stage.loosen(&self.impulse, &mut self.filter);
            }
            let first = res.iterations;
            let how = if loosened {
                for i in 0..self.particle_count() {
                    self.z[i] = self.filter.z(i, &self.state.x[i], &self.state.v[i], h);
                }
                Solve::Refilter
            } else {
                Solve::Continue
            };
            res = self.solve(inp, how, tol);
            res.iterations += first;
        } else {
            res = self.solve(inp, Solve::Setup, tol);
        }
        if self.stages_use_impulses() {
            self.constraint_impulses();
        }
        // convergence is judged on the true residual, recomputed from the matrix
        let true_residual =
            self.pcg
                .true_residual(&self.asm.a, &self.asm.b, &self.filter, &self.dv);
        let gravity_impulse = h * inp.gravity.norm() * self.guard.mass_norm;
        let (residual, converged) = step_guard::judge_residual(
            true_residual,
            res.rhs_norm,
            gravity_impulse,
            self.params.cg_tolerance,
        );
        if !(true_residual.is_finite() && res.rhs_norm.is_finite()) {
            return Err(Failure::This(format!(
                "the linear solve's true residual ‖S(b − AΔv)‖ = {true_residual:e} is not finite \
                 (right-hand side {:e}, {} CG iterations)",
                res.rhs_norm, res.iterations
            )));
        }
        let t2 = Instant::now();
        if self.stages_use_impulses() {
            self.x_step.copy_from_slice(&self.state.x);
        }
        // while sewing, no particle moves faster than the sewing allows, even on a step whose
        // solve did not converge
        let cap = self
            .sewing
            .as_ref()
            .filter(|s| s.sewing_at(self.state.time))
            .map_or(f64::INFINITY, |s| s.max_speed);
        for i in 0..self.particle_count() {
            self.state.v[i] += self.dv[i];
            let speed = self.state.v[i].norm();
            if speed > cap {
                self.state.v[i] *= cap / speed;
            }
            self.state.x[i] += self.state.v[i] * h;
        }
        let constraint_work = self.constraint_work();
        let (k1, g1) = self.kinetic_gravity();
        self.finish_constraints(h);
        let (k2, g2) = self.kinetic_gravity();
        self.check_state().map_err(Failure::This)?;
        step_guard::check_pins(&self.attachments, &self.state.x, t_end, self.guard.size)
            .map_err(Failure::This)?;
        step_guard::check_strain(&self.model, &self.state.x).map_err(Failure::This)?;
        // the energy balance is kept on steps that only the cloth's forces, gravity and
        // attachments drive: contact and holds move particles by work not measured here, and
        // Choi–Ko's arcs push with a buckling force that no energy of the model accounts for
        let responded = k1 != k2 || g1 != g2;
        let checked = !self.stages_constrain && !responded && self.model.arcs.is_empty();
        let work = constraint_work + (k2 + g2) - (k1 + g1);
        self.guard.record = checked.then_some(EnergyRecord {
            step: self.state.step,
            span: (self.state.time, t_end),
            total,
            work,
            scale: self.guard.scale(kinetic, elastic, work, inp.gravity),
            gravity: inp.gravity,
        });
        Ok(StepStats {
            kinetic,
            gravity,
            elastic,
            total,
            cg_iterations: res.iterations,
            residual,
            converged,
            assemble_ms: (t1 - t0).as_secs_f64() * 1e3,
            solve_ms: (t2 - t1).as_secs_f64() * 1e3,
            ..Default::default()
        })
    }

    /// The constraint impulses of the last solve into `impulse`: the residual A Δv − b, which
    /// lies in the constrained directions (zero for free particles).
    fn constraint_impulses(&mut self) {
        for i in 0..self.particle_count() {
            self.impulse[i] = match self.filter.kind[i] {
                ParticleFilter::Free => Vec3::zeros(),
                _ => self.asm.a.row_times(i, &self.dv) - self.asm.b[i],
            };
        }
    }

    /// The preconditioned CG solve of the assembled system for `dv`, finishing with
    /// block-Jacobi when a multigrid preconditioner breaks down, to the relative `tolerance`;
    /// `how` says what changed since the last solve (what the preconditioner rebuilds).
    fn solve(&mut self, inp: AssemblyInputs, how: Solve, tolerance: f64) -> PcgResult {
        let mut precond = match (self.mg.as_mut(), self.amg.as_mut()) {
            (Some(mg), _) => {
                if how != Solve::Continue {
                    mg.setup(
                        &self.asm.a,
                        &self.state.x,
                        &self.state.v,
                        &self.filter,
                        inp,
                        how == Solve::Refilter,
                    );
                }
                Preconditioner::Multigrid(mg)
            }
            (None, Some(amg)) => {
                if how != Solve::Continue {
                    amg.setup(&self.asm.a, &self.filter);
                }
                Preconditioner::Aggregation(amg)
            }
            (None, None) => Preconditioner::BlockJacobi(&self.asm.pinv),
        };
        let mut res = self.pcg.solve(
            &self.asm.a,
            &self.asm.b,
            &mut precond,
            &self.filter,
            &self.z,
            &mut self.dv,
            tolerance,
            self.params.cg_max_iterations,
        );
        let multigrid = self.mg.is_some() || self.amg.is_some();
        if !res.converged && res.iterations < self.params.cg_max_iterations && multigrid {
            // the multigrid preconditioner broke down (lost definiteness on an extreme
            // configuration): finish the solve with block-Jacobi from where it stopped
            self.asm.form_block_jacobi();
            let again = self.pcg.solve(
                &self.asm.a,
                &self.asm.b,
                &mut Preconditioner::BlockJacobi(&self.asm.pinv),
                &self.filter,
                &self.z,
                &mut self.dv,
                tolerance,
                self.params.cg_max_iterations - res.iterations,
            );
            res = PcgResult {
                iterations: res.iterations + again.iterations,
                ..again
            };
        }
        res
    }

    /// Work of the constraint impulses of the last solve on the velocities they produced:
    /// Σ J·v over constrained particles, with J = AΔv − b there (J).
    fn constraint_work(&self) -> f64 {
        if !self.filter.any {
            return 0.0;
        }
        let r = self.pcg.residual();
        let mut w = 0.0;
        for (i, kind) in self.filter.kind.iter().enumerate() {
            if !matches!(kind, ParticleFilter::Free) {
                w -= r[i].dot(&self.state.v[i]);
            }
        }
        w
    }

    /// Snaps fixed particles exactly onto their targets, then runs the stages' responses
    /// (friction, push-out, self-collision), last added first, on the step of length `h` that
    /// started at `x_step`.
    pub(super) fn finish_constraints(&mut self, h: f64) {
        for i in 0..self.particle_count() {
            if let ParticleFilter::Fixed { target } = self.filter.kind[i] {
                self.state.x[i] = target;
            }
        }
        for stage in self.stages.iter_mut().rev() {
            stage.respond(StepEnd {
                x_start: &self.x_step,
                x: &mut self.state.x,
                v: &mut self.state.v,
                impulse: &self.impulse,
                mass: &self.model.mass,
                filter: &self.filter,
                dt: h,
            });
        }
    }

    /// Copies the stages' statistics of the last step into `st` (no body near: an infinite
    /// distance).
    pub(super) fn contact_stats(&self, st: &mut StepStats) {
        st.min_distance = f64::INFINITY;
        for stage in &self.stages {
            stage.report(st);
        }
    }
}
