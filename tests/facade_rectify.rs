//! Rectification against ground truth: a synthetic facade seen in perspective (a known
//! homography) and brought back to a fronto-parallel view from its four corners: the picture
//! returns up to resampling blur, its floors and tiles are found again, and label maps follow
//! the same warp.

mod common;

use common::{facade, FLOOR, TILE};
use emilion::facade::homography::{warp_gray, warp_labels, Homography};
use emilion::facade::repetition::{detect, Axis};
use emilion::facade::{Class, LabelMap, Rect};
use nalgebra::Matrix3;

/// A street-level view: the facade turned away to the right and seen from below.
fn view() -> Homography {
    Homography(Matrix3::new(
        1.05, 0.06, 40.0, -0.22, 1.1, 90.0, -9e-4, 1e-4, 1.0,
    ))
}

/// The rectifying homography from the `w` × `h` facade's corners as a user would click them
/// in the view.
fn rectifier(v: &Homography, w: u32, h: u32) -> Homography {
    let corners = [
        [0.0, 0.0],
        [w as f64, 0.0],
        [w as f64, h as f64],
        [0.0, h as f64],
    ]
    .map(|p| v.apply(p).unwrap());
    Homography::rectifying(&corners, w as f64, h as f64).unwrap()
}

#[test]
fn four_corners_restore_the_fronto_parallel_facade() {
    let (w, h) = (301, 259);
    let front = facade(w, h, 11);
    let v = view();
    let photo = warp_gray(&front, &v, 560, 460).unwrap();
    let back = warp_gray(&photo, &rectifier(&v, w, h), w, h).unwrap();
    // the same picture up to resampling blur (two bilinear passes on a noisy texture)
    let mad = back
        .data
        .iter()
        .zip(&front.data)
        .map(|(a, b)| (*a as f64 - *b as f64).abs())
        .sum::<f64>()
        / front.data.len() as f64;
    assert!(mad < 8.0, "mean absolute difference {mad}");
    let floors = detect(&back, Axis::Rows, 20, 130).unwrap();
    let tiles = detect(&back, Axis::Columns, 15, 100).unwrap();
    assert_eq!((floors.period, tiles.period), (FLOOR, TILE));
}

#[test]
fn label_maps_follow_the_same_warp() {
    let (w, h) = (301u32, 259u32);
    let mut labels = LabelMap::filled(w, h, Class::Wall);
    for fy in 0..4 {
        for tx in 0..7 {
            labels.paint(
                &Rect {
                    x0: tx * TILE + 10,
                    y0: fy * FLOOR + 12,
                    x1: tx * TILE + 34,
                    y1: fy * FLOOR + 45,
                },
                Class::Window,
            );
        }
    }
    let v = view();
    let photo = warp_labels(&labels, &v, 560, 460).unwrap();
    // outside the facade the warped map is ignore
    assert_eq!(photo.at(559, 0), Class::Ignore);
    let back = warp_labels(&photo, &rectifier(&v, w, h), w, h).unwrap();
    let same = back
        .classes
        .iter()
        .zip(&labels.classes)
        .filter(|(a, b)| a == b)
        .count();
    let share = same as f64 / labels.classes.len() as f64;
    assert!(share > 0.97, "{share}");
    // nearest sampling: no class other than the two painted (and ignore at the rim)
    assert!(back
        .classes
        .iter()
        .all(|c| matches!(c, Class::Wall | Class::Window | Class::Ignore)));
}
