//! A simulation's state in a checkpoint: everything a step reads that an earlier step wrote,
//! so that a simulation set up again the same way and loaded from a checkpoint continues bit
//! for bit as the one that wrote it. That is the particles' state and clock, the settings,
//! pins and attachments (with their trajectories' clocks), the statistics of every step, the
//! warm start of the solver (the last Δv), the internal-friction states of the assembly and of
//! the geometric multigrid's coarse cloths, the element parameters a sewing schedule changes
//! (thread rest lengths and stiffness, seam hinges), the sewing's progress, the buckling
//! sides' random state, and each step stage's own state (contact, compression release).
//!
//! The fixed part (mesh, material, elements, bodies) is not stored: it is the setup, rebuilt by
//! the code that built it first, and checked by a [fingerprint](Simulation::fingerprint).

use super::elements::SpringKind;
use super::solver::assembly::Assembly;
use super::stats::StepStats;
use super::{Attachment, ClothError, Simulation, SimulationParameters};
use crate::geometry::checkpoint::{Decoder, Encoder, Fingerprint};
use crate::geometry::{GeometryError, Vec3};

fn bad(e: GeometryError) -> ClothError {
    ClothError::Parameter(e.to_string())
}

fn save_stats(e: &mut Encoder, s: &StepStats) {
    e.u64(s.step);
    for v in [s.time, s.kinetic, s.gravity, s.elastic, s.total] {
        e.f64(v);
    }
    e.u32(s.cg_iterations);
    e.f64(s.residual);
    e.bool(s.converged);
    for v in [s.assemble_ms, s.solve_ms, s.step_ms, s.collision_ms] {
        e.f64(v);
    }
    e.usize(s.contacts);
    e.usize(s.self_contacts);
    e.f64(s.min_distance);
    e.usize(s.penetrating);
    e.usize(s.intersections);
    e.u32(s.retries);
}

fn load_stats(d: &mut Decoder) -> Result<StepStats, GeometryError> {
    let w = "statistics";
    Ok(StepStats {
        step: d.u64(w)?,
        time: d.f64(w)?,
        kinetic: d.f64(w)?,
        gravity: d.f64(w)?,
        elastic: d.f64(w)?,
        total: d.f64(w)?,
        cg_iterations: d.u32(w)?,
        residual: d.f64(w)?,
        converged: d.bool(w)?,
        assemble_ms: d.f64(w)?,
        solve_ms: d.f64(w)?,
        step_ms: d.f64(w)?,
        collision_ms: d.f64(w)?,
        contacts: d.usize(w)?,
        self_contacts: d.usize(w)?,
        min_distance: d.f64(w)?,
        penetrating: d.usize(w)?,
        intersections: d.usize(w)?,
        retries: d.u32(w)?,
    })
}

impl Assembly {
    /// Writes the friction states (committed and trial) into a checkpoint.
    pub fn save_friction(&self, e: &mut Encoder) {
        for v in [
            &self.fric_spring,
            &self.fric_quad,
            &self.fric_hinge,
            &self.trial_spring,
            &self.trial_quad,
            &self.trial_hinge,
        ] {
            e.f64s(&v.iter().flatten().copied().collect::<Vec<_>>());
        }
        for v in [&self.fric_bend, &self.trial_bend] {
            e.vec3s(&v.iter().flatten().copied().collect::<Vec<_>>());
        }
    }

    /// Reads the friction states [`Assembly::save_friction`] wrote.
    pub fn load_friction(&mut self, d: &mut Decoder) -> Result<(), GeometryError> {
        let pairs = |d: &mut Decoder, what: &str| -> Result<Vec<[f64; 2]>, GeometryError> {
            let v = d.f64s(what)?;
            if v.len() % 2 != 0 {
                return Err(d.error(format!("{what}: an odd number of values")));
            }
            Ok(v.chunks(2).map(|c| [c[0], c[1]]).collect())
        };
        self.fric_spring = pairs(d, "spring friction")?;
        self.fric_quad = pairs(d, "shear friction")?;
        self.fric_hinge = pairs(d, "hinge friction")?;
        self.trial_spring = pairs(d, "spring trial friction")?;
        self.trial_quad = pairs(d, "shear trial friction")?;
        self.trial_hinge = pairs(d, "hinge trial friction")?;
        let bends = |d: &mut Decoder, what: &str| -> Result<Vec<[Vec3; 2]>, GeometryError> {
            let v = d.vec3s(what)?;
            if v.len() % 2 != 0 {
                return Err(d.error(format!("{what}: an odd number of values")));
            }
            Ok(v.chunks(2).map(|c| [c[0], c[1]]).collect())
        };
        self.fric_bend = bends(d, "bending friction")?;
        self.trial_bend = bends(d, "bending trial friction")?;
        let (t, c) = (&self.trial_spring, &self.fric_spring);
        if t.len() != c.len() || self.trial_bend.len() != self.fric_bend.len() {
            return Err(d.error("friction states of different lengths"));
        }
        Ok(())
    }
}

/// Bytes of one encoded [`StepStats`].
const STATS_BYTES: usize = 8 * 6 + 4 + 8 + 1 + 8 * 4 + 8 * 2 + 8 + 8 * 2 + 4;

impl Simulation {
    /// The fingerprint of the simulation's setup: particle count, mesh (triangles, rest and
    /// initial positions), element counts, fabric, grid, and the step stages (their kinds,
    /// bodies and sizes). A checkpoint loads only into a simulation of the same fingerprint.
    pub fn fingerprint(&self) -> u64 {
        let mut f = Fingerprint::default();
        let m = &self.model;
        f.str("cloth").u64(m.particle_count() as u64);
        for t in &m.mesh.triangles {
            t.iter().for_each(|&i| {
                f.u64(i as u64);
            });
        }
        for (p, r) in m.mesh.positions.iter().zip(&m.mesh.rest) {
            p.iter().chain(r.iter()).for_each(|&c| {
                f.f64(c);
            });
        }
        for n in [
            m.springs.len(),
            m.shear_quads.len(),
            m.bend_lines.len(),
            m.hinges.len(),
            m.arcs.len(),
        ] {
            f.u64(n as u64);
        }
        f.str(&format!(
            "{:?} {:?} {} {}",
            m.fabric,
            m.grid,
            m.choi_ko,
            m.law.has_friction()
        ));
        f.u64(self.stages.len() as u64);
        for s in &self.stages {
            f.str(s.stage_name());
            s.fingerprint(&mut f);
        }
        f.value()
    }

    /// Writes the simulation's state (see the module's description).
    pub fn save_state(&self, e: &mut Encoder) {
        e.usize(self.particle_count());
        e.vec3s(&self.state.x);
        e.vec3s(&self.state.v);
        e.f64(self.state.time);
        e.u64(self.state.step);
        e.str(&serde_json::to_string(&self.params).unwrap_or_default());
        e.str(&serde_json::to_string(&self.attachments).unwrap_or_default());
        e.usize(self.stats.len());
        self.stats.iter().for_each(|s| save_stats(e, s));
        e.u64(self.unconverged_steps);
        e.f64(self.gravity_share);
        e.vec3s(&self.dv);
        // the step guard: what the next step's checks compare with
        e.u64(self.retried_steps);
        e.bool(self.sewing_settled);
        e.bool(self.stages_constrain);
        e.bool(self.guard.record.is_some());
        if let Some(r) = &self.guard.record {
            e.u64(r.step);
            for v in [r.span.0, r.span.1, r.total, r.work, r.scale] {
                e.f64(v);
            }
            for v in r.gravity.iter() {
                e.f64(*v);
            }
        }
        for v in [&self.x_save, &self.v_save, &self.x_prev, &self.v_prev] {
            e.vec3s(v);
        }
        // element parameters a sewing schedule changes
        let m = &self.model;
        e.f64s(&m.springs.iter().map(|s| s.rest).collect::<Vec<_>>());
        let seams: Vec<f64> = m
            .springs
            .iter()
            .filter_map(|s| match s.kind {
                SpringKind::Seam {
                    stiffness,
                    max_force,
                } => Some([stiffness, max_force]),
                _ => None,
            })
            .flatten()
            .collect();
        e.f64s(&seams);
        e.f64s(&m.hinges.iter().map(|h| h.weight).collect::<Vec<_>>());
        e.bool(self.sewing.is_some());
        if let Some(sew) = &self.sewing {
            e.opt_f64(sew.sewn_at);
        }
        e.bool(self.sides.is_some());
        if let Some(sides) = &self.sides {
            e.u64(sides.rng_state());
            e.u64(sides.started);
        }
        self.asm.save_friction(e);
        e.bool(self.mg.is_some());
        if let Some(mg) = &self.mg {
            mg.save_state(e);
        }
        e.usize(self.stages.len());
        for s in &self.stages {
            e.str(s.stage_name());
            let mut inner = Encoder::new();
            s.save_state(&mut inner);
            e.bytes(&inner.buf);
        }
    }

    /// Reads a state [`Simulation::save_state`] wrote into this simulation, set up as the one
    /// that wrote it (the caller checks the [fingerprint](Simulation::fingerprint)). On an
    /// error the simulation may be left partly loaded: build it again.
    pub fn load_state(&mut self, d: &mut Decoder) -> Result<(), ClothError> {
        self.load_state_inner(d).map_err(bad)
    }

    fn load_state_inner(&mut self, d: &mut Decoder) -> Result<(), GeometryError> {
        let n = d.usize("particle count")?;
        if n != self.particle_count() {
            return Err(d.error(format!(
                "a cloth of {n} particles, this simulation has {}",
                self.particle_count()
            )));
        }
        d.vec3s_into(&mut self.state.x, "positions")?;
        d.vec3s_into(&mut self.state.v, "velocities")?;
        self.state.time = d.f64("time")?;
        self.state.step = d.u64("step")?;
        let json = d.str("settings")?;
        let params: SimulationParameters =
            serde_json::from_str(&json).map_err(|e| d.error(format!("settings: {e}")))?;
        params.validate().map_err(|e| d.error(e))?;
        self.params = params;
        let json = d.str("attachments")?;
        let attachments: Vec<Attachment> =
            serde_json::from_str(&json).map_err(|e| d.error(format!("attachments: {e}")))?;
        if attachments
            .iter()
            .flat_map(|a| &a.particles)
            .any(|&i| i >= n)
            || attachments
                .iter()
                .any(|a| a.anchors.len() != a.particles.len())
        {
            return Err(d.error("an attachment names a particle the cloth does not have"));
        }
        self.attachments = attachments;
        let count = d.len(STATS_BYTES, "statistics")?;
        self.stats = (0..count)
            .map(|_| load_stats(d))
            .collect::<Result<_, _>>()?;
        self.unconverged_steps = d.u64("unconverged steps")?;
        self.gravity_share = d.f64("gravity share")?;
        d.vec3s_into(&mut self.dv, "warm start")?;
        self.retried_steps = d.u64("retried steps")?;
        self.sewing_settled = d.bool("step guard")?;
        self.stages_constrain = d.bool("step guard")?;
        self.guard.record = if d.bool("step guard")? {
            let w = "step guard";
            let step = d.u64(w)?;
            let span = (d.f64(w)?, d.f64(w)?);
            let (total, work, scale) = (d.f64(w)?, d.f64(w)?, d.f64(w)?);
            let gravity = crate::geometry::Vec3::new(d.f64(w)?, d.f64(w)?, d.f64(w)?);
            Some(super::step_guard::EnergyRecord {
                step,
                span,
                total,
                work,
                scale,
                gravity,
            })
        } else {
            None
        };
        d.vec3s_into(&mut self.x_save, "step start")?;
        d.vec3s_into(&mut self.v_save, "step start")?;
        d.vec3s_into(&mut self.x_prev, "step before")?;
        d.vec3s_into(&mut self.v_prev, "step before")?;
        let rests = d.f64s("spring rest lengths")?;
        let seams = d.f64s("seam threads")?;
        let weights = d.f64s("hinge weights")?;
        let m = &mut self.model;
        let seam_count = m
            .springs
            .iter()
            .filter(|s| matches!(s.kind, SpringKind::Seam { .. }))
            .count();
        if rests.len() != m.springs.len()
            || seams.len() != 2 * seam_count
            || weights.len() != m.hinges.len()
        {
            return Err(d.error("springs or hinges of another cloth"));
        }
        let mut seam = seams.chunks(2);
        for (s, &r) in m.springs.iter_mut().zip(&rests) {
            s.rest = r;
            if let SpringKind::Seam { .. } = s.kind {
                let c = seam.next().expect("counted above");
                s.kind = SpringKind::Seam {
                    stiffness: c[0],
                    max_force: c[1],
                };
            }
        }
        for (h, &w) in m.hinges.iter_mut().zip(&weights) {
            h.weight = w;
        }
        let sewing = d.bool("sewing")?;
        if sewing != self.sewing.is_some() {
            return Err(d.error("a garment being sewn and one that is not"));
        }
        if let Some(sew) = &mut self.sewing {
            sew.sewn_at = d.opt_f64("sewn at")?;
        }
        let sides = d.bool("buckling sides")?;
        if sides != self.sides.is_some() {
            return Err(d.error("Choi–Ko buckling sides on one side only"));
        }
        if let Some(s) = &mut self.sides {
            s.set_rng_state(d.u64("buckling random state")?);
            s.started = d.u64("arcs started")?;
        }
        self.asm.load_friction(d)?;
        let mg = d.bool("multigrid")?;
        match (&mut self.mg, mg) {
            (Some(m), true) => m.load_state(d)?,
            (None, false) => {}
            _ => return Err(d.error("a multigrid preconditioner on one side only")),
        }
        let stages = d.usize("stage count")?;
        if stages != self.stages.len() {
            return Err(d.error(format!(
                "{stages} step stages, this simulation has {}",
                self.stages.len()
            )));
        }
        for s in &mut self.stages {
            let name = d.str("stage name")?;
            if name != s.stage_name() {
                return Err(d.error(format!(
                    "stage `{name}` where this simulation has `{}`",
                    s.stage_name()
                )));
            }
            let bytes = d.bytes("stage state")?;
            let mut inner = Decoder::new(bytes, &d.file);
            s.load_state(&mut inner)?;
            if !inner.finished() {
                return Err(d.error(format!("stage `{name}`: bytes left over")));
            }
        }
        Ok(())
    }
}
