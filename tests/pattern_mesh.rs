//! Meshing of pattern pieces (`emilion::garment::mesh_pattern`) on hand-built patterns: the
//! grain frame, seams sampled at common arc-length fractions, concave outlines, errors,
//! determinism, and mesh quality checked independently of the mesher.

use std::collections::BTreeMap;

use emilion::cloth::{ClothModel, FabricParameters};
use emilion::garment::{
    mesh_pattern, Copies, Corner, EdgeRef, GarmentMesh, MeshParameters, Outline, Pattern,
    PatternError, Piece, Seam, Segment, P2,
};

fn corner(name: &str, at: P2) -> Corner {
    Corner {
        name: name.into(),
        at,
        segment: Segment::Line,
    }
}

fn piece(name: &str, corners: Vec<Corner>, grain: [P2; 2]) -> Piece {
    Piece {
        name: name.into(),
        outline: Outline { corners },
        grain,
        seam_allowance: 0.0,
        notches: Vec::new(),
        fold: None,
        copies: Copies::One,
        placement: None,
    }
}

fn polygon(name: &str, pts: &[P2]) -> Piece {
    let corners = pts
        .iter()
        .enumerate()
        .map(|(i, &p)| corner(&format!("c{i}"), p))
        .collect();
    piece(name, corners, [[0.0, 0.0], [0.0, 1.0]])
}

fn pattern(pieces: Vec<Piece>, seams: Vec<Seam>) -> Pattern {
    Pattern {
        name: "test".into(),
        source: "test.json".into(),
        pieces,
        seams,
    }
}

fn edge(piece: &str, from: &str, to: &str) -> EdgeRef {
    EdgeRef {
        piece: piece.into(),
        from: from.into(),
        to: to.into(),
    }
}

fn params(h: f64) -> MeshParameters {
    MeshParameters {
        edge_length: h,
        ..MeshParameters::default()
    }
}

fn bezier(p: [P2; 4], t: f64) -> P2 {
    let s = 1.0 - t;
    let w = [s * s * s, 3.0 * s * s * t, 3.0 * s * t * t, t * t * t];
    [0, 1].map(|d| (0..4).map(|i| w[i] * p[i][d]).sum())
}

/// Dense polyline of a piece's outline (independent of the mesher's sampling).
fn dense_outline(piece: &Piece) -> Vec<P2> {
    let c = &piece.outline.corners;
    let mut out = Vec::new();
    for (j, k) in c.iter().enumerate() {
        let to = c[(j + 1) % c.len()].at;
        match k.segment {
            Segment::Line => out.push(k.at),
            Segment::Cubic { c1, c2 } => {
                out.extend((0..4000).map(|i| bezier([k.at, c1, c2, to], i as f64 / 4000.0)))
            }
        }
    }
    out
}

fn shoelace(p: &[P2]) -> f64 {
    let n = p.len();
    0.5 * (0..n)
        .map(|i| p[i][0] * p[(i + 1) % n][1] - p[(i + 1) % n][0] * p[i][1])
        .sum::<f64>()
}

fn dist(a: P2, b: P2) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

/// Quality figures of a meshed pattern.
#[derive(Debug)]
struct Quality {
    min_angle: f64,
    under_20: usize,
    mean_edge: f64,
    edge_histogram: [usize; 6],
}

/// Checks topology and geometry of every piece against the pattern; returns quality figures.
fn check(pattern: &Pattern, gm: &GarmentMesh, h: f64) -> Quality {
    let m = &gm.mesh;
    m.validate().expect("valid TriMesh");
    assert_eq!(gm.flat.len(), m.positions.len());
    assert_eq!(gm.pieces.len(), pattern.pieces.len());
    let mut q = Quality {
        min_angle: 180.0,
        under_20: 0,
        mean_edge: 0.0,
        edge_histogram: [0; 6],
    };
    let mut edge_sum = 0.0;
    let mut edge_count = 0usize;
    let mut next_vertex = 0;
    let mut next_triangle = 0;
    for (pm, piece) in gm.pieces.iter().zip(&pattern.pieces) {
        assert_eq!(pm.name, piece.name);
        assert_eq!(pm.vertices.start, next_vertex);
        assert_eq!(pm.triangles.start, next_triangle);
        next_vertex = pm.vertices.end;
        next_triangle = pm.triangles.end;
        // positions = flat at z = 0
        for v in pm.vertices.clone() {
            let p = m.positions[v];
            assert_eq!([p.x, p.y, p.z], [gm.flat[v][0], gm.flat[v][1], 0.0]);
        }
        // corners sit where the pattern puts them
        for ((name, v), c) in pm.corners.iter().zip(&piece.outline.corners) {
            assert_eq!(name, &c.name);
            assert_eq!(gm.flat[*v], c.at, "corner {name}");
        }
        // the outline's corners under 60°
        let b = &pm.boundary;
        let sharp: Vec<(usize, f64)> = pm
            .corners
            .iter()
            .map(|&(_, v)| {
                let k = b.iter().position(|&x| x == v).unwrap();
                let (p, n) = (b[(k + b.len() - 1) % b.len()], b[(k + 1) % b.len()]);
                let (c, p, n) = (m.rest[v], m.rest[p], m.rest[n]);
                let (u, w) = ([p[0] - c[0], p[1] - c[1]], [n[0] - c[0], n[1] - c[1]]);
                let cos = (u[0] * w[0] + u[1] * w[1]) / (u[0].hypot(u[1]) * w[0].hypot(w[1]));
                (v, cos.clamp(-1.0, 1.0).acos().to_degrees())
            })
            .filter(|&(_, alpha)| alpha < 60.0)
            .collect();
        // triangles: in range, positive rest area; edges counted per direction
        let mut area = 0.0;
        let mut directed: BTreeMap<(usize, usize), usize> = BTreeMap::new();
        for t in pm.triangles.clone() {
            let tri = m.triangles[t];
            assert!(tri.iter().all(|v| pm.vertices.contains(v)));
            let [a, b, c] = tri.map(|i| m.rest[i]);
            let signed = 0.5 * ((b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1]));
            assert!(signed > 0.0, "triangle {t} not CCW in rest space");
            area += signed;
            for k in 0..3 {
                let (i, j) = (tri[k], tri[(k + 1) % 3]);
                *directed.entry((i, j)).or_default() += 1;
                let (p, r, s) = (m.rest[i], m.rest[j], m.rest[tri[(k + 2) % 3]]);
                let (u, w) = ([r[0] - p[0], r[1] - p[1]], [s[0] - p[0], s[1] - p[1]]);
                let cos = (u[0] * w[0] + u[1] * w[1]) / (u[0].hypot(u[1]) * w[0].hypot(w[1]));
                let angle = cos.clamp(-1.0, 1.0).acos().to_degrees();
                q.min_angle = q.min_angle.min(angle);
                if angle < 20.0 {
                    q.under_20 += 1;
                    // only near a sharp corner (angle α) of the outline: the outline is
                    // narrower than h up to about h / tan(α/2) from the tip
                    let centre =
                        [0, 1].map(|d| tri.iter().map(|&v| m.rest[v][d]).sum::<f64>() / 3.0);
                    let near = sharp.iter().any(|&(v, alpha)| {
                        dist(m.rest[v], centre) < h / (0.5 * alpha).to_radians().tan()
                    });
                    assert!(near, "{angle}° angle away from sharp corners");
                }
            }
        }
        // rest area = outline area (dense shoelace)
        let exact = shoelace(&dense_outline(piece));
        assert!(
            (area - exact).abs() < 0.01 * exact,
            "{}: mesh area {area} vs outline {exact}",
            piece.name
        );
        // manifold: each directed edge once; boundary edges = the boundary loop
        assert!(directed.values().all(|&c| c == 1));
        let mut open: Vec<(usize, usize)> = directed
            .keys()
            .filter(|(i, j)| !directed.contains_key(&(*j, *i)))
            .copied()
            .collect();
        let mut loop_edges: Vec<_> = (0..b.len()).map(|k| (b[k], b[(k + 1) % b.len()])).collect();
        open.sort();
        loop_edges.sort();
        assert_eq!(open, loop_edges, "{}: boundary loop", piece.name);
        // Euler characteristic of a disc; every vertex used
        let mut used: Vec<usize> = pm.triangles.clone().flat_map(|t| m.triangles[t]).collect();
        used.sort();
        used.dedup();
        assert_eq!(used.len(), pm.vertices.len(), "unused vertices");
        let edges = directed
            .keys()
            .filter(|(i, j)| i < j || !directed.contains_key(&(*j, *i)))
            .count();
        let euler = pm.vertices.len() as i64 - edges as i64 + pm.triangles.len() as i64;
        assert_eq!(euler, 1, "{}: Euler characteristic", piece.name);
        for &(i, j) in directed
            .keys()
            .filter(|(i, j)| i < j || !directed.contains_key(&(*j, *i)))
        {
            let l = dist(m.rest[i], m.rest[j]);
            edge_sum += l;
            edge_count += 1;
            q.edge_histogram[((l / h / 0.25) as usize).min(5)] += 1;
        }
    }
    assert_eq!(next_vertex, m.positions.len());
    assert_eq!(next_triangle, m.triangles.len());
    q.mean_edge = edge_sum / edge_count as f64;
    eprintln!("quality: {q:?} (h = {h}, histogram bins of h/4)");
    q
}

fn assert_quality(q: &Quality, h: f64, allowed_under_20: usize) {
    assert!(
        (q.mean_edge - h).abs() < 0.25 * h,
        "mean edge {} vs target {h}",
        q.mean_edge
    );
    assert!(
        q.under_20 <= allowed_under_20,
        "{} angles under 20°",
        q.under_20
    );
}

#[test]
fn rotated_grain_gives_the_warp_as_rest_u() {
    let mut p = polygon("panel", &[[0.0, 0.0], [0.6, 0.0], [0.6, 0.4], [0.0, 0.4]]);
    let a = 30f64.to_radians();
    p.grain = [[0.1, 0.1], [0.1 + 0.2 * a.cos(), 0.1 + 0.2 * a.sin()]];
    let pat = pattern(vec![p], vec![]);
    let h = 0.02;
    let gm = mesh_pattern(&pat, &params(h)).unwrap();
    let q = check(&pat, &gm, h);
    assert_quality(&q, h, 0);
    assert!(q.min_angle >= 20.0);
    // rest is the flat drawing rotated by -30°: distances kept, grain-parallel edges have v = 0
    let m = &gm.mesh;
    let mut along_grain = 0;
    for t in &m.triangles {
        for k in 0..3 {
            let (i, j) = (t[k], t[(k + 1) % 3]);
            let f = [gm.flat[j][0] - gm.flat[i][0], gm.flat[j][1] - gm.flat[i][1]];
            let r = [m.rest[j][0] - m.rest[i][0], m.rest[j][1] - m.rest[i][1]];
            assert!((f[0].hypot(f[1]) - r[0].hypot(r[1])).abs() < 1e-12);
            let u = f[0] * a.cos() + f[1] * a.sin();
            let v = -f[0] * a.sin() + f[1] * a.cos();
            assert!((r[0] - u).abs() < 1e-12 && (r[1] - v).abs() < 1e-12);
            if (f[0] * a.sin() - f[1] * a.cos()).abs() < 1e-9 {
                along_grain += 1;
                assert!(r[1].abs() < 1e-9, "grain-parallel edge has v = {}", r[1]);
            }
        }
    }
    // the interior lattice runs along the warp
    assert!(along_grain > 100, "{along_grain} edges along the grain");
}

/// Piece A: a rectangle whose left side is straight; piece B: a panel whose right side is a
/// cubic of the same arc length. Seam: A's left side (top to bottom) with B's curve.
fn straight_to_curve(aligned: bool) -> (Pattern, [P2; 4], f64) {
    let cubic = [[0.3, 0.0], [0.42, 0.15], [0.38, 0.35], [0.3, 0.5]];
    let n = 200_000;
    let len: f64 = (0..n)
        .map(|i| {
            dist(
                bezier(cubic, i as f64 / n as f64),
                bezier(cubic, (i + 1) as f64 / n as f64),
            )
        })
        .sum();
    let a = polygon("a", &[[1.0, 0.0], [1.3, 0.0], [1.3, len], [1.0, len]]);
    let mut b = polygon("b", &[[0.0, 0.0], cubic[0], cubic[3], [0.0, 0.5]]);
    b.outline.corners[1].segment = Segment::Cubic {
        c1: cubic[1],
        c2: cubic[2],
    };
    // aligned: A's right side and B's curve, both bottom to top (a.from meets b.from)
    let (ea, eb) = if aligned {
        (edge("a", "c1", "c2"), edge("b", "c1", "c2"))
    } else {
        (edge("a", "c3", "c0"), edge("b", "c1", "c2"))
    };
    let seam = Seam {
        name: "side".into(),
        a: ea,
        b: eb,
        aligned,
    };
    (pattern(vec![a, b], vec![seam]), cubic, len)
}

/// Arc length along the cubic from its start to the point nearest `p`.
fn arc_length_to(cubic: [P2; 4], p: P2) -> f64 {
    let n = 100_000;
    let mut best = (f64::INFINITY, 0.0);
    let mut s = 0.0;
    let mut prev = cubic[0];
    for i in 0..=n {
        let q = bezier(cubic, i as f64 / n as f64);
        s += dist(prev, q);
        prev = q;
        if dist(q, p) < best.0 {
            best = (dist(q, p), s);
        }
    }
    assert!(
        best.0 < 1e-5,
        "point {p:?} is not on the curve ({})",
        best.0
    );
    best.1
}

#[test]
fn seam_between_straight_and_curved_edges_pairs_equal_fractions() {
    for aligned in [false, true] {
        let (pat, cubic, len) = straight_to_curve(aligned);
        let h = 0.02;
        let gm = mesh_pattern(&pat, &params(h)).unwrap();
        let q = check(&pat, &gm, h);
        assert_quality(&q, h, 0);
        let pairs = &gm.seams[0].pairs;
        assert_eq!(pairs.len(), (len / h).round() as usize + 1);
        let corner =
            |p: usize, name: &str| gm.pieces[p].corners.iter().find(|c| c.0 == name).unwrap().1;
        let (a_from, a_to) = if aligned { ("c1", "c2") } else { ("c3", "c0") };
        assert_eq!(
            pairs[0],
            (
                corner(0, a_from),
                corner(1, if aligned { "c1" } else { "c2" })
            )
        );
        assert_eq!(
            *pairs.last().unwrap(),
            (
                corner(0, a_to),
                corner(1, if aligned { "c2" } else { "c1" })
            )
        );
        let start = gm.flat[corner(0, a_from)];
        for &(i, j) in pairs {
            let fa = dist(gm.flat[i], start) / len;
            let fb = arc_length_to(cubic, gm.flat[j]) / len;
            let expect = if aligned { fa } else { 1.0 - fa };
            assert!((fb - expect).abs() < 1e-4, "fractions {fa} and {fb}");
            // the paired vertices are on the boundaries
            assert!(gm.pieces[0].boundary.contains(&i) && gm.pieces[1].boundary.contains(&j));
        }
    }
}

#[test]
fn seam_count_comes_from_the_longer_edge_and_near_corners_meet() {
    // a's top runs c2 → c3 → c4 (corner at half way); b's bottom runs c0 → c1 → c2, with its
    // corner at 0.48 of its length from c0, i.e. 0.52 from a.from's end: the corners meet
    let a = polygon(
        "a",
        &[[0.0, 0.0], [0.4, 0.0], [0.4, 0.3], [0.2, 0.31], [0.0, 0.3]],
    );
    let b = polygon(
        "b",
        &[[0.0, 0.5], [0.24, 0.45], [0.5, 0.5], [0.5, 0.8], [0.0, 0.8]],
    );
    let seam = Seam {
        name: "s".into(),
        a: edge("a", "c2", "c4"),
        b: edge("b", "c0", "c2"),
        aligned: false,
    };
    let pat = pattern(vec![a, b], vec![seam]);
    let h = 0.05;
    let gm = mesh_pattern(&pat, &params(h)).unwrap();
    check(&pat, &gm, h);
    let pairs = &gm.seams[0].pairs;
    let lb = dist([0.0, 0.5], [0.24, 0.45]) + dist([0.24, 0.45], [0.5, 0.5]);
    assert!(pairs.len() > (lb / h).round() as usize);
    let (a3, b1) = (gm.pieces[0].corners[3].1, gm.pieces[1].corners[1].1);
    assert!(pairs.contains(&(a3, b1)), "corner meets corner");
    let mut seen: Vec<usize> = pairs.iter().flat_map(|p| [p.0, p.1]).collect();
    seen.sort();
    seen.dedup();
    assert_eq!(seen.len(), 2 * pairs.len(), "pairs are one to one");
}

#[test]
fn concave_l_shape() {
    let pts = [
        [0.0, 0.0],
        [0.5, 0.0],
        [0.5, 0.2],
        [0.2, 0.2],
        [0.2, 0.6],
        [0.0, 0.6],
    ];
    let pat = pattern(vec![polygon("l", &pts)], vec![]);
    let h = 0.015;
    let gm = mesh_pattern(&pat, &params(h)).unwrap();
    let q = check(&pat, &gm, h);
    assert_quality(&q, h, 0);
    // no triangle covers the notch
    let m = &gm.mesh;
    for t in &m.triangles {
        let c = [0, 1].map(|d| t.iter().map(|&i| gm.flat[i][d]).sum::<f64>() / 3.0);
        assert!(!(c[0] > 0.2 && c[1] > 0.2));
    }
}

#[test]
fn sharp_corner_and_curves_keep_quality_elsewhere() {
    // a dart-like sharp tip (about 11°) and a curved hem
    let mut p = polygon("tip", &[[0.0, 0.0], [0.4, 0.0], [0.2, 1.0]]);
    p.outline.corners[0].segment = Segment::Cubic {
        c1: [0.1, -0.08],
        c2: [0.3, -0.08],
    };
    let pat = pattern(vec![p], vec![]);
    let h = 0.02;
    let gm = mesh_pattern(&pat, &params(h)).unwrap();
    let q = check(&pat, &gm, h);
    assert_quality(&q, h, 6);
}

#[test]
fn meshing_is_deterministic_and_feeds_a_cloth() {
    let (pat, _, _) = straight_to_curve(false);
    let a = mesh_pattern(&pat, &params(0.015)).unwrap();
    let b = mesh_pattern(&pat, &params(0.015)).unwrap();
    assert_eq!(
        serde_json::to_string(&a).unwrap(),
        serde_json::to_string(&b).unwrap()
    );
    let cloth = ClothModel::from_mesh(a.mesh, FabricParameters::default()).unwrap();
    assert!(!cloth.hinges.is_empty());
}

#[test]
fn invalid_parameters_are_named() {
    let pat = pattern(
        vec![polygon("p", &[[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]])],
        vec![],
    );
    for h in [0.0, -0.01, f64::NAN, f64::INFINITY] {
        let e = mesh_pattern(&pat, &params(h)).unwrap_err();
        assert!(
            matches!(e, PatternError::Parameter(ref m) if m.contains("edge_length")),
            "{e}"
        );
    }
    let bad = MeshParameters {
        min_angle_deg: f64::NAN,
        ..MeshParameters::default()
    };
    assert!(bad
        .validate()
        .unwrap_err()
        .to_string()
        .contains("min_angle_deg"));
    let p: MeshParameters = serde_json::from_str(r#"{"edge_length": 0.02}"#).unwrap();
    assert_eq!(p.min_angle_deg, 25.0);
}

#[test]
fn invalid_pieces_and_seams_are_named() {
    let h = params(0.05);
    // self-intersecting (bow tie)
    let bow = polygon("bow", &[[0.0, 0.0], [1.0, 1.0], [1.0, 0.0], [0.0, 1.0]]);
    let e = mesh_pattern(&pattern(vec![bow], vec![]), &h).unwrap_err();
    assert!(
        matches!(e, PatternError::Piece { ref piece, .. } if piece == "bow"),
        "{e}"
    );
    // a self-intersecting curve: a loop in a cubic
    let mut curl = polygon("curl", &[[0.0, 0.0], [1.0, 0.0], [0.5, 1.0]]);
    curl.outline.corners[0].segment = Segment::Cubic {
        c1: [1.5, 0.5],
        c2: [-0.5, 0.5],
    };
    let e = mesh_pattern(&pattern(vec![curl], vec![]), &h).unwrap_err();
    assert!(e.to_string().contains("intersects itself"), "{e}");
    // not expanded
    let mut fold = polygon("half", &[[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]);
    fold.fold = Some("c2".into());
    let e = mesh_pattern(&pattern(vec![fold], vec![]), &h).unwrap_err();
    assert!(
        e.to_string().contains("half") && e.to_string().contains("expand"),
        "{e}"
    );
    let mut pair = polygon("sleeve", &[[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]);
    pair.copies = Copies::Pair;
    assert!(mesh_pattern(&pattern(vec![pair], vec![]), &h).is_err());
    // unknown corner in a seam
    let tri = polygon("t", &[[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]);
    let seam = Seam {
        name: "s1".into(),
        a: edge("t", "c0", "c1"),
        b: edge("t", "c2", "c9"),
        aligned: false,
    };
    let e = mesh_pattern(&pattern(vec![tri], vec![seam]), &h).unwrap_err();
    let m = e.to_string();
    assert!(
        m.contains("s1") && m.contains("'t'") && m.contains("c9"),
        "{m}"
    );
    // clockwise outline
    let cw = polygon("cw", &[[0.0, 0.0], [0.0, 1.0], [1.0, 0.0]]);
    assert!(mesh_pattern(&pattern(vec![cw], vec![]), &h).is_err());
}

#[test]
fn narrow_strips_gathered_seams_and_sharp_tips() {
    let h = 0.01;
    // strips 1.2 h and 2.5 h wide
    for w in [0.012, 0.025] {
        let pat = pattern(
            vec![polygon(
                "strip",
                &[[0.0, 0.0], [0.5, 0.0], [0.5, w], [0.0, w]],
            )],
            vec![],
        );
        let gm = mesh_pattern(&pat, &params(h)).unwrap();
        eprint!("strip {w}: ");
        let q = check(&pat, &gm, h);
        assert_quality(&q, h, 0);
    }
    // a ruffle: a 0.6 m edge gathered onto a 0.3 m edge (spacing h/2 on the short one)
    let a = polygon("a", &[[0.0, 0.0], [0.3, 0.0], [0.3, 0.2], [0.0, 0.2]]);
    let b = polygon("b", &[[0.0, 0.3], [0.6, 0.3], [0.6, 0.4], [0.0, 0.4]]);
    let seam = Seam {
        name: "gather".into(),
        a: edge("a", "c2", "c3"),
        b: edge("b", "c0", "c1"),
        aligned: false,
    };
    let pat = pattern(vec![a, b], vec![seam]);
    let gm = mesh_pattern(&pat, &params(h)).unwrap();
    eprint!("gathered: ");
    let q = check(&pat, &gm, h);
    assert_quality(&q, h, 0);
    assert_eq!(gm.seams[0].pairs.len(), 61);
    // a 6° tip and a round piece of four cubics
    let tip = polygon("tip", &[[0.0, 0.0], [0.05, 0.0], [0.025, 0.24]]);
    let k = 0.5523 * 0.1;
    let mut round = polygon("round", &[[0.1, 0.0], [0.0, 0.1], [-0.1, 0.0], [0.0, -0.1]]);
    let ctrl = [
        ([0.1, k], [k, 0.1]),
        ([-k, 0.1], [-0.1, k]),
        ([-0.1, -k], [-k, -0.1]),
        ([k, -0.1], [0.1, -k]),
    ];
    for (c, (c1, c2)) in round.outline.corners.iter_mut().zip(ctrl) {
        c.segment = Segment::Cubic { c1, c2 };
    }
    let pat = pattern(vec![tip, round], vec![]);
    let gm = mesh_pattern(&pat, &params(h)).unwrap();
    eprint!("tip and round: ");
    let q = check(&pat, &gm, h);
    assert_quality(&q, h, 6);
}

#[test]
fn freesewing_garments_mesh_cleanly() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scripts/patterns");
    for name in ["aaron", "paco", "penelope"] {
        let pat = emilion::garment::read_garment(dir.join(format!("{name}.garment.json")))
            .unwrap()
            .expanded()
            .unwrap();
        let h = 0.02;
        let gm = mesh_pattern(&pat, &params(h)).unwrap();
        eprint!("{name}: ");
        let q = check(&pat, &gm, h);
        assert_quality(&q, h, 0);
        assert_eq!(gm.seams.len(), pat.seams.len());
    }
}
