//! Automatic rectification by vanishing points: a synthetic facade seen through a known
//! perspective comes back with axis-aligned window edges, a frontal one stays (nearly) as it
//! is, featureless pictures are refused with a clear error, and on the labelled street photos
//! of `../shared/data/facades/labelmefacade` (read in place; skipped when absent) the ground
//! truth windows become more rectangular on average.

mod common;

use std::path::{Path, PathBuf};
use std::time::Instant;

use common::{facade, FLOOR, TILE, WIN_X, WIN_Y};
use emilion::facade::homography::{warp_gray, warp_labels, Homography};
use emilion::facade::instances::window_instances;
use emilion::facade::report::labelled_images;
use emilion::facade::vanishing::{rectify, Rectification};
use emilion::facade::{Class, FacadeError, LabelMap};
use emilion::geometry::image::Gray;
use nalgebra::Matrix3;

/// Facade size: 7 tiles × 4 floors and a bit.
const W: u32 = 301;
const H: u32 = 259;

/// A street-level view (as in `facade_rectify.rs`): turned away to the right, seen from below.
fn view() -> Homography {
    Homography(Matrix3::new(
        1.05, 0.06, 40.0, -0.22, 1.1, 90.0, -9e-4, 1e-4, 1.0,
    ))
}

/// Groups of points that share a coordinate.
type Edges = Vec<Vec<[f64; 2]>>;

/// Window corners of the facade, grouped: for each tile column its left and right window
/// edges (points sharing x), for each floor its top and bottom edges (points sharing y).
fn edges() -> (Edges, Edges) {
    let (cols, rows) = (W / TILE, H / FLOOR);
    let mut vertical = Vec::new();
    for tx in 0..cols {
        for x in [WIN_X.0, WIN_X.1] {
            let x = (tx * TILE + x) as f64;
            vertical.push(
                (0..rows)
                    .flat_map(|fy| [WIN_Y.0, WIN_Y.1].map(|y| [x, (fy * FLOOR + y) as f64]))
                    .collect(),
            );
        }
    }
    let mut horizontal = Vec::new();
    for fy in 0..rows {
        for y in [WIN_Y.0, WIN_Y.1] {
            let y = (fy * FLOOR + y) as f64;
            horizontal.push(
                (0..cols)
                    .flat_map(|tx| [WIN_X.0, WIN_X.1].map(|x| [(tx * TILE + x) as f64, y]))
                    .collect(),
            );
        }
    }
    (vertical, horizontal)
}

/// Largest spread of x over the vertical edges and of y over the horizontal edges after `m`,
/// as shares of the mapped facade's width and height.
fn misalignment(m: &Homography) -> (f64, f64) {
    let (vertical, horizontal) = edges();
    let map = |p: [f64; 2]| m.apply(p).expect("finite");
    let spread = |pts: &Vec<[f64; 2]>, k: usize| {
        let v: Vec<f64> = pts.iter().map(|&p| map(p)[k]).collect();
        v.iter().cloned().fold(f64::MIN, f64::max) - v.iter().cloned().fold(f64::MAX, f64::min)
    };
    let corners = [
        [0.0, 0.0],
        [W as f64, 0.0],
        [W as f64, H as f64],
        [0.0, H as f64],
    ]
    .map(map);
    let extent = |k: usize| {
        corners.iter().map(|c| c[k]).fold(f64::MIN, f64::max)
            - corners.iter().map(|c| c[k]).fold(f64::MAX, f64::min)
    };
    let dx = vertical.iter().map(|e| spread(e, 0)).fold(0.0, f64::max) / extent(0);
    let dy = horizontal.iter().map(|e| spread(e, 1)).fold(0.0, f64::max) / extent(1);
    (dx, dy)
}

fn compose(a: &Homography, b: &Homography) -> Homography {
    // a after b
    Homography(a.0 * b.0)
}

/// A view from below and slightly rolled: the verticals converge upwards (the top of the
/// facade is 1.4 times further away than its bottom).
fn view_from_below() -> Homography {
    Homography(Matrix3::new(
        1.0, 0.05, 0.0, -0.04, 1.0, 0.0, 0.0, -1.5e-3, 1.39,
    ))
}

/// The facade seen through `v`, shifted so the picture has a 15 px margin; the shifted view.
fn photo(front: &Gray, v: &Homography) -> (Gray, Homography) {
    let c = [
        [0.0, 0.0],
        [W as f64, 0.0],
        [W as f64, H as f64],
        [0.0, H as f64],
    ]
    .map(|p| v.apply(p).expect("finite"));
    let (x0, y0) = (
        c.iter().map(|p| p[0]).fold(f64::MAX, f64::min),
        c.iter().map(|p| p[1]).fold(f64::MAX, f64::min),
    );
    let (x1, y1) = (
        c.iter().map(|p| p[0]).fold(f64::MIN, f64::max),
        c.iter().map(|p| p[1]).fold(f64::MIN, f64::max),
    );
    let t = Homography(Matrix3::new(
        1.0,
        0.0,
        15.0 - x0,
        0.0,
        1.0,
        15.0 - y0,
        0.0,
        0.0,
        1.0,
    ));
    let v = compose(&t, v);
    let img = warp_gray(front, &v, (x1 - x0 + 30.0) as u32, (y1 - y0 + 30.0) as u32);
    (img.expect("view"), v)
}

/// The tolerance 1.5 %: on this 301 × 259 facade that is 4.5 px across and 3.9 px up, a
/// residual tilt of about 1° over the whole facade, and about the 2 px window frames plus the
/// blur of two bilinear resamplings (view, then rectification). Unrectified, the street view
/// is off by 2.4 % across and 13 % up, the view from below by 23 % across and 4 % up.
#[test]
fn a_facade_in_perspective_comes_back_with_axis_aligned_windows() {
    let front = facade(W, H, 11);
    for (name, v0) in [("street", view()), ("below", view_from_below())] {
        let (photo, v) = photo(&front, &v0);
        let before = misalignment(&v);
        let t = Instant::now();
        let r = rectify(&photo).expect("rectified");
        let secs = t.elapsed().as_secs_f64();
        let total = compose(&r.h, &v);
        let (dx, dy) = misalignment(&total);
        eprintln!(
            "{name}: photo {}×{}, spread before {:.3}/{:.3}, after {dx:.4}/{dy:.4} (x/y share), \
             inliers {:?}, vp {:?} {:?}, output {}×{}, {:.0} ms",
            photo.width,
            photo.height,
            before.0,
            before.1,
            r.inliers,
            r.vertical_vp,
            r.horizontal_vp,
            r.width,
            r.height,
            secs * 1e3
        );
        assert!(before.0.max(before.1) > 0.1, "{name}: {before:?}");
        assert!(dx < 0.015 && dy < 0.015, "{name}: {dx} {dy}");
        // what is left is an axis scaling: the tiles are equally wide again, first vs last
        let m = |p: [f64; 2]| total.apply(p).expect("finite");
        let tile =
            |tx: u32| m([((tx + 1) * TILE) as f64, 100.0])[0] - m([(tx * TILE) as f64, 100.0])[0];
        let ratio = tile(0) / tile(W / TILE - 1);
        assert!(
            (ratio - 1.0).abs() < 0.03,
            "{name}: tile width ratio {ratio}"
        );
        let floor =
            |fy: u32| m([150.0, ((fy + 1) * FLOOR) as f64])[1] - m([150.0, (fy * FLOOR) as f64])[1];
        let ratio = floor(0) / floor(H / FLOOR - 1);
        assert!(
            (ratio - 1.0).abs() < 0.03,
            "{name}: floor height ratio {ratio}"
        );
        // upright, unmirrored, within the output
        assert!(m([0.0, 0.0])[1] < m([0.0, H as f64])[1]);
        assert!(m([0.0, 0.0])[0] < m([W as f64, 0.0])[0]);
        let (pw, ph) = (photo.width as f64, photo.height as f64);
        assert!((r.width as f64) * (r.height as f64) <= 2.0 * pw * ph + 2.0 * (pw + ph) + 1.0);
        for c in [[0.0, 0.0], [pw, 0.0], [pw, ph], [0.0, ph]] {
            let p = r.h.apply(c).expect("finite");
            assert!(p[0] > -1e-6 && p[1] > -1e-6, "{name}: {p:?}");
            assert!(
                p[0] <= r.width as f64 + 1e-6 && p[1] <= r.height as f64 + 1e-6,
                "{name}: {p:?}"
            );
        }
    }
}

/// A frontal facade: both families parallel, the points at infinity, H a translation up to
/// 0.5 % (scale change, shear or rotation) and edges aligned within 0.5 %.
#[test]
fn a_frontal_facade_stays_frontal() {
    let front = facade(W, H, 5);
    let r = rectify(&front).expect("rectified");
    let (dx, dy) = misalignment(&r.h);
    let m = r.h.0 / r.h.0[(2, 2)];
    eprintln!("frontal: {dx:.4}/{dy:.4}, inliers {:?}, H = {m}", r.inliers);
    assert!(dx < 0.005 && dy < 0.005, "{dx} {dy}");
    let lin = (m[(0, 0)] - 1.0)
        .abs()
        .max((m[(1, 1)] - 1.0).abs())
        .max(m[(0, 1)].abs())
        .max(m[(1, 0)].abs());
    assert!(lin < 0.005, "{m}");
    // projective terms: under 0.5 % change of scale across the image
    assert!(
        m[(2, 0)].abs() * W as f64 + m[(2, 1)].abs() * (H as f64) < 0.005,
        "{m}"
    );
    assert!(r.vertical_vp[2].abs() < 1e-3 && r.horizontal_vp[2].abs() < 1e-3);
}

fn refused(img: &Gray) -> String {
    match rectify(img) {
        Err(e @ FacadeError::Rectification { .. }) => e.to_string(),
        other => panic!("expected a rectification error, got {other:?}"),
    }
}

#[test]
fn featureless_pictures_are_refused_clearly() {
    let flat = Gray {
        width: 200,
        height: 150,
        data: vec![128; 200 * 150],
    };
    let msg = refused(&flat);
    eprintln!("uniform: {msg}");
    assert!(
        msg.contains("no dominant vertical direction: 0 near-vertical segments"),
        "{msg}"
    );
    let noise = common::noise(200, 150, 7);
    let msg = refused(&noise);
    eprintln!("noise: {msg}");
    assert!(
        msg.contains("no dominant") || msg.contains("no consistent"),
        "{msg}"
    );
    // vertical stripes only: no horizontal direction
    let stripes = Gray {
        width: 200,
        height: 150,
        data: (0..200 * 150)
            .map(|i| if (i % 200) / 20 % 2 == 0 { 40 } else { 210 })
            .collect(),
    };
    let msg = refused(&stripes);
    eprintln!("stripes: {msg}");
    assert!(msg.contains("horizontal"), "{msg}");
    // degenerate sizes and inconsistent data never panic
    for (w, h, n) in [(0, 0, 0), (1, 1, 1), (3, 2, 6), (64, 64, 10)] {
        refused(&Gray {
            width: w,
            height: h,
            data: vec![9; n],
        });
    }
}

fn data() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data/facades/labelmefacade")
}

/// Mean fill ratio (window pixels / bounding-box area) of the window components of `map`
/// that are not "don't care".
fn mean_fill(map: &LabelMap) -> Option<f64> {
    let fills: Vec<f64> = window_instances(map)
        .iter()
        .filter(|w| !w.dont_care)
        .map(|w| map.count_in(&w.rect, Class::Window) as f64 / w.rect.area().max(1) as f64)
        .collect();
    (!fills.is_empty()).then(|| fills.iter().sum::<f64>() / fills.len() as f64)
}

/// On the 23 labelled photos: the ground-truth windows, warped with the automatic
/// rectification, fill their bounding boxes at least as well on average as before (a tilted
/// or keystoned rectangle fills its box less). A photo that cannot be rectified counts as
/// unchanged.
#[test]
fn real_photos_get_more_rectangular_windows() {
    let dir = data();
    if !dir.join("images").is_dir() {
        eprintln!("skipped: {} is absent", dir.display());
        return;
    }
    let names = labelled_images(&dir).expect("listing");
    let (mut before, mut after) = (Vec::new(), Vec::new());
    let (mut improved, mut refusals, mut total_secs) = (0, 0, 0.0);
    for n in &names {
        let img = Gray::read(&dir.join("images").join(format!("{n}.jpg"))).expect("photo");
        let truth = LabelMap::read_labelmefacade(&dir.join("labels").join(format!("{n}.png")))
            .expect("labels");
        let t = Instant::now();
        let r = rectify(&img);
        let secs = t.elapsed().as_secs_f64();
        total_secs += secs;
        let Some(f0) = mean_fill(&truth) else {
            continue;
        };
        let f1 = match &r {
            Ok(Rectification {
                h, width, height, ..
            }) => warp_labels(&truth, h, *width, *height)
                .as_ref()
                .and_then(mean_fill)
                .unwrap_or(f0),
            Err(_) => f0,
        };
        match &r {
            Ok(r) => eprintln!(
                "{n:>70} {}×{} fill {f0:.3} → {f1:.3} ({:+.3}) inliers {:?} out {}×{} {:.0} ms",
                img.width,
                img.height,
                f1 - f0,
                r.inliers,
                r.width,
                r.height,
                secs * 1e3
            ),
            Err(e) => {
                refusals += 1;
                eprintln!("{n:>70} refused ({e}) {:.0} ms", secs * 1e3)
            }
        }
        improved += usize::from(f1 > f0 + 1e-9);
        before.push(f0);
        after.push(f1);
    }
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len().max(1) as f64;
    let (m0, m1) = (mean(&before), mean(&after));
    eprintln!(
        "mean fill {m0:.4} → {m1:.4}; improved {improved} of {}; refused {refusals}; {:.0} ms \
         per image",
        before.len(),
        1e3 * total_secs / names.len().max(1) as f64
    );
    assert_eq!(before.len(), 23);
    assert!(m1 >= m0, "mean fill got worse: {m0} → {m1}");
}
