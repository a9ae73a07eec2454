//! Files of facade meshes ([`FacadeMesh`]): Wavefront OBJ with its MTL material library, and
//! binary glTF 2.0 with PBR materials and the photo embedded as texture
//! (`facade-reconstruction.md` §5.4 "Geometry"). One group / primitive per [`Surface`]
//! (wall, window, door …, reveal, shell, element), so tools can pick parts apart. This module owns the
//! file formats and the look of each surface; the geometry comes from
//! [`super::facade_mesh`]. Writes are atomic (temporary file, then rename) and errors name
//! the file.

use std::fmt::Write as _;
use std::path::{Component, Path};

use super::error::FacadeError;
use super::facade_mesh::{FacadeMesh, Surface};
use super::labels::Class;
use crate::geometry::files::write_atomic;
use crate::geometry::gltf::{
    linear_from_srgb, write_glb_mesh, GlbMaterial, GlbMesh, GlbPrimitive, GlbTexture,
};
use crate::geometry::obj::{write_obj_mesh, ObjGroup, ObjMesh};
use crate::geometry::GeometryError;

/// How a surface looks when it carries no photo (and how it reflects either way).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Appearance {
    /// Diffuse / base colour, sRGB in [0, 1].
    pub srgb: [f64; 3],
    /// PBR metalness in [0, 1].
    pub metallic: f64,
    /// PBR roughness in [0, 1].
    pub roughness: f64,
}

/// The look of each surface: light stone walls, dark blue-grey glass, brown doors, grey
/// metal balconies, slate for background (roof), stone reveals and shell, white-painted
/// elements (frames, mullions, panels).
pub fn appearance(surface: Surface) -> Appearance {
    let (srgb, metallic, roughness) = match surface {
        Surface::Front(Class::Wall) => ([0.80, 0.76, 0.68], 0.0, 0.9),
        Surface::Front(Class::Window) => ([0.22, 0.27, 0.33], 0.3, 0.1),
        Surface::Front(Class::Door) => ([0.42, 0.27, 0.15], 0.0, 0.6),
        Surface::Front(Class::Balcony) => ([0.55, 0.56, 0.58], 0.6, 0.4),
        Surface::Front(Class::Background) => ([0.36, 0.38, 0.42], 0.0, 0.8),
        Surface::Front(Class::Ignore) => ([0.60, 0.60, 0.60], 0.0, 0.9),
        Surface::Reveal => ([0.70, 0.66, 0.58], 0.0, 0.9),
        Surface::Shell => ([0.74, 0.70, 0.62], 0.0, 0.95),
        Surface::Element => ([0.93, 0.93, 0.90], 0.0, 0.5),
    };
    Appearance {
        srgb,
        metallic,
        roughness,
    }
}

/// Writes `path_obj` (positions `v`, texture coordinates `vt` with OBJ's v up, i.e. `1 − v`
/// of the mesh, faces `f v/vt`, one `g`/`usemtl` per group) and, next to it with the
/// extension `.mtl`, its material library: one material per surface, with `map_Kd` pointing
/// at `texture_png` (relative to the OBJ's folder) on the textured surfaces when given (their
/// `Kd` is then white, as `map_Kd` is multiplied by it). The PNG is referenced, not copied.
/// Errors name the file: an invalid mesh, a missing texture, an I/O failure.
pub fn write_obj_mtl(
    path_obj: &Path,
    mesh: &FacadeMesh,
    texture_png: Option<&Path>,
) -> Result<(), FacadeError> {
    mesh.check_indices()
        .map_err(|m| file_err(path_obj, format!("invalid facade mesh: {m}")))?;
    if path_obj.file_name().is_none() {
        return Err(file_err(path_obj, "not a file path".into()));
    }
    let path_mtl = path_obj.with_extension("mtl");
    let mtl_name = path_mtl
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let map = match texture_png {
        Some(png) if !png.is_file() => {
            return Err(file_err(png, "texture not found (or not a file)".into()))
        }
        Some(png) => Some(relative_to(path_obj.parent().unwrap_or(Path::new("")), png)),
        None => None,
    };

    let mut mtl = String::from("# emilion facade materials\n");
    for g in &mesh.groups {
        let look = appearance(g.surface);
        let textured = map.is_some() && g.surface.textured();
        let [r, gr, b] = if textured { [1.0; 3] } else { look.srgb };
        let shiny = 1.0 - look.roughness;
        let _ = writeln!(mtl, "\nnewmtl {}", g.surface.name());
        let _ = writeln!(mtl, "Ka 0 0 0\nKd {r:.4} {gr:.4} {b:.4}");
        let _ = writeln!(
            mtl,
            "Ks {0:.3} {0:.3} {0:.3}\nNs {1:.1}",
            0.5 * shiny,
            1.0 + 250.0 * shiny * shiny
        );
        let _ = writeln!(mtl, "d 1\nillum 2");
        if let (true, Some(m)) = (textured, &map) {
            let _ = writeln!(mtl, "map_Kd {m}");
        }
    }

    let comments = ["emilion facade mesh: metres, x right, y up, z out of the facade".to_string()];
    let uvs: Vec<[f64; 2]> = mesh.uvs.iter().map(|&[u, v]| [u, 1.0 - v]).collect();
    let groups: Vec<ObjGroup> = mesh
        .groups
        .iter()
        .map(|g| ObjGroup {
            name: Some(g.surface.name()),
            material: Some(g.surface.name()),
            triangles: g.triangles.clone(),
        })
        .collect();
    let obj = ObjMesh {
        comments: &comments,
        material_library: Some(&mtl_name),
        object: Some("facade"),
        positions: &mesh.positions,
        uvs: &uvs,
        triangles: &mesh.triangles,
        uv_triangles: Some(&mesh.uv_triangles),
        groups: &groups,
        ..Default::default()
    };
    write_atomic(&path_mtl, |w| w.write_all(mtl.as_bytes()))
        .map_err(|e| geometry_err(&path_mtl, e))?;
    write_obj_mesh(path_obj, &obj).map_err(|e| geometry_err(path_obj, e))
}

/// Writes `path` as binary glTF 2.0: one scene, one node, one mesh with a primitive per group
/// (its own material), sharing `POSITION` (f32, with min/max), flat `NORMAL` (vertices split
/// per face plane) and `TEXCOORD_0` (glTF's top-left origin, as the mesh stores it), `u32`
/// indices. When `texture_png` is given its bytes are embedded in the binary chunk (image with
/// a buffer view and `image/png`), with a sampler and a texture used as `baseColorTexture` by
/// the textured surfaces (base colour factor white). Every buffer view starts on 4 bytes and
/// both chunks are padded. Errors name the file: an invalid or empty mesh, a texture that is
/// not a readable PNG, sizes beyond the format's limits, an I/O failure.
pub fn write_glb_textured(
    path: &Path,
    mesh: &FacadeMesh,
    texture_png: Option<&Path>,
) -> Result<(), FacadeError> {
    let invalid = |m: String| file_err(path, m);
    mesh.check_indices()
        .map_err(|m| invalid(format!("invalid facade mesh: {m}")))?;
    if mesh.triangles.is_empty() {
        return Err(invalid(
            "nothing to write: glTF needs at least one triangle".into(),
        ));
    }
    let png = match texture_png {
        Some(p) => Some(read_png(p)?),
        None => None,
    };

    // Vertices: one per (position, texture coordinate, face normal).
    let mut key_of = std::collections::HashMap::new();
    let (mut p32, mut n32, mut t32) = (Vec::new(), Vec::new(), Vec::new());
    let mut indices: Vec<u32> = Vec::with_capacity(3 * mesh.triangles.len());
    for (t, uv) in mesh.triangles.iter().zip(&mesh.uv_triangles) {
        let [a, b, c] = t.map(|i| mesh.positions[i]);
        let n = (b - a).cross(&(c - a));
        let n = if n.norm() > 0.0 {
            n.normalize()
        } else {
            crate::geometry::Vec3::z()
        };
        let n = [n.x as f32, n.y as f32, n.z as f32];
        for k in 0..3 {
            let key = (t[k], uv[k], n.map(f32::to_bits));
            let next = p32.len();
            let id = *key_of.entry(key).or_insert(next);
            if id == next {
                let p = mesh.positions[t[k]];
                p32.push([p.x as f32, p.y as f32, p.z as f32]);
                n32.push(n);
                t32.push(mesh.uvs[uv[k]].map(|x| x as f32));
            }
            let id = u32::try_from(id)
                .map_err(|_| invalid("more vertices than 32-bit indices allow".into()))?;
            indices.push(id);
        }
    }
    let primitives: Vec<GlbPrimitive> = mesh
        .groups
        .iter()
        .map(|g| {
            let look = appearance(g.surface);
            let textured = png.is_some() && g.surface.textured();
            let [r, gr, b] = if textured {
                [1.0; 3]
            } else {
                look.srgb.map(linear_from_srgb)
            };
            GlbPrimitive {
                indices: 3 * g.triangles.start..3 * g.triangles.end,
                material: Some(GlbMaterial {
                    base_colour: [r as f32, gr as f32, b as f32, 1.0],
                    textured,
                    metallic: look.metallic as f32,
                    roughness: look.roughness as f32,
                    double_sided: false,
                }),
            }
        })
        .collect();
    let glb = GlbMesh {
        positions: &p32,
        normals: &n32,
        uvs: Some(&t32),
        indices: &indices,
        primitives: &primitives,
        texture: png.as_deref().map(|png| GlbTexture {
            png,
            mipmapped: true,
        }),
        ..Default::default()
    };
    write_glb_mesh(path, &glb).map_err(|e| geometry_err(path, e))
}

/// The bytes of a PNG file, checked to be one (signature and header decode) of at most
/// `max_pixels`, read within `max_file_bytes`.
fn read_png(path: &Path) -> Result<Vec<u8>, FacadeError> {
    let (format, _, _) = crate::geometry::image::check_image_file(path)?;
    if format != image::ImageFormat::Png {
        return Err(file_err(
            path,
            "not a PNG image (glTF textures here are PNG)".into(),
        ));
    }
    crate::limits::read(path).map_err(|e| file_err(path, e.to_string()))
}

/// `target` relative to the folder `dir`, with `/` separators (as MTL files expect); the
/// absolute path when they share no root.
fn relative_to(dir: &Path, target: &Path) -> String {
    let abs = |p: &Path| {
        std::path::absolute(if p.as_os_str().is_empty() {
            Path::new(".")
        } else {
            p
        })
    };
    let (Ok(d), Ok(t)) = (abs(dir), abs(target)) else {
        return target.to_string_lossy().into_owned();
    };
    let (d, t2) = (clean(&d), clean(&t));
    let common = d.iter().zip(&t2).take_while(|(a, b)| a == b).count();
    if common == 0 {
        return t.to_string_lossy().into_owned();
    }
    let ups = d[common..].iter().map(|_| "..".to_string());
    let downs = t2[common..]
        .iter()
        .map(|c| c.as_os_str().to_string_lossy().into_owned());
    ups.chain(downs).collect::<Vec<_>>().join("/")
}

/// The components of `p` without `.`.
fn clean(p: &Path) -> Vec<Component<'_>> {
    p.components().filter(|c| *c != Component::CurDir).collect()
}

/// A file error naming `path`.
fn file_err(path: &Path, message: String) -> FacadeError {
    FacadeError::File {
        path: path.to_path_buf(),
        message,
    }
}

/// A geometry writer's error as a facade file error (the path once).
fn geometry_err(path: &Path, e: GeometryError) -> FacadeError {
    match e {
        GeometryError::Io { path, source } => file_err(&path, source.to_string()),
        other => file_err(path, other.to_string()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn relative_paths_for_map_kd() {
        assert_eq!(
            relative_to(Path::new("/a/b"), Path::new("/a/b/t.png")),
            "t.png"
        );
        assert_eq!(
            relative_to(Path::new("/a/b/c"), Path::new("/a/x/t.png")),
            "../../x/t.png"
        );
        assert_eq!(relative_to(Path::new(""), Path::new("./t.png")), "t.png");
    }
}
