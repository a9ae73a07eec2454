//! Binary glTF 2.0 (`.glb`) output, the one writer of every `.glb` the crate makes
//! ([`write_glb_mesh`]): a [`GlbMesh`] with single-precision positions and normals, optional
//! texture coordinates, optional morph targets, 32-bit indices split into primitives (each
//! with an optional PBR material), and an optional PNG texture embedded in the binary chunk.
//! [`write_glb`] writes a cloth's shape through it (smooth normals, a double-sided fabric
//! material).
//!
//! Layout, the same for every file: the binary chunk holds positions, normals, the morph
//! targets' displacements, texture coordinates, indices and the PNG, in that order; buffer
//! views and accessors list positions, normals, texture coordinates, morph targets, then each
//! primitive's indices (and the image's view last). Files are written atomically.

mod document;

mod animation;
pub use animation::write_animated_glb;

use std::ops::Range;
use std::path::Path;

use gltf_json::accessor::{ComponentType, Type};
use gltf_json::buffer::Target;
use gltf_json::material::{PbrBaseColorFactor, PbrMetallicRoughness, StrengthFactor};
use gltf_json::mesh::MorphTarget;
use gltf_json::texture::{Info, MinFilter};
use gltf_json::{Accessor, Index, Material, Root, Texture};

use crate::geometry::export_frame::{ExportFrame, Units, UpAxis};
use crate::geometry::files::check_mesh;
use crate::geometry::mesh::vertex_normals;
use crate::geometry::{GeometryError, Vec3};
use document::{
    f32_bounds, finish_glb, glb_accessor, glb_png_texture, glb_root, glb_triangles, glb_view,
};

/// Base colour of the exported material, sRGB (a muted denim blue).
const FABRIC_SRGB: [u8; 3] = [72, 104, 150];

/// A PBR metallic-roughness material of a primitive.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GlbMaterial {
    /// Base colour factor, linear RGBA (multiplies the texture where there is one).
    pub base_colour: [f32; 4],
    /// Whether the mesh's texture ([`GlbMesh::texture`]) is the base colour texture.
    pub textured: bool,
    /// Metalness in [0, 1].
    pub metallic: f32,
    /// Roughness in [0, 1].
    pub roughness: f32,
    /// Whether back faces are drawn too.
    pub double_sided: bool,
}

/// One primitive: a range of [`GlbMesh::indices`] (a multiple of 3 long) and its material.
#[derive(Debug, Clone, PartialEq)]
pub struct GlbPrimitive {
    /// Indices of its triangles, positions in [`GlbMesh::indices`].
    pub indices: Range<usize>,
    /// Its material; `None`: the viewer's default.
    pub material: Option<GlbMaterial>,
}

/// A PNG image embedded as the texture of the textured materials, sampled linearly and
/// clamped at the edges.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GlbTexture<'a> {
    /// The PNG file's bytes.
    pub png: &'a [u8],
    /// Minification through mipmaps (trilinear) rather than plain linear filtering.
    pub mipmapped: bool,
}

/// A morph target: one displacement per vertex, and its name (written to
/// `mesh.extras.targetNames`, the convention Blender, three.js and Unity read).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GlbMorphTarget<'a> {
    /// Name of the target.
    pub name: &'a str,
    /// Displacement of each vertex.
    pub displacements: &'a [[f32; 3]],
}

/// Everything [`write_glb_mesh`] writes: one mesh of one or more primitives sharing its
/// vertex attributes.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct GlbMesh<'a> {
    /// Vertex positions (`POSITION`, written with their bounds).
    pub positions: &'a [[f32; 3]],
    /// Vertex normals (`NORMAL`), one per position.
    pub normals: &'a [[f32; 3]],
    /// Texture coordinates (`TEXCOORD_0`, glTF's top-left origin), one per position, if any.
    pub uvs: Option<&'a [[f32; 2]]>,
    /// Morph targets (`POSITION` displacements, default weights zero).
    pub morph_targets: &'a [GlbMorphTarget<'a>],
    /// Triangle corners, 3 per triangle, indices into the positions.
    pub indices: &'a [u32],
    /// The primitives, each a range of `indices`.
    pub primitives: &'a [GlbPrimitive],
    /// The texture of the textured materials.
    pub texture: Option<GlbTexture<'a>>,
    /// An animation of the morph-target weights, if any.
    pub animation: Option<GlbWeightsAnimation<'a>>,
}

/// Key frames of the mesh's morph-target weights, interpolated linearly: at `times[k]` the
/// weights are `weights[k·T .. (k+1)·T]` for `T` targets.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GlbWeightsAnimation<'a> {
    /// Key times (s), increasing.
    pub times: &'a [f32],
    /// The weights of every target at every key time, time-major.
    pub weights: &'a [f32],
}

/// Writes `mesh` as binary glTF 2.0: one scene, one node, one mesh with a primitive per
/// [`GlbPrimitive`]; see the [module docs](self) for the layout. Parent folders are created;
/// the file is written to a temporary file and renamed, so a failure never leaves a
/// half-written file.
///
/// Fails, naming the file, on an empty mesh or primitive (glTF forbids empty accessors),
/// attributes whose length differs from the positions', indices out of range, a primitive
/// beyond the indices or not made of whole triangles, positions or displacements beyond
/// single-precision range, more than 4 GiB, or an I/O error.
pub fn write_glb_mesh(path: &Path, mesh: &GlbMesh) -> Result<(), GeometryError> {
    let invalid = |m: String| GeometryError::Invalid(format!("{}: {m}", path.display()));
    check_glb_mesh(mesh).map_err(invalid)?;
    let (lo, hi) = f32_bounds(mesh.positions).map_err(invalid)?;
    let mut target_bounds = Vec::with_capacity(mesh.morph_targets.len());
    for t in mesh.morph_targets {
        let bounds = f32_bounds(t.displacements)
            .map_err(|m| invalid(format!("morph target `{}`: {m}", t.name)))?;
        target_bounds.push(bounds);
    }

    // Binary chunk: positions, normals, displacements, texture coordinates, indices (each a
    // multiple of 4 bytes long), then the image.
    let n = mesh.positions.len() as u64;
    let mut bin: Vec<u8> = Vec::new();
    let floats = |bin: &mut Vec<u8>, data: &mut dyn Iterator<Item = &f32>| {
        let at = bin.len() as u64;
        data.for_each(|c| bin.extend_from_slice(&c.to_le_bytes()));
        at
    };
    let pos_at = floats(&mut bin, &mut mesh.positions.iter().flatten());
    let nrm_at = floats(&mut bin, &mut mesh.normals.iter().flatten());
    let target_at: Vec<u64> = mesh
        .morph_targets
        .iter()
        .map(|t| floats(&mut bin, &mut t.displacements.iter().flatten()))
        .collect();
    let uv_at = mesh
        .uvs
        .map(|uvs| floats(&mut bin, &mut uvs.iter().flatten()));
    let anim_at = mesh.animation.map(|a| {
        let times = floats(&mut bin, &mut a.times.iter());
        (times, floats(&mut bin, &mut a.weights.iter()))
    });
    let idx_at = bin.len() as u64;
    mesh.indices
        .iter()
        .for_each(|i| bin.extend_from_slice(&i.to_le_bytes()));
    let image_at = bin.len() as u64;
    if let Some(texture) = &mesh.texture {
        bin.extend_from_slice(texture.png);
    }

    let (mut root, buffer) = glb_root(bin.len());
    let array = Some(Target::ArrayBuffer);
    let attribute =
        |root: &mut Root, at: u64, type_: Type, bounds: Option<([f32; 3], [f32; 3])>| {
            let size = if type_ == Type::Vec2 { 8 } else { 12 };
            let view = root.push(glb_view(buffer, at, size * n, array));
            let accessor = glb_accessor(view, n, ComponentType::F32, type_);
            root.push(match bounds {
                Some((lo, hi)) => Accessor {
                    min: Some(serde_json::json!(lo)),
                    max: Some(serde_json::json!(hi)),
                    ..accessor
                },
                None => accessor,
            })
        };
    let pos_acc = attribute(&mut root, pos_at, Type::Vec3, Some((lo, hi)));
    let nrm_acc = attribute(&mut root, nrm_at, Type::Vec3, None);
    let uv_acc = uv_at.map(|at| attribute(&mut root, at, Type::Vec2, None));
    let targets: Vec<MorphTarget> = target_at
        .iter()
        .zip(&target_bounds)
        .map(|(&at, &bounds)| MorphTarget {
            positions: Some(attribute(&mut root, at, Type::Vec3, Some(bounds))),
            normals: None,
            tangents: None,
        })
        .collect();
    let index_accessors: Vec<Index<Accessor>> = mesh
        .primitives
        .iter()
        .map(|p| {
            let (first, count) = (p.indices.start as u64, p.indices.len() as u64);
            let view = root.push(glb_view(
                buffer,
                idx_at + 4 * first,
                4 * count,
                Some(Target::ElementArrayBuffer),
            ));
            root.push(glb_accessor(view, count, ComponentType::U32, Type::Scalar))
        })
        .collect();
    let texture = mesh.texture.map(|t| {
        let view = root.push(glb_view(buffer, image_at, t.png.len() as u64, None));
        let filter = if t.mipmapped {
            MinFilter::LinearMipmapLinear
        } else {
            MinFilter::Linear
        };
        glb_png_texture(&mut root, view, filter)
    });

    let primitives = mesh
        .primitives
        .iter()
        .zip(index_accessors)
        .map(|(p, indices)| {
            let material = p.material.map(|m| root.push(glb_material(&m, texture)));
            let targets = (!targets.is_empty()).then(|| targets.clone());
            glb_triangles(pos_acc, nrm_acc, uv_acc, indices, material, targets)
        })
        .collect();
    if let (Some(a), Some((times_at, weights_at))) = (mesh.animation, anim_at) {
        push_weights_animation(&mut root, buffer, a, times_at, weights_at);
    }
    let names: Vec<&str> = mesh.morph_targets.iter().map(|t| t.name).collect();
    finish_glb(path, root, primitives, &names, bin)
}

/// Adds the animation of the (first and only) node's weights, whose key times and weights lie
/// at `times_at` and `weights_at` of the buffer.
fn push_weights_animation(
    root: &mut Root,
    buffer: Index<gltf_json::Buffer>,
    a: GlbWeightsAnimation,
    times_at: u64,
    weights_at: u64,
) {
    use gltf_json::animation::{Channel, Interpolation, Property, Sampler, Target as AnimTarget};
    use gltf_json::validation::Checked::Valid;
    let nt = a.times.len() as u64;
    let view = root.push(glb_view(buffer, times_at, 4 * nt, None));
    let (t0, t1) = (a.times[0], a.times[a.times.len() - 1]);
    let input = root.push(Accessor {
        min: Some(serde_json::json!([t0])),
        max: Some(serde_json::json!([t1])),
        ..glb_accessor(view, nt, ComponentType::F32, Type::Scalar)
    });
    let nw = a.weights.len() as u64;
    let view = root.push(glb_view(buffer, weights_at, 4 * nw, None));
    let output = root.push(glb_accessor(view, nw, ComponentType::F32, Type::Scalar));
    let sampler = Index::new(0);
    root.animations.push(gltf_json::Animation {
        extensions: None,
        extras: Default::default(),
        channels: vec![Channel {
            sampler,
            target: AnimTarget {
                extensions: None,
                extras: Default::default(),
                node: Index::new(0),
                path: Valid(Property::MorphTargetWeights),
            },
            extensions: None,
            extras: Default::default(),
        }],
        samplers: vec![Sampler {
            extensions: None,
            extras: Default::default(),
            input,
            interpolation: Valid(Interpolation::Linear),
            output,
        }],
    });
}

/// Checks what [`write_glb_mesh`] needs of a mesh, saying what is wrong.
fn check_glb_mesh(mesh: &GlbMesh) -> Result<(), String> {
    let n = mesh.positions.len();
    if n == 0 || mesh.indices.is_empty() {
        return Err("nothing to write: glTF needs at least one vertex and one triangle".into());
    }
    let lengths = [
        ("normals", mesh.normals.len()),
        ("texture coordinates", mesh.uvs.map_or(n, <[_]>::len)),
    ];
    let targets = mesh
        .morph_targets
        .iter()
        .map(|t| (t.name, t.displacements.len()));
    if let Some((what, len)) = lengths
        .into_iter()
        .chain(targets)
        .find(|&(_, len)| len != n)
    {
        return Err(format!("{n} positions but {len} {what}"));
    }
    if let Some(i) = mesh.indices.iter().position(|&i| i as usize >= n) {
        return Err(format!(
            "index {i} is {}, beyond the {n} vertices",
            mesh.indices[i]
        ));
    }
    let whole = |r: &Range<usize>| {
        !r.is_empty() && r.len().is_multiple_of(3) && r.end <= mesh.indices.len()
    };
    if let Some(k) = mesh.primitives.iter().position(|p| !whole(&p.indices)) {
        return Err(format!(
            "primitive {k} has indices {:?} of {}: not whole triangles",
            mesh.primitives[k].indices,
            mesh.indices.len()
        ));
    }
    if let Some(a) = &mesh.animation {
        let nt = mesh.morph_targets.len();
        if a.times.is_empty() || a.weights.len() != a.times.len() * nt || nt == 0 {
            return Err(format!(
                "animation of {} key times and {} weights for {nt} morph targets",
                a.times.len(),
                a.weights.len()
            ));
        }
        if !a.times.windows(2).all(|w| w[0] < w[1]) || !a.times.iter().all(|t| t.is_finite()) {
            return Err("animation key times must be finite and increasing".into());
        }
    }
    Ok(())
}

/// The glTF material of `m`, its base colour texture `texture` when it is textured.
fn glb_material(m: &GlbMaterial, texture: Option<Index<Texture>>) -> Material {
    Material {
        double_sided: m.double_sided,
        pbr_metallic_roughness: PbrMetallicRoughness {
            base_color_factor: PbrBaseColorFactor(m.base_colour),
            base_color_texture: texture.filter(|_| m.textured).map(|index| Info {
                index,
                tex_coord: 0,
                extensions: None,
                extras: Default::default(),
            }),
            metallic_factor: StrengthFactor(m.metallic),
            roughness_factor: StrengthFactor(m.roughness),
            ..Default::default()
        },
        ..Default::default()
    }
}

/// Writes a triangle mesh of the engine (metres, +Z up) as binary glTF 2.0 (`.glb`) through
/// [`write_glb_mesh`], in glTF's frame (+Y up: see [`ExportFrame`]) scaled to `units`: one
/// primitive with `POSITION` (f32, with min/max), `NORMAL` (f32, area-weighted vertex normals,
/// `+y` where a vertex has none) and `u32` indices, and one double-sided, rough,
/// non-metallic fabric material. Parent folders are created; the file is written to a
/// temporary file and renamed, so a failure never leaves a half-written file.
///
/// Fails, naming the file, on an empty mesh (glTF forbids empty accessors), non-finite
/// positions or positions beyond f32 range, out-of-range indices, more than `u32::MAX`
/// vertices, or an I/O error.
pub fn write_glb(
    path: &Path,
    positions: &[Vec3],
    triangles: &[[usize; 3]],
    units: Units,
) -> Result<(), GeometryError> {
    let frame = ExportFrame {
        up: UpAxis::Y,
        units,
    };
    let invalid = |m: String| GeometryError::Invalid(format!("{}: {m}", path.display()));
    check_mesh(path, positions, triangles)?;
    if positions.is_empty() || triangles.is_empty() {
        return Err(invalid(
            "nothing to write: glTF needs at least one vertex and one triangle".into(),
        ));
    }
    if positions.len() > u32::MAX as usize {
        return Err(invalid(format!(
            "{} vertices do not fit 32-bit indices",
            positions.len()
        )));
    }
    let p32: Vec<[f32; 3]> = positions
        .iter()
        .map(|p| {
            let q = frame.point(p);
            [q.x as f32, q.y as f32, q.z as f32]
        })
        .collect();
    let normals: Vec<[f32; 3]> = vertex_normals(positions, triangles)
        .iter()
        .map(|nv| {
            let unit = nv.iter().all(|c| c.is_finite()) && (nv.norm() - 1.0).abs() < 1e-3;
            if unit {
                let d = frame.direction(nv);
                [d.x as f32, d.y as f32, d.z as f32]
            } else {
                [0.0, 1.0, 0.0]
            }
        })
        .collect();
    let indices: Vec<u32> = triangles.iter().flatten().map(|&i| i as u32).collect();
    let [r, g, b] = FABRIC_SRGB.map(srgb_to_linear);
    let fabric = GlbMaterial {
        base_colour: [r, g, b, 1.0],
        textured: false,
        metallic: 0.0,
        roughness: 0.85,
        double_sided: true,
    };
    let primitives = [GlbPrimitive {
        indices: 0..indices.len(),
        material: Some(fabric),
    }];
    write_glb_mesh(
        path,
        &GlbMesh {
            positions: &p32,
            normals: &normals,
            indices: &indices,
            primitives: &primitives,
            ..Default::default()
        },
    )
}

/// Converts an 8-bit sRGB component to linear (glTF colour factors are linear).
fn srgb_to_linear(c: u8) -> f32 {
    linear_from_srgb(f64::from(c) / 255.0) as f32
}

/// An sRGB component in [0, 1] to linear light.
pub(crate) fn linear_from_srgb(c: f64) -> f64 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

#[cfg(test)]
mod tests {
    use super::document::{CHUNK_BIN, CHUNK_JSON};
    use super::*;
    use crate::geometry::grid_mesh;
    use gltf_json::validation::Validate;

    fn u32_at(b: &[u8], at: usize) -> u32 {
        u32::from_le_bytes(b[at..at + 4].try_into().unwrap())
    }

    #[test]
    fn glb_header_chunks_and_counts() {
        let g = grid_mesh(1.0, 0.5, 4, 3).unwrap();
        let dir = std::env::temp_dir().join(format!("emilion-glb-{}", std::process::id()));
        let path = dir.join("out").join("grid.glb");
        write_glb(&path, &g.positions, &g.triangles, Units::Metres).unwrap();
        let b = std::fs::read(&path).unwrap();
        assert_eq!(&b[0..4], b"glTF");
        assert_eq!(u32_at(&b, 4), 2);
        assert_eq!(u32_at(&b, 8) as usize, b.len());
        let json_len = u32_at(&b, 12) as usize;
        assert_eq!(u32_at(&b, 16), CHUNK_JSON);
        assert_eq!(json_len % 4, 0);
        let json: serde_json::Value = serde_json::from_slice(&b[20..20 + json_len]).unwrap();
        let acc = json["accessors"].as_array().unwrap();
        assert_eq!(acc[0]["count"], g.positions.len());
        assert_eq!(acc[1]["count"], g.positions.len());
        assert_eq!(acc[2]["count"], 3 * g.triangles.len());
        // the engine's xy-plane is glTF's xz-plane (+Y up), engine +y along glTF −z
        assert_eq!(acc[0]["min"], serde_json::json!([-0.5, 0.0, -0.25]));
        assert_eq!(acc[0]["max"], serde_json::json!([0.5, 0.0, 0.25]));
        assert_eq!(json["materials"][0]["doubleSided"], true);
        let bin_at = 20 + json_len;
        let bin_len = u32_at(&b, bin_at) as usize;
        assert_eq!(u32_at(&b, bin_at + 4), CHUNK_BIN);
        assert_eq!(bin_at + 8 + bin_len, b.len());
        assert!(json["buffers"][0]["byteLength"].as_u64().unwrap() as usize <= bin_len);
        // The document passes gltf-json's own validation.
        let root = Root::from_slice(&b[20..20 + json_len]).unwrap();
        let mut errors = Vec::new();
        root.validate(&root, gltf_json::Path::new, &mut |p, e| {
            errors.push(format!("{}: {e:?}", p()))
        });
        assert!(errors.is_empty(), "{errors:?}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn glb_rejects_bad_meshes() {
        let path = std::env::temp_dir().join(format!("emilion-glb-bad-{}.glb", std::process::id()));
        let p = [Vec3::zeros(), Vec3::x(), Vec3::y()];
        for (pos, tri) in [
            (&p[..], &[][..]),
            (&p[..], &[[0, 1, 5]][..]),
            (&[Vec3::repeat(1e300), p[1], p[2]][..], &[[0, 1, 2]][..]),
        ] {
            let e = write_glb(&path, pos, tri, Units::Metres)
                .unwrap_err()
                .to_string();
            assert!(e.contains("emilion-glb-bad"), "{e}");
        }
        assert!(!path.exists());
    }
}
