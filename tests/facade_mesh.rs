//! 3D facades from a facade grammar: derived at its own size and resized, built into closed
//! slabs with recessed windows and doors, written as OBJ + MTL and textured GLB, and the
//! files read back and checked (OBJ through the crate's reader, GLB structurally: header,
//! chunks, buffer views, accessors, embedded PNG).

use std::path::{Path, PathBuf};

use emilion::facade::facade_export::{write_glb_textured, write_obj_mtl};
use emilion::facade::facade_mesh::{build, check_closed, FacadeMesh, MeshParams, Surface};
use emilion::facade::grammar::{Grammar, Leaf, Scope};
use emilion::facade::Class;
use emilion::geometry::read_obj_surface;
use gltf_json::validation::Validate;
use serde_json::Value;

/// Four floors of tiles (window over a balcony slab), a top band, and a ground floor with a
/// door reaching the pavement and a row of shop windows.
const RULES: &str = "// axiom Facade size 400 330
Facade --> split(y) { 30: Top | ~1: Floors | 60: Ground }
Top --> background
Floors --> repeat(y, 60) { Floor }
Floor --> split(x) { 20: Wall | ~1: Tiles | 20: Wall }
Tiles --> repeat(x, 60) { Tile }
Tile --> split(x) { ~1: Wall | 30: Col | ~1: Wall }
Col --> split(y) { ~1: Wall | 36: Window | 6: Balcony | ~1: Wall }
Ground --> split(x) { ~1: Wall | 40: DoorCol | ~1: GroundRest }
DoorCol --> split(y) { ~1: Wall | 50: Door }
GroundRest --> repeat(x, 60) { GTile }
GTile --> split(x) { ~1: Wall | 36: GCol | ~1: Wall }
GCol --> split(y) { ~1: Wall | 30: Window | ~1: Wall }
Wall --> wall
Window --> window
Door --> door
Balcony --> balcony
";

/// 3 m floors of 60 units.
const SCALE: f64 = 3.0 / 60.0;

fn scratch(name: &str) -> PathBuf {
    let dir =
        std::env::temp_dir().join(format!("emilion-facade-mesh-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("temp dir");
    dir
}

fn params(g: &Grammar) -> MeshParams {
    MeshParams {
        scale: SCALE,
        wall_thickness: 0.3,
        window_depth: 0.12,
        door_depth: 0.2,
        texture_size: g.size,
    }
}

/// W·H·t − Σ recess volumes, in m³.
fn analytic_volume(leaves: &[Leaf], w: f64, h: f64, p: &MeshParams) -> f64 {
    let recess: f64 = leaves
        .iter()
        .map(|l| l.scope.width() * l.scope.height() * p.scale * p.scale * p.depth(l.class))
        .sum();
    w * h * p.scale * p.scale * p.wall_thickness - recess
}

fn u32_at(b: &[u8], at: usize) -> u32 {
    u32::from_le_bytes(b[at..at + 4].try_into().expect("4 bytes"))
}

fn f32_at(b: &[u8], at: usize) -> f32 {
    f32::from_le_bytes(b[at..at + 4].try_into().expect("4 bytes"))
}

/// Structural GLB check (the Khronos rules checkable by hand): header and chunk lengths and
/// padding, every buffer view 4-byte aligned inside the BIN chunk, every accessor fitting its
/// view, POSITION min/max equal to the data, indices in range, the embedded PNG. Returns the
/// JSON document.
fn check_glb(path: &Path, mesh: &FacadeMesh, textured: bool) -> Value {
    let b = std::fs::read(path).expect("read glb");
    assert_eq!(&b[0..4], b"glTF");
    assert_eq!(u32_at(&b, 4), 2, "version");
    assert_eq!(u32_at(&b, 8) as usize, b.len(), "total length");
    let json_len = u32_at(&b, 12) as usize;
    assert_eq!(u32_at(&b, 16), 0x4E4F_534A, "JSON chunk first");
    assert_eq!(json_len % 4, 0, "JSON chunk padded");
    let json: Value = serde_json::from_slice(&b[20..20 + json_len]).expect("JSON chunk parses");
    let bin_at = 20 + json_len;
    let bin_len = u32_at(&b, bin_at) as usize;
    assert_eq!(u32_at(&b, bin_at + 4), 0x004E_4942, "BIN chunk second");
    assert_eq!(bin_len % 4, 0, "BIN chunk padded");
    assert_eq!(bin_at + 8 + bin_len, b.len(), "nothing after the BIN chunk");
    let bin = &b[bin_at + 8..];
    let buf_len = json["buffers"][0]["byteLength"]
        .as_u64()
        .expect("buffer length") as usize;
    assert!(
        buf_len <= bin_len && bin_len - buf_len < 4,
        "buffer {buf_len} vs chunk {bin_len}"
    );

    let views = json["bufferViews"].as_array().expect("views");
    let span = |v: &Value| {
        let off = v["byteOffset"].as_u64().unwrap_or(0) as usize;
        (off, v["byteLength"].as_u64().expect("view length") as usize)
    };
    for (k, v) in views.iter().enumerate() {
        let (off, len) = span(v);
        assert!(off.is_multiple_of(4), "view {k} offset {off} aligned");
        assert!(off + len <= buf_len, "view {k} inside the buffer");
    }
    let accessors = json["accessors"].as_array().expect("accessors");
    for (k, a) in accessors.iter().enumerate() {
        let comps = match a["type"].as_str().expect("type") {
            "SCALAR" => 1,
            "VEC2" => 2,
            "VEC3" => 3,
            t => panic!("accessor {k}: unexpected type {t}"),
        };
        let size = match a["componentType"].as_u64().expect("component") {
            5126 | 5125 => 4,
            c => panic!("accessor {k}: unexpected component type {c}"),
        };
        let (off, len) = span(&views[a["bufferView"].as_u64().expect("view") as usize]);
        let at = a["byteOffset"].as_u64().unwrap_or(0) as usize;
        let count = a["count"].as_u64().expect("count") as usize;
        assert!(
            count > 0 && at.is_multiple_of(size) && at + count * comps * size <= len,
            "accessor {k} fits its view"
        );
        let _ = off;
    }

    let prims = json["meshes"][0]["primitives"]
        .as_array()
        .expect("primitives");
    assert_eq!(prims.len(), mesh.groups.len(), "one primitive per group");
    let pos = &accessors[prims[0]["attributes"]["POSITION"]
        .as_u64()
        .expect("POSITION") as usize];
    let n = pos["count"].as_u64().expect("count") as usize;
    let (off, _) = span(&views[pos["bufferView"].as_u64().expect("view") as usize]);
    let (mut lo, mut hi) = ([f32::MAX; 3], [f32::MIN; 3]);
    for i in 0..n {
        for k in 0..3 {
            let c = f32_at(bin, off + 12 * i + 4 * k);
            lo[k] = lo[k].min(c);
            hi[k] = hi[k].max(c);
        }
    }
    assert_eq!(pos["min"], serde_json::json!(lo), "POSITION min");
    assert_eq!(pos["max"], serde_json::json!(hi), "POSITION max");
    let mut triangles = 0;
    for (p, g) in prims.iter().zip(&mesh.groups) {
        for attr in ["POSITION", "NORMAL", "TEXCOORD_0"] {
            assert_eq!(
                accessors[p["attributes"][attr].as_u64().expect(attr) as usize]["count"],
                n
            );
        }
        let idx = &accessors[p["indices"].as_u64().expect("indices") as usize];
        let (ioff, _) = span(&views[idx["bufferView"].as_u64().expect("view") as usize]);
        let count = idx["count"].as_u64().expect("count") as usize;
        assert_eq!(count, 3 * g.triangles.len());
        triangles += count / 3;
        assert!(
            (0..count).all(|i| (u32_at(bin, ioff + 4 * i) as usize) < n),
            "indices in range"
        );
        let mat = &json["materials"][p["material"].as_u64().expect("material") as usize];
        let has_tex = mat["pbrMetallicRoughness"]["baseColorTexture"].is_object();
        assert_eq!(
            has_tex,
            textured && g.surface.textured(),
            "{}",
            g.surface.name()
        );
    }
    assert_eq!(triangles, mesh.triangles.len());

    if textured {
        let image = &json["images"][0];
        assert_eq!(image["mimeType"], "image/png");
        let (ioff, ilen) = span(&views[image["bufferView"].as_u64().expect("image view") as usize]);
        assert!(
            ilen > 8 && bin[ioff..ioff + 8] == *b"\x89PNG\r\n\x1a\n",
            "embedded PNG"
        );
        assert_eq!(json["textures"][0]["source"], 0);
        assert!(json["samplers"][0].is_object());
    } else {
        assert!(json.get("images").is_none() && json.get("textures").is_none());
    }
    // and gltf-json's own validation
    let root = gltf_json::Root::from_slice(&b[20..20 + json_len]).expect("glTF document");
    let mut errors = Vec::new();
    root.validate(&root, gltf_json::Path::new, &mut |p, e| {
        errors.push(format!("{}: {e:?}", p()))
    });
    assert!(errors.is_empty(), "{errors:?}");
    json
}

#[test]
fn grammar_facades_become_closed_textured_slabs() {
    let g = Grammar::parse(RULES).expect("rules parse");
    let dir = scratch("slabs");
    let png = dir.join("photo.png");
    let (tw, th) = (g.size.0 as u32, g.size.1 as u32);
    image::RgbImage::from_fn(tw, th, |x, y| {
        image::Rgb([(x % 256) as u8, (y % 256) as u8, 128])
    })
    .save(&png)
    .expect("write texture");
    let p = params(&g);
    for (name, f) in [("own", 1.0), ("small", 0.75), ("large", 1.5)] {
        let (w, h) = (g.size.0 * f, g.size.1 * f);
        let leaves = g.derive(w, h).expect("derives");
        assert!(leaves.iter().any(|l| l.class == Class::Door));
        let mesh = build(&leaves, &p).unwrap_or_else(|e| panic!("{name}: {e}"));
        check_closed(&mesh).unwrap_or_else(|e| panic!("{name}: {e}"));
        let (v, expected) = (mesh.signed_volume(), analytic_volume(&leaves, w, h, &p));
        assert!(
            (v - expected).abs() <= 1e-9 * expected,
            "{name}: volume {v} vs {expected}"
        );
        for t in &mesh.triangles {
            let [a, b, c] = t.map(|i| mesh.positions[i]);
            assert!(
                (b - a).cross(&(c - a)).norm() > 1e-12,
                "{name}: degenerate triangle {t:?}"
            );
        }
        let count = |c: Class| leaves.iter().filter(|l| l.class == c).count();
        eprintln!(
            "{name}: {w} × {h}: {} leaves ({} windows, {} doors), {} vertices, {} triangles, {v:.4} m³",
            leaves.len(),
            count(Class::Window),
            count(Class::Door),
            mesh.positions.len(),
            mesh.triangles.len()
        );
        assert!(
            mesh.uvs.iter().flatten().all(|x| (0.0..=1.0).contains(x)),
            "{name}: uv in [0, 1]"
        );
        let surfaces: Vec<Surface> = mesh.groups.iter().map(|g| g.surface).collect();
        for s in [
            Class::Wall,
            Class::Window,
            Class::Door,
            Class::Balcony,
            Class::Background,
        ] {
            assert!(surfaces.contains(&Surface::Front(s)), "{name}: {s:?}");
        }
        assert!(surfaces.contains(&Surface::Reveal) && surfaces.contains(&Surface::Shell));
        // bounding box: the facade in metres, recesses within the wall
        let max = |k: usize| mesh.positions.iter().map(|q| q[k]).fold(f64::MIN, f64::max);
        let min = |k: usize| mesh.positions.iter().map(|q| q[k]).fold(f64::MAX, f64::min);
        assert!((max(0) - w * SCALE).abs() < 1e-9 && min(0).abs() < 1e-12);
        assert!((max(1) - h * SCALE).abs() < 1e-9 && min(1).abs() < 1e-12);
        assert!(max(2) == 0.0 && min(2) == -0.3);

        for textured in [true, false] {
            let tex = textured.then_some(png.as_path());
            let stem = format!("{name}-{}", if textured { "tex" } else { "plain" });
            let obj = dir.join(format!("{stem}.obj"));
            write_obj_mtl(&obj, &mesh, tex).expect("writes OBJ");
            let (positions, triangles) = read_obj_surface(&obj).expect("reads OBJ back");
            assert_eq!(positions.len(), mesh.positions.len(), "{stem}: vertices");
            assert_eq!(triangles.len(), mesh.triangles.len(), "{stem}: triangles");
            assert_eq!(positions, mesh.positions, "{stem}: exact round trip");
            assert_eq!(triangles, mesh.triangles, "{stem}: same faces");
            let text = std::fs::read_to_string(&obj).expect("OBJ text");
            assert_eq!(
                text.lines().filter(|l| l.starts_with("vt ")).count(),
                mesh.uvs.len()
            );
            assert!(text.contains(&format!("mtllib {stem}.mtl")));
            let mtl =
                std::fs::read_to_string(dir.join(format!("{stem}.mtl"))).expect("MTL written");
            for s in &surfaces {
                assert!(
                    mtl.contains(&format!("newmtl {}\n", s.name())),
                    "{stem}: material {}",
                    s.name()
                );
                assert!(text.contains(&format!("usemtl {}\n", s.name())));
            }
            let maps = mtl.lines().filter(|l| *l == "map_Kd photo.png").count();
            assert_eq!(
                maps,
                if textured { surfaces.len() - 1 } else { 0 },
                "{stem}: map_Kd"
            );

            let glb = dir.join(format!("{stem}.glb"));
            write_glb_textured(&glb, &mesh, tex).expect("writes GLB");
            check_glb(&glb, &mesh, textured);
        }
    }
    // no temporaries left behind
    let names: Vec<String> = std::fs::read_dir(&dir)
        .expect("dir")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    assert!(names.iter().all(|n| !n.starts_with('.')), "{names:?}");
    std::fs::remove_dir_all(&dir).expect("clean up");
}

#[test]
fn degenerate_inputs_are_clear_errors() {
    let g = Grammar::parse(RULES).expect("rules parse");
    let leaves = g.derive(g.size.0, g.size.1).expect("derives");
    let p = params(&g);
    assert!(build(&[], &p).expect_err("no leaves").contains("no leaves"));
    let nan = MeshParams {
        scale: f64::NAN,
        ..p
    };
    assert!(build(&leaves, &nan)
        .expect_err("NaN scale")
        .contains("scale"));
    let deep = MeshParams {
        window_depth: 0.3,
        ..p
    };
    assert!(build(&leaves, &deep)
        .expect_err("too deep")
        .contains("window depth"));
    let deeper = MeshParams {
        door_depth: 0.5,
        ..p
    };
    assert!(build(&leaves, &deeper)
        .expect_err("too deep")
        .contains("door depth"));
    let flat = MeshParams {
        wall_thickness: 0.0,
        ..p
    };
    assert!(build(&leaves, &flat)
        .expect_err("no thickness")
        .contains("thickness"));
    let notex = MeshParams {
        texture_size: (0.0, 330.0),
        ..p
    };
    assert!(build(&leaves, &notex)
        .expect_err("texture size")
        .contains("texture size"));

    let dir = scratch("errors");
    let mesh = build(&leaves, &p).expect("builds");
    let missing = dir.join("missing.png");
    let e = write_obj_mtl(&dir.join("a.obj"), &mesh, Some(&missing)).expect_err("missing texture");
    assert!(e.to_string().contains("missing.png"), "{e}");
    let e =
        write_glb_textured(&dir.join("a.glb"), &mesh, Some(&missing)).expect_err("missing texture");
    assert!(e.to_string().contains("missing.png"), "{e}");
    let not_png = dir.join("not.png");
    std::fs::write(&not_png, b"plain text").expect("write");
    let e = write_glb_textured(&dir.join("a.glb"), &mesh, Some(&not_png)).expect_err("not a PNG");
    assert!(e.to_string().contains("not.png"), "{e}");
    let e =
        write_glb_textured(&dir.join("e.glb"), &FacadeMesh::default(), None).expect_err("empty");
    assert!(e.to_string().contains("e.glb"), "{e}");
    let mut broken = mesh.clone();
    broken.triangles[0][0] = usize::MAX;
    let e = write_obj_mtl(&dir.join("b.obj"), &broken, None).expect_err("bad index");
    assert!(e.to_string().contains("b.obj"), "{e}");
    assert!(
        !dir.join("a.obj").exists() && !dir.join("a.glb").exists() && !dir.join("b.obj").exists()
    );
    std::fs::remove_dir_all(&dir).expect("clean up");
}

fn leaf(x0: f64, y0: f64, x1: f64, y1: f64, class: Class) -> Leaf {
    let scope = Scope { x0, y0, x1, y1 };
    Leaf {
        scope,
        class,
        source: scope,
        element: None,
    }
}

/// A 10 × 10 wall with a 4 × 4 window in its middle, as a guillotine partition.
fn framed_window() -> Vec<Leaf> {
    vec![
        leaf(0.0, 0.0, 3.0, 10.0, Class::Wall),
        leaf(3.0, 0.0, 7.0, 3.0, Class::Wall),
        leaf(3.0, 3.0, 7.0, 7.0, Class::Window),
        leaf(3.0, 7.0, 7.0, 10.0, Class::Wall),
        leaf(7.0, 0.0, 10.0, 10.0, Class::Wall),
    ]
}

#[test]
fn framed_window_is_a_closed_slab_with_a_recess() {
    let p = MeshParams::new(0.5, (10.0, 10.0));
    let m = build(&framed_window(), &p).expect("builds");
    check_closed(&m).expect("closed");
    let expected = 5.0 * 5.0 * 0.3 - 2.0 * 2.0 * 0.12;
    assert!(
        (m.signed_volume() - expected).abs() < 1e-12,
        "{}",
        m.signed_volume()
    );
    // 9 cells front + 9 back, 4 reveals, 12 boundary edges with 2 strips each (cut at the
    // window's depth level): 2 triangles per quad
    assert_eq!(m.triangles.len(), 2 * (9 + 9 + 4 + 12 * 2));
    let names: Vec<&str> = m.groups.iter().map(|g| g.surface.name()).collect();
    assert_eq!(names, ["wall", "window", "reveal", "shell"]);
    // y up: the window's top-left corner (3, 3) is at y = (10 − 3) · 0.5
    let w = &m.groups[1];
    let top = m.triangles[w.triangles.clone()]
        .iter()
        .flatten()
        .map(|&i| m.positions[i].y);
    assert_eq!(top.fold(f64::MIN, f64::max), 3.5);
    for (t, uv) in m.triangles.iter().zip(&m.uv_triangles) {
        for k in 0..3 {
            let (p, [u, v]) = (m.positions[t[k]], m.uvs[uv[k]]);
            if p.z == 0.0 {
                // at its own size the photo maps straight on: u = x / W, v = 1 − y / H
                assert!((u - p.x / 5.0).abs() < 1e-12 && (v - (1.0 - p.y / 5.0)).abs() < 1e-12);
            }
        }
    }
}

#[test]
fn bad_partitions_and_pinches_are_errors() {
    let p = MeshParams::new(1.0, (10.0, 10.0));
    let mut gap = framed_window();
    gap.remove(1);
    assert!(build(&gap, &p).unwrap_err().contains("no leaf covers"));
    let mut overlap = framed_window();
    overlap.push(leaf(2.0, 2.0, 4.0, 4.0, Class::Door));
    assert!(build(&overlap, &p).unwrap_err().contains("overlap"));
    let checker = vec![
        leaf(0.0, 0.0, 5.0, 5.0, Class::Window),
        leaf(5.0, 0.0, 10.0, 5.0, Class::Wall),
        leaf(0.0, 5.0, 5.0, 10.0, Class::Wall),
        leaf(5.0, 5.0, 10.0, 10.0, Class::Door),
    ];
    assert!(build(&checker, &p).unwrap_err().contains("pinch"));
    let outside = vec![Leaf {
        source: Scope {
            x0: 0.0,
            y0: 0.0,
            x1: 20.0,
            y1: 10.0,
        },
        ..leaf(0.0, 0.0, 10.0, 10.0, Class::Wall)
    }];
    assert!(build(&outside, &p)
        .unwrap_err()
        .contains("outside the texture"));
    let nan = vec![leaf(0.0, f64::NAN, 10.0, 10.0, Class::Wall)];
    assert!(build(&nan, &p).unwrap_err().contains("invalid rectangle"));
}

#[test]
fn check_closed_finds_holes_flips_and_slivers() {
    let p = MeshParams::new(1.0, (10.0, 10.0));
    let good = build(&framed_window(), &p).expect("builds");
    let mut flipped = good.clone();
    flipped.triangles[0].swap(1, 2);
    assert!(check_closed(&flipped).unwrap_err().contains("edge"));
    let mut holed = good.clone();
    holed.triangles.pop();
    holed.uv_triangles.pop();
    holed.groups.last_mut().expect("groups").triangles.end -= 1;
    assert!(check_closed(&holed).unwrap_err().contains("edge"));
    let mut inside_out = good.clone();
    inside_out.triangles.iter_mut().for_each(|t| t.swap(1, 2));
    assert!(check_closed(&inside_out).unwrap_err().contains("inwards"));
    let mut sliver = good;
    sliver.triangles[0] = [0, 0, 1];
    assert!(check_closed(&sliver).unwrap_err().contains("degenerate"));
}

#[test]
fn tiny_offsets_merge_into_one_grid_line() {
    let mut leaves = framed_window();
    leaves[1].scope.x0 = 3.0 + 1e-12;
    let m = build(&leaves, &MeshParams::new(1.0, (10.0, 10.0))).expect("builds");
    check_closed(&m).expect("closed");
    assert_eq!(m.triangles.len(), 2 * (9 + 9 + 4 + 12 * 2));
}
