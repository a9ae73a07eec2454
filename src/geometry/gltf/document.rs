//! The glTF document behind [`super::write_glb_mesh`]: an empty document with its one buffer,
//! buffer views, accessors, an embedded PNG texture, triangle primitives, and the binary
//! container (`.glb`: header, JSON and BIN chunks) it is written in.

use std::io::Write;
use std::path::Path;

use gltf_json::accessor::{ComponentType, GenericComponentType, Type};
use gltf_json::buffer::{Buffer, Target, View};
use gltf_json::image::MimeType;
use gltf_json::mesh::{Mode, MorphTarget, Primitive, Semantic};
use gltf_json::texture::{MagFilter, MinFilter, Sampler, WrappingMode};
use gltf_json::validation::{Checked::Valid, USize64};
use gltf_json::{Accessor, Image, Index, Material, Mesh, Node, Root, Scene, Texture};

use crate::geometry::files::write_atomic;
use crate::geometry::GeometryError;

/// GLB magic.
const MAGIC: &[u8; 4] = b"glTF";
/// Type of the JSON chunk.
pub(super) const CHUNK_JSON: u32 = 0x4E4F_534A;
/// Type of the binary chunk.
pub(super) const CHUNK_BIN: u32 = 0x004E_4942;

/// The bounds (glTF's accessor min and max) of single-precision positions, or which vertex
/// is beyond single-precision range. `p32` must not be empty.
pub(super) fn f32_bounds(p32: &[[f32; 3]]) -> Result<([f32; 3], [f32; 3]), String> {
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
/// chunk `finish_glb` writes.
pub(super) fn glb_root(len: usize) -> (Root, Index<Buffer>) {
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
pub(super) fn glb_view(
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
pub(super) fn glb_accessor(
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
pub(super) fn glb_png_texture(
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
pub(super) fn glb_triangles(
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
/// chunks padded to 4 bytes) atomically. With morph targets, the mesh's default weights are
/// zeros and the targets' names go to `mesh.extras.targetNames`.
pub(super) fn finish_glb(
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
