//! Facade structure against ground truth: a synthetic facade with known floor height and tile
//! width (windows on a textured wall, a lighting gradient from floor to floor, a tree in
//! front), whose repetition the mutual-information search must recover.

mod common;

use common::{facade, FLOOR, TILE, WIN_X, WIN_Y};
use emilion::facade::repetition::{detect, Axis};

#[test]
fn floors_and_tiles_of_a_synthetic_facade_are_found() {
    let img = facade(301, 259, 3);
    let floors = detect(&img, Axis::Rows, 20, 130).expect("floors");
    let tiles = detect(&img, Axis::Columns, 15, 100).expect("tiles");
    eprintln!("floors {floors:?}\ntiles {tiles:?}");
    assert_eq!(floors.period, FLOOR);
    assert_eq!(tiles.period, TILE);
    assert!(floors.strength > 0.3 && tiles.strength > 0.3);
    // splits run through wall (and frames), never through a window
    for &y in &floors.splits {
        assert!(
            !(WIN_Y.0..WIN_Y.1).contains(&(y % FLOOR)),
            "floor split {y}"
        );
    }
    for &x in &tiles.splits {
        assert!(!(WIN_X.0..WIN_X.1).contains(&(x % TILE)), "tile split {x}");
    }
    assert!(floors.splits.len() >= 4 && tiles.splits.len() >= 6);
}

#[test]
fn noise_has_no_strong_repetition() {
    let img = common::noise(200, 160, 99);
    let r = detect(&img, Axis::Rows, 10, 70).expect("some period");
    assert!(r.strength < 0.2, "{r:?}");
}
