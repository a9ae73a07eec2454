//! Files of a textured face for other tools: Wavefront OBJ with its MTL material, and binary
//! glTF 2.0 (`.glb`) with the texture embedded.
//!
//! This file owns the face exports:
//! - [`write_obj_mtl`]: `v` positions (metres), `vt` texture coordinates (OBJ's `v` up, as
//!   [`FaceMesh::uvs`]), `vn` area-weighted vertex normals, `f v/vt/vn` faces, `mtllib` and
//!   `usemtl`, and the `.mtl` next to it whose `map_Kd` names the texture image;
//! - [`write_textured_obj`]: the same plus the texture written as PNG beside them;
//! - [`write_glb`]: one mesh with `POSITION`, `NORMAL`, `TEXCOORD_0` (glTF's `v` points down:
//!   `(u, 1 − v)`), `u32` indices, and a double-sided material whose `baseColorTexture` is the
//!   texture, stored as PNG in the binary chunk.
//!
//! Unlike the cloth exports these do not create folders: a missing folder is an error naming
//! the file, as is any I/O failure. Files are written to a temporary file and renamed, so a
//! failure never leaves a half-written file.

use std::io::Cursor;
use std::path::Path;

use super::render::Texture;
use super::{FaceError, FaceMesh};
use crate::geometry::files::write_atomic;
use crate::geometry::gltf::{write_glb_mesh, GlbMaterial, GlbMesh, GlbPrimitive, GlbTexture};
use crate::geometry::obj::{write_obj_mesh, ObjGroup, ObjMesh};
use crate::geometry::{GeometryError, Vec3};

/// Name of the material in the `.mtl` file and the OBJ's `usemtl`.
pub const MATERIAL_NAME: &str = "face";

/// A geometry-layer error as a face error naming the file.
fn from_geometry(path: &Path, e: GeometryError) -> FaceError {
    match e {
        GeometryError::Io { path, source } => FaceError::io(path, source),
        other => FaceError::io(path, other),
    }
}

/// Fails, naming `path`, when its folder does not exist or it has no file name.
fn check_folder(path: &Path) -> Result<(), FaceError> {
    if path.file_name().is_none() {
        return Err(FaceError::io(path, "not a file path"));
    }
    match path.parent().filter(|d| !d.as_os_str().is_empty()) {
        Some(dir) if !dir.is_dir() => Err(FaceError::io(
            path,
            format!("folder {} does not exist", dir.display()),
        )),
        _ => Ok(()),
    }
}

/// Checks that a mesh can be exported: one finite texture coordinate per vertex, finite
/// positions, valid indices, at least one triangle.
fn check_mesh(path: &Path, mesh: &FaceMesh) -> Result<(), FaceError> {
    let bad = |m: String| FaceError::io(path, m);
    let n = mesh.positions.len();
    if mesh.uvs.len() != n {
        return Err(bad(format!(
            "mesh has {n} positions but {} texture coordinates",
            mesh.uvs.len()
        )));
    }
    if n == 0 || mesh.triangles.is_empty() {
        return Err(bad("mesh is empty: nothing to write".into()));
    }
    if n > u32::MAX as usize {
        return Err(bad(format!("{n} vertices do not fit 32-bit indices")));
    }
    if let Some(t) = mesh
        .triangles
        .iter()
        .position(|t| t.iter().any(|&i| i as usize >= n))
    {
        return Err(bad(format!("triangle {t} has a vertex index beyond {n}")));
    }
    if let Some(i) = mesh
        .positions
        .iter()
        .position(|p| !p.iter().all(|c| c.is_finite()))
    {
        return Err(bad(format!("vertex {i} has a non-finite position")));
    }
    if let Some(i) = mesh
        .uvs
        .iter()
        .position(|t| !t.iter().all(|c| c.is_finite()))
    {
        return Err(bad(format!(
            "vertex {i} has a non-finite texture coordinate"
        )));
    }
    Ok(())
}

/// Unit vertex normals of `mesh`, `+z` where a vertex has none (unused or degenerate).
fn unit_normals(mesh: &FaceMesh) -> Vec<Vec3> {
    mesh.vertex_normals()
        .into_iter()
        .map(|n| {
            if n.iter().all(|c| c.is_finite()) && (n.norm() - 1.0).abs() < 1e-6 {
                n
            } else {
                Vec3::z()
            }
        })
        .collect()
}

/// Writes `mesh` as a Wavefront OBJ at `obj_path` and its material as `<stem>.mtl` beside it,
/// whose `map_Kd` is `texture_file_name` (relative to the OBJ's folder, as OBJ readers expect);
/// see the [module docs](self) for the content.
///
/// Fails, naming the file, when its folder does not exist, on a texture name that is empty or
/// holds a line break, on an invalid mesh, or on an I/O error.
pub fn write_obj_mtl(
    obj_path: &Path,
    mesh: &FaceMesh,
    texture_file_name: &str,
) -> Result<(), FaceError> {
    check_folder(obj_path)?;
    check_mesh(obj_path, mesh)?;
    if texture_file_name.trim().is_empty() || texture_file_name.chars().any(char::is_control) {
        return Err(FaceError::parameter(
            "texture_file_name",
            format!("{texture_file_name:?} is not a usable file name"),
        ));
    }
    let mtl_path = obj_path.with_extension("mtl");
    if mtl_path == obj_path {
        return Err(FaceError::io(
            obj_path,
            "an OBJ file cannot end in .mtl (its material file would overwrite it)",
        ));
    }
    let Some(mtl_name) = mtl_path.file_name().and_then(|n| n.to_str()) else {
        return Err(FaceError::io(obj_path, "file name is not valid UTF-8"));
    };
    let mtl_name = mtl_name.to_string();
    write_atomic(&mtl_path, |w| {
        writeln!(w, "# emilion face material")?;
        writeln!(w, "newmtl {MATERIAL_NAME}")?;
        writeln!(w, "Ka 1 1 1")?;
        writeln!(w, "Kd 1 1 1")?;
        writeln!(w, "Ks 0 0 0")?;
        writeln!(w, "d 1")?;
        writeln!(w, "illum 1")?;
        writeln!(w, "map_Kd {texture_file_name}")
    })
    .map_err(|e| from_geometry(&mtl_path, e))?;
    let normals = unit_normals(mesh);
    let comments = [format!(
        "emilion face: {} vertices, {} triangles, metres",
        mesh.positions.len(),
        mesh.triangles.len()
    )];
    let triangles: Vec<[usize; 3]> = mesh
        .triangles
        .iter()
        .map(|t| t.map(|i| i as usize))
        .collect();
    let groups = [ObjGroup {
        name: None,
        material: Some(MATERIAL_NAME),
        triangles: 0..triangles.len(),
    }];
    let obj = ObjMesh {
        comments: &comments,
        material_library: Some(&mtl_name),
        positions: &mesh.positions,
        uvs: &mesh.uvs,
        normals: &normals,
        triangles: &triangles,
        groups: &groups,
        ..Default::default()
    };
    write_obj_mesh(obj_path, &obj).map_err(|e| from_geometry(obj_path, e))
}

/// Writes `<folder>/<stem>.obj`, `<stem>.mtl` and the texture as `<stem>.png`, all in `folder`
/// (which must exist). Errors as [`write_obj_mtl`] and [`Texture::save`].
pub fn write_textured_obj(
    folder: &Path,
    stem: &str,
    mesh: &FaceMesh,
    texture: &Texture,
) -> Result<(), FaceError> {
    if stem.is_empty() || stem.contains(['/', '\\']) || stem.chars().any(char::is_control) {
        return Err(FaceError::parameter(
            "stem",
            format!("{stem:?} is not a plain file name"),
        ));
    }
    let png = format!("{stem}.png");
    let png_path = folder.join(&png);
    check_folder(&png_path)?;
    check_texture(&png_path, texture)?;
    texture.save(&png_path)?;
    write_obj_mtl(&folder.join(format!("{stem}.obj")), mesh, &png)
}

/// Fails, naming `path`, on an empty texture or one whose texel count disagrees with its size.
fn check_texture(path: &Path, texture: &Texture) -> Result<(), FaceError> {
    let n = texture.width.checked_mul(texture.height);
    if texture.width == 0 || texture.height == 0 || n != Some(texture.rgb.len()) {
        return Err(FaceError::io(
            path,
            format!(
                "texture is {}×{} with {} texels",
                texture.width,
                texture.height,
                texture.rgb.len()
            ),
        ));
    }
    if texture.width > u32::MAX as usize || texture.height > u32::MAX as usize {
        return Err(FaceError::io(path, "texture too large"));
    }
    Ok(())
}

/// Writes `mesh` textured with `texture` as binary glTF 2.0 at `path`; see the
/// [module docs](self) for the content.
///
/// Fails, naming the file, when its folder does not exist, on an invalid mesh or texture
/// (empty, or texel count not `width × height`), positions beyond single precision, or an I/O
/// error.
pub fn write_glb(path: &Path, mesh: &FaceMesh, texture: &Texture) -> Result<(), FaceError> {
    check_folder(path)?;
    check_mesh(path, mesh)?;
    check_texture(path, texture)?;
    let mut png = Vec::new();
    texture
        .to_image()
        .write_to(&mut Cursor::new(&mut png), image::ImageFormat::Png)
        .map_err(|e| FaceError::io(path, format!("texture PNG: {e}")))?;

    let p32: Vec<[f32; 3]> = mesh
        .positions
        .iter()
        .map(|p| [p.x as f32, p.y as f32, p.z as f32])
        .collect();
    let normals: Vec<[f32; 3]> = unit_normals(mesh)
        .iter()
        .map(|n| [n.x as f32, n.y as f32, n.z as f32])
        .collect();
    let uvs: Vec<[f32; 2]> = mesh
        .uvs
        .iter()
        .map(|uv| [uv[0] as f32, (1.0 - uv[1]) as f32])
        .collect();
    let indices: Vec<u32> = mesh.triangles.iter().flatten().copied().collect();
    let primitives = [GlbPrimitive {
        indices: 0..indices.len(),
        material: Some(GlbMaterial {
            base_colour: [1.0, 1.0, 1.0, 1.0],
            textured: true,
            metallic: 0.0,
            roughness: 0.8,
            double_sided: true,
        }),
    }];
    let glb = GlbMesh {
        positions: &p32,
        normals: &normals,
        uvs: Some(&uvs),
        indices: &indices,
        primitives: &primitives,
        texture: Some(GlbTexture {
            png: &png,
            mipmapped: false,
        }),
        ..Default::default()
    };
    write_glb_mesh(path, &glb).map_err(|e| from_geometry(path, e))
}
