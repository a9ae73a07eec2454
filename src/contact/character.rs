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

/// The MakeHuman mannequin read from `makehuman_dir` as a collision body, at rest, or driven by
/// the BVH clip `motion` (retargeted with `options`; animation time 0 is the simulation's 0).
pub fn mannequin_body(
    makehuman_dir: &Path,
    motion: Option<&Path>,
    options: RetargetOptions,
) -> Result<Body, ContactError> {
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
            let anim = Animation::new(man, clip, options).map_err(err)?;
            let mut start = Vec::new();
            anim.vertices_at(0.0, &mut start);
            let mut mesh = MeshBody::new(name, start, &tris)?;
            mesh.animate(Arc::new(anim))?;
            Ok(Body::mesh(mesh))
        }
    }
}
