//! Real garments on the person of a synthetic sequence ([`Wardrobe`]): each garment table
//! (FreeSewing patterns, `scripts/patterns/*.garment.json`) is meshed, pre-positioned, sewn
//! and draped on the person at rest with [`crate::garment::dress()`] in a measured fabric; the
//! body then moves from its rest pose into the motion's pose at [`BodyMotion::start`] and
//! plays the motion, and each garment is simulated through it (body contact and
//! self-collision on), so the cloth folds, slides and hides the body as clothes do.
//!
//! The simulations run in the person's rest frame: the motion is moved by the horizontal turn
//! and shift that bring the hips at the start onto the hips at rest (a rigid motion that keeps
//! gravity, so the physics is the same), and the cloth is moved back for rendering. So the
//! garments are carried from the rest pose into the start pose by the posture alone, not
//! dragged across the floor to where the capture stands.
//!
//! Sim time runs: sewing and draping at rest for [`DressingOptions::settle`] s after the last
//! seam closes, with a step of 1/120 s; then [`DressingOptions::blend`] s from the rest pose
//! into the start pose; then the motion, with a step of [`DressingOptions::dt`].
//! [`Wardrobe::positions_at`] asks for the cloth at motion times that never go back; each
//! garment is stepped past the instant and its positions interpolated linearly between steps.

use std::fmt;
use std::path::PathBuf;
use std::sync::Arc;
use std::time::Instant;

use super::clothing::{Garment, Palette};
use super::sequence_files::SequenceError;
use crate::body::Mannequin;
use crate::cloth::{Simulation, SimulationParameters};
use crate::contact::{BodyAnimation, Shape, SimulationContact};
use crate::garment::{dress, read_garment, DressParameters};
use crate::geometry::Vec3;
use crate::kes::lab::measured_fabric;
use crate::kes::read_fabric;

/// Largest push-out speed of the cloth from the moving body (m/s; the contact default, 1 m/s,
/// suits a garment at rest).
const MOTION_PUSH_SPEED: f64 = 4.0;

/// Step while the garments are sewn and draped at rest (s).
const DRAPE_DT: f64 = 1.0 / 120.0;

/// Settings of [`Wardrobe::dress`].
#[derive(Clone, Debug, PartialEq)]
pub struct DressingOptions {
    /// Garment tables (`*.garment.json`), dressed in this order; a table whose name holds
    /// `trouser`, `paco` or `pant` is coloured as trousers, any other as a shirt.
    pub garments: Vec<PathBuf>,
    /// The fabric file (`kes::fabric` format) all garments are cut from.
    pub fabric: PathBuf,
    /// Target edge length of the garment meshes (m, 0.005..=0.08). Default 0.02.
    pub edge: f64,
    /// Step through the motion (s, 1e-4..=1/60). Default 1/240.
    pub dt: f64,
    /// Draping at rest after the last seam closes (s, 0..=10). Default 1.0.
    pub settle: f64,
    /// Move from the rest pose into the start pose (s, 0.05..=5). Default 0.6.
    pub blend: f64,
    /// Motion played before the first frame, so the clothes have caught up with the body
    /// (s, 0..=5). Default 0.8.
    pub lead_in: f64,
}

impl DressingOptions {
    /// The defaults with these garment tables and fabric.
    pub fn new(garments: Vec<PathBuf>, fabric: PathBuf) -> Self {
        DressingOptions {
            garments,
            fabric,
            edge: 0.02,
            dt: 1.0 / 240.0,
            settle: 1.0,
            blend: 0.6,
            lead_in: 0.8,
        }
    }

    /// Checks the ranges given in the field docs.
    pub fn validate(&self) -> Result<(), SequenceError> {
        let bad = |m: String| Err(SequenceError::Options(m));
        if self.garments.is_empty() || self.garments.len() > 4 {
            return bad(format!(
                "dressing needs 1 to 4 garment tables, got {}",
                self.garments.len()
            ));
        }
        for (name, v, lo, hi) in [
            ("edge", self.edge, 0.005, 0.08),
            ("dt", self.dt, 1e-4, 1.0 / 60.0),
            ("settle", self.settle, 0.0, 10.0),
            ("blend", self.blend, 0.05, 5.0),
            ("lead_in", self.lead_in, 0.0, 5.0),
        ] {
            if !(v.is_finite() && (lo..=hi).contains(&v)) {
                return bad(format!(
                    "dressing `{name}` must be in [{lo}, {hi}], got {v}"
                ));
            }
        }
        Ok(())
    }
}

/// The skin at a motion time, written into a reused buffer.
pub type SkinAt = Arc<dyn Fn(f64, &mut Vec<Vec3>) + Send + Sync>;

/// The person's skin through the motion, in the world.
#[derive(Clone)]
pub struct BodyMotion {
    /// The skin (one position per skin vertex of the mannequin dressed) at motion time `t`.
    pub skin_at: SkinAt,
    /// The motion time the garments join the motion at (the body reaches its pose there at
    /// the end of the blend).
    pub start: f64,
    /// Left and right hip joints at rest.
    pub hips_rest: [Vec3; 2],
    /// Left and right hip joints at `start`.
    pub hips_start: [Vec3; 2],
}

impl fmt::Debug for BodyMotion {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("BodyMotion")
            .field("start", &self.start)
            .finish_non_exhaustive()
    }
}

/// A turn about the vertical and a horizontal shift: world = `turn`(local − `from`) + `to`.
#[derive(Clone, Copy, Debug)]
struct Placement {
    cos: f64,
    sin: f64,
    from: Vec3,
    to: Vec3,
}

impl Placement {
    /// The placement taking the hips at rest onto the hips at the start (horizontally).
    fn of(rest: [Vec3; 2], start: [Vec3; 2]) -> Placement {
        let flat = |v: Vec3| Vec3::new(v.x, v.y, 0.0);
        let a = flat(rest[0] - rest[1]);
        let b = flat(start[0] - start[1]);
        let angle = b.y.atan2(b.x) - a.y.atan2(a.x);
        Placement {
            cos: angle.cos(),
            sin: angle.sin(),
            from: flat((rest[0] + rest[1]) * 0.5),
            to: flat((start[0] + start[1]) * 0.5),
        }
    }

    fn to_world(self, p: Vec3) -> Vec3 {
        let d = p - self.from;
        Vec3::new(
            self.cos * d.x - self.sin * d.y,
            self.sin * d.x + self.cos * d.y,
            d.z,
        ) + self.to
    }

    fn to_local(self, p: Vec3) -> Vec3 {
        let d = p - self.to;
        Vec3::new(
            self.cos * d.x + self.sin * d.y,
            -self.sin * d.x + self.cos * d.y,
            d.z,
        ) + self.from
    }
}

/// The body of the garments' simulations: at rest while they are draped, eased into the
/// start pose, then the motion, in the rest frame.
struct Carried {
    rest: Vec<Vec3>,
    motion: BodyMotion,
    placement: Placement,
    /// Sim time the blend starts at, and its length.
    drape: f64,
    blend: f64,
}

impl fmt::Debug for Carried {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Carried")
            .field("drape", &self.drape)
            .field("blend", &self.blend)
            .finish_non_exhaustive()
    }
}

impl BodyAnimation for Carried {
    fn positions_at(&self, t: f64, out: &mut Vec<Vec3>) {
        if t <= self.drape {
            out.clear();
            out.extend_from_slice(&self.rest);
            return;
        }
        let s = ((t - self.drape) / self.blend).min(1.0);
        let motion_t = self.motion.start + (t - self.drape - self.blend).max(0.0);
        (self.motion.skin_at)(motion_t, out);
        for p in out.iter_mut() {
            *p = self.placement.to_local(*p);
        }
        if s < 1.0 {
            let w = s * s * (3.0 - 2.0 * s);
            for (o, r) in out.iter_mut().zip(&self.rest) {
                *o = r + (*o - r) * w;
            }
        }
    }
}

/// One garment in its simulation.
#[derive(Debug)]
struct Layer {
    sim: Simulation,
    /// Positions and sim time before the last step.
    before: Vec<Vec3>,
    before_time: f64,
    colours: Vec<[f32; 3]>,
    triangles: Vec<[u32; 3]>,
}

/// What dressing and simulating the garments took and gave.
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct WardrobeReport {
    /// Garment file names, in layer order.
    pub garments: Vec<String>,
    /// Cloth vertices, all garments.
    pub vertices: usize,
    /// Cloth triangles, all garments.
    pub triangles: usize,
    /// Mesh edge asked for (m).
    pub edge: f64,
    /// Wall time of meshing, pre-positioning, sewing and draping at rest (s).
    pub dress_seconds: f64,
    /// Wall time of the simulation through the blend and the motion (s).
    pub motion_seconds: f64,
    /// Cloth steps taken, all garments.
    pub steps: u64,
    /// Frames whose garments were checked against the body.
    pub checked_frames: usize,
    /// Most garment vertices inside the body at one checked frame.
    pub worst_penetrating: usize,
    /// Garment vertices inside the body at each checked frame.
    pub penetrating: Vec<usize>,
    /// Smallest signed cloth–body distance seen at a checked frame (m).
    pub min_distance: f64,
    /// Largest distance of a garment vertex from the body at a checked frame (m): the
    /// clothes are worn, not fallen.
    pub max_distance: f64,
}

/// Garments simulated on a moving person (see the module docs).
#[derive(Debug)]
pub struct Wardrobe {
    layers: Vec<Layer>,
    placement: Placement,
    /// Sim time at motion time `motion.start`.
    sim_at_start: f64,
    start: f64,
    dt: f64,
    /// What was done so far.
    pub report: WardrobeReport,
}

impl Wardrobe {
    /// Dresses `person` (the mannequin with the person's rest skin,
    /// [`Mannequin::with_rest_skin`]) in the garments of `options`, sews and drapes them at
    /// rest, and gets them ready to follow `motion`. Colours from `palette`. Errors name the
    /// garment file.
    pub fn dress(
        person: &Mannequin,
        motion: BodyMotion,
        palette: &Palette,
        options: &DressingOptions,
    ) -> Result<Wardrobe, SequenceError> {
        options.validate()?;
        let t0 = Instant::now();
        let fail = |path: &PathBuf, m: String| SequenceError::Motion {
            path: path.clone(),
            message: format!("dressing: {m}"),
        };
        let spec =
            read_fabric(&options.fabric).map_err(|e| fail(&options.fabric, e.to_string()))?;
        let (fabric, law) = measured_fabric(&spec).map_err(|e| fail(&options.fabric, e))?;
        let law = Arc::new(law);
        let placement = Placement::of(motion.hips_rest, motion.hips_start);
        let mut params = DressParameters::default();
        params.mesh.edge_length = options.edge;
        let sim_params = SimulationParameters {
            dt: DRAPE_DT,
            ..SimulationParameters::default()
        };
        let mut layers = Vec::new();
        let mut report = WardrobeReport {
            edge: options.edge,
            min_distance: f64::INFINITY,
            ..WardrobeReport::default()
        };
        let mut dressed = Vec::new();
        let mut drape: f64 = 0.0;
        for path in &options.garments {
            let pattern = read_garment(path).map_err(|e| fail(path, e.to_string()))?;
            let mut d = dress(&pattern, fabric, person, &params, sim_params)
                .map_err(|e| fail(path, e.to_string()))?;
            d.simulation
                .set_material(law.clone())
                .map_err(|e| fail(path, e.to_string()))?;
            drape = drape.max(d.report.closing_time + options.settle);
            let name = path
                .file_name()
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_default();
            let lower = name.to_lowercase();
            let kind = if ["trouser", "paco", "pant"]
                .iter()
                .any(|k| lower.contains(k))
            {
                Garment::Trousers
            } else {
                Garment::Shirt
            };
            report.garments.push(name);
            dressed.push((path, d, kind));
        }
        for (path, mut d, kind) in dressed {
            let carried = Arc::new(Carried {
                rest: person.rest_positions().to_vec(),
                motion: motion.clone(),
                placement,
                drape,
                blend: options.blend,
            });
            let body = d
                .simulation
                .contact_mut()
                .bodies
                .first_mut()
                .ok_or_else(|| fail(path, "the dressed simulation has no body".into()))?;
            if let Shape::Mesh(mesh) = &mut body.shape {
                mesh.animate(carried)
                    .map_err(|e| fail(path, e.to_string()))?;
            }
            let sim = d.simulation;
            let colours = sim
                .state
                .x
                .iter()
                .map(|p| palette.colour(kind, *p))
                .collect();
            let triangles: Vec<[u32; 3]> = sim
                .model
                .mesh
                .triangles
                .iter()
                .map(|t| t.map(|i| i as u32))
                .collect();
            report.vertices += sim.state.x.len();
            report.triangles += triangles.len();
            layers.push(Layer {
                before: sim.state.x.clone(),
                before_time: 0.0,
                sim,
                colours,
                triangles,
            });
        }
        let mut w = Wardrobe {
            layers,
            placement,
            sim_at_start: drape + options.blend,
            start: motion.start,
            dt: options.dt,
            report,
        };
        // sew and drape at rest, then move into the start pose
        w.step_to(drape, DRAPE_DT)?;
        // a body part moving at metres per second (a golfer's arms) into the cloth: pushed
        // out within a step or two (the push-out's speed is not kept as velocity)
        for l in &mut w.layers {
            l.sim.contact_mut().settings.max_push_speed = MOTION_PUSH_SPEED;
        }
        w.report.dress_seconds = t0.elapsed().as_secs_f64();
        Ok(w)
    }

    /// Steps every garment until its sim time reaches `t`, with step `dt`.
    fn step_to(&mut self, t: f64, dt: f64) -> Result<(), SequenceError> {
        for (k, layer) in self.layers.iter_mut().enumerate() {
            layer.sim.params.dt = dt;
            while layer.sim.state.time < t - 1e-9 {
                layer.before.copy_from_slice(&layer.sim.state.x);
                layer.before_time = layer.sim.state.time;
                layer.sim.step().map_err(|e| SequenceError::Motion {
                    path: PathBuf::from(&self.report.garments[k]),
                    message: format!("the garment's simulation failed: {e}"),
                })?;
                self.report.steps += 1;
            }
        }
        Ok(())
    }

    /// Cloth vertices, all garments, in the order of [`Self::positions_at`].
    pub fn vertex_count(&self) -> usize {
        self.layers.iter().map(|l| l.before.len()).sum()
    }

    /// The garments' triangles, indices offset by `offset` (the vertices placed after
    /// `offset` others in a scene), in the order of [`Self::positions_at`].
    pub fn triangles(&self, offset: u32) -> Vec<[u32; 3]> {
        let mut out = Vec::new();
        let mut base = offset;
        for l in &self.layers {
            out.extend(l.triangles.iter().map(|t| t.map(|i| i + base)));
            base += l.before.len() as u32;
        }
        out
    }

    /// The garments' colours, in the order of [`Self::positions_at`].
    pub fn colours(&self) -> Vec<[f32; 3]> {
        self.layers
            .iter()
            .flat_map(|l| l.colours.iter().copied())
            .collect()
    }

    /// Appends to `out` the garments' vertices in the world at motion time `t` (not before
    /// the last time asked for: the simulations only go forward), stepping them as needed.
    pub fn positions_at(&mut self, t: f64, out: &mut Vec<Vec3>) -> Result<(), SequenceError> {
        let t0 = Instant::now();
        let sim_t = self.sim_at_start + (t - self.start);
        // the blend at the drape's step, then the motion's
        let blend_end = self.sim_at_start;
        if sim_t > self.layers[0].sim.state.time {
            self.step_to(sim_t.min(blend_end), DRAPE_DT)?;
            if sim_t > blend_end {
                self.step_to(sim_t, self.dt)?;
            }
        }
        for l in &self.layers {
            let now = l.sim.state.time;
            let span = now - l.before_time;
            let w = if span > 0.0 {
                ((sim_t - l.before_time) / span).clamp(0.0, 1.0)
            } else {
                1.0
            };
            out.extend(
                l.before
                    .iter()
                    .zip(&l.sim.state.x)
                    .map(|(a, b)| self.placement.to_world(a + (b - a) * w)),
            );
        }
        self.report.motion_seconds += t0.elapsed().as_secs_f64();
        Ok(())
    }

    /// Checks the garments against the body now: counts the vertices inside it and keeps
    /// the worst count, the smallest and the largest distance in the report.
    pub fn check(&mut self) {
        let mut inside = 0;
        for l in &self.layers {
            let body = &l.sim.contact().bodies[0];
            for q in l
                .sim
                .state
                .x
                .iter()
                .filter_map(|p| body.proximity(p, f64::INFINITY))
            {
                inside += usize::from(q.distance < 0.0);
                self.report.min_distance = self.report.min_distance.min(q.distance);
                self.report.max_distance = self.report.max_distance.max(q.distance);
            }
        }
        self.report.worst_penetrating = self.report.worst_penetrating.max(inside);
        self.report.penetrating.push(inside);
        self.report.checked_frames += 1;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn placement_maps_the_rest_hips_onto_the_start_hips_and_back() {
        let rest = [Vec3::new(0.1, 0.0, 0.9), Vec3::new(-0.1, 0.0, 0.9)];
        let start = [Vec3::new(2.0, 1.1, 0.95), Vec3::new(2.0, 0.9, 0.95)];
        let p = Placement::of(rest, start);
        for (r, s) in rest.iter().zip(&start) {
            let w = p.to_world(*r);
            assert!((w.x - s.x).abs() < 1e-12 && (w.y - s.y).abs() < 1e-12);
            assert_eq!(w.z, r.z);
        }
        let q = Vec3::new(0.3, -0.7, 1.2);
        assert!((p.to_local(p.to_world(q)) - q).norm() < 1e-12);
    }
}
