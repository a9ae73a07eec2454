//! Simulation checkpoints: the contact stage's state (animated bodies where they are and how
//! fast their surface moves, friction, pins to bodies, the per-vertex contact memory: last
//! normal impulse, held or sliding, slip direction, depth inside a body), the frames recorded
//! so far, and the checkpoint file of a simulation with its recordings
//! ([`write_simulation_checkpoint`], [`read_simulation_checkpoint`]).
//!
//! A checkpoint holds state, not setup: it loads into a simulation set up again as the one that
//! wrote it (same cloth, bodies, stages and recordings), which its fingerprint checks. The
//! container (magic, version, hash) is [`crate::geometry::checkpoint`]'s.

use std::path::Path;

use super::body::{FrictionCoefficients, Shape};
use super::body_pin::BodyPin;
use super::collisions::{Collisions, ContactSettings};
use super::recording::Recording;
use crate::cloth::{ClothError, Simulation};
use crate::geometry::checkpoint::{self, Decoder, Encoder, Fingerprint};
use crate::geometry::GeometryError;

/// The kind of a simulation checkpoint file.
pub const SIMULATION_KIND: &str = "simulation";

impl Collisions {
    /// Feeds the bodies (names, shapes, mesh sizes and rest poses) into a fingerprint.
    pub(crate) fn fingerprint_into(&self, f: &mut Fingerprint) {
        f.u64(self.bodies.len() as u64);
        for b in &self.bodies {
            f.str(&b.name);
            match &b.shape {
                Shape::Mesh(m) => {
                    f.str("mesh").u64(m.positions().len() as u64);
                    f.u64(m.triangles().len() as u64);
                    for p in m.rest_positions() {
                        p.iter().for_each(|&c| {
                            f.f64(c);
                        });
                    }
                }
                other => {
                    f.str(&format!("{other:?}"));
                }
            }
        }
    }

    /// Writes the contact state that carries from one step to the next.
    pub(crate) fn save_into(&self, e: &mut Encoder) {
        e.str(&serde_json::to_string(&self.settings).unwrap_or_default());
        e.bool(self.frictionless);
        e.usize(self.bodies.len());
        for b in &self.bodies {
            e.f64(b.friction.static_);
            e.f64(b.friction.kinetic);
            if let Shape::Mesh(m) = &b.shape {
                e.vec3s(m.positions());
                e.vec3s(m.velocities());
            }
        }
        e.usize(self.pins.len());
        for p in &self.pins {
            e.usize(p.body);
            e.usize(p.particle);
            p.vertices.iter().for_each(|&v| e.usize(v));
            p.weights.iter().for_each(|&w| e.f64(w));
            e.vec3(&p.offset);
            e.vec3(&p.normal);
            e.bool(p.snap.is_some());
            if let Some((g, a, b)) = p.snap {
                e.f64s(&[g, a, b]);
            }
        }
        e.f64s(&self.last_impulse);
        e.bools(&self.stuck);
        e.f64s(&self.depth);
        e.vec3s(&self.slip);
        e.vec3s(&self.applied);
        let zone = self.self_collision.as_ref().map_or(&[][..], |s| &s.zone);
        e.usizes(&zone.iter().map(|&z| z as usize).collect::<Vec<_>>());
    }

    /// Reads what [`Collisions::save_into`] wrote.
    pub(crate) fn load_from(&mut self, d: &mut Decoder) -> Result<(), GeometryError> {
        let json = d.str("contact settings")?;
        let settings: ContactSettings =
            serde_json::from_str(&json).map_err(|e| d.error(format!("contact settings: {e}")))?;
        settings.validate().map_err(|e| d.error(e))?;
        self.settings = settings;
        self.frictionless = d.bool("frictionless")?;
        let bodies = d.usize("body count")?;
        if bodies != self.bodies.len() {
            return Err(d.error(format!(
                "{bodies} bodies, this simulation has {}",
                self.bodies.len()
            )));
        }
        for b in &mut self.bodies {
            b.friction = FrictionCoefficients {
                static_: d.f64("body friction")?,
                kinetic: d.f64("body friction")?,
            };
            if let Shape::Mesh(m) = &mut b.shape {
                let (p, v) = (d.vec3s("body positions")?, d.vec3s("body velocities")?);
                m.restore(&p, &v).map_err(|e| d.error(e))?;
            }
        }
        let pins = d.len(8, "body pins")?;
        let mut loaded = Vec::with_capacity(pins);
        for _ in 0..pins {
            let w = "body pin";
            let body = d.usize(w)?;
            let particle = d.usize(w)?;
            let vertices = [d.usize(w)?, d.usize(w)?, d.usize(w)?];
            let weights = [d.f64(w)?, d.f64(w)?, d.f64(w)?];
            let (offset, normal) = (d.vec3(w)?, d.vec3(w)?);
            let snap = if d.bool(w)? {
                let s = d.f64s(w)?;
                if s.len() != 3 {
                    return Err(d.error("a body pin's snap is not (gap, from, to)"));
                }
                Some((s[0], s[1], s[2]))
            } else {
                None
            };
            let fits = match self.bodies.get(body).map(|b| &b.shape) {
                Some(Shape::Mesh(m)) => vertices.iter().all(|&v| v < m.positions().len()),
                _ => false,
            };
            if !fits {
                return Err(d.error(format!("a pin to body {body} this setup lacks")));
            }
            loaded.push(BodyPin {
                body,
                particle,
                vertices,
                weights,
                offset,
                normal,
                snap,
            });
        }
        self.pins = loaded;
        self.last_impulse = d.f64s("last impulses")?;
        self.stuck = d.bools("held contacts")?;
        self.depth = d.f64s("depths")?;
        self.slip = d.vec3s("slip directions")?;
        self.applied = d.vec3s("applied friction")?;
        let zone = d.usizes("pass-through zones")?;
        if let Some(sc) = self.self_collision.as_mut() {
            sc.zone = zone.iter().map(|&z| z as u32).collect();
        }
        Ok(())
    }
}

/// Writes the frames recorded so far.
fn save_recordings(e: &mut Encoder, recordings: &[Recording]) {
    e.usize(recordings.len());
    for r in recordings {
        e.usize(r.animation.meshes.len());
        for m in &r.animation.meshes {
            e.usize(m.vertices);
            e.usize(m.frames.len());
            for f in &m.frames {
                f.iter().flatten().for_each(|&c| e.f32(c));
            }
        }
    }
}

/// Reads the frames [`save_recordings`] wrote into recordings started the same way.
fn load_recordings(d: &mut Decoder, recordings: &mut [Recording]) -> Result<(), GeometryError> {
    let n = d.usize("recording count")?;
    if n != recordings.len() {
        return Err(d.error(format!(
            "{n} recordings, this simulation has {} started",
            recordings.len()
        )));
    }
    for r in recordings.iter_mut() {
        let meshes = d.usize("recorded meshes")?;
        if meshes != r.animation.meshes.len() {
            return Err(d.error(format!(
                "{}: {meshes} recorded meshes, this recording has {}",
                r.path.display(),
                r.animation.meshes.len()
            )));
        }
        for m in &mut r.animation.meshes {
            let vertices = d.usize("recorded vertices")?;
            if vertices != m.vertices {
                return Err(d.error(format!(
                    "recorded mesh `{}` of {vertices} vertices, this one has {}",
                    m.name, m.vertices
                )));
            }
            let frames = d.len(vertices.max(1) * 12, "recorded frames")?;
            let mut all = Vec::with_capacity(frames);
            for _ in 0..frames {
                let f: Vec<[f32; 3]> = (0..vertices)
                    .map(|_| Ok([d.f32("frame")?, d.f32("frame")?, d.f32("frame")?]))
                    .collect::<Result<_, GeometryError>>()?;
                all.push(f);
            }
            m.frames = all;
        }
    }
    Ok(())
}

/// The payload of a simulation checkpoint: the simulation's state and its recordings' frames.
pub fn encode_simulation(sim: &Simulation, recordings: &[Recording]) -> Vec<u8> {
    let mut e = Encoder::new();
    sim.save_state(&mut e);
    save_recordings(&mut e, recordings);
    e.buf
}

/// Loads a payload [`encode_simulation`] wrote (read from `file`, for messages) into `sim`
/// and its `recordings`, set up again as those that wrote it.
pub fn decode_simulation(
    payload: &[u8],
    file: &str,
    sim: &mut Simulation,
    recordings: &mut [Recording],
) -> Result<(), ClothError> {
    let mut d = Decoder::new(payload, file);
    sim.load_state(&mut d)?;
    load_recordings(&mut d, recordings).map_err(|e| ClothError::Parameter(e.to_string()))?;
    if !d.finished() {
        return Err(ClothError::Parameter(format!(
            "checkpoint {file}: bytes left over after the simulation's state"
        )));
    }
    Ok(())
}

/// Checks that a checkpoint of fingerprint `found` (file `file`) belongs to `sim`.
pub fn check_fingerprint(file: &str, found: u64, sim: &Simulation) -> Result<(), ClothError> {
    let own = sim.fingerprint();
    if found != own {
        return Err(ClothError::Parameter(format!(
            "checkpoint {file} is of another scene (setup fingerprint {found:016x}, this \
             simulation's {own:016x}: another cloth, other bodies, stages or settings)"
        )));
    }
    Ok(())
}

/// Writes `sim` and its `recordings` to a checkpoint file, atomically.
pub fn write_simulation_checkpoint(
    path: &Path,
    sim: &Simulation,
    recordings: &[Recording],
) -> Result<(), ClothError> {
    let payload = encode_simulation(sim, recordings);
    checkpoint::write_file(path, SIMULATION_KIND, sim.fingerprint(), &payload).map_err(|e| {
        ClothError::Output {
            path: path.display().to_string(),
            message: e.to_string(),
        }
    })
}

/// Reads a checkpoint file into `sim` and its `recordings`, which must be set up as those that
/// wrote it: another format version, another scene or a damaged file is refused with a
/// message naming the file.
pub fn read_simulation_checkpoint(
    path: &Path,
    sim: &mut Simulation,
    recordings: &mut [Recording],
) -> Result<(), ClothError> {
    let f = checkpoint::read_file(path, SIMULATION_KIND)
        .map_err(|e| ClothError::Parameter(e.to_string()))?;
    let file = path.display().to_string();
    check_fingerprint(&file, f.fingerprint, sim)?;
    decode_simulation(&f.payload, &file, sim, recordings)
}
