//! Element recognition and insertion against ground truth: synthetic facades whose windows
//! are drawn from a library element's front view (light bars on dark glass) must be recognised
//! as that element, the grammar must insert it (and read back), and the facades generated at
//! other widths must stay closed meshes with one element per window. The synthetic facades'
//! frames (2 px at scale 1) are found by tile refinement and built as casing.

mod common;

use common::{facade, facade_with_bars, WIN_X, WIN_Y};
use emilion::facade::element_library::{insert_elements, Library};
use emilion::facade::element_match::recognise_elements;
use emilion::facade::facade_mesh::{build, check_closed, MeshParams, Surface};
use emilion::facade::grammar::Grammar;
use emilion::facade::parse::{parse, Priors};
use emilion::facade::refinement::Refinement;
use emilion::facade::window_grammar::grammar_of_windows;
use emilion::facade::{Class, Rect};
use emilion::geometry::image::Gray;

#[test]
fn windows_drawn_from_each_element_are_recognised_and_inserted() {
    let lib = Library::builtin().expect("library");
    // twice the common facade's lengths: the panes of a cross window are then large enough
    // to be found (17 × 19 pixels above the transom)
    let (w, h) = (860, 684);
    let (ww, wh) = (2 * (WIN_X.1 - WIN_X.0), 2 * (WIN_Y.1 - WIN_Y.0));
    for name in [
        "window_plain",
        "window_mullion",
        "window_cross",
        "window_sash",
    ] {
        let mask = lib
            .get(name)
            .expect("element")
            .front_mask(ww as usize, wh as usize);
        let img = facade_with_bars(w, h, 5, 2, &|x, y| mask[(y * ww + x) as usize] > 0.5);
        let (mut g, s) = parse(&img, &Priors::default()).expect("parses");
        eprintln!(
            "{name}: {} windows found one by one, grammar of them: {}",
            s.windows.len(),
            s.from_windows
        );
        // the common facade draws a light frame 2 px wide (here 4) round each window; the
        // element's own frame (a light ring 0.07 of the window wide) joins it
        eprintln!("{name}: {:?}", s.refinement);
        assert!(
            (4..=8).contains(&s.refinement.frame),
            "{name}: {:?}",
            s.refinement
        );
        let found = recognise_elements(&mut g, &img, &lib);
        let window = found
            .iter()
            .find(|m| m.class == Class::Window)
            .expect("windows recognised");
        eprintln!(
            "{name}: {:?} over {} windows",
            window.scores, window.instances
        );
        assert_eq!(window.element, name, "{:?}", window.scores);
        let text = g.to_text();
        assert!(text.contains(&format!("insert(window, {name})")), "{text}");
        assert_eq!(Grammar::parse(&text).expect("reads back"), g);
        // every window of a wider facade gets its element, and the mesh stays closed
        let leaves = g.derive(w as f64 * 1.5, h as f64).expect("derives");
        let params = MeshParams::new(0.05, (w as f64, h as f64));
        let mut mesh = build(&leaves, &params).expect("builds");
        let n = insert_elements(&mut mesh, &leaves, &g.elements(), &lib, &params).expect("inserts");
        let windows = leaves.iter().filter(|l| l.class == Class::Window).count();
        // each window, the four strips of its frame and its sill if one was found
        let frames: Vec<_> = leaves
            .iter()
            .filter(|l| l.class == Class::Wall && l.element.is_some())
            .collect();
        let sill = usize::from(s.refinement.sill > 0);
        assert_eq!(frames.len(), (4 + sill) * windows);
        assert_eq!(n, windows + frames.len());
        assert!(windows > 40, "{windows} windows at 1.5×");
        check_closed(&mesh).expect("closed with its elements");
        let group = mesh.groups.last().expect("groups");
        assert_eq!(group.surface, Surface::Element);
        let per = lib.get(name).expect("element").triangles.len();
        let strip = lib.get("wall_frame").expect("casing").triangles.len();
        assert_eq!(strip, lib.get("wall_sill").expect("sill").triangles.len());
        assert_eq!(group.triangles.len(), windows * per + frames.len() * strip);
        // each element lies in its window's recess: inside the opening, from the recess's
        // back 6 cm towards the street; or on a strip of frame or a sill, standing out of the
        // wall (3 and 6 cm)
        let (xmin, ymax) = (0.0, h as f64);
        let scopes = |class: Class| -> Vec<(f64, f64, f64, f64)> {
            leaves
                .iter()
                .filter(|l| l.class == class && l.element.is_some())
                .map(|l| {
                    let s = params.scale;
                    (
                        (l.scope.x0 - xmin) * s,
                        (l.scope.x1 - xmin) * s,
                        (ymax - l.scope.y1) * s,
                        (ymax - l.scope.y0) * s,
                    )
                })
                .collect()
        };
        let (openings, strips) = (scopes(Class::Window), scopes(Class::Wall));
        let within = |rects: &[(f64, f64, f64, f64)], p: &emilion::geometry::Vec3| {
            rects.iter().any(|&(x0, x1, y0, y1)| {
                (x0 - 1e-9..=x1 + 1e-9).contains(&p.x) && (y0 - 1e-9..=y1 + 1e-9).contains(&p.y)
            })
        };
        let back = -params.window_depth;
        for t in &mesh.triangles[group.triangles.clone()] {
            for &i in t {
                let p = mesh.positions[i];
                let in_recess = p.z >= back - 1e-12 && p.z <= back + 0.06 + 1e-12;
                let on_wall = p.z >= -1e-12 && p.z <= 0.06 + 1e-12;
                assert!(
                    (in_recess && within(&openings, &p)) || (on_wall && within(&strips, &p)),
                    "{name}: vertex {p:?} neither in a window's recess nor on its frame"
                );
            }
        }
    }
}

#[test]
fn the_plain_facade_gets_plain_windows_and_an_unknown_element_is_an_error() {
    let lib = Library::builtin().expect("library");
    let (w, h) = (430, 342);
    let img = facade(w, h, 9);
    let (mut g, s) = parse(&img, &Priors::default()).expect("parses");
    // tile refinement: the frame the common facade draws (2 px), no sill, and the layout's
    // windows already on their edges
    assert_eq!(
        s.refinement,
        Refinement {
            sides: [0; 4],
            frame: 2,
            sill: 0
        }
    );
    let found = recognise_elements(&mut g, &img, &lib);
    assert_eq!(found.len(), 1, "windows only, no doors: {found:?}");
    assert_eq!(found[0].element, "window_plain", "{:?}", found[0].scores);
    // a rule file may name an element the library lacks: building says which
    let text = g.to_text().replace("window_plain", "window_gothic");
    let odd = Grammar::parse(&text).expect("syntax is fine");
    let leaves = odd.derive(w as f64, h as f64).expect("derives");
    let params = MeshParams::new(0.05, (w as f64, h as f64));
    let mut mesh = build(&leaves, &params).expect("builds");
    let e = insert_elements(&mut mesh, &leaves, &odd.elements(), &lib, &params).unwrap_err();
    assert!(e.contains("window_gothic"), "{e}");
}

#[test]
fn a_hand_written_rule_file_builds_closed_facades_with_its_elements() {
    let lib = Library::builtin().expect("library");
    let text = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scripts/townhouse.cga"),
    )
    .expect("the example rule file");
    let g = Grammar::parse(&text).expect("parses");
    assert_eq!(g.size, (800.0, 1000.0));
    let params = MeshParams::new(0.01, g.size);
    let names = g.elements();
    let count = |leaves: &[emilion::facade::grammar::Leaf], element: &str| {
        let k = names.iter().position(|n| n == element);
        leaves.iter().filter(|l| l.element == k).count()
    };
    // 1000 − 60 − 340 = 600: two floors of 300; 800 − 100 = 700: four bays of 175, and at 2×
    // (1600 − 100) / 175 = 8.6: nine bays; the ground floor keeps one door and two windows
    for (factor, bays) in [(1.0, 4), (2.0, 9)] {
        let leaves = g.derive(800.0 * factor, 1000.0).expect("derives");
        assert_eq!(count(&leaves, "window_cross"), 2 * bays);
        assert_eq!(count(&leaves, "window_sash"), 2);
        assert_eq!(count(&leaves, "door_panel"), 1);
        let mut mesh = build(&leaves, &params).expect("builds");
        let n = insert_elements(&mut mesh, &leaves, &names, &lib, &params).expect("inserts");
        assert_eq!(n, 2 * bays + 3);
        check_closed(&mesh).expect("closed");
        // the door stands on the ground: its element reaches the facade's bottom edge
        let tris = |name: &str| lib.get(name).expect("element").triangles.len();
        let group = mesh.groups.last().expect("elements");
        assert_eq!(
            group.triangles.len(),
            2 * bays * tris("window_cross") + 2 * tris("window_sash") + tris("door_panel")
        );
        let lowest = mesh.triangles[group.triangles.clone()]
            .iter()
            .flatten()
            .map(|&i| mesh.positions[i].y)
            .fold(f64::INFINITY, f64::min);
        assert!(lowest.abs() < 1e-12, "door element starts at {lowest} m");
    }
}

/// A wall with an upper row of five tall windows of `upper`'s type, a lower row of five wide
/// windows of `lower`'s, and two odd plain windows (too few to be a size of their own); light
/// bars on dark glass, with noise. Returns the picture and every window with its type.
fn two_rows(lib: &Library, upper: &str, lower: &str) -> (Gray, Vec<(Rect, String)>) {
    let (w, h) = (420u32, 200u32);
    let kinds: Vec<(Rect, String)> = (0..5)
        .map(|k| {
            (
                Rect::new(20 + 80 * k, 20, 56 + 80 * k, 72),
                upper.to_string(),
            )
        })
        .chain((0..5).map(|k| {
            (
                Rect::new(14 + 80 * k, 110, 62 + 80 * k, 146),
                lower.to_string(),
            )
        }))
        .chain([
            (Rect::new(30, 165, 44, 185), "window_plain".to_string()),
            (Rect::new(350, 160, 380, 190), "window_plain".to_string()),
        ])
        .collect();
    let masks: Vec<Vec<f64>> = kinds
        .iter()
        .map(|(r, name)| {
            let m = lib.get(name).expect("element");
            m.front_mask((r.x1 - r.x0) as usize, (r.y1 - r.y0) as usize)
        })
        .collect();
    let img = Gray::painted(w, h, 3, 40.0, |x, y| {
        let inside = kinds
            .iter()
            .position(|(r, _)| (r.x0..r.x1).contains(&x) && (r.y0..r.y1).contains(&y));
        match inside {
            Some(k) => {
                let r = kinds[k].0;
                if masks[k][((y - r.y0) * (r.x1 - r.x0) + x - r.x0) as usize] > 0.5 {
                    215.0
                } else {
                    55.0
                }
            }
            None => 160.0,
        }
    });
    (img, kinds)
}

/// The element each window of `kinds` gets from `g`.
fn elements_of(g: &Grammar, img: &Gray, kinds: &[(Rect, String)]) -> Vec<String> {
    let leaves = g
        .derive(img.width as f64, img.height as f64)
        .expect("derives");
    let names = g.elements();
    kinds
        .iter()
        .map(|(r, _)| {
            let l = leaves
                .iter()
                .find(|l| {
                    l.class == Class::Window
                        && l.scope.x0 == r.x0 as f64
                        && l.scope.y0 == r.y0 as f64
                })
                .expect("the window is in the parse");
            names[l.element.expect("an element")].clone()
        })
        .collect()
}

#[test]
fn windows_of_two_sizes_and_two_types_each_get_their_element() {
    let lib = Library::builtin().expect("library");
    let (img, kinds) = two_rows(&lib, "window_cross", "window_sash");
    let rects: Vec<Rect> = kinds.iter().map(|k| k.0).collect();
    let mut g = grammar_of_windows(&rects, img.width, img.height, &|_| Refinement::default());
    // two sizes of five: `Window` (the upper row's, first) and `Window2`; the odd two join
    // `Window`
    assert!(g.rules.contains_key("Window2") && !g.rules.contains_key("Window3"));
    let found = recognise_elements(&mut g, &img, &lib);
    let text = g.to_text();
    eprintln!("{found:?}\n{text}");
    let got = elements_of(&g, &img, &kinds);
    assert_eq!(
        &got[..10],
        &kinds[..10].iter().map(|k| k.1.clone()).collect::<Vec<_>>()[..]
    );
    assert!(
        text.contains("Window --> insert(window, window_cross)"),
        "{text}"
    );
    assert!(
        text.contains("Window2 --> insert(window, window_sash)"),
        "{text}"
    );
    assert_eq!(
        found.len(),
        2,
        "all the windows, then the lower row's own: {found:?}"
    );
    assert_eq!(found[1].rule.as_deref(), Some("Window2"));
    assert_eq!(Grammar::parse(&text).expect("reads back"), g);
    // one type in both sizes: the rules merge back into one, every window a cross window
    let (img, kinds) = two_rows(&lib, "window_cross", "window_cross");
    let rects: Vec<Rect> = kinds.iter().map(|k| k.0).collect();
    let mut g = grammar_of_windows(&rects, img.width, img.height, &|_| Refinement::default());
    assert!(g.rules.contains_key("Window2"));
    let found = recognise_elements(&mut g, &img, &lib);
    assert_eq!(found.len(), 1, "{found:?}");
    assert!(!g.rules.contains_key("Window2"), "{}", g.to_text());
    let got = elements_of(&g, &img, &kinds);
    assert!(got.iter().all(|e| e == "window_cross"), "{got:?}");
}
