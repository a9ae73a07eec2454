//! The contact stage of a simulation step. Before the implicit solve, every cloth vertex that
//! will come within the thickness of a body during the step gets its normal velocity
//! prescribed through Baraff–Witkin's filter (S = I − n nᵀ, z); after the solve the contact
//! impulse read from the solve's residual drives Coulomb friction (static and kinetic), the
//! vertices still inside the thickness are pushed out (Provot), cloth–cloth contact is resolved
//! ([`SelfCollision`]), and the step's statistics are gathered.

use std::time::Instant;

use rayon::prelude::*;

use super::body::{Body, FrictionCoefficients, Shape};
use super::body_pin::BodyPin;
pub use super::contact_settings::{ContactSettings, ContactStats};
use super::proximity::Proximity;
use super::self_collision::{SelfCollision, SelfCollisionReport};
use super::ContactError;
use crate::cloth::constraints::{Filter, ParticleFilter};
use crate::geometry::Vec3;

/// Per-vertex body contact of the current step.
#[derive(Debug, Clone, Copy)]
struct Slot {
    body: u32,
    normal: Vec3,
    velocity: Vec3,
    /// Held fully (static friction) rather than sliding.
    stuck: bool,
    /// The normal velocity prescribed while sliding (m/s).
    vn: f64,
    /// Distance to the body at the start of the step (m).
    distance: f64,
}

const NO_BODY: u32 = u32::MAX;

/// Bodies, settings and workspaces of a cloth's contacts.
#[derive(Debug, Clone, Default)]
pub struct Collisions {
    /// Collision bodies.
    pub bodies: Vec<Body>,
    /// Settings.
    pub settings: ContactSettings,
    /// Statistics of the last step.
    pub stats: ContactStats,
    /// Particles that follow mesh bodies.
    pub pins: Vec<BodyPin>,
    /// Contacts slide without friction while set (a garment being sewn slips into place).
    pub frictionless: bool,
    slots: Vec<Slot>,
    pub(super) last_impulse: Vec<f64>,
    pub(super) stuck: Vec<bool>,
    /// Per vertex: how deep inside a body it was at the last statistics pass (m, 0 outside).
    pub(super) depth: Vec<f64>,
    pub(super) self_collision: Option<SelfCollision>,
    inv_mass: Vec<f64>,
    /// Per particle, the direction it slides along a body (zero if not sliding).
    pub(super) slip: Vec<Vec3>,
    /// Per particle, the unit direction of the kinetic friction put into this step's solve.
    pub(super) applied: Vec<Vec3>,
    ms: f64,
}

impl Collisions {
    /// Whether anything collides (bodies, or self-collision on).
    pub fn is_active(&self) -> bool {
        !self.bodies.is_empty() || self.settings.self_collision
    }

    /// The contact of a cloth with these triangles and rest positions: no bodies, default
    /// settings, self-collision ready to be switched on.
    pub fn for_cloth(triangles: &[[usize; 3]], rest: &[Vec3]) -> Self {
        Collisions {
            self_collision: Some(SelfCollision::new(triangles, rest)),
            ..Default::default()
        }
    }

    /// Sets self-collision's pass-through zones (see [`SelfCollision::set_zones`]).
    pub fn set_zones(&mut self, zone: &[u32]) {
        if let Some(sc) = self.self_collision.as_mut() {
            sc.set_zones(zone);
        }
    }

    /// Declares pairs of vertices sewn together (see [`SelfCollision::set_welds`]).
    pub fn set_welds(&mut self, n: usize, pairs: &[(usize, usize)]) {
        if let Some(sc) = self.self_collision.as_mut() {
            sc.set_welds(n, pairs);
        }
    }

    /// Pins cloth `particles` (now at `x`) to mesh body `body`: each follows the point of the
    /// body's surface nearest to it in the rest pose (so that a waistband picks the waist, not a
    /// hand swinging by), keeping its present offset from it, turned with the surface normal.
    /// Neighbouring particles follow distinct, ordered surface points, so a gathered rim keeps
    /// its order instead of folding through itself (following the nearest vertex, as before,
    /// stacked several particles on one vertex and crossed the rim's edges). With
    /// `snap = Some((gap, from, to))` the offset eases between times `from` and `to` to `gap`
    /// along the vertex normal: the particles are drawn onto the body (a gathered waistband).
    pub fn pin_to_body(
        &mut self,
        body: usize,
        particles: &[usize],
        x: &[Vec3],
        snap: Option<(f64, f64, f64)>,
    ) -> Result<(), ContactError> {
        let mesh = BodyPin::mesh_of(&self.bodies, body, snap)?;
        for &p in particles {
            let pin = BodyPin::new(mesh, body, p, x, snap)?;
            self.pins.retain(|q| q.particle != p);
            self.pins.push(pin);
        }
        Ok(())
    }

    /// Before the solve of the step from `t` to `t + dt`: moves animated bodies to `t + dt` and
    /// constrains the normal velocity of vertices that would end within the thickness.
    pub fn begin_step(&mut self, x: &[Vec3], v: &[Vec3], t: f64, dt: f64, filter: &mut Filter) {
        let t0 = Instant::now();
        let n = x.len();
        self.slots.clear();
        self.slots.resize(
            n,
            Slot {
                body: NO_BODY,
                normal: Vec3::zeros(),
                velocity: Vec3::zeros(),
                stuck: false,
                vn: 0.0,
                distance: 0.0,
            },
        );
        self.last_impulse.resize(n, 0.0);
        self.stuck.resize(n, false);
        for b in &mut self.bodies {
            b.advance_to(t + dt, dt);
        }
        for pin in &self.pins {
            if let Some(Shape::Mesh(m)) = self.bodies.get(pin.body).map(|b| &b.shape) {
                let (at, normal) = pin.anchor(m);
                let target = pin.target(&at, &normal, t + dt);
                if matches!(filter.kind[pin.particle], ParticleFilter::Fixed { .. }) {
                    continue; // a simulation attachment takes precedence
                }
                filter.kind[pin.particle] = ParticleFilter::Fixed { target };
                filter.any = true;
            }
        }
        self.stats = ContactStats {
            min_distance: f64::INFINITY,
            ..Default::default()
        };
        if self.bodies.is_empty() {
            self.ms = t0.elapsed().as_secs_f64() * 1e3;
            return;
        }
        let h = self.settings.thickness;
        let bodies = &self.bodies;
        let bounds: Vec<(Vec3, Vec3)> = bodies.iter().map(|b| b.bounds()).collect();
        let last = &self.last_impulse;
        let depth = &self.depth;
        let found: Vec<Option<(u32, Proximity)>> = (0..n)
            .into_par_iter()
            .with_min_len(256)
            .map(|i| {
                let reach = 1.5 * h + v[i].norm() * dt + depth.get(i).copied().unwrap_or(0.0);
                let mut best: Option<(u32, Proximity, f64)> = None;
                for (k, b) in bodies.iter().enumerate() {
                    let (lo, hi) = &bounds[k];
                    if (0..3).any(|a| x[i][a] < lo[a] - reach || x[i][a] > hi[a] + reach) {
                        continue;
                    }
                    if let Some(p) = b.proximity(&x[i], reach) {
                        // predicted gap at the end of the step (the body is at its end pose)
                        let gap = p.distance + v[i].dot(&p.normal) * dt;
                        if best.as_ref().is_none_or(|bb| gap < bb.2) {
                            best = Some((k as u32, p, gap));
                        }
                    }
                }
                let (k, p, gap) = best?;
                // a contact that pulled last step lets go unless the vertex is inside
                let pulling = last[i] < 0.0 && p.distance >= 0.9 * h;
                // only vertices already near the surface: one falling fast from further up (a top
                // layer onto cloth resting on the body) is left to cloth–cloth contact and push-out
                (gap < 1.1 * h && p.distance < 1.5 * h && !pulling).then_some((k, p))
            })
            .collect();
        let max_push = self.settings.max_push_speed;
        for (i, f) in found.into_iter().enumerate() {
            let Some((k, p)) = f else {
                self.last_impulse[i] = 0.0;
                self.stuck[i] = false;
                continue;
            };
            if matches!(filter.kind[i], ParticleFilter::Fixed { .. }) {
                continue;
            }
            // end exactly at the thickness, never pushing out faster than max_push
            let vn = ((h - p.distance) / dt).min(p.velocity.dot(&p.normal) + max_push);
            let stuck = self.stuck[i] && self.last_impulse[i] > 0.0;
            if stuck {
                // static friction inside the solve: the particle moves with the surface
                let vt_body = p.velocity - p.normal * p.normal.dot(&p.velocity);
                let mut target = x[i] + (vt_body + p.normal * vn) * dt;
                // where the surface bends (an armpit, a garment pinched between arm and chest)
                // the surface's tangential motion can carry the target into another part of
                // the body: a held particle ends no deeper than planned
                let planned = p.distance + vn * dt;
                if let Some(q) =
                    self.bodies[k as usize].proximity(&target, h + (vt_body.norm() + vn.abs()) * dt)
                {
                    if q.distance < planned - 0.25 * h {
                        target += q.normal * (planned - q.distance);
                    }
                }
                filter.kind[i] = ParticleFilter::Fixed { target };
                filter.any = true;
            } else {
                filter.constrain_normal(i, p.normal, vn);
            }
            self.slots[i] = Slot {
                body: k,
                normal: p.normal,
                velocity: p.velocity,
                stuck,
                vn,
                distance: p.distance,
            };
            self.stats.contacts += 1;
        }
        self.ms = t0.elapsed().as_secs_f64() * 1e3;
    }

    /// Whether this step holds any particle by static friction (set by `begin_step`): only
    /// then may [`Collisions::release_pulling_holds`] let one go.
    pub fn holds_any(&self) -> bool {
        self.slots.iter().any(|s| s.body != NO_BODY && s.stuck)
    }

    /// After a solve: a particle held by static friction whose normal impulse (`impulse`,
    /// momentum, from the solve's residual) pulls it onto the body is not held: in `filter`
    /// it becomes free where it lies outside 0.9 times the thickness, a sliding contact (its
    /// normal velocity still prescribed) where it is deeper, and the step is solved again.
    /// Left to the next step, such a hold was let go only then, the neighbours that had pulled
    /// it threw it into the body on that step, and it was caught and held again a few steps
    /// later (the rim of a drape on Galerkin coarse levels cycled so). Returns whether any hold
    /// was loosened.
    pub fn release_pulling_holds(&mut self, impulse: &[Vec3], filter: &mut Filter) -> bool {
        let h = self.settings.thickness;
        let mut any = false;
        for (i, s) in self.slots.iter_mut().enumerate() {
            if s.body == NO_BODY || !s.stuck || s.normal.dot(&impulse[i]) >= 0.0 {
                continue;
            }
            s.stuck = false;
            filter.kind[i] = if s.distance >= 0.9 * h {
                ParticleFilter::Free
            } else {
                ParticleFilter::Normal {
                    normal: s.normal,
                    velocity: s.vn,
                }
            };
            any = true;
        }
        any
    }

    /// Friction coefficients of a contact with body `body` (zero while frictionless).
    fn friction_with(&self, body: u32) -> FrictionCoefficients {
        if self.frictionless {
            return FrictionCoefficients {
                static_: 0.0,
                kinetic: 0.0,
            };
        }
        self.settings
            .friction
            .combine(&self.bodies[body as usize].friction)
    }

    /// Kinetic friction inside an implicit step's solve: after `begin_step`, adds to the
    /// right-hand side `b` (momentum) of each sliding contact the impulse −μk jn t̂, jn the
    /// normal impulse of its last step and t̂ its slip direction (the last step's tangential
    /// velocity relative to the body, or the way the particle broke loose). Without it the
    /// friction would be a correction of the solved velocity, judged by momentum, which a
    /// particle driven by a stiff spring barely has: it would be stopped on every step and
    /// never slide. Particles held by static friction are fixed in the solve instead.
    pub fn add_kinetic_friction(&mut self, b: &mut [Vec3]) {
        let n = b.len();
        self.applied.clear();
        self.applied.resize(n, Vec3::zeros());
        self.slip.resize(n, Vec3::zeros());
        for i in 0..n {
            let s = self.slots[i];
            if s.body == NO_BODY || s.stuck || self.last_impulse[i] <= 0.0 {
                continue;
            }
            // the slip direction, if it still lies mostly along the surface
            let t = self.slip[i] - s.normal * s.normal.dot(&self.slip[i]);
            let len = t.norm();
            let along = len > 0.5 * self.slip[i].norm(); // false for a zero (or NaN) slip
            if !along {
                continue;
            }
            let mu = self.friction_with(s.body).kinetic;
            if mu <= 0.0 {
                continue;
            }
            let t = t / len;
            b[i] -= t * (mu * self.last_impulse[i]);
            self.applied[i] = t;
        }
    }

    /// After the solve: friction from the contact impulses `impulse` (momentum, from the
    /// solve's residual), push-out of vertices inside the thickness, cloth–cloth response, and
    /// statistics. `x_old` are the positions at the start of the step, `x`, `v` the solved end
    /// state (corrected in place), `mass` the particle masses, `filter` the step's filter.
    ///
    /// A held particle stays held while the tangential impulse that held it in the solve is
    /// within μs times the normal one; else it slips the way it was pushed. A slipping particle
    /// whose kinetic friction was in the solve (`add_kinetic_friction`) keeps its solved
    /// velocity unless the friction reversed it, which stops it (held from the next step). A
    /// new contact loses μk times its normal impulse of tangential momentum and is held if
    /// that stops it. A contact that pushed ends with the particle moving with the surface
    /// along the normal: the push-out to the thickness is a position correction, not a
    /// velocity the particle keeps.
    #[allow(clippy::too_many_arguments)]
    pub fn end_step(
        &mut self,
        x_old: &[Vec3],
        x: &mut [Vec3],
        v: &mut [Vec3],
        impulse: &[Vec3],
        mass: &[f64],
        filter: &Filter,
        dt: f64,
    ) {
        let t0 = Instant::now();
        let n = x.len();
        let h = self.settings.thickness;
        self.applied.resize(n, Vec3::zeros());
        self.slip.resize(n, Vec3::zeros());
        for i in 0..n {
            let s = self.slots[i];
            let applied = std::mem::replace(&mut self.applied[i], Vec3::zeros());
            if s.body == NO_BODY {
                self.slip[i] = Vec3::zeros();
                continue;
            }
            let jn = s.normal.dot(&impulse[i]);
            self.last_impulse[i] = jn;
            if jn <= 0.0 {
                self.stuck[i] = false;
                self.slip[i] = Vec3::zeros();
                continue;
            }
            let mu = self.friction_with(s.body);
            if s.stuck {
                let jt = impulse[i] - s.normal * jn;
                self.stuck[i] = jt.norm() <= mu.static_ * jn;
                // the reaction opposed the push: the particle slips the other way
                self.slip[i] = if self.stuck[i] { Vec3::zeros() } else { -jt };
                continue;
            }
            let rel = v[i] - s.velocity;
            let vn = s.normal * s.normal.dot(&rel);
            let vt = rel - vn;
            if applied != Vec3::zeros() {
                // kinetic friction was in the solve: it stops the particle if it reversed it
                self.stuck[i] = vt.dot(&applied) <= 0.0;
                if self.stuck[i] {
                    v[i] = s.velocity + vn;
                    x[i] = x_old[i] + v[i] * dt;
                    self.slip[i] = Vec3::zeros();
                } else {
                    self.slip[i] = vt;
                }
                continue;
            }
            let speed = vt.norm();
            let dv = jn / mass[i];
            self.stuck[i] = speed <= mu.static_ * dv;
            let vt_new = if self.stuck[i] {
                Vec3::zeros()
            } else {
                vt * (1.0 - mu.kinetic * dv / speed).max(0.0)
            };
            self.slip[i] = vt_new;
            v[i] = s.velocity + vn + vt_new;
            x[i] = x_old[i] + v[i] * dt;
        }
        // a contact that pushed leaves the particle on the surface moving with it: the normal
        // velocity that carried it out to the thickness was a position correction (up to
        // max_push_speed), and kept as velocity it flew the particle off and the cloth's
        // forces drove it back in on the next step (a two-step cycle). Not while frictionless
        // (a garment being sewn: the threads drag the pieces round the body, and without the
        // push-out speed the trousers' crotch point stayed 4.4 mm open at 16 mm edges)
        for i in 0..n {
            let s = self.slots[i];
            if s.body != NO_BODY && self.last_impulse[i] > 0.0 && !self.frictionless {
                let rel = v[i] - s.velocity;
                v[i] -= s.normal * s.normal.dot(&rel);
            }
        }
        // push-out (Provot) and body statistics
        if !self.bodies.is_empty() {
            self.push_out(x_old, x, v, filter, 0.5 * h, None);
        }
        // cloth–cloth
        if self.settings.self_collision {
            if let Some(sc) = self.self_collision.as_mut() {
                self.inv_mass.clear();
                // particles held by pins or bodies are not moved by cloth–cloth impulses: the
                // free layer gives way, so nothing is pushed into a body
                // (a compression release's hold yields: its particle is free here, so a
                // release never carries it through another layer)
                self.inv_mass.extend((0..n).map(|i| match filter.kind[i] {
                    ParticleFilter::Fixed { .. } if !filter.is_yielding(i) => 0.0,
                    _ => 1.0 / mass[i],
                }));
                let rep: SelfCollisionReport = sc.respond(
                    x_old,
                    x,
                    v,
                    &self.inv_mass,
                    dt,
                    self.settings.self_thickness,
                    self.settings.self_friction,
                );
                if !self.bodies.is_empty() && sc.moved_any() {
                    let moved = sc.moved().to_vec();
                    self.push_out(x_old, x, v, filter, 0.1 * h, Some(&moved));
                }
                self.stats.self_contacts = rep.proximities;
                self.stats.ccd_hits = rep.ccd_hits;
                self.stats.zone_rounds = rep.zone_rounds;
                self.stats.self_stopped = rep.stopped;
            }
        }
        self.stats.collision_ms = self.ms + t0.elapsed().as_secs_f64() * 1e3;
        let t1 = Instant::now();
        if !self.bodies.is_empty() {
            self.body_statistics(x);
        }
        if self.settings.count_intersections {
            if let Some(sc) = self.self_collision.as_mut() {
                self.stats.intersections = sc.count_intersections(x);
            }
        }
        self.stats.stats_ms = t1.elapsed().as_secs_f64() * 1e3;
    }

    /// Distance to bodies, penetrations and self-intersections of the cloth at `x`, computed
    /// now (not the last step's figures).
    pub fn report(&mut self, x: &[Vec3]) -> ContactStats {
        let saved = self.stats;
        self.stats = ContactStats {
            min_distance: f64::INFINITY,
            ..Default::default()
        };
        if !self.bodies.is_empty() {
            self.body_statistics(x);
        }
        if let Some(sc) = self.self_collision.as_mut() {
            self.stats.intersections = sc.count_intersections(x);
        }
        std::mem::replace(&mut self.stats, saved)
    }

    /// The intersecting (edge, triangle) pairs of the cloth at `x` (empty without
    /// self-collision), for diagnostics.
    pub fn self_intersections(&mut self, x: &[Vec3]) -> Vec<([u32; 2], [u32; 3])> {
        self.self_collision
            .as_mut()
            .map_or_else(Vec::new, |sc| sc.intersections(x))
    }

    /// Moves vertices closer than `target` to a body back out to `target` and removes their
    /// approaching normal velocity. Only vertices with `only[i]` when given. A vertex is searched
    /// as deep as it was found inside a body at the last statistics pass plus how far it moved
    /// this step (from `x_old`): one that crossed the thickness in one step is still found.
    fn push_out(
        &self,
        x_old: &[Vec3],
        x: &mut [Vec3],
        v: &mut [Vec3],
        filter: &Filter,
        target: f64,
        only: Option<&[bool]>,
    ) {
        let bodies = &self.bodies;
        let depth = &self.depth;
        let h = self.settings.thickness;
        x.par_iter_mut()
            .zip(v.par_iter_mut())
            .enumerate()
            .with_min_len(256)
            .for_each(|(i, (xi, vi))| {
                if matches!(filter.kind[i], ParticleFilter::Fixed { .. })
                    || only.is_some_and(|o| !o[i])
                {
                    return;
                }
                let reach = h + depth.get(i).copied().unwrap_or(0.0) + (*xi - x_old[i]).norm();
                for b in bodies {
                    let (lo, hi) = b.bounds();
                    if (0..3).any(|a| xi[a] < lo[a] - reach || xi[a] > hi[a] + reach) {
                        continue;
                    }
                    if let Some(p) = b.proximity(xi, reach) {
                        if p.distance < target {
                            *xi += p.normal * (target - p.distance);
                            let rel = (*vi - p.velocity).dot(&p.normal);
                            if rel < 0.0 {
                                *vi -= p.normal * rel;
                            }
                        }
                    }
                }
            });
    }

    fn body_statistics(&mut self, x: &[Vec3]) {
        let bodies = &self.bodies;
        let h = self.settings.thickness;
        self.depth.resize(x.len(), 0.0);
        x.par_iter()
            .zip(self.depth.par_iter_mut())
            .with_min_len(256)
            .for_each(|(xi, di)| {
                let mut m = f64::INFINITY;
                for b in bodies {
                    let (lo, hi) = b.bounds();
                    if (0..3).any(|a| xi[a] < lo[a] - 4.0 * h || xi[a] > hi[a] + 4.0 * h) {
                        continue;
                    }
                    if let Some(p) = b.proximity(xi, f64::INFINITY) {
                        m = m.min(p.distance);
                    }
                }
                // the signed distance, negated, for the reduction below
                *di = if m.is_finite() { -m } else { f64::NEG_INFINITY };
            });
        let (min, inside) = self.depth.iter().fold((f64::INFINITY, 0), |(m, k), &d| {
            (m.min(-d), k + usize::from(d > 0.0))
        });
        for d in &mut self.depth {
            *d = d.max(0.0);
        }
        self.stats.min_distance = min;
        self.stats.penetrating = inside;
    }
}
