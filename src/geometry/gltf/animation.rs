//! An [`Animation`] as binary glTF: every mesh's vertices in one glTF mesh (a primitive and a
//! material per animated mesh), the first frame as the base shape and every later frame as a
//! morph target, and one animation whose weights bring in target `k` at frame `k`'s time
//! `k / fps`, linearly between frames — so the played positions are the recorded ones at every frame.
//! +Y up (glTF's frame: see [`ExportFrame`]), in the given units.

use std::path::Path;

use super::{
    linear_from_srgb, write_glb_mesh, GlbMaterial, GlbMesh, GlbMorphTarget, GlbPrimitive,
    GlbWeightsAnimation,
};
use crate::geometry::animation::{to_vec3, Animation};
use crate::geometry::export_frame::{ExportFrame, Units, UpAxis};
use crate::geometry::mesh::vertex_normals;
use crate::geometry::GeometryError;

/// Writes `anim` as an animated `.glb` (see the module docs). Fails, naming the file, on an
/// empty recording, more than `u32::MAX` vertices, or what [`write_glb_mesh`] refuses.
pub fn write_animated_glb(
    path: &Path,
    anim: &Animation,
    units: Units,
) -> Result<(), GeometryError> {
    anim.check_not_empty(path)?;
    let frame = ExportFrame {
        up: UpAxis::Y,
        units,
    };
    let invalid = |m: String| GeometryError::Invalid(format!("{}: {m}", path.display()));
    let nv: usize = anim.meshes.iter().map(|m| m.vertices).sum();
    if nv > u32::MAX as usize {
        return Err(invalid(format!("{nv} vertices do not fit 32-bit indices")));
    }
    let n = anim.frame_count();
    // per frame, all meshes' vertices in the file's frame
    let file_frame = |k: usize| -> Vec<[f32; 3]> {
        anim.meshes
            .iter()
            .flat_map(|m| to_vec3(&m.frames[k]))
            .map(|v| {
                let q = frame.point(&v);
                [q.x as f32, q.y as f32, q.z as f32]
            })
            .collect()
    };
    let base = file_frame(0);
    let mut normals = Vec::with_capacity(nv);
    let mut indices = Vec::new();
    let mut primitives = Vec::new();
    let mut offset = 0u32;
    for m in &anim.meshes {
        let engine = to_vec3(&m.frames[0]);
        normals.extend(vertex_normals(&engine, &m.triangles).iter().map(|v| {
            if v.iter().all(|c| c.is_finite()) && v.norm() > 0.5 {
                let d = frame.direction(v);
                [d.x as f32, d.y as f32, d.z as f32]
            } else {
                [0.0, 1.0, 0.0]
            }
        }));
        let start = indices.len();
        indices.extend(m.triangles.iter().flatten().map(|&i| offset + i as u32));
        let [r, g, b] = m
            .colour
            .map(|c| linear_from_srgb(f64::from(c) / 255.0) as f32);
        primitives.push(GlbPrimitive {
            indices: start..indices.len(),
            material: Some(GlbMaterial {
                base_colour: [r, g, b, 1.0],
                textured: false,
                metallic: 0.0,
                roughness: 0.85,
                double_sided: true,
            }),
        });
        offset += m.vertices as u32;
    }
    let displacements: Vec<Vec<[f32; 3]>> = (1..n)
        .map(|k| {
            file_frame(k)
                .iter()
                .zip(&base)
                .map(|(p, b)| [p[0] - b[0], p[1] - b[1], p[2] - b[2]])
                .collect()
        })
        .collect();
    let names: Vec<String> = (1..n).map(|k| format!("frame_{k}")).collect();
    let targets: Vec<GlbMorphTarget> = names
        .iter()
        .zip(&displacements)
        .map(|(name, d)| GlbMorphTarget {
            name,
            displacements: d,
        })
        .collect();
    let times: Vec<f32> = (0..n).map(|k| (k as f64 / anim.fps) as f32).collect();
    let nt = n - 1;
    let mut weights = vec![0f32; n * nt];
    for k in 1..n {
        weights[k * nt + (k - 1)] = 1.0;
    }
    let animation = (nt > 0).then_some(GlbWeightsAnimation {
        times: &times,
        weights: &weights,
    });
    write_glb_mesh(
        path,
        &GlbMesh {
            positions: &base,
            normals: &normals,
            morph_targets: &targets,
            indices: &indices,
            primitives: &primitives,
            animation,
            ..Default::default()
        },
    )
}
