//! Pre-positioning of meshed patterns around the MakeHuman mannequin: every vertex ends
//! outside the skin, edges keep their rest lengths (mean strain under 10 %), and the side seams
//! of front and back pieces meet. Patterns are built here by hand so that the expected figures
//! are known: a straight skirt whose width is given.

mod support;

use std::path::PathBuf;
use std::sync::OnceLock;

use emilion::body::Mannequin;
use emilion::contact::MeshBody;
use emilion::garment::{
    mesh_pattern, preposition, BodyFrame, Copies, Corner, EdgeRef, GarmentMesh, Landmarks,
    MeshParameters, Outline, Pattern, Piece, Placement, PrepositionParameters, PrepositionReport,
    Seam, Segment, Side, Silhouettes,
};
use emilion::geometry::Vec3;

struct Body {
    sil: Silhouettes,
    marks: Landmarks,
    skin: MeshBody,
}

fn body() -> &'static Body {
    static B: OnceLock<Body> = OnceLock::new();
    B.get_or_init(|| {
        let dir = PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../shared/data"))
            .join("bodies/makehuman");
        let m = Mannequin::load_makehuman(&dir).unwrap();
        let f = BodyFrame::of(m.rest_positions(), m.triangles()).unwrap();
        let sil = Silhouettes::of(f, m.rest_positions(), m.triangles(), 0.005).unwrap();
        let marks = sil.landmarks().unwrap();
        let skin = MeshBody::new("skin", m.rest_positions().to_vec(), m.triangles()).unwrap();
        Body { sil, marks, skin }
    })
}

fn rect(name: &str, w: f64, h: f64, side: Side) -> Piece {
    let c = |n: &str, x: f64, y: f64| Corner {
        name: n.into(),
        at: [x, y],
        segment: Segment::Line,
    };
    Piece {
        name: name.into(),
        outline: Outline {
            corners: vec![
                c("bl", 0.0, 0.0),
                c("br", w, 0.0),
                c("tr", w, h),
                c("tl", 0.0, h),
            ],
        },
        grain: [[w / 2.0, 0.1], [w / 2.0, h - 0.1]],
        seam_allowance: 0.0,
        notches: vec![],
        fold: None,
        copies: Copies::One,
        placement: Some(Placement {
            side,
            anchor: "tl".into(),
            x: -w / 2.0,
            level: "waist".into(),
            dz: 0.02,
        }),
    }
}

fn edge(piece: &str, from: &str, to: &str) -> EdgeRef {
    EdgeRef {
        piece: piece.into(),
        from: from.into(),
        to: to.into(),
    }
}

/// A straight skirt of two rectangles `w` wide, `h` long, sewn at the sides.
fn skirt(w: f64, h: f64) -> Pattern {
    Pattern {
        name: "tube".into(),
        source: "test".into(),
        pieces: vec![
            rect("front", w, h, Side::Front),
            rect("back", w, h, Side::Back),
        ],
        seams: vec![
            // front's right edge (body's left) with back's left edge (body's left)
            Seam {
                name: "left".into(),
                a: edge("front", "br", "tr"),
                b: edge("back", "tl", "bl"),
                aligned: false,
            },
            Seam {
                name: "right".into(),
                a: edge("back", "br", "tr"),
                b: edge("front", "tl", "bl"),
                aligned: false,
            },
        ],
    }
}

/// Meshes `pat` at `edge` and pre-positions it on the mannequin.
fn placed(pat: &Pattern, edge: f64) -> (GarmentMesh, Vec<Vec3>, PrepositionReport) {
    let b = body();
    let g = mesh_pattern(
        pat,
        &MeshParameters {
            edge_length: edge,
            ..Default::default()
        },
    )
    .unwrap();
    let (x, rep) = preposition(
        pat,
        &g,
        &b.sil,
        &b.marks,
        &b.skin,
        &PrepositionParameters::default(),
    )
    .unwrap();
    (g, x, rep)
}

#[test]
fn a_loose_skirt_is_placed_outside_the_body_with_little_strain() {
    let b = body();
    let pat = skirt(0.56, 0.5);
    let (g, x, rep) = placed(&pat, 0.015);
    eprintln!("{rep:?}");
    assert_eq!(rep.inside, 0);
    assert!(rep.min_distance > 0.0);
    assert!(rep.mean_strain < 0.10, "mean strain {}", rep.mean_strain);
    // side seams meet: the widest gap between paired seam vertices
    let gap = g
        .seams
        .iter()
        .flat_map(|s| s.pairs.iter().map(|&(a, c)| (x[a] - x[c]).norm()))
        .fold(0.0f64, f64::max);
    eprintln!("largest seam gap {gap}");
    assert!(gap < 0.02, "seam gap {gap}");
    // the waist row is at the waist: top corners within a few cm of the landmark height
    let f = b.sil.frame;
    let tl = g.pieces[0].corners.iter().find(|c| c.0 == "tl").unwrap().1;
    let h = f.to_body(&x[tl])[1];
    assert!((h - (b.marks.waist + 0.02)).abs() < 0.01, "{h}");
}

/// The three FreeSewing garments: pre-positioning alone leaves every vertex outside the skin
/// (checked here with an independent ray-parity test against the skin mesh) and a mean edge
/// strain under 10 %.
#[test]
fn freesewing_garments_are_prepositioned_outside_the_body() {
    let dir = PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../shared/data"))
        .join("bodies/makehuman");
    let m = Mannequin::load_makehuman(&dir).unwrap();
    let skin: Vec<[f64; 3]> = m.rest_positions().iter().map(|p| [p.x, p.y, p.z]).collect();
    for name in ["aaron", "penelope", "paco"] {
        let pat = emilion::garment::read_garment(format!(
            "{}/scripts/patterns/{name}.garment.json",
            env!("CARGO_MANIFEST_DIR")
        ))
        .unwrap();
        let (_, x, rep) = placed(&pat, 0.02);
        assert!(
            rep.mean_strain < 0.10,
            "{name}: mean strain {}",
            rep.mean_strain
        );
        let pts: Vec<[f64; 3]> = x.iter().map(|p| [p.x, p.y, p.z]).collect();
        let inside = support::inside::count_inside(&pts, &skin, m.triangles());
        assert_eq!(inside, 0, "{name}: {inside} vertices inside the body");
    }
}

/// Regression: the pencil skirt's pre-positioned pieces intersected each other (502 pairs,
/// counted with exact predicates, seam partners counted as one vertex):
/// its rows were widened for the fabric's width without the darts' gaps, so front and back
/// overlapped at the sides, and the two back halves' vent extensions lay on one surface.
/// Rows now take each side's full extent and overlapping pieces are layered.
#[test]
fn prepositioned_shirt_and_skirt_do_not_intersect_themselves() {
    for name in ["aaron", "penelope"] {
        let pat = emilion::garment::read_garment(format!(
            "{}/scripts/patterns/{name}.garment.json",
            env!("CARGO_MANIFEST_DIR")
        ))
        .unwrap();
        let (g, x, _) = placed(&pat, 0.015);
        let pts: Vec<[f64; 3]> = x.iter().map(|p| [p.x, p.y, p.z]).collect();
        // seam partners count as one vertex (as the engine's self-collision welds them): an
        // edge meeting a triangle at its partner's corner along a seam is not a crossing
        let mut rep: Vec<usize> = (0..x.len()).collect();
        for s in &g.seams {
            for &(a, b) in &s.pairs {
                let (ra, rb) = (root(&rep, a), root(&rep, b));
                rep[ra.max(rb)] = ra.min(rb);
            }
        }
        let r: Vec<usize> = (0..x.len()).map(|i| root(&rep, i)).collect();
        let mut n = 0;
        for (a, b) in support::intersections::unique_edges(&g.mesh.triangles) {
            let (pa, pb) = (pts[a], pts[b]);
            for t in &g.mesh.triangles {
                if t.iter().any(|&k| r[k] == r[a] || r[k] == r[b]) {
                    continue;
                }
                let [p0, p1, p2] = t.map(|k| pts[k]);
                let apart = (0..3).any(|d| {
                    pa[d].max(pb[d]) < p0[d].min(p1[d]).min(p2[d])
                        || pa[d].min(pb[d]) > p0[d].max(p1[d]).max(p2[d])
                });
                if !apart
                    && support::intersections::segment_triangle_intersect_exact(pa, pb, p0, p1, p2)
                {
                    n += 1;
                }
            }
        }
        assert_eq!(n, 0, "{name}: {n} intersecting edge–triangle pairs");
    }
}

fn root(rep: &[usize], mut i: usize) -> usize {
    while rep[i] != i {
        i = rep[i];
    }
    i
}

/// The multi-resolution relaxation (coarser meshes of the same pattern relaxed first, their
/// displacement carried over) leaves less strain than relaxing the fine mesh alone with the
/// same number of sweeps per level, and keeps every vertex outside the body.
#[test]
fn coarse_levels_lower_the_residual_strain() {
    let b = body();
    let pat = emilion::garment::read_garment(format!(
        "{}/scripts/patterns/aaron.garment.json",
        env!("CARGO_MANIFEST_DIR")
    ))
    .unwrap();
    let g = mesh_pattern(
        &pat,
        &MeshParameters {
            edge_length: 0.01,
            ..Default::default()
        },
    )
    .unwrap();
    let strain = |levels: usize| {
        let params = PrepositionParameters {
            levels,
            ..Default::default()
        };
        let (_, rep) = preposition(&pat, &g, &b.sil, &b.marks, &b.skin, &params).unwrap();
        assert_eq!(rep.inside, 0, "levels {levels}: vertices inside");
        rep.mean_strain
    };
    let (one, three) = (strain(1), strain(3));
    assert!(
        three < 0.85 * one,
        "mean strain {three} with three levels, {one} with one"
    );
}

#[test]
fn bad_relaxation_levels_are_rejected_by_name() {
    let b = body();
    let pat = skirt(1.0, 0.5);
    let g = mesh_pattern(&pat, &MeshParameters::default()).unwrap();
    for levels in [0, 7] {
        let params = PrepositionParameters {
            levels,
            ..Default::default()
        };
        let e = preposition(&pat, &g, &b.sil, &b.marks, &b.skin, &params).unwrap_err();
        assert!(e.to_string().contains("levels"), "{e}");
    }
}
