//! A plain rectangle of fabric meshed like a pattern piece (constrained Delaunay, irregular
//! triangles, the warp along x): the triangle-mesh counterpart of a grid cloth, for experiments
//! that must not depend on a grid's regular lines.

use crate::garment::error::PatternError;
use crate::garment::mesh::{mesh_pattern, MeshParameters};
use crate::garment::pattern::{Copies, Corner, Outline, Pattern, Piece, Segment};
use crate::geometry::TriMesh;

/// A `width` × `height` m rectangle meshed with triangles about `edge_length` m long, flat in
/// the XY plane at z = 0 and centred at the origin; its rest coordinates have the warp along
/// +x.
pub fn rectangle_mesh(width: f64, height: f64, edge_length: f64) -> Result<TriMesh, PatternError> {
    for (name, v) in [("width", width), ("height", height)] {
        if !(v.is_finite() && v > 0.0) {
            return Err(PatternError::Parameter(format!(
                "{name} must be a positive length in metres, got {v}"
            )));
        }
    }
    let (w, h) = (0.5 * width, 0.5 * height);
    let corner = |k: usize, at: [f64; 2]| Corner {
        name: format!("c{k}"),
        at,
        segment: Segment::Line,
    };
    let piece = Piece {
        name: "rectangle".into(),
        outline: Outline {
            corners: vec![
                corner(0, [-w, -h]),
                corner(1, [w, -h]),
                corner(2, [w, h]),
                corner(3, [-w, h]),
            ],
        },
        grain: [[-w, 0.0], [w, 0.0]],
        seam_allowance: 0.0,
        notches: Vec::new(),
        fold: None,
        copies: Copies::One,
        placement: None,
    };
    let pattern = Pattern {
        name: "rectangle".into(),
        source: format!(
            "rectangle {} m × {} m",
            crate::limits::short(width),
            crate::limits::short(height)
        ),
        pieces: vec![piece],
        seams: Vec::new(),
    };
    // the pattern's own checks: a piece within MAX_PIECE_SIZE (a 100 km × 1.3 m patch within
    // the particle limit took minutes to mesh, out of reach of the run's deadline)
    pattern.validate()?;
    let params = MeshParameters {
        edge_length,
        ..MeshParameters::default()
    };
    Ok(mesh_pattern(&pattern, &params)?.mesh)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_rectangle_is_covered_by_irregular_triangles_with_the_warp_along_x() {
        let m = rectangle_mesh(0.4, 0.3, 0.02).unwrap();
        let area: f64 = (0..m.triangles.len()).map(|t| m.rest_area(t)).sum();
        assert!((area - 0.12).abs() < 1e-9, "area {area}");
        let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
        for p in &m.positions {
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        assert!((lo[0] + 0.2).abs() < 1e-12 && (hi[0] - 0.2).abs() < 1e-12);
        assert!((lo[1] + 0.15).abs() < 1e-12 && (hi[1] - 0.15).abs() < 1e-12);
        assert!(lo[2] == 0.0 && hi[2] == 0.0);
        // rest coordinates are the positions (warp along x), up to a shift
        let d = [
            m.rest[0][0] - m.positions[0].x,
            m.rest[0][1] - m.positions[0].y,
        ];
        for (r, p) in m.rest.iter().zip(&m.positions) {
            assert!((r[0] - p.x - d[0]).abs() < 1e-12 && (r[1] - p.y - d[1]).abs() < 1e-12);
        }
        // not a grid: vertex valences vary
        let mut valence = vec![0usize; m.positions.len()];
        for t in &m.triangles {
            for &v in t {
                valence[v] += 1;
            }
        }
        assert!(valence.contains(&6) && valence.iter().any(|&v| v != 6 && v > 3));
    }
}
