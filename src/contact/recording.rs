//! Recording a simulation as an animation cache: the cloth (with its rest coordinates as
//! texture coordinates) and every mesh body (a mannequin) captured frame by frame into an
//! [`Animation`], then written as USD (`.usda`), PC2 point caches with their rest OBJs, or
//! animated glTF (`.glb`). Spheres, boxes and planes do not move and are left out.

use std::path::{Path, PathBuf};

use super::body::Shape;
use super::SimulationContact;
use crate::cloth::Simulation;
use crate::geometry::animation::{AnimatedMesh, Animation};
use crate::geometry::export_frame::{ExportFrame, UpAxis};
use crate::geometry::gltf::write_animated_glb;
use crate::geometry::pc2::write_pc2;
use crate::geometry::usd::write_usda;
use crate::geometry::{write_obj, GeometryError, Vec3};

/// Colour of the cloth in caches (sRGB, the renderer's fabric blue).
const CLOTH_COLOUR: [u8; 3] = [72, 104, 150];
/// Colour of bodies in caches (sRGB, the renderer's body beige).
const BODY_COLOUR: [u8; 3] = [206, 196, 178];

/// The file format of a recording.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CacheFormat {
    /// A USD stage as text (`.usda`).
    Usd,
    /// PC2 point caches, one per mesh, each beside its rest OBJ.
    Pc2,
    /// Animated binary glTF (morph targets).
    Glb,
}

impl CacheFormat {
    /// Parses `usd` (or `usda`), `pc2` or `glb` (or `gltf`).
    pub fn parse(s: &str) -> Result<Self, String> {
        match s {
            "usd" | "usda" => Ok(CacheFormat::Usd),
            "pc2" => Ok(CacheFormat::Pc2),
            "glb" | "gltf" => Ok(CacheFormat::Glb),
            _ => Err(format!(
                "cache format `{s}`: expected \"usd\", \"pc2\" or \"glb\""
            )),
        }
    }

    /// The format a path's extension names, if any.
    pub fn from_path(path: &Path) -> Option<Self> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        Self::parse(&ext).ok()
    }
}

/// A simulation being recorded.
#[derive(Debug, Clone)]
pub struct Recording {
    /// Where the cache goes (for PC2: the cloth's cache; bodies get `<stem>_<name>.pc2`).
    pub path: PathBuf,
    /// Its format.
    pub format: CacheFormat,
    /// Its axes and units.
    pub frame: ExportFrame,
    /// The frames so far.
    pub animation: Animation,
    /// Indices of the recorded (mesh) bodies.
    bodies: Vec<usize>,
}

impl Recording {
    /// Starts recording `sim` at `fps` frames per second into `path`; the current state is
    /// frame 0 (frame `k` is then the state after `k` frames of `run_frames`). Fails on a glTF cache asked to be other than +Y up, or a bad frame rate.
    pub fn start(
        sim: &Simulation,
        path: PathBuf,
        format: CacheFormat,
        frame: ExportFrame,
        fps: f64,
    ) -> Result<Self, GeometryError> {
        if format == CacheFormat::Glb && frame.up != UpAxis::Y {
            return Err(GeometryError::Invalid(format!(
                "{}: glTF is +Y up by its specification",
                path.display()
            )));
        }
        let mesh = &sim.model.mesh;
        let mut meshes = vec![AnimatedMesh {
            name: "cloth".into(),
            triangles: mesh.triangles.clone(),
            uvs: Some(mesh.rest.clone()),
            colour: CLOTH_COLOUR,
            vertices: sim.particle_count(),
            frames: Vec::new(),
        }];
        let mut bodies = Vec::new();
        for (k, b) in sim.contact().bodies.iter().enumerate() {
            if let Shape::Mesh(m) = &b.shape {
                bodies.push(k);
                meshes.push(AnimatedMesh {
                    name: format!("body_{k}"),
                    triangles: m.triangles().to_vec(),
                    uvs: None,
                    colour: BODY_COLOUR,
                    vertices: m.positions().len(),
                    frames: Vec::new(),
                });
            }
        }
        let mut rec = Recording {
            path,
            format,
            frame,
            animation: Animation::new(fps, meshes)?,
            bodies,
        };
        rec.capture(sim)?;
        Ok(rec)
    }

    /// Appends the simulation's current state as the next frame.
    pub fn capture(&mut self, sim: &Simulation) -> Result<(), GeometryError> {
        let bodies = &sim.contact().bodies;
        let mut frame: Vec<&[Vec3]> = vec![&sim.state.x];
        for &k in &self.bodies {
            match bodies.get(k).map(|b| &b.shape) {
                Some(Shape::Mesh(m)) => frame.push(m.positions()),
                _ => {
                    return Err(GeometryError::Invalid(format!(
                        "{}: body {k} is no longer a mesh body",
                        self.path.display()
                    )))
                }
            }
        }
        self.animation.push_frame(&frame)
    }

    /// Writes the cache (and for PC2 the rest OBJs); returns the files written.
    pub fn write(&self) -> Result<Vec<PathBuf>, GeometryError> {
        let path = &self.path;
        match self.format {
            CacheFormat::Usd => {
                write_usda(path, &self.animation, self.frame)?;
                Ok(vec![path.clone()])
            }
            CacheFormat::Glb => {
                write_animated_glb(path, &self.animation, self.frame.units)?;
                Ok(vec![path.clone()])
            }
            CacheFormat::Pc2 => self.write_pc2(),
        }
    }

    /// One PC2 cache and one rest OBJ (the first frame) per mesh.
    fn write_pc2(&self) -> Result<Vec<PathBuf>, GeometryError> {
        self.animation.check_not_empty(&self.path)?;
        let stem = self.path.with_extension("");
        let mut written = Vec::new();
        for (k, m) in self.animation.meshes.iter().enumerate() {
            let base = if k == 0 {
                stem.clone()
            } else {
                PathBuf::from(format!("{}_{}", stem.display(), m.name))
            };
            let (pc2, obj) = (base.with_extension("pc2"), base.with_extension("obj"));
            write_pc2(&pc2, m, self.frame, 0.0)?;
            let rest = crate::geometry::animation::to_vec3(&m.frames[0]);
            write_obj(&obj, &rest, &m.triangles, m.uvs.as_deref(), self.frame)?;
            written.extend([pc2, obj]);
        }
        Ok(written)
    }
}
