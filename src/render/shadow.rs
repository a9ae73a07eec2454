//! The area of a mesh's shadow on the ground plane (its vertical projection's union), by
//! covering pixel centres with the crate's one triangle traversal
//! ([`TriangleScan`]): what a drape tester's photograph measures
//! to give a drape coefficient.

use super::raster::TriangleScan;

/// The area (m²) of the union of the triangles' projections on z = 0, counted on square
/// pixels of side `pixel` (m) over the mesh's horizontal bounds: overlapping folds count once.
/// Its error is about a pixel's width times the outline's length, scattered in sign. `None`
/// for an empty mesh, a non-finite position, a pixel that is not positive and finite, or more
/// than 64 million pixels.
pub fn shadow_area(positions: &[[f64; 3]], triangles: &[[usize; 3]], pixel: f64) -> Option<f64> {
    if positions.is_empty() || !(pixel.is_finite() && pixel > 0.0) {
        return None;
    }
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in positions {
        if !p.iter().all(|c| c.is_finite()) {
            return None;
        }
        for k in 0..2 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let w = ((hi[0] - lo[0]) / pixel).ceil() as usize + 2;
    let h = ((hi[1] - lo[1]) / pixel).ceil() as usize + 2;
    if (w as u64) * (h as u64) > 64_000_000 {
        return None;
    }
    let mut covered = vec![false; w * h];
    let to_px = |p: &[f64; 3]| [(p[0] - lo[0]) / pixel + 0.5, (p[1] - lo[1]) / pixel + 0.5];
    for t in triangles {
        if t.iter().any(|&i| i >= positions.len()) {
            return None;
        }
        let corners = t.map(|i| to_px(&positions[i]));
        if let Some(scan) = TriangleScan::new(corners, w, h) {
            scan.for_each(|x, y, _| covered[y * w + x] = true);
        }
    }
    let count = covered.iter().filter(|&&c| c).count();
    Some(count as f64 * pixel * pixel)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_folded_square_and_a_disc_cast_their_own_areas() {
        // a unit square in two triangles, tilted 60° about x: shadow 0.5 m²
        let c = 0.5f64;
        let s = (60f64).to_radians().sin();
        let p = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, c, s], [0.0, c, s]];
        let a = shadow_area(&p, &[[0, 1, 2], [0, 2, 3]], 1e-3).unwrap();
        assert!((a - 0.5).abs() < 2e-3, "{a}");
        // the same square twice (a fold lying on itself) counts once
        let a2 = shadow_area(&p, &[[0, 1, 2], [0, 2, 3], [0, 2, 1]], 1e-3).unwrap();
        assert_eq!(a, a2);
        // a disc of radius 0.3 as a fan of 256 triangles: π r² cos-corrected polygon area
        let n = 256;
        let mut q = vec![[0.0, 0.0, 0.2]];
        for i in 0..n {
            let t = i as f64 / n as f64 * std::f64::consts::TAU;
            q.push([0.3 * t.cos(), 0.3 * t.sin(), 0.0]);
        }
        let tris: Vec<[usize; 3]> = (0..n).map(|i| [0, 1 + i, 1 + (i + 1) % n]).collect();
        let exact = 0.5 * n as f64 * 0.09 * (std::f64::consts::TAU / n as f64).sin();
        let a = shadow_area(&q, &tris, 5e-4).unwrap();
        assert!((a / exact - 1.0).abs() < 2e-3, "{a} vs {exact}");
        assert!(shadow_area(&[[f64::NAN, 0.0, 0.0]], &[], 1e-3).is_none());
    }
}
