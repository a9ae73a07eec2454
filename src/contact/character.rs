//! Animated characters as collision bodies: the MakeHuman mannequin skinned by a retargeted
//! BVH clip ([`crate::body::Animation`]) becomes a [`MeshBody`] whose vertices follow the clip.

use std::path::Path;
use std::sync::Arc;

use super::body::Body;
use super::mesh_body::{BodyAnimation, MeshBody};
use super::ContactError;
use crate::body::{Animation, Mannequin, Motion, RetargetOptions};
use crate::geometry::Vec3;

impl BodyAnimation for Animation {
    fn positions_at(&self, t: f64, out: &mut Vec<Vec3>) {
        self.vertices_at(t, out);
    }
}

/// A clip preceded by a move from the rest pose into its first frame, so that garments put on
/// the mannequin at rest (where nothing crosses them) are carried into the motion: over the first
/// `blend` seconds each vertex eases from its rest position to its place in the clip's first
/// frame; then the clip plays from its start.
#[derive(Debug)]
pub struct Dressing {
    animation: Animation,
    rest: Vec<Vec3>,
    blend: f64,
}

impl BodyAnimation for Dressing {
    fn positions_at(&self, t: f64, out: &mut Vec<Vec3>) {
        if t >= self.blend {
            self.animation.vertices_at(t - self.blend, out);
            return;
        }
        self.animation.vertices_at(0.0, out);
        let s = (t / self.blend).clamp(0.0, 1.0);
        let w = s * s * (3.0 - 2.0 * s);
        for (o, r) in out.iter_mut().zip(&self.rest) {
            *o = r + (*o - r) * w;
        }
    }
}

/// The MakeHuman mannequin read from `makehuman_dir` as a collision body, at rest, or driven by
/// the BVH clip `motion` (retargeted with `options`), reached from the rest pose over `blend`
/// seconds (the clip starts at simulation time `blend`).
pub fn mannequin_body(
    makehuman_dir: &Path,
    motion: Option<&Path>,
    options: RetargetOptions,
    blend: f64,
) -> Result<Body, ContactError> {
    if !(blend.is_finite() && blend >= 0.0) {
        return Err(ContactError::Parameter(format!(
            "mannequin: the blend from the rest pose must be finite and >= 0 s, got {blend}"
        )));
    }
    let err = |e: crate::body::BodyError| ContactError::Parameter(e.to_string());
    let man = Mannequin::load_makehuman(makehuman_dir).map_err(err)?;
    let name = "mannequin";
    match motion {
        None => {
            let mesh = MeshBody::new(name, man.rest_positions().to_vec(), man.triangles())?;
            Ok(Body::mesh(mesh))
        }
        Some(path) => {
            let clip = Motion::load_bvh(path).map_err(err)?;
            let tris = man.triangles().to_vec();
            let rest = man.rest_positions().to_vec();
            let anim = Animation::new(man, clip, options).map_err(err)?;
            let mut mesh = MeshBody::new(name, rest.clone(), &tris)?;
            if blend > 0.0 {
                mesh.animate(Arc::new(Dressing {
                    animation: anim,
                    rest,
                    blend,
                }))?;
            } else {
                mesh.animate(Arc::new(anim))?;
            }
            Ok(Body::mesh(mesh))
        }
    }
}
