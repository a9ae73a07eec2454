//! Meshes a shirt-like pattern (a T-shaped front, 1 m × 1.3 m, and the same as a back sewn at
//! the sides and shoulders) at 1 cm and prints vertices, triangles, time and quality.
//!
//! `cargo run --release --example pattern_to_mesh [EDGE_LENGTH_M]`

use std::time::Instant;

use emilion::garment::{
    mesh_pattern, Copies, Corner, EdgeRef, MeshParameters, Outline, Pattern, Piece, Seam, Segment,
};

/// A T-shirt outline: hem, sides, underarms, sleeves, shoulders, a curved neckline (CCW).
fn shirt(name: &str, dx: f64, neck_depth: f64) -> Piece {
    let pts = [
        ("hem_l", [-0.3, 0.0]),
        ("hem_r", [0.3, 0.0]),
        ("arm_r", [0.3, 0.8]),
        ("cuff_r0", [0.5, 0.95]),
        ("cuff_r1", [0.5, 1.2]),
        ("neck_r", [0.1, 1.3]),
        ("neck_l", [-0.1, 1.3]),
        ("cuff_l1", [-0.5, 1.2]),
        ("cuff_l0", [-0.5, 0.95]),
        ("arm_l", [-0.3, 0.8]),
    ];
    let corners = pts
        .iter()
        .map(|&(n, p)| {
            let segment = match n {
                "arm_r" => Segment::Cubic {
                    c1: [0.3 + dx, 0.88],
                    c2: [0.4 + dx, 0.93],
                },
                "neck_r" => Segment::Cubic {
                    c1: [0.08 + dx, 1.3 - neck_depth],
                    c2: [-0.08 + dx, 1.3 - neck_depth],
                },
                "cuff_l0" => Segment::Cubic {
                    c1: [-0.4 + dx, 0.93],
                    c2: [-0.3 + dx, 0.88],
                },
                _ => Segment::Line,
            };
            Corner {
                name: n.into(),
                at: [p[0] + dx, p[1]],
                segment,
            }
        })
        .collect();
    Piece {
        name: name.into(),
        outline: Outline { corners },
        grain: [[dx, 0.2], [dx, 1.0]],
        seam_allowance: 0.01,
        notches: Vec::new(),
        fold: None,
        copies: Copies::One,
        placement: None,
    }
}

fn seam(name: &str, a: (&str, &str, &str), b: (&str, &str, &str)) -> Seam {
    let e = |(p, f, t): (&str, &str, &str)| EdgeRef {
        piece: p.into(),
        from: f.into(),
        to: t.into(),
    };
    Seam {
        name: name.into(),
        a: e(a),
        b: e(b),
        aligned: false,
    }
}

fn report(label: &str, pattern: &Pattern, params: &MeshParameters) {
    let mut best = f64::INFINITY;
    let mut gm = None;
    for _ in 0..5 {
        let t = Instant::now();
        let m = mesh_pattern(pattern, params).expect("meshing");
        best = best.min(t.elapsed().as_secs_f64() * 1e3);
        gm = Some(m);
    }
    let gm = gm.unwrap();
    let m = &gm.mesh;
    let (mut min_angle, mut under20, mut sum, mut count) = (180f64, 0, 0.0, 0);
    for t in &m.triangles {
        for k in 0..3 {
            let (p, q, r) = (m.rest[t[k]], m.rest[t[(k + 1) % 3]], m.rest[t[(k + 2) % 3]]);
            let (u, w) = ([q[0] - p[0], q[1] - p[1]], [r[0] - p[0], r[1] - p[1]]);
            let (lu, lw) = (u[0].hypot(u[1]), w[0].hypot(w[1]));
            let a = ((u[0] * w[0] + u[1] * w[1]) / (lu * lw))
                .clamp(-1.0, 1.0)
                .acos();
            min_angle = min_angle.min(a.to_degrees());
            under20 += (a.to_degrees() < 20.0) as usize;
            sum += lu; // every edge twice over interior, once on the boundary: an estimate
            count += 1;
        }
    }
    println!(
        "{label}: {} vertices, {} triangles, {} seams, {best:.1} ms (best of 5); min angle \
         {min_angle:.1}°, {under20} angles < 20°, mean edge {:.2} mm",
        m.positions.len(),
        m.triangles.len(),
        gm.seams.len(),
        sum / count as f64 * 1e3
    );
}

fn main() {
    let h: f64 = std::env::args()
        .nth(1)
        .map(|s| s.parse().expect("edge length in metres"))
        .unwrap_or(0.01);
    let params = MeshParameters {
        edge_length: h,
        ..MeshParameters::default()
    };
    let one = Pattern {
        name: "front".into(),
        pieces: vec![shirt("front", 0.0, 0.15)],
        ..Pattern::default()
    };
    report("one piece", &one, &params);
    let two = Pattern {
        name: "shirt".into(),
        pieces: vec![shirt("front", 0.0, 0.15), shirt("back", 1.2, 0.05)],
        seams: vec![
            seam(
                "side_r",
                ("front", "hem_r", "arm_r"),
                ("back", "arm_l", "hem_l"),
            ),
            seam(
                "side_l",
                ("front", "arm_l", "hem_l"),
                ("back", "hem_r", "arm_r"),
            ),
            seam(
                "shoulder_r",
                ("front", "cuff_r1", "neck_r"),
                ("back", "neck_l", "cuff_l1"),
            ),
            seam(
                "shoulder_l",
                ("front", "neck_l", "cuff_l1"),
                ("back", "cuff_r1", "neck_r"),
            ),
            seam(
                "sleeve_r",
                ("front", "arm_r", "cuff_r0"),
                ("back", "cuff_l0", "arm_l"),
            ),
            seam(
                "sleeve_l",
                ("front", "cuff_l0", "arm_l"),
                ("back", "arm_r", "cuff_r0"),
            ),
        ],
        ..Pattern::default()
    };
    report("front + back, 6 seams", &two, &params);
}
