//! The facade pipeline end to end on photos with known answers: a synthetic facade seen in
//! perspective is rectified automatically, parsed into a grammar whose windows overlap the
//! true ones (the label map carried through the same homography), whose rule file round-trips
//! exactly, and which writes an overlay, a rule file and closed 3D facades at three widths;
//! a picture that is no facade gives a clear message and still writes its overlay.

mod common;

use std::path::{Path, PathBuf};

use common::{facade, noise, window_truth, FLOOR, TILE};
use emilion::facade::analysis::{analyze, Options, Rectify};
use emilion::facade::homography::{warp_gray, warp_labels, Homography};
use emilion::facade::outputs::{write_outputs, OutputOptions};
use emilion::facade::rasterize::{rasterize, round_trip};
use emilion::facade::{Class, LabelMap, PixelScore};
use emilion::geometry::image::Gray;
use emilion::geometry::read_obj_surface;
use nalgebra::Matrix3;

fn out_dir(name: &str) -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn save(g: &Gray, path: &Path) {
    let img = image::GrayImage::from_raw(g.width, g.height, g.data.clone()).unwrap();
    img.save(path).unwrap();
}

#[test]
fn perspective_facade_is_rectified_parsed_and_built() {
    let (w, h) = (473, 399);
    let front = facade(w, h, 21);
    // seen from the street, turned away and from below
    let view = Homography(Matrix3::new(
        1.05, 0.06, 40.0, -0.12, 1.1, 60.0, -4e-4, 1e-4, 1.0,
    ));
    let (pw, ph) = (620, 560);
    let photo = warp_gray(&front, &view, pw, ph).unwrap();
    let dir = out_dir("facade_pipeline");
    let path = dir.join("view.png");
    save(&photo, &path);
    let a = analyze(&path, &Options::default()).unwrap();
    assert_eq!(a.problem(), None);
    let (g, s) = a.parse.as_ref().unwrap();
    eprintln!(
        "floor {} tile {} ({}×{} cells, {} with a window) stages {:?}",
        s.floor,
        s.tile,
        s.count.0,
        s.count.1,
        s.present.iter().filter(|&&p| p).count(),
        a.seconds
    );
    // the truth goes to the rectified frame through the view and the found rectification
    let (rw, rh) = (a.gray.width, a.gray.height);
    let in_photo = warp_labels(&window_truth(w, h), &view, pw, ph).unwrap();
    let t = warp_labels(&in_photo, &a.homography, rw, rh).unwrap();
    let p = rasterize(&g.derive(rw as f64, rh as f64).unwrap(), rw, rh);
    let files = write_outputs(&a, &dir, "view", &OutputOptions::default()).unwrap();
    let score = PixelScore::of(&p.labels, &t).unwrap();
    let iou = score.iou(Class::Window);
    eprintln!("window IoU {iou:.3}, {} windows", p.windows.len());
    assert!(iou > 0.6, "window IoU {iou}");
    assert_eq!(round_trip(g, rw, rh).unwrap(), 1.0);
    // outputs: overlay, rules, closed textured facades at three widths
    for f in [
        "view_overlay.png",
        "view_rectified.png",
        "view.cga",
        "view_w1.5.glb",
    ] {
        assert!(files.contains(&dir.join(f)), "{f} in {files:?}");
    }
    for f in ["view_w1.obj", "view_w0.75.obj", "view_w1.5.obj"] {
        let (v, t) = read_obj_surface(&dir.join(f)).unwrap();
        assert!(!v.is_empty() && !t.is_empty(), "{f}");
    }
    let rules = std::fs::read_to_string(dir.join("view.cga")).unwrap();
    assert!(
        rules.contains("Floors -->") && rules.contains("--> insert(window, window_plain)"),
        "{rules}"
    );
}

#[test]
fn four_corners_rectify_too() {
    let (w, h) = (430, 342);
    let front = facade(w, h, 4);
    let view = Homography(Matrix3::new(
        1.0, 0.05, 30.0, -0.15, 1.05, 70.0, -5e-4, 0.0, 1.0,
    ));
    let photo = warp_gray(&front, &view, 560, 520).unwrap();
    let dir = out_dir("facade_corners");
    let path = dir.join("view.png");
    save(&photo, &path);
    let c = [
        [0.0, 0.0],
        [w as f64, 0.0],
        [w as f64, h as f64],
        [0.0, h as f64],
    ]
    .map(|p| view.apply(p).unwrap());
    let a = analyze(
        &path,
        &Options {
            rectify: Rectify::Corners(c),
            ..Options::default()
        },
    )
    .unwrap();
    let (_, s) = a.parse.as_ref().expect("parses");
    write_outputs(&a, &dir, "view", &OutputOptions::default()).unwrap();
    // the corners go to an upright rectangle of the quadrilateral's mean side lengths: the
    // periods scale with it
    let (rw, rh) = (a.gray.width as f64, a.gray.height as f64);
    let (ef, et) = (FLOOR as f64 * rh / h as f64, TILE as f64 * rw / w as f64);
    eprintln!(
        "rectified {rw}×{rh}: floor {} (expected {ef:.1}), tile {} (expected {et:.1}), splits {:?}",
        s.floor, s.tile, s.floor_splits
    );
    assert!((s.floor as f64 - ef).abs() <= 1.0 && (s.tile as f64 - et).abs() <= 1.0);
}

#[test]
fn a_picture_without_a_facade_gives_a_clear_message_and_its_overlay() {
    let dir = out_dir("facade_none");
    let noise = noise(300, 240, 7);
    let path = dir.join("noise.png");
    save(&noise, &path);
    let a = analyze(&path, &Options::default()).unwrap();
    let problem = a.problem().expect("a problem");
    eprintln!("{problem}");
    assert!(problem.contains("rectification failed"), "{problem}");
    assert!(
        problem.contains("no facade") || problem.contains("no repeated"),
        "{problem}"
    );
    let files = write_outputs(&a, &dir, "noise", &OutputOptions::default()).unwrap();
    assert_eq!(files, vec![dir.join("noise_overlay.png")]);
    assert!(dir.join("noise_overlay.png").exists());
    // an unreadable photo is an error naming the file
    let e = analyze(&dir.join("missing.jpg"), &Options::default()).unwrap_err();
    assert!(e.to_string().contains("missing.jpg"));
}

#[test]
fn a_street_photo_is_parsed_into_its_windows_and_built_at_three_widths() {
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data/facades/labelmefacade");
    let name = "spatial_envelope_256x256_static_8outdoorcategories__insidecity_urb267";
    let photo = data.join(format!("images/{name}.jpg"));
    let a = analyze(&photo, &Options::default()).unwrap();
    let (g, s) = a.parse.as_ref().expect("parses");
    // the floors × tiles lattice does not fit this street: the grammar is the windows'
    assert!(s.from_windows, "{} windows found", s.windows.len());
    let (rw, rh) = (a.gray.width, a.gray.height);
    let p = rasterize(&g.derive(rw as f64, rh as f64).unwrap(), rw, rh);
    eprintln!(
        "{} windows found, {} in the parse",
        s.windows.len(),
        p.windows.len()
    );
    assert!(s.windows.len() >= 10);
    // the XY cuts lose only windows that overlap another
    for w in s.windows.iter().filter(|w| !p.windows.contains(w)) {
        assert!(
            s.windows.iter().any(|v| v != w && v.intersection(w) > 0),
            "{w:?} lost"
        );
    }
    assert_eq!(round_trip(g, rw, rh).unwrap(), 1.0);
    let truth = LabelMap::read_labelmefacade(&data.join(format!("labels/{name}.png"))).unwrap();
    let t = warp_labels(&truth, &a.homography, rw, rh).unwrap();
    let iou = PixelScore::of(&p.labels, &t).unwrap().iou(Class::Window);
    eprintln!("window IoU {iou:.3}");
    assert!(iou > 0.3, "window IoU {iou}");
    // closed facades at three widths (write_outputs checks each mesh is closed)
    let dir = out_dir("facade_street");
    write_outputs(&a, &dir, "street", &OutputOptions::default()).unwrap();
    for f in ["street_w1.obj", "street_w0.75.obj", "street_w1.5.obj"] {
        let (v, t) = read_obj_surface(&dir.join(f)).unwrap();
        assert!(!v.is_empty() && !t.is_empty(), "{f}");
    }
}
