//! `Simulation`: a cloth model, its state, constraints and step stages, stepped by the
//! implicit (Baraff–Witkin, `simulation/implicit.rs`) or the explicit (symplectic Euler) integrator. Every
//! step checks for divergence and leaves the state untouched when it fails; an implicit step
//! is guarded further ([`super::step_guard`]) and retried smaller when it fails.

mod implicit;

use std::sync::Arc;
use std::time::Instant;

use super::buckling::buckling_side::BucklingSides;
use super::constraints::{Attachment, Filter, ParticleFilter, Trajectory};
use super::elements::material::MaterialLaw;
use super::model::ClothModel;
use super::parameters::{Integrator, PreconditionerKind, SimulationParameters, AGGREGATION_MIN};
use super::sewing::Sewing;
use super::solver::amg::AggregationMultigrid;
use super::solver::assembly::{Assembly, AssemblyInputs};
use super::solver::multigrid::Multigrid;
use super::solver::pcg::PcgWorkspace;
use super::stage::{Obstacles, StepStage};
use super::state::ClothState;
use super::stats::StepStats;
use super::step_guard::StepGuard;
use super::ClothError;
use crate::geometry::Vec3;

/// A simulation's geometric and aggregation multigrid, either or both absent.
type Preconditioners = (Option<Multigrid>, Option<AggregationMultigrid>);

/// The multigrid preconditioners `params` asks for on `model`, whose implicit system `asm`
/// assembles (none: block-Jacobi, which `asm` then forms during assembly).
fn preconditioners(
    model: &ClothModel,
    params: &SimulationParameters,
    asm: &mut Assembly,
) -> Result<Preconditioners, ClothError> {
    let mg = match (params.preconditioner, model.grid) {
        (PreconditionerKind::BlockJacobi, _) => None,
        (PreconditionerKind::Auto, Some((nx, ny))) if nx.min(ny) >= 16 => {
            Some(Multigrid::new(model, &mut asm.a)?)
        }
        (PreconditionerKind::Multigrid, _) => Some(Multigrid::new(model, &mut asm.a)?),
        _ => None,
    };
    let amg = match params.preconditioner {
        PreconditionerKind::Aggregation => Some(AggregationMultigrid::new(model, &asm.a)),
        PreconditionerKind::Auto if mg.is_none() && model.particle_count() >= AGGREGATION_MIN => {
            Some(AggregationMultigrid::new(model, &asm.a))
        }
        _ => None,
    };
    // a multigrid enabled the single-precision mirrors its smoother reads
    asm.jacobi = mg.is_none() && amg.is_none();
    Ok((mg, amg))
}

/// A running cloth simulation.
#[derive(Debug)]
pub struct Simulation {
    /// The fixed model.
    pub model: ClothModel,
    /// The side each flat Choi–Ko connection buckles to (with Choi–Ko only).
    pub sides: Option<BucklingSides>,
    /// The changing state.
    pub state: ClothState,
    /// Settings.
    pub params: SimulationParameters,
    /// Pins and moving attachments.
    pub attachments: Vec<Attachment>,
    /// Statistics of every step taken.
    pub stats: Vec<StepStats>,
    /// The sewing schedule of a garment's seams, if any.
    pub sewing: Option<Sewing>,
    /// Steps whose CG solve did not reach the tolerance.
    pub unconverged_steps: u64,
    /// Implicit steps that failed whole and were retried split into substeps.
    pub retried_steps: u64,
    /// Share of `params.gravity` acting (a garment's sewing turns it down while it sews).
    pub(super) gravity_share: f64,
    /// Stages of every step beside the cloth's forces (contact), in the order added.
    pub(super) stages: Vec<Box<dyn StepStage>>,
    filter: Filter,
    z: Vec<Vec3>,
    pub(super) dv: Vec<Vec3>,
    /// The state at the start of the step (after it: the state it left, to see whether
    /// anything moved the cloth between steps).
    pub(super) x_save: Vec<Vec3>,
    pub(super) v_save: Vec<Vec3>,
    /// The state at the start of the step before (to rewind a step found to gain energy).
    pub(super) x_prev: Vec<Vec3>,
    pub(super) v_prev: Vec<Vec3>,
    /// The checks of a step and the last step's energy.
    pub(super) guard: StepGuard,
    /// Whether the sewing (if any) had stopped changing the model at the last step.
    pub(super) sewing_settled: bool,
    /// Whether a stage constrained particles in the last step's filter (contact, holds).
    pub(super) stages_constrain: bool,
    impulse: Vec<Vec3>,
    x_step: Vec<Vec3>,
    pub(super) asm: Assembly,
    pcg: PcgWorkspace,
    pub(super) mg: Option<Multigrid>,
    amg: Option<AggregationMultigrid>,
}

impl Simulation {
    /// A simulation of `model`, at rest at its mesh positions.
    pub fn new(model: ClothModel, params: SimulationParameters) -> Result<Self, ClothError> {
        params.validate()?;
        model.fabric.validate().map_err(ClothError::Parameter)?;
        let n = model.particle_count();
        let mut asm = Assembly::new(&model);
        let state = ClothState::at_rest(model.mesh.positions.clone());
        let (mg, amg) = preconditioners(&model, &params, &mut asm)?;
        let sides = (model.choi_ko && !model.flexion_sides.is_empty())
            .then(|| BucklingSides::new(model.flexion_sides.clone(), model.choi_ko_seed));
        Ok(Simulation {
            sides,
            impulse: vec![Vec3::zeros(); n],
            x_step: vec![Vec3::zeros(); n],
            state,
            params,
            attachments: Vec::new(),
            gravity_share: 1.0,
            stages: Vec::new(),
            stats: Vec::new(),
            sewing: None,
            unconverged_steps: 0,
            retried_steps: 0,
            guard: StepGuard::new(&model),
            sewing_settled: true,
            stages_constrain: false,
            filter: Filter::new(n),
            z: vec![Vec3::zeros(); n],
            dv: vec![Vec3::zeros(); n],
            x_save: vec![Vec3::zeros(); n],
            v_save: vec![Vec3::zeros(); n],
            x_prev: vec![Vec3::zeros(); n],
            v_prev: vec![Vec3::zeros(); n],
            asm,
            pcg: PcgWorkspace::new(n),
            mg,
            amg,
            model,
        })
    }

    /// Gives the cloth another material law (a measured one, say) and rebuilds what was made
    /// from the old one (the geometric multigrid's coarse cloths).
    pub fn set_material(&mut self, law: Arc<dyn MaterialLaw>) -> Result<(), ClothError> {
        self.model.set_law(law);
        self.guard = StepGuard::new(&self.model);
        let (mg, amg) = preconditioners(&self.model, &self.params, &mut self.asm)?;
        self.mg = mg;
        self.amg = amg;
        Ok(())
    }

    /// Multigrid time spent so far: (setup s, V-cycles s, V-cycle count); `None` without multigrid.
    pub fn multigrid_timing(&self) -> Option<(f64, f64, u64)> {
        self.mg
            .as_ref()
            .map(|m| m.timing)
            .or(self.amg.as_ref().map(|m| m.timing))
    }

    /// Levels of the multigrid hierarchy (1 when block-Jacobi preconditions).
    pub fn multigrid_levels(&self) -> usize {
        self.mg
            .as_ref()
            .map(|m| m.depth())
            .or(self.amg.as_ref().map(|m| m.depth()))
            .unwrap_or(1)
    }

    /// Bytes held by the implicit system's matrix (pattern, blocks, single-precision mirrors).
    pub fn system_matrix_bytes(&self) -> usize {
        self.asm.a.bytes()
    }

    /// Number of particles.
    pub fn particle_count(&self) -> usize {
        self.model.particle_count()
    }

    fn check_particles(&self, particles: &[usize]) -> Result<(), ClothError> {
        let n = self.particle_count();
        match particles.iter().find(|&&i| i >= n) {
            Some(i) => Err(ClothError::Parameter(format!(
                "particle index {i} out of range (cloth has {n})"
            ))),
            None => Ok(()),
        }
    }

    /// Pins `particles` where they are now. Returns the attachment index.
    pub fn pin(&mut self, particles: &[usize]) -> Result<usize, ClothError> {
        self.attach(particles, Trajectory::Fixed)
    }

    /// Attaches `particles` to a target moving along `trajectory` from their current positions,
    /// with the trajectory's clock starting now. Returns the attachment index.
    pub fn attach(
        &mut self,
        particles: &[usize],
        trajectory: Trajectory,
    ) -> Result<usize, ClothError> {
        self.check_particles(particles)?;
        trajectory.validate().map_err(ClothError::Parameter)?;
        let t0 = self.state.time;
        let shift = trajectory.displacement(t0);
        let anchors = particles
            .iter()
            .map(|&i| (self.state.x[i] - shift).into())
            .collect();
        self.attachments.push(Attachment {
            particles: particles.to_vec(),
            anchors,
            trajectory,
        });
        Ok(self.attachments.len() - 1)
    }

    /// Removes every attachment of `particles` (they become free); an index past the cloth's
    /// particles is an error (nothing is released then).
    pub fn release(&mut self, particles: &[usize]) -> Result<(), ClothError> {
        self.check_particles(particles)?;
        for at in &mut self.attachments {
            let keep: Vec<bool> = at
                .particles
                .iter()
                .map(|i| !particles.contains(i))
                .collect();
            let mut k = keep.iter();
            at.particles.retain(|_| *k.next().unwrap());
            let mut k = keep.iter();
            at.anchors.retain(|_| *k.next().unwrap());
        }
        self.attachments.retain(|a| !a.particles.is_empty());
        Ok(())
    }

    /// Target position of every attached particle at time `t`.
    pub fn attachment_targets(&self, t: f64) -> Vec<(usize, Vec3)> {
        let mut out = Vec::new();
        for at in &self.attachments {
            let d = at.trajectory.displacement(t);
            for (k, &i) in at.particles.iter().enumerate() {
                out.push((i, Vec3::from(at.anchors[k]) + d));
            }
        }
        out
    }

    /// Adds a stage to every step: stages constrain particles in the order added and respond
    /// in reverse order (add contact with bodies first).
    pub fn add_stage(&mut self, stage: Box<dyn StepStage>) {
        self.stages.push(stage);
    }

    /// The step's stages, in the order added.
    pub fn stages(&self) -> &[Box<dyn StepStage>] {
        &self.stages
    }

    /// The first stage of type `T`, if any.
    pub fn stage<T: StepStage>(&self) -> Option<&T> {
        self.stages.iter().find_map(|s| s.as_any().downcast_ref())
    }

    /// The first stage of type `T`, mutable, if any.
    pub fn stage_mut<T: StepStage>(&mut self) -> Option<&mut T> {
        self.stages
            .iter_mut()
            .find_map(|s| s.as_any_mut().downcast_mut())
    }

    /// Whether some stage reads the step's start positions and constraint impulses.
    fn stages_use_impulses(&self) -> bool {
        self.stages.iter().any(|s| s.uses_impulses())
    }

    /// Energies of the current state: (kinetic, gravitational, elastic). Reading them leaves
    /// the simulation as it was: the internal-friction states the evaluation passes through
    /// are not committed (they were, so a script printing the energy every frame drove a
    /// fabric with hysteresis along another trajectory than one that did not).
    pub fn energy(&mut self) -> (f64, f64, f64) {
        let inp = AssemblyInputs {
            dt: self.params.dt,
            gravity: self.gravity(),
            matrix: false,
        };
        let commit = std::mem::replace(&mut self.asm.auto_commit, false);
        let elastic = self
            .asm
            .assemble(&self.model, &self.state.x, &self.state.v, inp);
        self.asm.auto_commit = commit;
        let (k, g) = self.kinetic_gravity();
        (k, g, elastic)
    }

    /// The gravity acting now (m/s²): the parameters' times the share a garment's sewing
    /// lets act.
    pub fn gravity(&self) -> Vec3 {
        Vec3::from(self.params.gravity) * self.gravity_share
    }

    fn kinetic_gravity(&self) -> (f64, f64) {
        let gr = self.gravity();
        let (mut k, mut g) = (0.0, 0.0);
        for i in 0..self.particle_count() {
            let m = self.model.mass[i];
            k += 0.5 * m * self.state.v[i].norm_squared();
            g -= m * gr.dot(&self.state.x[i]);
        }
        (k, g)
    }

    fn build_filter(&mut self, t_end: f64, dt: f64) {
        self.filter.clear();
        // attachments first: the stages leave fixed particles alone, so
        // friction never holds back (or moves) a particle that follows its target
        for at in &self.attachments {
            let d = at.trajectory.displacement(t_end);
            for (k, &i) in at.particles.iter().enumerate() {
                self.filter.kind[i] = ParticleFilter::Fixed {
                    target: Vec3::from(at.anchors[k]) + d,
                };
                self.filter.any = true;
            }
        }
        let constrained = |f: &Filter| {
            f.kind
                .iter()
                .filter(|k| **k != ParticleFilter::Free)
                .count()
        };
        let attached = if self.stages.is_empty() {
            0
        } else {
            constrained(&self.filter)
        };
        // each stage sees the obstacles of the stages before it
        for k in 0..self.stages.len() {
            let (before, rest) = self.stages.split_at_mut(k);
            rest[0].constrain(
                &self.state.x,
                &self.state.v,
                t_end - dt,
                dt,
                &mut self.filter,
                Obstacles::of(before),
            );
        }
        self.stages_constrain = !self.stages.is_empty() && constrained(&self.filter) != attached;
    }

    /// Advances one step of `params.dt`.
    pub fn step(&mut self) -> Result<StepStats, ClothError> {
        // run on a pool thread so the many small parallel loops of a step fork cheaply
        rayon::scope(|_| self.step_inner())
    }

    fn step_inner(&mut self) -> Result<StepStats, ClothError> {
        self.params.validate()?;
        let t_start = Instant::now();
        // the model is the last step's unless a sewing still changes it
        let same_model = self.sewing_settled;
        if let Some(sew) = &mut self.sewing {
            self.gravity_share = sew.update(&mut self.model, self.state.time, &self.state.x);
            for stage in &mut self.stages {
                stage.follow_sewing(sew, self.state.time);
            }
        }
        self.sewing_settled = self.sewing_quiet();
        if let Some(sides) = &mut self.sides {
            let attachments = &self.attachments;
            let obstacles = Obstacles::of(&self.stages);
            sides.start_arcs(
                &mut self.state.x,
                |i| attachments.iter().any(|a| a.particles.contains(&i)),
                |p| obstacles.is_clear(p),
            );
        }
        // `x_save` holds the state the last step left: the energy check holds while nothing
        // moved the cloth since
        if !(same_model && self.state.x == self.x_save && self.state.v == self.v_save) {
            self.x_save.copy_from_slice(&self.state.x);
            self.v_save.copy_from_slice(&self.state.v);
            self.guard.forget();
        }
        let mut st = match self.params.integrator {
            Integrator::Implicit => self.advance_implicit()?,
            Integrator::Explicit => {
                self.guard.forget();
                let st = self.step_explicit();
                if let Err(cause) = self.check_state() {
                    let err = ClothError::Diverged {
                        step: self.state.step,
                        time: self.state.time,
                        cause,
                    };
                    self.state.x.copy_from_slice(&self.x_save);
                    self.state.v.copy_from_slice(&self.v_save);
                    return Err(err);
                }
                st
            }
        };
        if let Some(sew) = &self.sewing {
            sew.slow_down(self.state.time, &mut self.state.v);
            if let Some(sep) = sew.separation.as_ref() {
                if sew.sewing_at(self.state.time) {
                    let mut crossings = Vec::new();
                    for stage in &mut self.stages {
                        crossings.extend(stage.crossings(&self.state.x));
                    }
                    sep.apply(&crossings, &mut self.state.x);
                }
            }
        }
        self.contact_stats(&mut st);
        st.step = self.state.step;
        st.time = self.state.time;
        st.step_ms = t_start.elapsed().as_secs_f64() * 1e3;
        if !st.converged {
            self.unconverged_steps += 1;
        }
        if st.retries > 0 {
            self.retried_steps += 1;
        }
        self.state.step += 1;
        self.state.time += self.params.dt;
        self.stats.push(st);
        // keep this step's start (to rewind it) and the state it left
        std::mem::swap(&mut self.x_prev, &mut self.x_save);
        std::mem::swap(&mut self.v_prev, &mut self.v_save);
        self.x_save.copy_from_slice(&self.state.x);
        self.v_save.copy_from_slice(&self.state.v);
        Ok(st)
    }

    /// Whether a garment's sewing has stopped changing the model (its threads' rest lengths
    /// at zero, the seams stitched); true without sewing.
    fn sewing_quiet(&self) -> bool {
        self.sewing
            .as_ref()
            .is_none_or(|s| !s.sewing_at(self.state.time) && self.state.time >= s.closing_time())
    }

    fn check_state(&self) -> Result<(), String> {
        let vmax2 = self.params.max_speed * self.params.max_speed;
        for i in 0..self.particle_count() {
            let (x, v) = (&self.state.x[i], &self.state.v[i]);
            if !(x.iter().all(|c| c.is_finite()) && v.iter().all(|c| c.is_finite())) {
                return Err(format!(
                    "particle {i} got a non-finite position or velocity (NaN)"
                ));
            }
            if v.norm_squared() > vmax2 {
                return Err(format!(
                    "energy blow-up: particle {i} reached {:.3e} m/s (max_speed {} m/s); reduce dt or use the implicit integrator",
                    v.norm(),
                    self.params.max_speed
                ));
            }
        }
        Ok(())
    }

    fn step_explicit(&mut self) -> StepStats {
        let sub = self.params.explicit_substeps.max(1);
        let h = self.params.dt / sub as f64;
        let gravity = self.gravity();
        let (kinetic, grav) = self.kinetic_gravity();
        let mut elastic0 = 0.0;
        let t0 = Instant::now();
        for k in 0..sub {
            let t_end = self.state.time + h * (k + 1) as f64;
            self.build_filter(t_end, h);
            let inp = AssemblyInputs {
                dt: h,
                gravity,
                matrix: false,
            };
            let e = self
                .asm
                .assemble(&self.model, &self.state.x, &self.state.v, inp);
            if k == 0 {
                elastic0 = e;
            }
            if self.stages_use_impulses() {
                self.x_step.copy_from_slice(&self.state.x);
            }
            for i in 0..self.particle_count() {
                let vn = self.state.v[i] + self.asm.b[i] * (h / self.model.mass[i]);
                // constrained directions take the prescribed velocity
                let z = self.filter.z(i, &self.state.x[i], &self.state.v[i], h);
                let v_new = self.filter.apply(i, vn)
                    + (self.state.v[i] + z - self.filter.apply(i, self.state.v[i] + z));
                self.impulse[i] = (v_new - vn) * self.model.mass[i];
                self.state.v[i] = v_new;
                self.state.x[i] += self.state.v[i] * h;
            }
            self.finish_constraints(h);
        }
        StepStats {
            kinetic,
            gravity: grav,
            elastic: elastic0,
            total: kinetic + grav + elastic0,
            assemble_ms: t0.elapsed().as_secs_f64() * 1e3,
            converged: true,
            ..Default::default()
        }
    }
}
