//! The facade parse against ground truth: a synthetic facade with known floors, tiles and
//! windows (a tree in front of the lower left, lighting varying from floor to floor) is parsed
//! into a grammar whose windows must overlap the true ones; the grammar's rule file must
//! regenerate its own parse (round trip ≥ 99 % of pixels) and stay valid at other sizes.

mod common;

use common::{facade, window_truth, FLOOR, TILE};
use emilion::facade::grammar::Grammar;
use emilion::facade::parse::{parse, Priors};
use emilion::facade::rasterize::rasterize;
use emilion::facade::{Class, PixelScore};

#[test]
fn synthetic_facade_parses_into_its_windows() {
    let (w, h) = (430, 342);
    let img = facade(w, h, 5);
    let (g, s) = parse(&img, &Priors::default()).expect("parses");
    eprintln!(
        "floor {} tile {} window {:?} stages {:?}\n{}",
        s.floor,
        s.tile,
        s.window,
        s.seconds,
        g.to_text()
    );
    assert_eq!((s.floor, s.tile), (FLOOR, TILE));
    let leaves = g.derive(w as f64, h as f64).expect("derives");
    let p = rasterize(&leaves, w, h);
    let score = PixelScore::of(&p.labels, &window_truth(w, h)).expect("same size");
    let iou = score.iou(Class::Window);
    eprintln!("window IoU {iou:.3}, {} windows", p.windows.len());
    // the repeated part spans whole tiles only: windows cut by the image border are missed
    assert!(iou > 0.9, "window IoU {iou}");
}

#[test]
fn grammar_round_trip_reproduces_the_parse_and_resizes() {
    let (w, h) = (430, 342);
    let img = facade(w, h, 5);
    let (g, _) = parse(&img, &Priors::default()).expect("parses");
    let own = rasterize(&g.derive(w as f64, h as f64).expect("derives"), w, h);
    let text = g.to_text();
    let back = Grammar::parse(&text).expect("reads its rule file");
    let again = rasterize(&back.derive(w as f64, h as f64).expect("derives"), w, h);
    let agree = own
        .labels
        .classes
        .iter()
        .zip(&again.labels.classes)
        .filter(|(a, b)| a == b)
        .count() as f64
        / own.labels.classes.len() as f64;
    eprintln!("round trip agreement {agree}");
    assert!(agree >= 0.99);
    for (sx, sy) in [(0.75, 1.0), (1.5, 1.0), (1.0, 0.75), (1.0, 1.5)] {
        let (nw, nh) = (w as f64 * sx, h as f64 * sy);
        let leaves = back.derive(nw, nh).expect("derives resized");
        // leaves tile the facade: no overlap, no gap, none negative
        let area: f64 = leaves
            .iter()
            .map(|l| {
                assert!(l.scope.width() >= 0.0 && l.scope.height() >= 0.0);
                assert!(l.scope.x0 >= -1e-9 && l.scope.x1 <= nw + 1e-9);
                assert!(l.scope.y0 >= -1e-9 && l.scope.y1 <= nh + 1e-9);
                l.scope.width() * l.scope.height()
            })
            .sum();
        assert!((area - nw * nh).abs() < 1e-6 * nw * nh);
        // window sizes stay absolute; floors and tiles follow the size
        let win: Vec<_> = leaves.iter().filter(|l| l.class == Class::Window).collect();
        let ww = win[0].scope.width();
        assert!(win.iter().all(|l| (l.scope.width() - ww).abs() < 1e-9));
        eprintln!("{sx}×{sy}: {} windows", win.len());
    }
}
