//! Binary glTF 2.0 (`.glb`) output: one triangle mesh with positions, smooth normals, 32-bit
//! indices and a double-sided fabric material, for viewers and 3D tools.

use std::io::Write;
use std::path::Path;

use gltf_json::accessor::{ComponentType, GenericComponentType, Type};
use gltf_json::buffer::{Buffer, Target, View};
use gltf_json::image::MimeType;
use gltf_json::material::{PbrBaseColorFactor, PbrMetallicRoughness, StrengthFactor};
use gltf_json::mesh::{Mode, MorphTarget, Primitive, Semantic};
use gltf_json::texture::{MagFilter, MinFilter, Sampler, WrappingMode};
use gltf_json::validation::{Checked::Valid, USize64};
use gltf_json::{Accessor, Image, Index, Material, Mesh, Node, Root, Scene, Texture};

use super::files::{check_mesh, write_atomic};
use super::mesh::vertex_normals;
use super::{GeometryError, Vec3};

/// Base colour of the exported material, sRGB (a muted denim blue).
const FABRIC_SRGB: [u8; 3] = [72, 104, 150];

/// GLB chunk types and magic.
const MAGIC: &[u8; 4] = b"glTF";
const CHUNK_JSON: u32 = 0x4E4F_534A;
const CHUNK_BIN: u32 = 0x004E_4942;

/// Writes a triangle mesh as binary glTF 2.0 (`.glb`): one scene, one node, one mesh whose
/// primitive has `POSITION` (f32, with min/max), `NORMAL` (f32, area-weighted vertex normals)
/// and `u32` indices, and one double-sided, rough, non-metallic fabric material. Parent
/// folders are created; the file is written to a temporary file and renamed, so a failure
/// never leaves a half-written file.
///
/// Fails, naming the file, on an empty mesh (glTF forbids empty accessors), non-finite
/// positions or positions beyond f32 range, out-of-range indices, more than `u32::MAX`
/// vertices, or an I/O error.
pub fn write_glb(
    path: &Path,
    positions: &[Vec3],
    triangles: &[[usize; 3]],
) -> Result<(), GeometryError> {
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
        .map(|p| [p.x as f32, p.y as f32, p.z as f32])
        .collect();
    let (lo, hi) = f32_bounds(&p32).map_err(invalid)?;
    let normals = vertex_normals(positions, triangles);

    // Binary chunk: positions, normals, indices, each 4-byte aligned by construction.
    let n = positions.len();
    let mut bin = Vec::with_capacity(24 * n + 12 * triangles.len());
    for p in &p32 {
        p.iter()
            .for_each(|c| bin.extend_from_slice(&c.to_le_bytes()));
    }
    for nv in &normals {
        let unit = nv.iter().all(|c| c.is_finite()) && (nv.norm() - 1.0).abs() < 1e-3;
        let nv = if unit {
            [nv.x as f32, nv.y as f32, nv.z as f32]
        } else {
            [0.0, 0.0, 1.0]
        };
        nv.iter()
            .for_each(|c| bin.extend_from_slice(&c.to_le_bytes()));
    }
    for t in triangles {
        t.iter()
            .for_each(|&i| bin.extend_from_slice(&(i as u32).to_le_bytes()));
    }
    let (pos_len, idx_len) = (12 * n as u64, 12 * triangles.len() as u64);

    let (mut root, buffer) = glb_root(bin.len());
    let view = |offset, length, target| glb_view(buffer, offset, length, Some(target));
    let pos_view = root.push(view(0, pos_len, Target::ArrayBuffer));
    let nrm_view = root.push(view(pos_len, pos_len, Target::ArrayBuffer));
    let idx_view = root.push(view(2 * pos_len, idx_len, Target::ElementArrayBuffer));
    let accessor = glb_accessor;
    let pos_acc = root.push(Accessor {
        min: Some(serde_json::json!(lo)),
        max: Some(serde_json::json!(hi)),
        ..accessor(pos_view, n as u64, ComponentType::F32, Type::Vec3)
    });
    let nrm_acc = root.push(accessor(nrm_view, n as u64, ComponentType::F32, Type::Vec3));
    let idx_acc = root.push(accessor(
        idx_view,
        3 * triangles.len() as u64,
        ComponentType::U32,
        Type::Scalar,
    ));

    let [r, g, b] = FABRIC_SRGB.map(srgb_to_linear);
    let material = root.push(Material {
        double_sided: true,
        pbr_metallic_roughness: PbrMetallicRoughness {
            base_color_factor: PbrBaseColorFactor([r, g, b, 1.0]),
            metallic_factor: StrengthFactor(0.0),
            roughness_factor: StrengthFactor(0.85),
            ..Default::default()
        },
        ..Default::default()
    });
    let primitive = glb_triangles(pos_acc, nrm_acc, None, idx_acc, Some(material), None);
    finish_glb(path, root, vec![primitive], bin)
}

/// The bounds (glTF's accessor min and max) of single-precision positions, or which vertex
/// is beyond single-precision range. `p32` must not be empty.
pub(crate) fn f32_bounds(p32: &[[f32; 3]]) -> Result<([f32; 3], [f32; 3]), String> {
    if let Some(i) = p32.iter().position(|p| !p.iter().all(|c| c.is_finite())) {
        return Err(format!("vertex {i} is beyond single-precision range"));
    }
    let first = p32.first().copied().unwrap_or([0.0; 3]);
    let (mut lo, mut hi) = (first, first);
    for p in p32 {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    Ok((lo, hi))
}

/// An empty glTF document (its generator set) holding one buffer of `len` bytes, the binary
/// chunk [`finish_glb`] writes.
pub(crate) fn glb_root(len: usize) -> (Root, Index<Buffer>) {
    let mut root = Root {
        asset: gltf_json::Asset {
            generator: Some(format!("emilion {}", env!("CARGO_PKG_VERSION"))),
            ..Default::default()
        },
        ..Default::default()
    };
    let buffer = root.push(Buffer {
        byte_length: USize64(len as u64),
        uri: None,
        extensions: None,
        extras: Default::default(),
    });
    (root, buffer)
}

/// A view of `length` bytes at `offset` of `buffer`.
pub(crate) fn glb_view(
    buffer: Index<Buffer>,
    offset: u64,
    length: u64,
    target: Option<Target>,
) -> View {
    View {
        buffer,
        byte_length: USize64(length),
        byte_offset: Some(USize64(offset)),
        byte_stride: None,
        target: target.map(Valid),
        extensions: None,
        extras: Default::default(),
    }
}

/// A tightly packed accessor of `count` elements at the start of `view`, without bounds.
pub(crate) fn glb_accessor(
    view: Index<View>,
    count: u64,
    component: ComponentType,
    type_: Type,
) -> Accessor {
    Accessor {
        buffer_view: Some(view),
        byte_offset: Some(USize64(0)),
        count: USize64(count),
        component_type: Valid(GenericComponentType(component)),
        extensions: None,
        extras: Default::default(),
        type_: Valid(type_),
        min: None,
        max: None,
        normalized: false,
        sparse: None,
    }
}

/// A PNG image stored in `view`, sampled linearly (minification `min_filter`), clamped at the
/// edges, as a texture.
pub(crate) fn glb_png_texture(
    root: &mut Root,
    view: Index<View>,
    min_filter: MinFilter,
) -> Index<Texture> {
    let image = root.push(Image {
        buffer_view: Some(view),
        mime_type: Some(MimeType("image/png".into())),
        uri: None,
        extensions: None,
        extras: Default::default(),
    });
    let sampler = root.push(Sampler {
        mag_filter: Some(Valid(MagFilter::Linear)),
        min_filter: Some(Valid(min_filter)),
        wrap_s: Valid(WrappingMode::ClampToEdge),
        wrap_t: Valid(WrappingMode::ClampToEdge),
        ..Default::default()
    });
    root.push(Texture {
        sampler: Some(sampler),
        source: image,
        extensions: None,
        extras: Default::default(),
    })
}

/// A triangle-list primitive with positions, normals, optional texture coordinates, indices,
/// an optional material and optional morph targets.
pub(crate) fn glb_triangles(
    positions: Index<Accessor>,
    normals: Index<Accessor>,
    uvs: Option<Index<Accessor>>,
    indices: Index<Accessor>,
    material: Option<Index<Material>>,
    targets: Option<Vec<MorphTarget>>,
) -> Primitive {
    let mut attributes: std::collections::BTreeMap<_, _> = [
        (Valid(Semantic::Positions), positions),
        (Valid(Semantic::Normals), normals),
    ]
    .into_iter()
    .collect();
    if let Some(uv) = uvs {
        attributes.insert(Valid(Semantic::TexCoords(0)), uv);
    }
    Primitive {
        attributes,
        extensions: None,
        extras: Default::default(),
        indices: Some(indices),
        material,
        mode: Valid(Mode::Triangles),
        targets,
    }
}

/// Completes a glTF document whose buffers, views, accessors and materials are in `root`:
/// one mesh of `primitives`, one node, one scene; then writes it as binary glTF (JSON and BIN
/// chunks padded to 4 bytes) atomically. Shared by every `.glb` writer.
pub(crate) fn finish_glb(
    path: &Path,
    root: Root,
    primitives: Vec<Primitive>,
    bin: Vec<u8>,
) -> Result<(), GeometryError> {
    finish_glb_morph(path, root, primitives, &[], bin)
}

/// [`finish_glb`] for a mesh with morph targets: the mesh's default weights are zeros and the
/// targets' names go to `mesh.extras.targetNames` (the convention Blender, three.js and
/// Unity read). With no names, exactly [`finish_glb`].
pub(crate) fn finish_glb_morph(
    path: &Path,
    mut root: Root,
    primitives: Vec<Primitive>,
    target_names: &[&str],
    mut bin: Vec<u8>,
) -> Result<(), GeometryError> {
    let invalid = |m: String| GeometryError::Invalid(format!("{}: {m}", path.display()));
    let mesh = root.push(Mesh {
        extensions: None,
        extras: Default::default(),
        primitives,
        weights: (!target_names.is_empty()).then(|| vec![0.0; target_names.len()]),
    });
    let node = root.push(Node {
        mesh: Some(mesh),
        ..Default::default()
    });
    let scene = root.push(Scene {
        extensions: None,
        extras: Default::default(),
        nodes: vec![node],
    });
    root.scene = Some(scene);
    let mut json = if target_names.is_empty() {
        gltf_json::serialize::to_vec(&root).map_err(|e| invalid(format!("glTF JSON: {e}")))?
    } else {
        // gltf-json is built without its `extras` feature: the names go into the JSON value
        let mut value =
            serde_json::to_value(&root).map_err(|e| invalid(format!("glTF JSON: {e}")))?;
        value["meshes"][mesh.value()]["extras"] =
            serde_json::json!({ "targetNames": target_names });
        serde_json::to_vec(&value).map_err(|e| invalid(format!("glTF JSON: {e}")))?
    };
    json.resize(json.len().next_multiple_of(4), b' ');
    bin.resize(bin.len().next_multiple_of(4), 0);
    let total = 12 + 8 + json.len() as u64 + 8 + bin.len() as u64;
    let total = u32::try_from(total)
        .map_err(|_| invalid(format!("{total} bytes exceed the 4 GiB GLB limit")))?;
    write_atomic(path, |w: &mut dyn Write| {
        w.write_all(MAGIC)?;
        w.write_all(&2u32.to_le_bytes())?;
        w.write_all(&total.to_le_bytes())?;
        w.write_all(&(json.len() as u32).to_le_bytes())?;
        w.write_all(&CHUNK_JSON.to_le_bytes())?;
        w.write_all(&json)?;
        w.write_all(&(bin.len() as u32).to_le_bytes())?;
        w.write_all(&CHUNK_BIN.to_le_bytes())?;
        w.write_all(&bin)
    })
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
        write_glb(&path, &g.positions, &g.triangles).unwrap();
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
        assert_eq!(acc[0]["min"], serde_json::json!([-0.5, -0.25, 0.0]));
        assert_eq!(acc[0]["max"], serde_json::json!([0.5, 0.25, 0.0]));
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
            let e = write_glb(&path, pos, tri).unwrap_err().to_string();
            assert!(e.contains("emilion-glb-bad"), "{e}");
        }
        assert!(!path.exists());
    }
}
