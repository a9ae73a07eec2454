//! Writing Wavefront OBJ files: [`write_obj_mesh`] writes any [`ObjMesh`] (positions, optional
//! texture coordinates with their own indices, optional normals, comments, a material library,
//! an object name, and groups with materials); [`write_obj`] writes a cloth's shape through
//! it (rest coordinates as `vt`, area-weighted vertex normals as `vn`).

use std::ops::Range;
use std::path::Path;

use crate::geometry::export_frame::ExportFrame;
use crate::geometry::files::{check_mesh, write_atomic};
use crate::geometry::mesh::vertex_normals;
use crate::geometry::{GeometryError, Vec3};

/// A run of triangles under a `g` (group) line and/or a `usemtl` (material) line.
#[derive(Debug, Clone, PartialEq)]
pub struct ObjGroup<'a> {
    /// Name on its `g` line; `None`: no `g` line.
    pub name: Option<&'a str>,
    /// Name on its `usemtl` line; `None`: no `usemtl` line.
    pub material: Option<&'a str>,
    /// Its triangles, positions in [`ObjMesh::triangles`].
    pub triangles: Range<usize>,
}

/// Everything [`write_obj_mesh`] writes, in file order: `#` comments, `mtllib`, `o`, `v`
/// positions, `vt` texture coordinates, `vn` normals, then the faces, by group.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ObjMesh<'a> {
    /// Comment lines (without the leading `# `).
    pub comments: &'a [String],
    /// The material library (`mtllib`), relative to the OBJ's folder.
    pub material_library: Option<&'a str>,
    /// Object name (`o`).
    pub object: Option<&'a str>,
    /// Vertex positions.
    pub positions: &'a [Vec3],
    /// Texture coordinates (`vt`); empty: none.
    pub uvs: &'a [[f64; 2]],
    /// Normals (`vn`), one per position (faces use the position's index); empty: none.
    pub normals: &'a [Vec3],
    /// Triangles, indices into `positions`.
    pub triangles: &'a [[usize; 3]],
    /// Per triangle, indices into `uvs`; `None`: the position indices.
    pub uv_triangles: Option<&'a [[usize; 3]]>,
    /// Groups of triangles, in order; empty: all the triangles, without `g` or `usemtl`.
    pub groups: &'a [ObjGroup<'a>],
}

/// Writes `mesh` as Wavefront OBJ: see [`ObjMesh`] for the content; face corners are
/// `v`, `v/vt`, `v//vn` or `v/vt/vn` (1-based) as the mesh has texture coordinates and
/// normals. Numbers are written in full (f64 `Display`, so they read back exactly). Parent
/// folders are created; the file is written to a temporary file and renamed, so a failure
/// never leaves a half-written file. Fails, naming the file, on indices out of range, normals
/// not one per position, groups beyond the triangles, or an I/O error; the values themselves
/// are the caller's to check.
pub fn write_obj_mesh(path: &Path, mesh: &ObjMesh) -> Result<(), GeometryError> {
    check_obj_mesh(mesh).map_err(|m| GeometryError::Invalid(format!("{}: {m}", path.display())))?;
    let all = [ObjGroup {
        name: None,
        material: None,
        triangles: 0..mesh.triangles.len(),
    }];
    let groups = if mesh.groups.is_empty() {
        &all[..]
    } else {
        mesh.groups
    };
    let (has_uv, has_normal) = (!mesh.uvs.is_empty(), !mesh.normals.is_empty());
    let uv_triangles = mesh.uv_triangles.unwrap_or(mesh.triangles);
    write_atomic(path, |w| {
        for c in mesh.comments {
            writeln!(w, "# {c}")?;
        }
        if let Some(lib) = mesh.material_library {
            writeln!(w, "mtllib {lib}")?;
        }
        if let Some(o) = mesh.object {
            writeln!(w, "o {o}")?;
        }
        for p in mesh.positions {
            writeln!(w, "v {} {} {}", p.x, p.y, p.z)?;
        }
        for t in mesh.uvs {
            writeln!(w, "vt {} {}", t[0], t[1])?;
        }
        for n in mesh.normals {
            writeln!(w, "vn {} {} {}", n.x, n.y, n.z)?;
        }
        for g in groups {
            if let Some(name) = g.name {
                writeln!(w, "g {name}")?;
            }
            if let Some(material) = g.material {
                writeln!(w, "usemtl {material}")?;
            }
            for t in g.triangles.clone() {
                let (p, uv) = (mesh.triangles[t], uv_triangles[t]);
                write!(w, "f")?;
                for k in 0..3 {
                    let (v, vt) = (p[k] + 1, uv[k] + 1);
                    match (has_uv, has_normal) {
                        (true, true) => write!(w, " {v}/{vt}/{v}")?,
                        (true, false) => write!(w, " {v}/{vt}")?,
                        (false, true) => write!(w, " {v}//{v}")?,
                        (false, false) => write!(w, " {v}")?,
                    }
                }
                writeln!(w)?;
            }
        }
        Ok(())
    })
}

/// Checks the indices of an [`ObjMesh`], saying what is wrong.
fn check_obj_mesh(mesh: &ObjMesh) -> Result<(), String> {
    let n = mesh.positions.len();
    if !mesh.normals.is_empty() && mesh.normals.len() != n {
        return Err(format!("{n} positions but {} normals", mesh.normals.len()));
    }
    let out =
        |tris: &[[usize; 3]], len: usize| tris.iter().position(|t| t.iter().any(|&i| i >= len));
    if let Some(t) = out(mesh.triangles, n) {
        return Err(format!(
            "triangle {t} {:?} indexes a vertex out of range (mesh has {n} vertices)",
            mesh.triangles[t]
        ));
    }
    if !mesh.uvs.is_empty() || mesh.uv_triangles.is_some() {
        let uv_triangles = mesh.uv_triangles.unwrap_or(mesh.triangles);
        if uv_triangles.len() != mesh.triangles.len() {
            return Err(format!(
                "{} triangles but {} texture triangles",
                mesh.triangles.len(),
                uv_triangles.len()
            ));
        }
        if let Some(t) = out(uv_triangles, mesh.uvs.len()) {
            return Err(format!(
                "triangle {t} indexes a texture coordinate out of range (mesh has {})",
                mesh.uvs.len()
            ));
        }
    }
    if let Some(g) = mesh
        .groups
        .iter()
        .position(|g| g.triangles.end > mesh.triangles.len())
    {
        return Err(format!(
            "group {g} has triangles {:?} of {}",
            mesh.groups[g].triangles,
            mesh.triangles.len()
        ));
    }
    Ok(())
}

/// Writes a cloth's shape (engine frame: metres, +Z up) as Wavefront OBJ in the file frame
/// `frame` (see [`ExportFrame`]; +Y up in metres is what Blender and Maya expect) through
/// [`write_obj_mesh`]: `v` positions, `vt`
/// rest coordinates (metres, when `rest` is given), `vn` area-weighted vertex normals (zero
/// where a vertex has none), and `f a/a/a` faces (1-based; `f a//a` without rest
/// coordinates). Parent folders are created; the file is written to a temporary file and
/// renamed, so a failure never leaves a half-written file.
///
/// Fails, naming the file, on non-finite positions or rest coordinates, out-of-range indices,
/// a `rest` of the wrong length, or an I/O error.
pub fn write_obj(
    path: &Path,
    positions: &[Vec3],
    triangles: &[[usize; 3]],
    rest: Option<&[[f64; 2]]>,
    frame: ExportFrame,
) -> Result<(), GeometryError> {
    check_mesh(path, positions, triangles)?;
    if let Some(rest) = rest {
        if rest.len() != positions.len() {
            return Err(GeometryError::Invalid(format!(
                "{}: {} positions but {} rest coordinates",
                path.display(),
                positions.len(),
                rest.len()
            )));
        }
        if let Some(i) = rest.iter().position(|r| !r.iter().all(|c| c.is_finite())) {
            return Err(GeometryError::Invalid(format!(
                "{}: vertex {i} has a non-finite rest coordinate {:?}",
                path.display(),
                rest[i]
            )));
        }
    }
    let normals: Vec<Vec3> = vertex_normals(positions, triangles)
        .into_iter()
        .map(|n| {
            if n.iter().all(|c| c.is_finite()) {
                frame.direction(&n)
            } else {
                Vec3::zeros()
            }
        })
        .collect();
    let file_positions: Vec<Vec3> = positions.iter().map(|p| frame.point(p)).collect();
    let mut comments = vec![
        format!(
            "emilion cloth mesh: {} vertices, {} triangles",
            positions.len(),
            triangles.len()
        ),
        frame.describe(),
    ];
    if rest.is_some() {
        comments.push("vt: rest (pattern) coordinates in metres, u = warp, v = weft".into());
    }
    write_obj_mesh(
        path,
        &ObjMesh {
            comments: &comments,
            positions: &file_positions,
            uvs: rest.unwrap_or(&[]),
            normals: &normals,
            triangles,
            ..Default::default()
        },
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tmp(name: &str) -> std::path::PathBuf {
        std::env::temp_dir().join(format!("emilion-obj-write-{}-{name}", std::process::id()))
    }

    #[test]
    fn write_rejects_bad_input_without_touching_the_file() {
        let path = tmp("bad.obj");
        let p = [Vec3::zeros(), Vec3::x(), Vec3::y()];
        let e = write_obj(&path, &p, &[[0, 1, 3]], None, ExportFrame::ENGINE)
            .unwrap_err()
            .to_string();
        assert!(e.contains("bad.obj") && e.contains("out of range"), "{e}");
        let nan = [Vec3::zeros(), Vec3::x(), Vec3::new(f64::NAN, 0.0, 0.0)];
        assert!(write_obj(&path, &nan, &[[0, 1, 2]], None, ExportFrame::ENGINE).is_err());
        assert!(write_obj(
            &path,
            &p,
            &[[0, 1, 2]],
            Some(&[[0.0, 0.0]]),
            ExportFrame::ENGINE
        )
        .is_err());
        assert!(!path.exists());
    }

    #[test]
    fn groups_materials_and_own_texture_indices() {
        let path = tmp("groups.obj");
        let p = [
            Vec3::zeros(),
            Vec3::x(),
            Vec3::y(),
            Vec3::new(1.0, 1.0, 0.0),
        ];
        let comments = ["a test".to_string()];
        let groups = [
            ObjGroup {
                name: Some("wall"),
                material: Some("stone"),
                triangles: 0..1,
            },
            ObjGroup {
                name: None,
                material: Some("glass"),
                triangles: 1..2,
            },
        ];
        let mesh = ObjMesh {
            comments: &comments,
            material_library: Some("groups.mtl"),
            object: Some("facade"),
            positions: &p,
            uvs: &[[0.0, 0.0], [0.5, 1.0]],
            triangles: &[[0, 1, 2], [1, 3, 2]],
            uv_triangles: Some(&[[0, 1, 0], [1, 1, 0]]),
            groups: &groups,
            ..Default::default()
        };
        write_obj_mesh(&path, &mesh).unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        assert_eq!(
            text,
            "# a test\nmtllib groups.mtl\no facade\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\n\
             vt 0 0\nvt 0.5 1\ng wall\nusemtl stone\nf 1/1 2/2 3/1\nusemtl glass\nf 2/2 4/2 3/1\n"
        );
        let bad = ObjMesh {
            uv_triangles: Some(&[[0, 1, 0], [1, 2, 0]]),
            ..mesh
        };
        let e = write_obj_mesh(&path, &bad).unwrap_err().to_string();
        assert!(
            e.contains("groups.obj") && e.contains("texture coordinate"),
            "{e}"
        );
        std::fs::remove_file(&path).unwrap();
    }
}
