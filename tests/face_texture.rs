//! Texture baking, textured exports and the signed error map of the face module, checked
//! against ground truth: a known texture rendered through known cameras and baked back, files
//! read back, and a mesh offset by a known distance along its normals.

use std::path::PathBuf;

use emilion::face::error_map::{
    error_colours, error_map_image, render_error_map, signed_distances, ErrorStats, LEGEND_HEIGHT,
};
use emilion::face::export::{write_glb, write_obj_mtl, write_textured_obj};
use emilion::face::model::NOSE_TIP;
use emilion::face::render::{FaceRenderer, Texture};
use emilion::face::texture_bake::{
    bake_texture, bake_texture_with, rasterize_uv, BakeOptions, UvTexel,
};
use emilion::face::FaceMesh;
use emilion::geometry::Camera;
use emilion::geometry::Vec3;
use image::{Rgb, RgbImage};
use nalgebra::Matrix3;

const SIZE: usize = 256;

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!(
        "emilion-face-texture-{}-{name}",
        std::process::id()
    ));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Copies a test output to `$EMILION_TEST_OUT` when that variable is set (to look at it).
fn keep(path: &std::path::Path) {
    if let Some(dir) = std::env::var_os("EMILION_TEST_OUT") {
        let dir = PathBuf::from(dir);
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::copy(path, dir.join(path.file_name().unwrap())).unwrap();
    }
}

/// A 640×480 camera, focal 1000 px, looking at the face centroid from 0.5 m, turned by `yaw`
/// degrees about the vertical axis (positive: the camera on the subject's left, +x).
fn camera(mesh: &FaceMesh, yaw_deg: f64) -> Camera {
    let yaw = yaw_deg.to_radians();
    let target = mesh.centroid();
    let d = Vec3::new(yaw.sin(), 0.0, yaw.cos());
    let centre = target + d * 0.5;
    let z = -d;
    let y = Vec3::new(0.0, -1.0, 0.0);
    let x = y.cross(&z);
    let r = Matrix3::from_rows(&[x.transpose(), y.transpose(), z.transpose()]);
    let t = -(r * centre);
    Camera::new(1000.0, 1000.0, 319.5, 239.5, r, t, 640, 480)
}

/// The surface point and unit normal of a texel.
fn texel_point(mesh: &FaceMesh, normals: &[Vec3], t: &UvTexel) -> (Vec3, Vec3) {
    let tri = mesh.triangles[t.triangle as usize].map(|i| i as usize);
    let b = t.bary;
    let p = (0..3).map(|k| mesh.positions[tri[k]] * b[k]).sum::<Vec3>();
    let n = (0..3).map(|k| normals[tri[k]] * b[k]).sum::<Vec3>();
    (p, n.normalize())
}

fn cos_to(cam: &Camera, p: &Vec3, n: &Vec3) -> f64 {
    let d = cam.center() - p;
    n.dot(&d) / d.norm()
}

/// Smooth gradient (red along u, green along v) plus a 16-texel checker in blue.
fn known_texture() -> Texture {
    let mut t = Texture::filled(SIZE, SIZE, [0.0; 3]);
    for y in 0..SIZE {
        for x in 0..SIZE {
            let (u, v) = (
                (x as f32 + 0.5) / SIZE as f32,
                1.0 - (y as f32 + 0.5) / SIZE as f32,
            );
            let check = if (x / 16 + y / 16) % 2 == 0 {
                1.0
            } else {
                -1.0
            };
            t.rgb[y * SIZE + x] = [60.0 + 150.0 * u, 60.0 + 150.0 * v, 128.0 + 40.0 * check];
        }
    }
    t
}

fn render(mesh: &FaceMesh, cam: &Camera, texture: &Texture) -> (RgbImage, FaceRenderer) {
    let mut r = FaceRenderer::new(640, 480);
    r.render(cam, &mesh.positions, &mesh.uvs, &mesh.triangles, texture);
    let background = RgbImage::from_pixel(640, 480, Rgb([0, 0, 255]));
    (r.composite(&background).unwrap(), r)
}

#[test]
fn bake_round_trip_recovers_known_texture() {
    let mesh = FaceMesh::mediapipe().unwrap();
    let truth = known_texture();
    let cams: Vec<Camera> = [0.0, -40.0, 40.0]
        .iter()
        .map(|&y| camera(&mesh, y))
        .collect();
    let photos: Vec<RgbImage> = cams.iter().map(|c| render(&mesh, c, &truth).0).collect();
    let views: Vec<(&Camera, &RgbImage)> = cams.iter().zip(&photos).collect();
    let start = std::time::Instant::now();
    let baked = bake_texture(&mesh, &views, SIZE).unwrap();
    let elapsed = start.elapsed();
    // deterministic
    assert_eq!(bake_texture(&mesh, &views, SIZE).unwrap(), baked);
    let dir = scratch("bake");
    baked.texture.save(&dir.join("baked.png")).unwrap();
    photos[2].save(dir.join("photo_yaw40.png")).unwrap();
    keep(&dir.join("baked.png"));
    keep(&dir.join("photo_yaw40.png"));
    std::fs::remove_dir_all(&dir).unwrap();

    let layout = rasterize_uv(&mesh, SIZE).unwrap();
    let normals = mesh.vertex_normals();
    let inside = |x: i64, y: i64| {
        (0..SIZE as i64).contains(&x)
            && (0..SIZE as i64).contains(&y)
            && layout[y as usize * SIZE + x as usize].is_some()
    };
    let (mut err, mut count, mut worst) = (0.0f64, 0usize, 0.0f32);
    for y in 0..SIZE {
        for x in 0..SIZE {
            let Some(t) = layout[y * SIZE + x] else {
                continue;
            };
            let (p, n) = texel_point(&mesh, &normals, &t);
            let best = cams.iter().map(|c| cos_to(c, &p, &n)).fold(-1.0, f64::max);
            let interior =
                (-2..=2).all(|dy| (-2..=2).all(|dx| inside(x as i64 + dx, y as i64 + dy)));
            if best < 0.5 || !interior || baked.weight[y * SIZE + x] <= 0.0 {
                continue;
            }
            let (a, b) = (baked.texture.rgb[y * SIZE + x], truth.rgb[y * SIZE + x]);
            for k in 0..3 {
                err += (a[k] - b[k]).abs() as f64;
                worst = worst.max((a[k] - b[k]).abs());
            }
            count += 1;
        }
    }
    let inside_count = layout.iter().filter(|t| t.is_some()).count();
    let mae = err / (3 * count) as f64;
    println!(
        "bake round trip: {count} texels checked of {inside_count} in the layout, mean abs \
         error {mae:.2} levels, worst {worst:.0}, coverage {:.3}, bake {:.0} ms",
        baked.coverage,
        elapsed.as_secs_f64() * 1e3
    );
    assert!(count > inside_count / 2, "only {count} texels checked");
    assert!(mae < 6.0, "mean abs error {mae}");
    assert!(baked.coverage > 0.9, "coverage {}", baked.coverage);
    // no black holes anywhere in the layout or its padding
    let darkest = baked
        .texture
        .rgb
        .iter()
        .map(|c| c[0] + c[1] + c[2])
        .fold(f32::MAX, f32::min);
    assert!(darkest > 100.0, "darkest texel sum {darkest}");
}

#[test]
fn single_view_weights_follow_viewing_angle() {
    let mesh = FaceMesh::mediapipe().unwrap();
    let truth = known_texture();
    let layout = rasterize_uv(&mesh, SIZE).unwrap();
    let normals = mesh.vertex_normals();
    for yaw in [0.0, 40.0] {
        let cam = camera(&mesh, yaw);
        let photo = render(&mesh, &cam, &truth).0;
        let baked = bake_texture(&mesh, &[(&cam, &photo)], SIZE).unwrap();
        let (mut away, mut grazing, mut frontal, mut frontal_ok) = (0, 0, 0, 0);
        for (i, t) in layout.iter().enumerate() {
            let Some(t) = t else {
                assert_eq!(
                    baked.weight[i], 0.0,
                    "texel {i} outside the layout was sampled"
                );
                continue;
            };
            let (p, n) = texel_point(&mesh, &normals, t);
            let c = cos_to(&cam, &p, &n);
            let w = baked.weight[i] as f64;
            if c <= 0.0 {
                away += 1;
                assert_eq!(
                    w, 0.0,
                    "yaw {yaw}: texel {i} faces away (cos {c:.2}) but has weight {w}"
                );
            } else if c < 0.3 {
                grazing += 1;
                assert!(
                    w <= c * c + 1e-3,
                    "yaw {yaw}: grazing texel {i}: cos {c:.2}, weight {w}"
                );
            } else if c > 0.8 {
                frontal += 1;
                frontal_ok += usize::from(w > 0.6);
            }
        }
        println!(
            "yaw {yaw}: {away} texels facing away (weight 0), {grazing} grazing (weight ≤ cos²), \
             {frontal_ok}/{frontal} facing (cos > 0.8) with weight > 0.6, coverage {:.3}",
            baked.coverage
        );
        assert!(frontal > 1000 && frontal_ok as f64 > 0.9 * frontal as f64);
        if yaw != 0.0 {
            assert!(away > 500, "the far side should face away: {away}");
        }
        assert!(grazing > 100);
    }
}

#[test]
fn occluded_cheek_takes_no_colour_from_the_nose() {
    let mesh = FaceMesh::mediapipe().unwrap();
    let layout = rasterize_uv(&mesh, SIZE).unwrap();
    let normals = mesh.vertex_normals();
    let tip = mesh.positions[NOSE_TIP];
    let mut tex = Texture::filled(SIZE, SIZE, [40.0, 160.0, 160.0]);
    let mut red = vec![false; SIZE * SIZE];
    for (i, t) in layout.iter().enumerate() {
        if let Some(t) = t {
            if (texel_point(&mesh, &normals, t).0 - tip).norm() < 0.02 {
                tex.rgb[i] = [230.0, 20.0, 20.0];
                red[i] = true;
            }
        }
    }
    let cam = camera(&mesh, 50.0);
    let (photo, renderer) = render(&mesh, &cam, &tex);
    // ground truth: texels off the nose, facing the camera, whose line of sight hits the red nose
    let mut behind = Vec::new();
    for (i, t) in layout.iter().enumerate() {
        let Some(t) = t else { continue };
        let (p, n) = texel_point(&mesh, &normals, t);
        if (p - tip).norm() < 0.025 || cos_to(&cam, &p, &n) < 0.2 {
            continue;
        }
        let [px, py] = cam.project(&p).unwrap();
        let (x, y) = (px.round() as u32, py.round() as u32);
        let z = cam.to_camera_frame(&p).z as f32;
        let pix = photo.get_pixel(x, y).0;
        if renderer.target.depth[(y * 640 + x) as usize] < z - 0.005 && pix[0] > 150 && pix[1] < 80
        {
            behind.push(i);
        }
    }
    let baked = bake_texture(&mesh, &[(&cam, &photo)], SIZE).unwrap();
    let sampled = baked.weight.iter().filter(|&&w| w > 0.0).count();
    let redness = |c: [f32; 3]| c[0] - c[1];
    let max_red = behind
        .iter()
        .map(|&i| redness(baked.texture.rgb[i]))
        .fold(f32::MIN, f32::max);
    println!(
        "occlusion: {} cheek texels behind the nose, {} of them sampled, max redness (r − g) \
         {max_red:.0}; {sampled} texels sampled, coverage {:.3}",
        behind.len(),
        behind.iter().filter(|&&i| baked.weight[i] > 0.0).count(),
        baked.coverage
    );
    assert!(
        behind.len() >= 20,
        "test geometry: only {} texels behind the nose",
        behind.len()
    );
    for &i in &behind {
        assert_eq!(
            baked.weight[i], 0.0,
            "texel {i} behind the nose was sampled"
        );
    }
    // filled from their visible, non-red neighbours
    assert!(
        max_red < 60.0,
        "texel behind the nose filled red: {max_red}"
    );
    // the nose itself was sampled red where visible
    let nose_ok = (0..SIZE * SIZE)
        .filter(|&i| red[i] && baked.weight[i] > 0.0)
        .count();
    assert!(nose_ok > 50);

    // without the depth test (huge tolerance) the same texels do take the nose's red
    let loose = BakeOptions {
        depth_tolerance: 1.0,
        ..BakeOptions::default()
    };
    let baked = bake_texture_with(&mesh, &[(&cam, &photo)], SIZE, &loose).unwrap();
    let reddened = behind
        .iter()
        .filter(|&&i| redness(baked.texture.rgb[i]) > 100.0)
        .count();
    println!(
        "without the depth test {reddened}/{} take the nose's red",
        behind.len()
    );
    assert!(reddened * 2 > behind.len());
}

#[test]
fn bake_rejects_bad_input() {
    let mesh = FaceMesh::mediapipe().unwrap();
    let cam = camera(&mesh, 0.0);
    let small = RgbImage::new(320, 240);
    let e = bake_texture(&mesh, &[(&cam, &small)], 64)
        .unwrap_err()
        .to_string();
    assert!(e.contains("views[0]"), "{e}");
    let photo = RgbImage::new(640, 480);
    let e = bake_texture(&mesh, &[(&cam, &photo)], 0)
        .unwrap_err()
        .to_string();
    assert!(e.contains("size"), "{e}");
    let e = bake_texture(&mesh, &[], 64).unwrap_err().to_string();
    assert!(e.contains("views"), "{e}");
    let mut bad = mesh.clone();
    bad.uvs.pop();
    let e = bake_texture(&bad, &[(&cam, &photo)], 64)
        .unwrap_err()
        .to_string();
    assert!(e.contains("mesh"), "{e}");
    let mut bad = mesh.clone();
    bad.triangles[3][1] = 10_000;
    assert!(bake_texture(&bad, &[(&cam, &photo)], 64).is_err());
    // a black photo of the background only: nothing sampled, no panic
    let far = Camera::new(
        1000.0,
        1000.0,
        319.5,
        239.5,
        Matrix3::identity(),
        Vec3::new(5.0, 0.0, 0.5),
        640,
        480,
    );
    let b = bake_texture(&mesh, &[(&far, &photo)], 32).unwrap();
    assert_eq!(b.coverage, 0.0);
}

#[test]
fn obj_mtl_round_trip() {
    let mesh = FaceMesh::mediapipe().unwrap();
    let dir = scratch("obj");
    let obj = dir.join("face.obj");
    write_obj_mtl(&obj, &mesh, "face_albedo.png").unwrap();
    let back = emilion::geometry::read_obj(&obj).unwrap();
    assert_eq!(back.positions.len(), mesh.positions.len());
    for (a, b) in back.positions.iter().zip(&mesh.positions) {
        assert!((a - b).norm() <= 1e-12);
    }
    for (a, b) in back.rest.iter().zip(&mesh.uvs) {
        assert!((a[0] - b[0]).abs() <= 1e-12 && (a[1] - b[1]).abs() <= 1e-12);
    }
    let tris: Vec<[usize; 3]> = mesh
        .triangles
        .iter()
        .map(|t| t.map(|i| i as usize))
        .collect();
    assert_eq!(back.triangles, tris);
    let text = std::fs::read_to_string(&obj).unwrap();
    assert!(text.contains("mtllib face.mtl\n") && text.contains("usemtl face\n"));
    assert_eq!(text.lines().filter(|l| l.starts_with("vn ")).count(), 468);
    assert!(
        text.contains("\nf 1/1/1 ")
            || text.lines().any(
                |l| l.starts_with("f ") && l.split(' ').nth(1).unwrap().split('/').count() == 3
            )
    );
    let mtl = std::fs::read_to_string(dir.join("face.mtl")).unwrap();
    assert!(
        mtl.contains("newmtl face\n") && mtl.contains("map_Kd face_albedo.png\n"),
        "{mtl}"
    );

    // all three files
    write_textured_obj(&dir, "person", &mesh, &known_texture()).unwrap();
    let png = image::open(dir.join("person.png")).unwrap().to_rgb8();
    assert_eq!(png, known_texture().to_image());
    assert!(std::fs::read_to_string(dir.join("person.mtl"))
        .unwrap()
        .contains("map_Kd person.png"));

    // a missing folder is an error naming the file
    let missing = dir.join("no_such_folder").join("face.obj");
    let e = write_obj_mtl(&missing, &mesh, "t.png")
        .unwrap_err()
        .to_string();
    assert!(e.contains("no_such_folder"), "{e}");
    let e = write_obj_mtl(&obj, &mesh, "").unwrap_err().to_string();
    assert!(e.contains("texture_file_name"), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
}

fn u32_at(b: &[u8], at: usize) -> u32 {
    u32::from_le_bytes(b[at..at + 4].try_into().unwrap())
}

#[test]
fn glb_round_trip() {
    let mesh = FaceMesh::mediapipe().unwrap();
    let tex = known_texture();
    let dir = scratch("glb");
    let path = dir.join("face.glb");
    write_glb(&path, &mesh, &tex).unwrap();
    let b = std::fs::read(&path).unwrap();
    assert_eq!(&b[0..4], b"glTF");
    assert_eq!(u32_at(&b, 8) as usize, b.len());
    let json_len = u32_at(&b, 12) as usize;
    let json: serde_json::Value = serde_json::from_slice(&b[20..20 + json_len]).unwrap();
    let bin = &b[20 + json_len + 8..];
    let prim = &json["meshes"][0]["primitives"][0];
    let acc = |name: &str| &json["accessors"][prim["attributes"][name].as_u64().unwrap() as usize];
    assert_eq!(acc("POSITION")["count"], 468);
    assert_eq!(acc("NORMAL")["count"], 468);
    assert_eq!(acc("TEXCOORD_0")["count"], 468);
    assert_eq!(acc("TEXCOORD_0")["type"], "VEC2");
    let idx = &json["accessors"][prim["indices"].as_u64().unwrap() as usize];
    assert_eq!(idx["count"], 3 * 898);
    // the bytes behind an accessor
    let view_bytes = |view: usize| {
        let v = &json["bufferViews"][view];
        let at = v["byteOffset"].as_u64().unwrap_or(0) as usize;
        &bin[at..at + v["byteLength"].as_u64().unwrap() as usize]
    };
    let uv = view_bytes(acc("TEXCOORD_0")["bufferView"].as_u64().unwrap() as usize);
    for (i, t) in mesh.uvs.iter().enumerate() {
        let f =
            |k: usize| f32::from_le_bytes(uv[8 * i + 4 * k..8 * i + 4 * k + 4].try_into().unwrap());
        assert_eq!((f(0), f(1)), (t[0] as f32, (1.0 - t[1]) as f32), "uv {i}");
    }
    let ind = view_bytes(idx["bufferView"].as_u64().unwrap() as usize);
    assert_eq!(u32_at(ind, 4 * 3 * 7 + 4), mesh.triangles[7][1]);
    // material → texture → image → PNG of the texture
    let mat = &json["materials"][prim["material"].as_u64().unwrap() as usize];
    let t = mat["pbrMetallicRoughness"]["baseColorTexture"]["index"]
        .as_u64()
        .unwrap() as usize;
    let img = &json["images"][json["textures"][t]["source"].as_u64().unwrap() as usize];
    assert_eq!(img["mimeType"], "image/png");
    let png =
        image::load_from_memory(view_bytes(img["bufferView"].as_u64().unwrap() as usize)).unwrap();
    assert_eq!((png.width(), png.height()), (SIZE as u32, SIZE as u32));
    assert_eq!(png.to_rgb8(), tex.to_image());
    // valid for gltf-json
    use gltf_json::validation::Validate;
    let root = gltf_json::Root::from_slice(&b[20..20 + json_len]).unwrap();
    let mut errors = Vec::new();
    root.validate(&root, gltf_json::Path::new, &mut |p, e| {
        errors.push(format!("{}: {e:?}", p()))
    });
    assert!(errors.is_empty(), "{errors:?}");

    let missing = dir.join("absent").join("face.glb");
    let e = write_glb(&missing, &mesh, &tex).unwrap_err().to_string();
    assert!(e.contains("absent"), "{e}");
    let bad = Texture {
        width: 4,
        height: 4,
        rgb: vec![[0.0; 3]; 3],
    };
    let e = write_glb(&path, &mesh, &bad).unwrap_err().to_string();
    assert!(e.contains("face.glb"), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Vertices on the open border of the mesh (on an edge used by one triangle).
fn border_vertices(mesh: &FaceMesh) -> Vec<bool> {
    let mut edges = std::collections::HashMap::new();
    for t in &mesh.triangles {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            *edges.entry((a.min(b), a.max(b))).or_insert(0) += 1;
        }
    }
    let mut border = vec![false; mesh.positions.len()];
    for ((a, b), n) in edges {
        if n == 1 {
            border[a as usize] = true;
            border[b as usize] = true;
        }
    }
    border
}

/// A UV sphere of `radius` with `rings × segments` quads (poles as fans), outward triangles.
fn sphere(radius: f64, rings: usize, segments: usize) -> FaceMesh {
    let mut positions = vec![Vec3::new(0.0, radius, 0.0)];
    let mut uvs = vec![[0.5, 1.0]];
    for i in 1..rings {
        let th = std::f64::consts::PI * i as f64 / rings as f64;
        for j in 0..segments {
            let ph = 2.0 * std::f64::consts::PI * j as f64 / segments as f64;
            positions.push(Vec3::new(th.sin() * ph.cos(), th.cos(), th.sin() * ph.sin()) * radius);
            uvs.push([j as f64 / segments as f64, 1.0 - i as f64 / rings as f64]);
        }
    }
    positions.push(Vec3::new(0.0, -radius, 0.0));
    uvs.push([0.5, 0.0]);
    let south = positions.len() as u32 - 1;
    let at = |i: usize, j: usize| (1 + (i - 1) * segments + j % segments) as u32;
    let mut triangles = Vec::new();
    for j in 0..segments {
        triangles.push([0, at(1, j), at(1, j + 1)]);
        triangles.push([south, at(rings - 1, j + 1), at(rings - 1, j)]);
        for i in 1..rings - 1 {
            triangles.push([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
            triangles.push([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
        }
    }
    // orient every triangle outwards
    for t in &mut triangles {
        let [a, b, c] = t.map(|i| positions[i as usize]);
        if (b - a).cross(&(c - a)).dot(&(a + b + c)) < 0.0 {
            t.swap(1, 2);
        }
    }
    FaceMesh {
        positions,
        uvs,
        triangles,
    }
}

#[test]
fn signed_distances_of_offset_surfaces() {
    let mesh = FaceMesh::mediapipe().unwrap();
    let same = signed_distances(&mesh, &mesh);
    let s = ErrorStats::of(&same);
    println!("self distance: max {:.2e} m", s.max_abs);
    assert_eq!(s.count, 468);
    assert!(s.max_abs <= 1e-9);

    let normals = mesh.vertex_normals();
    let mut inflated = mesh.clone();
    for (p, n) in inflated.positions.iter_mut().zip(&normals) {
        *p += n * 0.002;
    }
    let border = border_vertices(&mesh);
    let out = signed_distances(&inflated, &mesh);
    let inn = signed_distances(&mesh, &inflated);
    let interior = |d: &[f64]| -> Vec<f64> {
        d.iter()
            .zip(&border)
            .filter(|(_, &b)| !b)
            .map(|(&d, _)| d)
            .collect()
    };
    let (io, ii) = (interior(&out), interior(&inn));
    let (so, si) = (ErrorStats::of(&io), ErrorStats::of(&ii));
    let dev = |d: &[f64], target: f64| d.iter().map(|x| (x - target).abs()).fold(0.0, f64::max);
    println!(
        "inflated 2 mm vs original, {} interior vertices: mean {:.3} mm, max |d − 2 mm| {:.3} mm; \
         original vs inflated: mean {:.3} mm, max |d + 2 mm| {:.3} mm; all vertices min {:.3} mm",
        io.len(),
        so.mean * 1e3,
        dev(&io, 0.002) * 1e3,
        si.mean * 1e3,
        dev(&ii, -0.002) * 1e3,
        out.iter().copied().fold(f64::INFINITY, f64::min) * 1e3
    );
    // the offset surface is parallel where the mesh is smooth at the 2 mm scale; the closed
    // lips (a fold thinner than 4 mm), the nostrils and creases of the coarse mesh are not
    let within = |d: &[f64], target: f64| d.iter().filter(|x| (*x - target).abs() <= 2e-4).count();
    let median = |d: &[f64], target: f64| {
        let mut e: Vec<f64> = d.iter().map(|x| (x - target).abs()).collect();
        e.sort_by(f64::total_cmp);
        e[e.len() / 2]
    };
    let mouth = (mesh.positions[13] + mesh.positions[14]) / 2.0;
    let away: Vec<usize> = (0..468)
        .filter(|&i| (mesh.positions[i] - mouth).norm() > 0.028)
        .collect();
    let signs_ok = away
        .iter()
        .filter(|&&i| out[i] > 0.0 && inn[i] < 0.0)
        .count();
    println!(
        "face inflated by 2 mm: {}/{} interior vertices at +2 ± 0.2 mm (median error {:.4} mm), \
         {}/{} of the original at −2 ± 0.2 mm (median {:.4} mm); signs right both ways for \
         {signs_ok}/{} vertices away from the lips, for {}/468 overall",
        within(&io, 0.002),
        io.len(),
        median(&io, 0.002) * 1e3,
        within(&ii, -0.002),
        ii.len(),
        median(&ii, -0.002) * 1e3,
        away.len(),
        (0..468).filter(|&i| out[i] > 0.0 && inn[i] < 0.0).count()
    );
    assert!(io.len() > 350);
    assert!(within(&io, 0.002) as f64 >= 0.85 * io.len() as f64);
    assert!(within(&ii, -0.002) as f64 >= 0.85 * ii.len() as f64);
    assert!(median(&io, 0.002) < 5e-5 && median(&ii, -0.002) < 5e-5);
    assert!(away.len() > 350 && signs_ok == away.len());

    // a closed, smooth surface: a sphere of 10 cm and one of 10.2 cm, every vertex ±0.2 mm
    let small = sphere(0.1, 40, 80);
    let mut big = small.clone();
    for p in &mut big.positions {
        *p *= 0.102 / 0.1;
    }
    let (o, i) = (
        signed_distances(&big, &small),
        signed_distances(&small, &big),
    );
    println!(
        "spheres 10.2 / 10 cm: {:.4}..{:.4} mm outside, {:.4}..{:.4} mm inside",
        o.iter().copied().fold(f64::INFINITY, f64::min) * 1e3,
        o.iter().copied().fold(f64::NEG_INFINITY, f64::max) * 1e3,
        i.iter().copied().fold(f64::INFINITY, f64::min) * 1e3,
        i.iter().copied().fold(f64::NEG_INFINITY, f64::max) * 1e3
    );
    assert!(o.iter().all(|d| (d - 0.002).abs() <= 2e-4));
    assert!(i.iter().all(|d| (d + 0.002).abs() <= 2e-4));
    // stats of a known list
    let st = ErrorStats::of(&[3.0, -4.0, f64::NAN]);
    assert_eq!((st.count, st.mean_abs, st.max_abs), (2, 3.5, 4.0));
    assert!((st.rms - 12.5f64.sqrt()).abs() < 1e-12);
}

#[test]
fn error_map_colours_and_image() {
    let c = error_colours(&[0.0, 0.001, -0.001, 0.01, -0.01, f64::NAN], 0.002);
    assert_eq!(c[0], [0.0, 0.0, 0.0]);
    assert_eq!(c[1], [0.0, 127.5, 0.0]);
    assert_eq!(c[2], [127.5, 0.0, 0.0]);
    assert_eq!(c[3], [0.0, 255.0, 0.0]);
    assert_eq!(c[4], [255.0, 0.0, 0.0]);
    assert_eq!(c[5], [128.0; 3]);

    let mesh = FaceMesh::mediapipe().unwrap();
    let normals = mesh.vertex_normals();
    let mut inflated = mesh.clone();
    for (p, n) in inflated.positions.iter_mut().zip(&normals) {
        *p += n * 0.002;
    }
    let cam = camera(&mesh, 0.0);
    let dir = scratch("errmap");
    for (name, a, b, green) in [
        ("out", &inflated, &mesh, true),
        ("in", &mesh, &inflated, false),
    ] {
        let d = signed_distances(a, b);
        let path = dir.join(format!("error_{name}.png"));
        let stats = render_error_map(a, &d, &cam, &path, 0.004).unwrap();
        keep(&path);
        let img = image::open(&path).unwrap().to_rgb8();
        assert_eq!((img.width(), img.height()), (640, 480 + LEGEND_HEIGHT));
        let (mut face, mut right) = (0, 0);
        for y in 0..480 {
            for x in 0..640 {
                let p = img.get_pixel(x, y).0;
                if p != [255, 255, 255] {
                    face += 1;
                    let (main, other) = if green { (p[1], p[0]) } else { (p[0], p[1]) };
                    right += usize::from(main > 90 && other < 10 && p[2] < 10);
                }
            }
        }
        println!("error map {name}: {face} face pixels, {right} of the expected colour; {stats:?}");
        assert!(face > 30_000 && right as f64 > 0.95 * face as f64);
        // the legend's bar: red at the left, black in the middle, green at the right
        let bar = |x: u32| img.get_pixel(x, 480 + 12).0;
        assert!(bar(10)[0] > 240 && bar(10)[1] == 0);
        assert!(bar(320).iter().all(|&c| c < 5), "{:?}", bar(320));
        assert!(bar(629)[1] > 240 && bar(629)[0] == 0);
    }
    let d = vec![0.0; 468];
    let e = render_error_map(&mesh, &d, &cam, &dir.join("nope").join("e.png"), 0.002)
        .unwrap_err()
        .to_string();
    assert!(e.contains("nope"), "{e}");
    assert!(error_map_image(&mesh, &d[..10], &cam, 0.002)
        .unwrap_err()
        .to_string()
        .contains("distances"));
    // tiny images: the legend is clipped, nothing panics
    for (w, h) in [(1, 1), (2, 3), (40, 10)] {
        let tiny = Camera::new(5.0, 5.0, 0.0, 0.0, cam.rotation, cam.translation, w, h);
        let img = error_map_image(&mesh, &d, &tiny, 0.002).unwrap();
        assert_eq!((img.width(), img.height()), (w, h + LEGEND_HEIGHT));
    }
    assert!(error_map_image(&mesh, &d, &cam, 0.0)
        .unwrap_err()
        .to_string()
        .contains("scale"));
    std::fs::remove_dir_all(&dir).unwrap();
}
