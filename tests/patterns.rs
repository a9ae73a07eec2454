//! Pattern files: JSON and SVG import, validation, expansion, and the FreeSewing garments
//! of `scripts/patterns/` (see `scripts/patterns/PROVENANCE.md`).

use std::path::{Path, PathBuf};

use emilion::garment::formats::svg::parse_pattern_svg;
use emilion::garment::{
    read_garment, read_pattern_json, read_pattern_svg, write_pattern_json, Copies, EdgeRef,
    Pattern, Piece, SvgOptions,
};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).to_path_buf()
}

fn patterns_dir() -> PathBuf {
    root().join("scripts/patterns")
}

fn describe(p: &Pattern) -> String {
    let mut s = String::new();
    for piece in &p.pieces {
        s += &format!(
            "piece {} fold {:?} sa {:.4} grain {:?} area {:.4} m², {} notches\n",
            piece.name,
            piece.fold,
            piece.seam_allowance,
            piece.grain,
            piece.outline.area(),
            piece.notches.len()
        );
        let n = piece.outline.corners.len();
        for (i, c) in piece.outline.corners.iter().enumerate() {
            s += &format!(
                "  {:5} ({:8.1}, {:8.1}) mm  {:5} → {:5} {:7.1} mm\n",
                c.name,
                c.at[0] * 1e3,
                c.at[1] * 1e3,
                if matches!(c.segment, emilion::garment::Segment::Line) {
                    "line"
                } else {
                    "cubic"
                },
                piece.outline.corners[(i + 1) % n].name,
                piece.outline.segment_length(i) * 1e3
            );
        }
    }
    s
}

/// Lists the corners of the FreeSewing SVGs (to write the garment tables):
/// `cargo test --release --test patterns -- --ignored --nocapture list_corners`.
#[test]
#[ignore]
fn list_corners() {
    for name in ["aaron", "penelope", "paco"] {
        let p = read_pattern_svg(
            patterns_dir().join(format!("{name}.svg")),
            &SvgOptions::default(),
        )
        .unwrap();
        println!("== {name}\n{}", describe(&p));
        println!("-- expanded\n{}", describe(&p.expanded().unwrap()));
    }
}

fn bad(name: &str) -> PathBuf {
    root().join("tests/data/patterns_bad").join(name)
}

fn garment(name: &str) -> Pattern {
    read_garment(patterns_dir().join(format!("{name}.garment.json")))
        .unwrap_or_else(|e| panic!("{name}: {e}"))
}

fn piece<'a>(p: &'a Pattern, name: &str) -> &'a Piece {
    p.pieces
        .iter()
        .find(|x| x.name == name)
        .unwrap_or_else(|| panic!("no piece {name}"))
}

/// Arc length of a seam edge (m).
fn edge_length(p: &Pattern, e: &EdgeRef) -> f64 {
    let o = &piece(p, &e.piece).outline;
    o.edge_length(
        o.corner_index(&e.from).unwrap(),
        o.corner_index(&e.to).unwrap(),
    )
}

fn message(e: impl std::fmt::Display) -> String {
    e.to_string()
}

#[test]
fn freesewing_garments_load_validate_and_expand() {
    for (name, pieces, seams) in [
        ("aaron", vec!["front", "back"], 4),
        ("penelope", vec!["front", "back_l", "back_r"], 11),
        ("paco", vec!["front_l", "front_r", "back_l", "back_r"], 6),
    ] {
        let g = garment(name);
        let names: Vec<&str> = g.pieces.iter().map(|p| p.name.as_str()).collect();
        assert_eq!(names, pieces, "{name}");
        assert_eq!(g.seams.len(), seams, "{name}");
        g.validate().unwrap();
        for p in &g.pieces {
            assert!(
                p.fold.is_none() && p.copies == Copies::One,
                "{name}/{}: not expanded",
                p.name
            );
            assert!(p.outline.area() > 0.0, "{name}/{}: clockwise", p.name);
            assert!(
                (p.seam_allowance - 0.01).abs() < 1e-9,
                "{name}/{}: sa {}",
                p.name,
                p.seam_allowance
            );
            let pl = p
                .placement
                .as_ref()
                .unwrap_or_else(|| panic!("{name}/{}: no placement", p.name));
            assert!(p.outline.corner_index(&pl.anchor).is_some());
            // FreeSewing draws pieces upright: the grain points up the page.
            assert!(p.grain[1][1] > p.grain[0][1] && (p.grain[1][0] - p.grain[0][0]).abs() < 1e-9);
        }
        // The pattern of an expanded garment expands to itself.
        assert_eq!(g.expanded().unwrap(), g);
    }
}

#[test]
fn seam_edges_of_the_garments_have_matching_lengths() {
    for name in ["aaron", "penelope", "paco"] {
        let g = garment(name);
        for s in &g.seams {
            let (a, b) = (edge_length(&g, &s.a), edge_length(&g, &s.b));
            assert!(a > 0.02, "{name}/{}: {a} m", s.name);
            // FreeSewing drafts seams to match; 1 mm covers rounding of its 0.01 mm output.
            assert!(
                (a - b).abs() < 1e-3,
                "{name}/{}: {:.2} mm vs {:.2} mm",
                s.name,
                a * 1e3,
                b * 1e3
            );
        }
    }
}

#[test]
fn seams_join_the_corners_they_should() {
    // Default seams meet a.from with b.to: check that the corners that meet are at the same
    // height on the drawn pattern (hems with hems, armpits with armpits, waists with waists).
    let g = garment("paco");
    for s in &g.seams {
        let y = |e: &EdgeRef, c: &str| {
            let p = piece(&g, &e.piece);
            p.outline.corners[p.outline.corner_index(c).unwrap()].at[1]
        };
        let fronts_or_legs = s.name.starts_with("outseam") || s.name.starts_with("inseam");
        if fronts_or_legs {
            // Both pieces are drawn hem down, with their hems at different sheet heights:
            // compare heights relative to each piece's hem.
            let hem = |e: &EdgeRef| {
                piece(&g, &e.piece)
                    .outline
                    .corners
                    .iter()
                    .map(|c| c.at[1])
                    .fold(f64::MAX, f64::min)
            };
            let da = y(&s.a, &s.a.from) - hem(&s.a);
            let db = y(&s.b, &s.b.to) - hem(&s.b);
            assert_eq!(
                da < 1e-6,
                db < 1e-6,
                "{}: a.from and b.to should both be at the hem or both not",
                s.name
            );
            let (ea, eb) = (y(&s.a, &s.a.to) - hem(&s.a), y(&s.b, &s.b.from) - hem(&s.b));
            assert_eq!(
                ea < 1e-6,
                eb < 1e-6,
                "{}: a.to and b.from should both be at the hem or both not",
                s.name
            );
        }
    }
    let g = garment("aaron");
    let front = piece(&g, "front");
    let back = piece(&g, "back");
    for s in &g.seams {
        let at = |e: &EdgeRef, c: &str| {
            let p = if e.piece == "front" { front } else { back };
            p.outline.corners[p.outline.corner_index(c).unwrap()].at
        };
        // Front and back are drawn side by side with their hems at the same height.
        let (a0, b1) = (at(&s.a, &s.a.from), at(&s.b, &s.b.to));
        let (a1, b0) = (at(&s.a, &s.a.to), at(&s.b, &s.b.from));
        assert!(
            (a0[1] - b1[1]).abs() < 1e-6 && (a1[1] - b0[1]).abs() < 1e-6,
            "{}",
            s.name
        );
    }
}

#[test]
fn aaron_hem_matches_the_model_hips_with_the_design_ease() {
    // cisFemaleAdult34 (PROVENANCE.md): hips 900 mm. Aaron's defaults: hipsEase 8 %,
    // stretchFactor 5 %, so the hem runs round hips × 1.08 × 0.95 = 923.4 mm.
    let expected = 0.900 * 1.08 * 0.95;
    let g = garment("aaron");
    let hem = |p: &Piece| {
        let o = &p.outline;
        o.edge_length(
            o.corner_index("c2'").unwrap(),
            o.corner_index("c2").unwrap(),
        )
    };
    let round = hem(piece(&g, "front")) + hem(piece(&g, "back"));
    assert!(
        (round - expected).abs() < 0.005 * expected,
        "hem {round} m, expected {expected} m"
    );
    // The front is roughly a rectangle of that half-width and the HPS-to-hip length
    // (hpsToWaistFront 400 mm + waistToHips 125 mm), less the neck and armholes.
    let front = piece(&g, "front");
    let ratio = front.outline.area() / (expected / 2.0 * (0.400 + 0.125));
    assert!(
        (0.6..1.0).contains(&ratio),
        "front area {} m², ratio {ratio}",
        front.outline.area()
    );
}

#[test]
fn json_round_trip_keeps_the_pattern() {
    let g = garment("penelope");
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR"));
    let file = dir.join("penelope_pattern.json");
    write_pattern_json(&g, &file).unwrap();
    let back = read_pattern_json(&file).unwrap();
    assert_eq!(back.source, file.display().to_string());
    // serde_json reads floats back to within an ulp or so, not bit for bit.
    assert_close(
        &serde_json::to_value(Pattern {
            source: g.source.clone(),
            ..back
        })
        .unwrap(),
        &serde_json::to_value(&g).unwrap(),
    );
}

fn assert_close(a: &serde_json::Value, b: &serde_json::Value) {
    use serde_json::Value;
    match (a, b) {
        (Value::Number(x), Value::Number(y)) => {
            let (x, y) = (x.as_f64().unwrap(), y.as_f64().unwrap());
            assert!((x - y).abs() <= 1e-12 * x.abs().max(1.0), "{x} vs {y}");
        }
        (Value::Array(x), Value::Array(y)) => {
            assert_eq!(x.len(), y.len());
            x.iter().zip(y).for_each(|(x, y)| assert_close(x, y));
        }
        (Value::Object(x), Value::Object(y)) => {
            assert_eq!(x.keys().collect::<Vec<_>>(), y.keys().collect::<Vec<_>>());
            x.values()
                .zip(y.values())
                .for_each(|(x, y)| assert_close(x, y));
        }
        _ => assert_eq!(a, b),
    }
}

#[test]
fn clockwise_json_outlines_are_turned_round_on_reading() {
    let text = r#"{"name": "cw", "pieces": [{"name": "p", "grain": [[0.1, 0.1], [0.1, 0.2]],
        "outline": {"corners": [{"name": "a", "at": [0, 0]}, {"name": "b", "at": [0, 1]},
                                {"name": "c", "at": [1, 1]}, {"name": "d", "at": [1, 0]}]}}]}"#;
    let file = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("clockwise.json");
    std::fs::write(&file, text).unwrap();
    let p = read_pattern_json(&file).unwrap();
    let o = &p.pieces[0].outline;
    assert!((o.area() - 1.0).abs() < 1e-12);
    let names: Vec<&str> = o.corners.iter().map(|c| c.name.as_str()).collect();
    assert_eq!(names, ["a", "d", "c", "b"]);
}

#[test]
fn an_open_sewing_line_names_file_piece_and_gap() {
    let file = bad("open_outline.svg");
    let e = message(read_pattern_svg(&file, &SvgOptions::default()).unwrap_err());
    assert!(e.contains("open_outline.svg"), "{e}");
    assert!(
        e.contains("piece 'front'") && e.contains("does not close"),
        "{e}"
    );
    assert!(e.contains("12.00 mm"), "{e}");
}

#[test]
fn malformed_svg_gives_line_and_column() {
    let e = message(read_pattern_svg(bad("malformed.svg"), &SvgOptions::default()).unwrap_err());
    assert!(
        e.contains("malformed.svg:5:3:") && e.contains("</h>"),
        "{e}"
    );
}

#[test]
fn a_self_intersecting_outline_names_piece_and_both_edges() {
    let e = message(read_pattern_json(bad("self_intersecting.json")).unwrap_err());
    assert!(
        e.contains("self_intersecting.json") && e.contains("piece 'front'"),
        "{e}"
    );
    // The dart point (0.1, −0.1) lies below the hem: both of its edges cross the hem, and
    // those are the outline's only two crossings. The test reports the first its sweep meets.
    assert!(
        e.contains("edge hem_cf→hem_side crosses edge waist_side→dart")
            || e.contains("edge hem_cf→hem_side crosses edge dart→waist_cf"),
        "{e}"
    );
}

#[test]
fn mismatched_seam_lengths_name_seam_pieces_edges_and_lengths() {
    let e = message(read_pattern_json(bad("seam_lengths.json")).unwrap_err());
    assert!(
        e.contains("seam_lengths.json") && e.contains("seam 'side'"),
        "{e}"
    );
    assert!(e.contains("front.hem_side→waist_side (600.0 mm)"), "{e}");
    assert!(e.contains("back.waist_cb→hem_cb (550.0 mm)"), "{e}");
}

#[test]
fn unknown_pieces_and_corners_in_seams_are_named() {
    let e = message(read_pattern_json(bad("unknown_piece.json")).unwrap_err());
    assert!(
        e.contains("unknown_piece.json") && e.contains("seam 'side'"),
        "{e}"
    );
    assert!(
        e.contains("piece 'back_l' does not exist") && e.contains("back_l.waist_cb→hem_cb"),
        "{e}"
    );
    let e = message(read_pattern_json(bad("unknown_corner.json")).unwrap_err());
    assert!(
        e.contains("unknown_corner.json") && e.contains("seam 'side'"),
        "{e}"
    );
    assert!(e.contains("piece 'back' has no corner 'hem_sid'"), "{e}");
}

#[test]
fn malformed_json_gives_line_and_column() {
    let e = message(read_pattern_json(bad("malformed.json")).unwrap_err());
    assert!(
        e.contains("malformed.json:8:35:") && e.contains("expected `,` or `]`"),
        "{e}"
    );
}

#[test]
fn a_garment_table_naming_a_missing_part_is_an_error() {
    let e = message(read_garment(bad("unknown_part.garment.json")).unwrap_err());
    assert!(
        e.contains("unknown_part.garment.json") && e.contains("piece 'sleeve'"),
        "{e}"
    );
    assert!(e.contains("front, back, armBinding, neckBinding"), "{e}");
}

#[test]
fn truncated_or_corrupted_files_give_errors_not_panics() {
    let svg = std::fs::read_to_string(patterns_dir().join("penelope.svg")).unwrap();
    let path = Path::new("penelope_cut.svg");
    let step = (svg.len() / 97).max(1);
    for cut in (0..svg.len()).step_by(step) {
        if svg.is_char_boundary(cut) {
            let _ =
                parse_pattern_svg(&svg[..cut], path, &SvgOptions::default()).map(|p| p.validate());
        }
    }
    // Corrupt numbers in path data and transforms.
    for (from, to) in [
        ("L ", "L x"),
        ("C ", "C 1e999 "),
        ("translate(", "translate(q"),
        ("M ", "M ,"),
    ] {
        let broken = svg.replacen(from, to, 3);
        let _ = parse_pattern_svg(&broken, path, &SvgOptions::default()).map(|p| p.validate());
    }
    let json = std::fs::read_to_string(patterns_dir().join("paco.garment.json")).unwrap();
    let file = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("paco_cut.json");
    for cut in (0..json.len()).step_by(7) {
        std::fs::write(&file, &json[..cut]).unwrap();
        assert!(read_garment(&file).is_err());
    }
}

#[test]
fn generic_svg_pieces_with_transforms_arcs_notches_and_allowance() {
    // 1 user unit = 1 mm (width in cm over a viewBox of 10× the number). A 200 × 100 mm panel
    // whose top edge is a half-disc (arc), drawn clockwise with relative commands inside a
    // translated group; a 15 mm seam allowance path; a notch; a grain line drawn downwards.
    let svg = r##"<svg xmlns="http://www.w3.org/2000/svg" xmlns:xlink="http://www.w3.org/1999/xlink"
        width="30cm" height="30cm" viewBox="0 0 300 300">
      <defs><g id="notch"><circle r="2"/></g></defs>
      <g id="layer1">
        <g id="panel" transform="translate(50 150)">
          <path class="cutting" d="m 0,0 a 100,100 0 0 1 200,0 v 100 h -200 z"/>
          <path class="sa" d="M -15,0 L -15,115 L 215,115 L 215,0"/>
          <path class="grainline" d="M 100,80 L 100,20"/>
          <use xlink:href="#notch" x="200" y="50"/>
          <text>ignored</text>
        </g>
      </g>
    </svg>"##;
    let p = parse_pattern_svg(svg, Path::new("panel.svg"), &SvgOptions::default()).unwrap();
    p.validate().unwrap();
    assert_eq!(p.pieces.len(), 1);
    let panel = &p.pieces[0];
    assert_eq!(panel.name, "panel");
    let area = 0.2 * 0.1 + std::f64::consts::PI * 0.1 * 0.1 / 2.0;
    // Cubic quarter arcs bulge out by 0.027 % of the radius.
    assert!(
        (panel.outline.area() - area).abs() < 1e-5,
        "{}",
        panel.outline.area()
    );
    // Corners: the arc start (the path's start), the arc's 90° split point, its end, and the
    // two bottom corners; c0 is the start point.
    let o = &panel.outline;
    assert_eq!(o.corners.len(), 5, "{:?}", o.corners);
    assert_eq!(o.corners[0].name, "c0");
    assert!((o.corners[0].at[0] - 0.05).abs() < 1e-12 && (o.corners[0].at[1] + 0.15).abs() < 1e-12);
    let perimeter = o.edge_length(0, 0);
    let expected = std::f64::consts::PI * 0.1 + 0.2 + 2.0 * 0.1;
    assert!(
        (perimeter - expected).abs() < 1e-4,
        "{perimeter} vs {expected}"
    );
    assert!(
        (panel.seam_allowance - 0.015).abs() < 1e-9,
        "{}",
        panel.seam_allowance
    );
    assert_eq!(panel.notches.len(), 1);
    assert!(
        (panel.notches[0][0] - 0.25).abs() < 1e-12 && (panel.notches[0][1] + 0.2).abs() < 1e-12
    );
    assert!(
        panel.grain[1][1] > panel.grain[0][1],
        "grain points up: {:?}",
        panel.grain
    );
    assert!(panel.fold.is_none());
    // The same drawing read at 1 unit = 1 cm is ten times larger.
    let options = SvgOptions {
        metres_per_unit: Some(0.01),
        ..SvgOptions::default()
    };
    let big = parse_pattern_svg(svg, Path::new("panel.svg"), &options).unwrap();
    assert!((big.pieces[0].outline.area() - 100.0 * area).abs() < 1e-3);
}
