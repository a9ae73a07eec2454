//! Relaxation of a pre-positioned garment: Jacobi sweeps towards the rest edge lengths (the
//! stretch part of the cloth's energy, minimised locally) that keep the skin clear.

use crate::contact::MeshBody;
use crate::garment::mesh::GarmentMesh;
use crate::geometry::Vec3;

/// Moves vertices closer to the skin than half the clearance out to the clearance, along the
/// skin normal; returns how many moved.
pub(super) fn push_out(x: &mut [Vec3], skin: &MeshBody, dz: f64) -> usize {
    let mut moved = 0;
    for p in x.iter_mut() {
        if let Some(pr) = skin.proximity(p, 1.0) {
            if pr.distance < 0.5 * dz {
                *p += pr.normal * (dz - pr.distance);
                moved += 1;
            }
        }
    }
    moved
}

/// Removes what is left of the mapping's distortion: Jacobi sweeps that move each edge's ends
/// towards its rest length (the stretch part of the cloth's energy, minimised locally), every
/// fifth sweep keeping the skin clear.
pub(super) fn relax(
    garment: &GarmentMesh,
    x: &mut [Vec3],
    skin: &MeshBody,
    dz: f64,
    sweeps: usize,
) {
    let m = &garment.mesh;
    let mut edges: Vec<(usize, usize, f64)> = Vec::with_capacity(3 * m.triangles.len());
    for t in &m.triangles {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            let r = (m.rest[a][0] - m.rest[b][0]).hypot(m.rest[a][1] - m.rest[b][1]);
            edges.push((a.min(b), a.max(b), r));
        }
    }
    edges.sort_by_key(|e| (e.0, e.1));
    edges.dedup_by(|p, q| p.0 == q.0 && p.1 == q.1);
    let mut corr = vec![Vec3::zeros(); x.len()];
    let mut count = vec![0u32; x.len()];
    for &(a, b, _) in &edges {
        count[a] += 1;
        count[b] += 1;
    }
    for sweep in 0..sweeps {
        corr.fill(Vec3::zeros());
        for &(a, b, r) in &edges {
            let d = x[b] - x[a];
            let l = d.norm();
            if l > 1e-12 {
                let c = d * (0.5 * (l - r) / l);
                corr[a] += c;
                corr[b] -= c;
            }
        }
        for v in 0..x.len() {
            if count[v] > 0 {
                x[v] += corr[v] / count[v] as f64;
            }
        }
        if sweep % 5 == 4 || sweep + 1 == sweeps {
            push_out(x, skin, dz);
        }
    }
}
