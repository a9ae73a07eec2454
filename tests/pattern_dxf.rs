//! DXF-AAMA pattern files: the hand-written fixtures in `tests/data/patterns_dxf/` read into
//! the expected pieces (figures worked out by hand from the coordinates in the files), units,
//! INSERT transforms, round trips through the writer, errors that name file and piece, and
//! damaged files that never panic the reader.

use std::path::{Path, PathBuf};

use emilion::garment::{
    parse_pattern_dxf, read_pattern_dxf, write_pattern_dxf, Copies, Corner, Outline, Pattern,
    PatternError, Piece, Segment, P2,
};

const INCH: f64 = 0.0254;

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/patterns_dxf")
        .join(name)
}

fn piece<'a>(p: &'a Pattern, name: &str) -> &'a Piece {
    p.pieces.iter().find(|x| x.name == name).unwrap()
}

fn bez(p: [P2; 4], t: f64) -> P2 {
    let s = 1.0 - t;
    let w = [s * s * s, 3.0 * s * s * t, 3.0 * s * t * t, t * t * t];
    [0, 1].map(|k| (0..4).map(|i| w[i] * p[i][k]).sum())
}

/// The outline as a dense polygon (each cubic cut into 200 chords).
fn dense(o: &Outline) -> Vec<P2> {
    let cs = &o.corners;
    let mut pts = Vec::new();
    for (i, c) in cs.iter().enumerate() {
        let end = cs[(i + 1) % cs.len()].at;
        match c.segment {
            Segment::Line => pts.push(c.at),
            Segment::Cubic { c1, c2 } => {
                pts.extend((0..200).map(|k| bez([c.at, c1, c2, end], k as f64 / 200.0)))
            }
        }
    }
    pts
}

fn area(pts: &[P2]) -> f64 {
    let n = pts.len();
    (0..n)
        .map(|i| pts[i][0] * pts[(i + 1) % n][1] - pts[(i + 1) % n][0] * pts[i][1])
        .sum::<f64>()
        / 2.0
}

fn dist(a: P2, b: P2) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

/// Distance from `p` to the closed polygon `poly`.
fn to_polygon(poly: &[P2], p: P2) -> f64 {
    let n = poly.len();
    (0..n)
        .map(|i| {
            let (a, b) = (poly[i], poly[(i + 1) % n]);
            let d = [b[0] - a[0], b[1] - a[1]];
            let l2 = d[0] * d[0] + d[1] * d[1];
            let t = if l2 > 0.0 {
                (((p[0] - a[0]) * d[0] + (p[1] - a[1]) * d[1]) / l2).clamp(0.0, 1.0)
            } else {
                0.0
            };
            dist(p, [a[0] + t * d[0], a[1] + t * d[1]])
        })
        .fold(f64::INFINITY, f64::min)
}

/// Largest distance between two outlines, both ways.
fn outline_gap(a: &Outline, b: &Outline) -> f64 {
    let (pa, pb) = (dense(a), dense(b));
    let ab = pa.iter().map(|&p| to_polygon(&pb, p)).fold(0.0, f64::max);
    let ba = pb.iter().map(|&p| to_polygon(&pa, p)).fold(0.0, f64::max);
    ab.max(ba)
}

fn inches(p: P2) -> P2 {
    [p[0] / INCH, p[1] / INCH]
}

fn close(a: P2, b: P2, tol: f64) -> bool {
    dist(a, b) <= tol
}

#[test]
fn shirt_pieces_as_drawn() {
    let p = read_pattern_dxf(&data("shirt_aama.dxf")).unwrap();
    assert_eq!(p.name, "SHIRT");
    let names: Vec<&str> = p.pieces.iter().map(|x| x.name.as_str()).collect();
    assert_eq!(names, ["FRONT", "BACK"]);

    // FRONT: 8 × 10 in with a parabolic top edge through (4, 12): 80 + ⅔·(8·4/2) in².
    let front = piece(&p, "FRONT");
    let kinds: Vec<bool> = front
        .outline
        .corners
        .iter()
        .map(|c| c.segment == Segment::Line)
        .collect();
    assert_eq!(kinds, [true, true, false, true], "{:?}", front.outline);
    let at: Vec<P2> = front.outline.corners.iter().map(|c| inches(c.at)).collect();
    for (a, b) in at
        .iter()
        .zip([[0.0, 0.0], [8.0, 0.0], [8.0, 10.0], [0.0, 10.0]])
    {
        assert!(close(*a, b, 1e-9), "{at:?}");
    }
    let want = (80.0 + 2.0 / 3.0 * 16.0) * INCH * INCH;
    let got = area(&dense(&front.outline));
    assert!((got - want).abs() < 1e-4 * want, "area {got} vs {want}");
    // The top edge is the parabola y = 10 + x (8 − x) / 8 through the file's vertices; as a
    // cubic it is the quadratic (8,10) → (4,14) → (0,10) raised: controls ⅔ towards (4,14).
    let c = &front.outline.corners[2];
    let Segment::Cubic { c1, c2 } = c.segment else {
        unreachable!()
    };
    let end = front.outline.corners[3].at;
    for k in 0..=100 {
        let [x, y] = inches(bez([c.at, c1, c2, end], k as f64 / 100.0));
        assert!(
            (y - (10.0 + x * (8.0 - x) / 8.0)).abs() < 2e-3,
            "({x}, {y}) off the parabola"
        );
    }
    assert!(
        close(inches(c1), [16.0 / 3.0, 38.0 / 3.0], 0.02),
        "{:?}",
        inches(c1)
    );
    assert!(
        close(inches(c2), [8.0 / 3.0, 38.0 / 3.0], 0.02),
        "{:?}",
        inches(c2)
    );
    assert_eq!(front.copies, Copies::Pair);
    assert_eq!(front.fold, None);
    assert!(
        (front.seam_allowance - 0.375 * INCH).abs() < 1e-6,
        "{}",
        front.seam_allowance
    );
    let g = front.grain;
    assert!(close(inches(g[0]), [4.0, 2.0], 1e-9) && close(inches(g[1]), [4.0, 8.0], 1e-9));
    assert_eq!(front.notches.len(), 2);
    assert!(
        close(inches(front.notches[0]), [8.0, 5.0], 1e-9),
        "{:?}",
        front.notches
    );
    assert!(
        close(inches(front.notches[1]), [4.0, 0.0], 1e-9),
        "{:?}",
        front.notches
    );

    // BACK, inserted 20 in to the right: half back on the fold x = 20 in, 7 × 10 in less the
    // shoulder triangle (1 × 4 / 2): 68 in².
    let back = piece(&p, "BACK");
    let at: Vec<P2> = back.outline.corners.iter().map(|c| inches(c.at)).collect();
    let want_at = [
        [20.0, 0.0],
        [27.0, 0.0],
        [27.0, 9.0],
        [23.0, 10.0],
        [20.0, 10.0],
    ];
    assert_eq!(at.len(), 5, "{at:?}");
    for (a, b) in at.iter().zip(want_at) {
        assert!(close(*a, b, 1e-9), "{at:?}");
    }
    assert!(back
        .outline
        .corners
        .iter()
        .all(|c| c.segment == Segment::Line));
    let got = area(&dense(&back.outline));
    assert!((got - 68.0 * INCH * INCH).abs() < 1e-9, "area {got}");
    assert_eq!(back.fold.as_deref(), Some("c4"));
    assert_eq!(back.copies, Copies::One);
    assert!(
        (back.seam_allowance - 0.5 * INCH).abs() < 1e-6,
        "{}",
        back.seam_allowance
    );
    let g = back.grain;
    assert!(close(inches(g[0]), [23.5, 2.0], 1e-9) && close(inches(g[1]), [23.5, 8.0], 1e-9));
    assert_eq!(back.notches.len(), 1);
    assert!(close(inches(back.notches[0]), [27.0, 4.5], 1e-9));
}

/// A one-piece DXF (no blocks) around `entities`, with the given style text.
fn flat_dxf(header: &str, entities: &str) -> String {
    format!("0\nSECTION\n2\nHEADER\n9\n$ACADVER\n1\nAC1009\n{header}0\nENDSEC\n0\nSECTION\n2\nENTITIES\n{entities}0\nENDSEC\n0\nEOF\n")
}

fn square(layer: &str, w: f64, h: f64) -> String {
    let mut s = format!("0\nPOLYLINE\n8\n{layer}\n66\n1\n70\n1\n");
    for (x, y) in [(0.0, 0.0), (w, 0.0), (w, h), (0.0, h)] {
        s += &format!("0\nVERTEX\n8\n{layer}\n10\n{x}\n20\n{y}\n");
    }
    s + "0\nSEQEND\n"
}

fn text(s: &str) -> String {
    format!("0\nTEXT\n8\n1\n10\n0\n20\n0\n40\n1\n1\n{s}\n")
}

fn parse(s: &str) -> Result<Pattern, PatternError> {
    parse_pattern_dxf(s.as_bytes(), Path::new("inline.dxf"))
}

#[test]
fn units_from_text_then_header() {
    let top_right = |p: &Pattern| p.pieces[0].outline.corners[2].at;
    let inch = parse(&flat_dxf(
        "",
        &(square("1", 10.0, 5.0) + &*text("Units: ENGLISH")),
    ))
    .unwrap();
    assert!(close(top_right(&inch), [0.254, 0.127], 1e-12));
    let mm = parse(&flat_dxf(
        "",
        &(square("1", 10.0, 5.0) + &*text("Units: METRIC")),
    ))
    .unwrap();
    assert!(close(top_right(&mm), [0.010, 0.005], 1e-12));
    let cm = parse(&flat_dxf("9\n$INSUNITS\n70\n5\n", &square("1", 10.0, 5.0))).unwrap();
    assert!(close(top_right(&cm), [0.10, 0.05], 1e-12));
    let none = parse(&flat_dxf("", &square("1", 10.0, 5.0))).unwrap();
    assert!(
        close(top_right(&none), [0.010, 0.005], 1e-12),
        "millimetres by default"
    );
    assert_eq!(
        none.pieces[0].name, "inline",
        "no piece name: the file stem"
    );
    let bad = parse(&flat_dxf(
        "",
        &(square("1", 1.0, 1.0) + &*text("Units: FURLONG")),
    ));
    assert!(bad.unwrap_err().to_string().contains("FURLONG"));
}

#[test]
fn insert_rotation_scale_and_base_point() {
    // Block square 2 × 1 with base point (1, 0), inserted at (10, 5) turned 90°, scaled 2 × 3:
    // p ↦ (10, 5) + R90 · (2 (x − 1), 3 y) = (10 − 3y, 5 + 2x − 2).
    let block = format!(
        "0\nSECTION\n2\nBLOCKS\n0\nBLOCK\n8\n1\n2\nSQ\n70\n0\n10\n1\n20\n0\n30\n0\n{}0\nENDBLK\n0\nENDSEC\n",
        square("1", 2.0, 1.0)
    );
    let ents = "0\nSECTION\n2\nENTITIES\n0\nINSERT\n8\n1\n2\nSQ\n10\n10\n20\n5\n41\n2\n42\n3\n50\n90\n0\nENDSEC\n";
    let s = format!("{block}{ents}0\nEOF\n");
    let p = parse(&s).unwrap();
    let sq = &p.pieces[0];
    assert_eq!(sq.name, "SQ", "no piece name: the block name");
    let at: Vec<P2> = sq
        .outline
        .corners
        .iter()
        .map(|c| [c.at[0] * 1e3, c.at[1] * 1e3])
        .collect();
    // Images of (0,0), (2,0), (2,1), (0,1): (10,3), (10,7), (7,7), (7,3); counter-clockwise
    // from the lowest-leftmost: (7,3), (10,3), (10,7), (7,7).
    let want = [[7.0, 3.0], [10.0, 3.0], [10.0, 7.0], [7.0, 7.0]];
    assert_eq!(at.len(), 4);
    for (a, b) in at.iter().zip(want) {
        assert!(close(*a, b, 1e-9), "{at:?}");
    }
}

#[test]
fn round_trip_preserves_geometry() {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR"));
    let mut original = read_pattern_dxf(&data("shirt_aama.dxf")).unwrap();
    // Add a piece with a real cubic (a rounded patch) and no allowance.
    let r = 0.05;
    let k = 0.5523 * r;
    let corner = |name: &str, at: P2, c1: P2, c2: P2| Corner {
        name: name.into(),
        at,
        segment: Segment::Cubic { c1, c2 },
    };
    original.pieces.push(Piece {
        name: "PATCH".into(),
        outline: Outline {
            corners: vec![
                corner("c0", [0.0, -r], [k, -r], [r, -k]),
                corner("c1", [r, 0.0], [r, k], [k, r]),
                corner("c2", [0.0, r], [-k, r], [-r, k]),
                corner("c3", [-r, 0.0], [-r, -k], [-k, -r]),
            ],
        },
        grain: [[0.0, -0.02], [0.0, 0.02]],
        seam_allowance: 0.0,
        notches: vec![[r, 0.0]],
        fold: None,
        copies: Copies::One,
        placement: None,
    });
    let path = dir.join("round_trip.dxf");
    write_pattern_dxf(&original, &path).unwrap();
    let again = read_pattern_dxf(&path).unwrap();
    assert_eq!(again.name, original.name);
    assert_eq!(again.pieces.len(), original.pieces.len());
    for (a, b) in original.pieces.iter().zip(&again.pieces) {
        assert_eq!(a.name, b.name);
        assert_eq!(
            a.outline.corners.len(),
            b.outline.corners.len(),
            "{}",
            a.name
        );
        let gap = outline_gap(&a.outline, &b.outline);
        assert!(gap < 1e-4, "{}: outlines {gap} m apart", a.name);
        assert!(
            (a.seam_allowance - b.seam_allowance).abs() < 1e-4,
            "{}",
            a.name
        );
        assert_eq!(a.copies, b.copies);
        assert_eq!(a.fold.is_some(), b.fold.is_some());
        if let (Some(fa), Some(fb)) = (&a.fold, &b.fold) {
            let at =
                |p: &Piece, n: &str| p.outline.corners.iter().find(|c| c.name == n).unwrap().at;
            assert!(close(at(a, fa), at(b, fb), 1e-4), "{}: fold", a.name);
        }
        assert!(close(a.grain[0], b.grain[0], 1e-6) && close(a.grain[1], b.grain[1], 1e-6));
        assert_eq!(a.notches.len(), b.notches.len());
        for (p, q) in a.notches.iter().zip(&b.notches) {
            assert!(close(*p, *q, 1e-4), "{}: notch {p:?} vs {q:?}", a.name);
        }
    }
    // Writing is deterministic.
    let (p1, p2) = (dir.join("det_1.dxf"), dir.join("det_2.dxf"));
    write_pattern_dxf(&again, &p1).unwrap();
    write_pattern_dxf(&again, &p2).unwrap();
    assert!(std::fs::read(&p1).unwrap() == std::fs::read(&p2).unwrap());
}

fn error_of(name: &str) -> String {
    let e = read_pattern_dxf(&data(name)).unwrap_err();
    let s = e.to_string();
    assert!(s.contains(name), "{s}");
    s
}

#[test]
fn bad_files_name_file_piece_and_fault() {
    let s = error_of("open_boundary.dxf");
    assert!(s.contains("'YOKE'") && s.contains("does not close"), "{s}");
    assert!(s.contains("6.350 mm"), "gap of 0.25 in: {s}");
    let s = error_of("unknown_entity.dxf");
    assert!(
        s.contains("'POCKET'") && s.contains("HATCH on layer 1"),
        "{s}"
    );
    assert!(s.contains("line 89:"), "{s}");
    let s = error_of("no_boundary.dxf");
    assert!(s.contains("'CUFF'") && s.contains("no boundary"), "{s}");
    let e = read_pattern_dxf(&data("garbage.dxf")).unwrap_err();
    assert!(matches!(e, PatternError::Parse { .. }), "{e}");
    assert!(e.to_string().contains("garbage.dxf"), "{e}");
    let e = read_pattern_dxf(&data("missing.dxf")).unwrap_err();
    assert!(matches!(e, PatternError::Io { .. }), "{e}");
}

#[test]
fn inline_faults() {
    let two = flat_dxf(
        "",
        &(square("1", 2.0, 2.0) + &*square("1", 1.0, 1.0) + &*text("Piece Name: TWO")),
    );
    let s = parse(&two).unwrap_err().to_string();
    assert!(s.contains("'TWO'") && s.contains("2 closed loops"), "{s}");
    let nan = flat_dxf("", &square("1", 2.0, 2.0).replace("10\n2\n", "10\nnan\n"));
    let e = parse(&nan).unwrap_err();
    assert!(e.to_string().contains("not a finite number"), "{e}");
    // In a piece block, the piece is named; a number the crate would drop silently is caught.
    let yoke = std::fs::read_to_string(data("open_boundary.dxf")).unwrap();
    for bad in ["nan", "1x.0", "inf"] {
        let s = parse(&yoke.replacen(" 10\n6\n", &format!(" 10\n{bad}\n"), 1))
            .unwrap_err()
            .to_string();
        assert!(
            s.contains("'YOKE'") && s.contains("not a finite number"),
            "{s}"
        );
        assert!(s.contains("line 60:"), "{s}");
    }
    let spline = flat_dxf(
        "",
        &(square("1", 2.0, 2.0) + "0\nSPLINE\n8\n14\n70\n8\n71\n3\n"),
    );
    let s = parse(&spline).unwrap_err().to_string();
    assert!(s.contains("SPLINE on layer 14 (sew line)"), "{s}");
    let sew_only = flat_dxf("", &square("14", 2.0, 2.0));
    let s = parse(&sew_only).unwrap_err().to_string();
    assert!(s.contains("'inline'") && s.contains("no boundary"), "{s}");
    let s = parse(&flat_dxf("", &text("Units: METRIC")))
        .unwrap_err()
        .to_string();
    assert!(s.contains("no pattern piece"), "{s}");
    let inverted = flat_dxf("", &(square("1", 1.0, 1.0) + &*square("14", 2.0, 2.0)));
    let s = parse(&inverted).unwrap_err().to_string();
    assert!(s.contains("not inside the boundary"), "{s}");
}

#[test]
fn damaged_files_never_panic() {
    let good = std::fs::read(data("shirt_aama.dxf")).unwrap();
    let name = Path::new("damaged.dxf");
    let mut outcomes = [0usize; 2];
    let mut record = |r: Result<Pattern, PatternError>| outcomes[r.is_ok() as usize] += 1;
    // Truncations.
    for cut in (0..good.len()).step_by(97) {
        record(parse_pattern_dxf(&good[..cut], name));
    }
    // Byte flips, a few at a time, from a fixed-seed generator.
    let mut seed: u64 = 0x9E37_79B9_7F4A_7C15;
    let mut next = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        seed
    };
    // DXF_FUZZ_ROUNDS=100000 for a longer run.
    let rounds = std::env::var("DXF_FUZZ_ROUNDS")
        .ok()
        .and_then(|r| r.parse().ok())
        .unwrap_or(400);
    for _ in 0..rounds {
        let mut bad = good.clone();
        for _ in 0..1 + next() % 4 {
            let i = (next() % bad.len() as u64) as usize;
            bad[i] = match next() % 4 {
                0 => b'\n',
                1 => b'-',
                2 => b'x',
                _ => (next() % 256) as u8,
            };
        }
        record(parse_pattern_dxf(&bad, name));
    }
    // Binary DXF sentinel followed by noise.
    for _ in 0..rounds / 4 {
        let mut bad = b"AutoCAD Binary DXF\r\n\x1a\0".to_vec();
        bad.extend((0..next() % 600).map(|_| (next() % 256) as u8));
        record(parse_pattern_dxf(&bad, name));
    }
    assert!(outcomes[0] > 0 && outcomes[1] > 0, "{outcomes:?}");
}

#[test]
fn binary_dxf_reads_like_ascii() {
    let ascii = read_pattern_dxf(&data("shirt_aama.dxf")).unwrap();
    let drawing = dxf::Drawing::load_file(data("shirt_aama.dxf")).unwrap();
    let path = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("shirt_binary.dxf");
    drawing.save_file_binary(&path).unwrap();
    let binary = read_pattern_dxf(&path).unwrap();
    assert_eq!(ascii.pieces.len(), binary.pieces.len());
    for (a, b) in ascii.pieces.iter().zip(&binary.pieces) {
        assert_eq!(a.name, b.name);
        assert!(outline_gap(&a.outline, &b.outline) < 1e-9, "{}", a.name);
        assert_eq!(
            (&a.fold, a.copies, a.notches.len()),
            (&b.fold, b.copies, b.notches.len())
        );
        assert!((a.seam_allowance - b.seam_allowance).abs() < 1e-9);
    }
}
