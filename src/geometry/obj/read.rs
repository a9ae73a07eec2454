//! Reading Wavefront OBJ files, with a small double-precision parser of the OBJ subset a mesh
//! needs that keeps the file's vertex order and names lines in its errors: a cloth mesh whose
//! texture coordinates are its rest (pattern) coordinates in metres ([`read_obj`]), the
//! surface of a collision body ([`read_obj_surface`]), or the polygons of a file with the
//! groups they belong to ([`obj_polygons_from_text`]).

use std::path::Path;

use crate::geometry::{GeometryError, TriMesh, Vec3};

/// Reads a cloth mesh from a Wavefront OBJ file. The texture coordinates are the rest
/// (pattern) coordinates in metres, so every face corner needs one (`f 1/1 2/2 3/3`); each
/// distinct (position, texture coordinate) pair becomes one vertex, numbered in the order of
/// the `v` lines (a position used with several texture coordinates, as along a seam, gives one
/// vertex per coordinate, in `vt` order), so a file written by [`super::write_obj`] reads back with
/// the same numbering. Normal indices are ignored (flat-shaded exports stay connected), as are
/// positions no face uses, objects and groups (all merged), materials, points and lines.
/// Polygons are split into triangle fans; a `v` line's optional fourth number divides it
/// (homogeneous w). Numbers are read in double precision.
///
/// Fails with [`GeometryError::Io`] when the file cannot be read, and with
/// [`GeometryError::Parse`] naming the file and the line (0 when no single line is at fault)
/// on malformed numbers or faces, out-of-range indices, face corners without texture
/// coordinates, zero-area rest triangles, a file without faces, or an otherwise invalid mesh.
pub fn read_obj(path: &Path) -> Result<TriMesh, GeometryError> {
    let text = crate::limits::read_to_string(path).map_err(|source| GeometryError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    obj_mesh_from_text(&text, path)
}

/// [`read_obj`] of OBJ text already in memory; `path` names it in errors.
pub fn obj_mesh_from_text(text: &str, path: &Path) -> Result<TriMesh, GeometryError> {
    let err = |line: usize, message: String| parse_error(path, line, message);
    let (mesh, face_lines) =
        parse(text, true).map_err(|(line, message)| parse_error(path, line, message))?;
    if mesh.triangles.is_empty() {
        return Err(err(
            0,
            "no faces: a cloth mesh needs triangles (`f` lines)".into(),
        ));
    }
    if let Some(t) =
        (0..mesh.triangles.len()).find(|&t| mesh.rest_area(t).is_nan() || mesh.rest_area(t) <= 0.0)
    {
        return Err(err(
            face_lines[t],
            "face has zero area in its texture coordinates (the rest shape): degenerate or repeated UVs".into(),
        ));
    }
    mesh.validate().map_err(|e| match e {
        GeometryError::Invalid(message) => err(0, message),
        other => other,
    })?;
    Ok(mesh)
}

/// Reads the surface of an OBJ file (a collision body): vertex positions and triangles, polygons
/// fanned; texture coordinates and normals are ignored. Errors as [`read_obj`] (file and line);
/// the mesh's own validity (degenerate or non-manifold faces) is left to its user.
pub fn read_obj_surface(path: &Path) -> Result<(Vec<Vec3>, Vec<[usize; 3]>), GeometryError> {
    let text = crate::limits::read_to_string(path).map_err(|source| GeometryError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    obj_surface_from_text(&text, path)
}

/// [`read_obj_surface`] of OBJ text already in memory (a built-in asset); `path` names it in
/// errors.
pub fn obj_surface_from_text(
    text: &str,
    path: &Path,
) -> Result<(Vec<Vec3>, Vec<[usize; 3]>), GeometryError> {
    let (mesh, _) =
        parse(text, false).map_err(|(line, message)| parse_error(path, line, message))?;
    if mesh.triangles.is_empty() {
        return Err(parse_error(path, 0, "no faces (`f` lines)".into()));
    }
    Ok((mesh.positions, mesh.triangles))
}

fn parse_error(path: &Path, line: usize, message: String) -> GeometryError {
    GeometryError::Parse {
        path: path.to_path_buf(),
        line,
        message,
    }
}

/// Why texture coordinates are required.
const NEEDS_UV: &str = "a cloth mesh needs texture coordinates (vt) as rest coordinates in metres";

/// The polygons of an OBJ file as written (not triangulated), with the `g`/`o` names they
/// were declared under.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ObjPolygons {
    /// Vertex positions, in `v` order (divided by their optional w).
    pub positions: Vec<Vec3>,
    /// Texture coordinates, in `vt` order.
    pub uvs: Vec<[f64; 2]>,
    /// The faces, in file order.
    pub faces: Vec<ObjFace>,
    /// The names of each `g` or `o` line, in file order.
    pub group_names: Vec<Vec<String>>,
}

/// One face (`f` line) of an [`ObjPolygons`].
#[derive(Debug, Clone, PartialEq)]
pub struct ObjFace {
    /// Corners: 0-based (position, texture coordinate); the texture coordinate is 0 where
    /// texture coordinates were not asked for.
    pub corners: Vec<[usize; 2]>,
    /// 1-based line of the face.
    pub line: usize,
    /// The last `g` or `o` line before it (index into [`ObjPolygons::group_names`]).
    pub group: Option<usize>,
}

impl ObjPolygons {
    /// Whether `face` is in the group or object `name` (named on the last `g`/`o` line before it).
    pub fn in_group(&self, face: &ObjFace, name: &str) -> bool {
        face.group
            .is_some_and(|g| self.group_names[g].iter().any(|n| n == name))
    }
}

/// The polygons of OBJ text already in memory; `path` names it in errors. Texture
/// coordinates and normals are checked but not required; errors as [`read_obj`] (file and
/// line).
pub fn obj_polygons_from_text(text: &str, path: &Path) -> Result<ObjPolygons, GeometryError> {
    parse_polygons(text, false).map_err(|(line, message)| parse_error(path, line, message))
}

/// Parses OBJ text into a mesh and, per triangle, the 1-based line of its face (polygons
/// split into triangle fans). Errors carry the 1-based line and a message. Without `need_uv`,
/// texture coordinates are ignored (every corner takes a zero rest coordinate, so vertices
/// are never split at UV seams).
fn parse(text: &str, need_uv: bool) -> Result<(TriMesh, Vec<usize>), (usize, String)> {
    let obj = parse_polygons(text, need_uv)?;
    // Per triangle corner: (position, texture coordinate), 0-based.
    let mut corners: Vec<[usize; 2]> = Vec::new();
    let mut face_lines = Vec::new();
    for face in &obj.faces {
        let c = &face.corners;
        for k in 1..c.len() - 1 {
            corners.extend([c[0], c[k], c[k + 1]]);
            face_lines.push(face.line);
        }
    }
    // One vertex per distinct (position, texture coordinate), in that order.
    let mut keys = corners.clone();
    keys.sort_unstable();
    keys.dedup();
    let mesh = TriMesh {
        positions: keys.iter().map(|k| obj.positions[k[0]]).collect(),
        rest: keys
            .iter()
            .map(|k| if need_uv { obj.uvs[k[1]] } else { [0.0, 0.0] })
            .collect(),
        triangles: corners
            .chunks_exact(3)
            .map(|c| [0, 1, 2].map(|j| keys.binary_search(&c[j]).unwrap_or_default()))
            .collect(),
    };
    Ok((mesh, face_lines))
}

/// Parses OBJ text into its polygons. Errors carry the 1-based line and a message. Without
/// `need_uv`, face corners need no texture coordinate (and take 0).
fn parse_polygons(text: &str, need_uv: bool) -> Result<ObjPolygons, (usize, String)> {
    let mut total = [0usize; 3];
    for line in text.lines() {
        match line.split_whitespace().next() {
            Some("v") => total[0] += 1,
            Some("vt") => total[1] += 1,
            Some("vn") => total[2] += 1,
            _ => {}
        }
    }
    let mut obj = ObjPolygons {
        positions: Vec::with_capacity(total[0]),
        uvs: Vec::with_capacity(total[1]),
        ..Default::default()
    };
    let mut normals = 0;
    for (i, line) in text.lines().enumerate() {
        let ln = i + 1;
        let mut words = line.split_whitespace();
        let keyword = words.next();
        let (needed, what) = match keyword {
            Some("v") => (3, "vertex position"),
            Some("vt") => (2, "texture coordinate"),
            Some("vn") => (3, "normal"),
            Some("g") | Some("o") => {
                obj.group_names.push(words.map(str::to_string).collect());
                continue;
            }
            Some("f") => {
                let seen = [obj.positions.len(), obj.uvs.len(), normals];
                let face = words
                    .map(|c| corner(c, &seen, &total, need_uv))
                    .collect::<Result<Vec<_>, _>>();
                let face = face.map_err(|m| (ln, m))?;
                if face.len() < 3 {
                    return Err((
                        ln,
                        format!("face needs at least 3 corners: `{}`", line.trim()),
                    ));
                }
                obj.faces.push(ObjFace {
                    corners: face,
                    line: ln,
                    group: obj.group_names.len().checked_sub(1),
                });
                continue;
            }
            _ => continue,
        };
        let values: Vec<f64> = words.map_while(|w| w.parse::<f64>().ok()).collect();
        if values.len() < needed || !values.iter().all(|x| x.is_finite()) {
            return Err((
                ln,
                format!("{what} needs {needed} finite numbers: `{}`", line.trim()),
            ));
        }
        match keyword {
            Some("v") => {
                let w = if values.len() == 4 { values[3] } else { 1.0 };
                if w == 0.0 {
                    return Err((ln, format!("vertex position has w = 0: `{}`", line.trim())));
                }
                obj.positions
                    .push(Vec3::new(values[0], values[1], values[2]) / w);
            }
            Some("vt") => obj.uvs.push([values[0], values[1]]),
            _ => normals += 1,
        }
    }
    Ok(obj)
}

/// Resolves one face corner `v/vt[/vn]` to 0-based (position, texture coordinate) indices,
/// checking it against the elements seen so far (negative, relative indices) and in the
/// whole file (positive indices).
fn corner(
    corner: &str,
    seen: &[usize; 3],
    total: &[usize; 3],
    need_uv: bool,
) -> Result<[usize; 2], String> {
    const NAMES: [&str; 3] = ["vertex", "texture coordinate", "normal"];
    let parts: Vec<&str> = corner.split('/').collect();
    if parts.len() > 3 {
        return Err(format!("malformed face corner `{corner}`"));
    }
    let mut resolved = [usize::MAX; 3];
    for (k, part) in parts.iter().enumerate() {
        if part.is_empty() {
            if k == 0 {
                return Err(format!("face corner `{corner}` has no vertex index"));
            }
            continue;
        }
        let Ok(x) = part.parse::<i64>() else {
            return Err(format!("face corner `{corner}`: `{part}` is not an index"));
        };
        let index = match x {
            x if x > 0 && (x as u64) <= total[k] as u64 => Some(x as usize - 1),
            x if x < 0 && x.unsigned_abs() <= seen[k] as u64 => {
                Some(seen[k] - x.unsigned_abs() as usize)
            }
            _ => None,
        };
        let Some(index) = index else {
            return Err(format!(
                "face corner `{corner}` refers to {} {x}, but there are {} (OBJ indices start at 1; negative ones count back)",
                NAMES[k],
                if x > 0 { total[k] } else { seen[k] }
            ));
        };
        resolved[k] = index;
    }
    if !need_uv {
        return Ok([resolved[0], 0]);
    }
    if resolved[1] == usize::MAX {
        return Err(format!(
            "face corner `{corner}` has no texture coordinate: {NEEDS_UV}"
        ));
    }
    Ok([resolved[0], resolved[1]])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::grid_mesh;
    use crate::geometry::obj::write_obj;
    use crate::geometry::ExportFrame;
    use std::fs;

    fn tmp(name: &str) -> std::path::PathBuf {
        std::env::temp_dir().join(format!("emilion-obj-{}-{name}", std::process::id()))
    }

    #[test]
    fn write_then_read_grid() {
        let g = grid_mesh(1.0, 0.5, 4, 3).unwrap();
        let path = tmp("dir").join("sub").join("grid.obj");
        write_obj(
            &path,
            &g.positions,
            &g.triangles,
            Some(&g.rest),
            ExportFrame::ENGINE,
        )
        .unwrap();
        let back = read_obj(&path).unwrap();
        // Same numbering, and f64 values survive the text round trip exactly.
        assert_eq!(back.triangles, g.triangles);
        assert_eq!(back.positions, g.positions);
        assert_eq!(back.rest, g.rest);
        let text = fs::read_to_string(&path).unwrap();
        assert_eq!(text.lines().filter(|l| l.starts_with("vn ")).count(), 12);
        assert!(text.contains("f 1/1/1 2/2/2 6/6/6"));
        // No temporary file left behind.
        let left: Vec<_> = fs::read_dir(path.parent().unwrap()).unwrap().collect();
        assert_eq!(left.len(), 1);
        fs::remove_dir_all(tmp("dir")).unwrap();
    }

    fn read_str(name: &str, text: &str) -> Result<TriMesh, GeometryError> {
        let path = tmp(name);
        fs::write(&path, text).unwrap();
        let r = read_obj(&path);
        fs::remove_file(&path).unwrap();
        r
    }

    const HEAD: &str = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\n";

    #[test]
    fn malformed_obj_names_file_and_line() {
        let cases = [
            ("range.obj", format!("{HEAD}f 1/1 2/2 99/3\n"), 7),
            ("garbage.obj", format!("v 0 0 0\nv x y\n{HEAD}"), 2),
            ("nan.obj", format!("{HEAD}v nan 0 0\n"), 7),
            ("nouv.obj", format!("{HEAD}f 1 2 3\n"), 7),
            (
                "zero.obj",
                format!("{HEAD}f 1/1 2/2 3/3\nf 1/1 2/2 3/2\n"),
                8,
            ),
            ("short.obj", format!("{HEAD}f 1/1 2/2\n"), 7),
            (
                "huge.obj",
                format!("{HEAD}f 1/1 2/2 3/-99999999999999999\n"),
                7,
            ),
            ("short_vt.obj", format!("{HEAD}vt 0.5\n"), 7),
            ("w0.obj", format!("{HEAD}v 1 2 3 0\n"), 7),
            ("corner.obj", format!("{HEAD}f 1/1 2/x 3/3\n"), 7),
        ];
        for (name, text, line) in cases {
            let e = read_str(name, &text).unwrap_err();
            let msg = e.to_string();
            assert!(msg.contains(name), "{msg}");
            match e {
                GeometryError::Parse { line: l, .. } => assert_eq!(l, line, "{msg}"),
                other => panic!("expected a parse error, got {other}"),
            }
        }
        let e = read_str("empty.obj", HEAD).unwrap_err().to_string();
        assert!(e.contains("empty.obj") && e.contains("no faces"), "{e}");
        let e = read_obj(&tmp("missing.obj")).unwrap_err();
        assert!(matches!(e, GeometryError::Io { .. }) && e.to_string().contains("missing.obj"));
    }

    #[test]
    fn quads_groups_negative_indices_normals_and_seams() {
        // A quad with relative indices, then a second group sharing two of its vertices.
        let text = "o a\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n\
                    f -4/-4 -3/-3 -2/-2 -1/-1\ng b\nv 5 5 5\nvt 2 2\nf 2/2 5/5 3/3\n";
        let m = read_str("quad.obj", text).unwrap();
        assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3], [1, 4, 2]]);
        assert_eq!(m.positions[4], Vec3::new(5.0, 5.0, 5.0));
        // Per-face normals (flat-shaded export) do not split vertices.
        let text = format!("{HEAD}v 1 1 0\nvt 1 1\nvn 0 0 1\nvn 0 0 -1\nf 1/1/1 2/2/1 3/3/1\nf 2/2/2 4/4/2 3/3/2\n");
        let m = read_str("flat.obj", &text).unwrap();
        assert_eq!((m.positions.len(), m.triangles.len()), (4, 2));
        // One position with two texture coordinates (a seam) gives two vertices, in vt order.
        let text = format!("{HEAD}vt 2 0\nf 1/1 2/2 3/3\nf 1/1 2/4 3/3\n");
        let m = read_str("seam.obj", &text).unwrap();
        assert_eq!(m.positions.len(), 4);
        assert_eq!(m.rest[2], [2.0, 0.0]);
        assert_eq!(m.triangles, vec![[0, 1, 3], [0, 2, 3]]);
    }

    #[test]
    fn polygons_keep_their_groups() {
        let text = format!("{HEAD}v 1 1 0\nf 1 2 3\ng skin arm\nf 1 2 4 3\no helper\nf 2 4 3\n");
        let obj = obj_polygons_from_text(&text, Path::new("groups.obj")).unwrap();
        assert_eq!(obj.faces.len(), 3);
        assert_eq!(
            obj.faces[1]
                .corners
                .iter()
                .map(|c| c[0])
                .collect::<Vec<_>>(),
            [0, 1, 3, 2]
        );
        let in_skin: Vec<bool> = obj.faces.iter().map(|f| obj.in_group(f, "skin")).collect();
        assert_eq!(in_skin, [false, true, false]);
        assert_eq!(obj.faces[2].line, 12);
    }
}
