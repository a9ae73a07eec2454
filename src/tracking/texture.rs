//! The puppet's texture, learnt from the images by back-projection: every vertex of the
//! light mesh takes the colour the cameras see at its projection, averaged over the cameras
//! where it is visible (z-buffer test) and weighted by how squarely each camera sees it
//! (cos² of the angle between the surface normal and the line of sight). Vertices no camera
//! sees take the mean of their mesh neighbours (repeated diffusion), so the puppet has no
//! holes where it was hidden on the first frame. Pixels a view marks as unusable (where a
//! static occluder stands in front of the person) give no colour: a limb behind an
//! occluder in one camera takes its colour from the cameras that see it.

use super::puppet_mesh::TrackingMesh;
use super::pyramid::Level;
use crate::geometry::Camera;
use crate::geometry::Vec3;
use crate::render::raster::{draw_triangles, project_vertices, RasterTarget};

/// Depth tolerance of the visibility test, metres.
const VISIBILITY_TOLERANCE: f32 = 0.03;
/// Views seen more obliquely than this (cosine) do not contribute.
const MIN_COSINE: f64 = 0.2;

/// Area-weighted vertex normals of a posed mesh (outward for outward-wound triangles).
pub fn vertex_normals(positions: &[Vec3], triangles: &[[u32; 3]], out: &mut Vec<Vec3>) {
    out.clear();
    out.resize(positions.len(), Vec3::zeros());
    for t in triangles {
        let [a, b, c] = t.map(|i| i as usize);
        let n = (positions[b] - positions[a]).cross(&(positions[c] - positions[a]));
        out[a] += n;
        out[b] += n;
        out[c] += n;
    }
    for n in out.iter_mut() {
        *n = n.try_normalize(1e-20).unwrap_or_else(Vec3::zeros);
    }
}

/// Learns one colour per vertex of `mesh`, posed at `skinned`, from the views
/// (camera, image at the same resolution and, optionally, which of its pixels may be used).
/// Returns the colours and how many vertices at least one camera saw.
pub fn learn_colours(
    mesh: &TrackingMesh,
    skinned: &[Vec3],
    views: &[(&Camera, &Level, Option<&[bool]>)],
) -> (Vec<[f32; 3]>, usize) {
    let n = skinned.len();
    let mut normals = Vec::new();
    vertex_normals(skinned, &mesh.triangles, &mut normals);
    let mut sum = vec![[0.0f64; 3]; n];
    let mut weight = vec![0.0f64; n];
    let mut projected = Vec::with_capacity(n);
    let grey = vec![[0.0f32; 3]; n];
    for &(camera, image, usable) in views {
        project_vertices(camera, skinned, &mut projected);
        let mut target = RasterTarget::new(image.width, image.height);
        draw_triangles(&mut target, &projected, &grey, &mesh.triangles);
        let centre = camera.center();
        for v in 0..n {
            let [x, y, z] = projected[v];
            // the pixel whose centre is nearest (pixel (i, j) is centred on (i, j))
            let (rx, ry) = (x + 0.5, y + 0.5);
            if !(rx >= 0.0 && ry >= 0.0) || z <= 0.0 {
                continue;
            }
            let (px, py) = (rx as usize, ry as usize);
            if px >= image.width || py >= image.height {
                continue;
            }
            // nearest depth around the projection (the vertex lies on triangle edges)
            let mut nearest = f32::INFINITY;
            for dy in -1i64..=1 {
                for dx in -1i64..=1 {
                    let (qx, qy) = (px as i64 + dx, py as i64 + dy);
                    if qx >= 0
                        && qy >= 0
                        && (qx as usize) < image.width
                        && (qy as usize) < image.height
                    {
                        nearest =
                            nearest.min(target.depth[qy as usize * image.width + qx as usize]);
                    }
                }
            }
            if z > nearest + VISIBILITY_TOLERANCE
                || usable.is_some_and(|u| u.get(py * image.width + px) != Some(&true))
            {
                continue;
            }
            let to_cam = Vec3::new(centre.x, centre.y, centre.z) - skinned[v];
            let cos = normals[v].dot(&to_cam) / to_cam.norm().max(1e-12);
            if cos < MIN_COSINE {
                continue;
            }
            if let Some(c) = image.sample(x as f64, y as f64) {
                let w = cos * cos;
                for k in 0..3 {
                    sum[v][k] += w * c[k] as f64;
                }
                weight[v] += w;
            }
        }
    }
    let seen = weight.iter().filter(|&&w| w > 0.0).count();
    let mut colours: Vec<[f32; 3]> = (0..n)
        .map(|v| {
            if weight[v] > 0.0 {
                sum[v].map(|s| (s / weight[v]) as f32)
            } else {
                [0.0; 3]
            }
        })
        .collect();
    fill_unseen(mesh, &weight, &mut colours);
    (colours, seen)
}

/// Gives unseen vertices (weight 0) the mean colour of their known neighbours, spreading
/// inward until every vertex connected to a seen one has a colour.
fn fill_unseen(mesh: &TrackingMesh, weight: &[f64], colours: &mut [[f32; 3]]) {
    let n = colours.len();
    let mut known: Vec<bool> = weight.iter().map(|&w| w > 0.0).collect();
    if known.iter().all(|&k| k) || !known.iter().any(|&k| k) {
        return;
    }
    let mut neighbours: Vec<Vec<u32>> = vec![Vec::new(); n];
    for t in &mesh.triangles {
        for k in 0..3 {
            let (a, b) = (t[k] as usize, t[(k + 1) % 3]);
            neighbours[a].push(b);
            neighbours[b as usize].push(t[k]);
        }
    }
    loop {
        let mut changed = Vec::new();
        for v in 0..n {
            if known[v] {
                continue;
            }
            let (mut s, mut c) = ([0.0f32; 3], 0);
            for &u in &neighbours[v] {
                if known[u as usize] {
                    for k in 0..3 {
                        s[k] += colours[u as usize][k];
                    }
                    c += 1;
                }
            }
            if c > 0 {
                changed.push((v, s.map(|x| x / c as f32)));
            }
        }
        if changed.is_empty() {
            break;
        }
        for (v, col) in changed {
            colours[v] = col;
            known[v] = true;
        }
    }
    // parts not connected to any seen vertex: the mean of the seen colours
    let (mut s, mut c) = ([0.0f64; 3], 0.0);
    for (v, col) in colours.iter().enumerate() {
        if weight[v] > 0.0 {
            for k in 0..3 {
                s[k] += col[k] as f64;
            }
            c += 1.0;
        }
    }
    for v in 0..n {
        if !known[v] {
            colours[v] = s.map(|x| (x / c) as f32);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tracking::puppet::PartGroup;
    use nalgebra::Vector3;

    /// A 0.4 m square at z = 0 facing +z, as two outward-wound triangles.
    fn square() -> (TrackingMesh, Vec<Vec3>) {
        let rest = vec![
            Vec3::new(-0.2, -0.2, 0.0),
            Vec3::new(0.2, -0.2, 0.0),
            Vec3::new(0.2, 0.2, 0.0),
            Vec3::new(-0.2, 0.2, 0.0),
        ];
        let mesh = TrackingMesh {
            rest: rest.clone(),
            triangles: vec![[0, 1, 2], [0, 2, 3]],
            bone: vec![0; 4],
            part: vec![PartGroup::Torso; 4],
            source: vec![0; 4],
            lbs_bones: vec![[0; 4]; 4],
            lbs_weights: vec![[1.0, 0.0, 0.0, 0.0]; 4],
        };
        (mesh, rest)
    }

    fn flat(colour: [f32; 3]) -> Level {
        Level {
            width: 64,
            height: 64,
            rgb: vec![colour; 64 * 64],
        }
    }

    #[test]
    fn pixels_marked_unusable_give_no_colour() {
        // regression: the tracker's texture took the colours of static occluders standing in
        // front of a limb in some cameras, so the limb was not recognised where it was seen
        let (mesh, skinned) = square();
        let a = Camera::looking_at(Vector3::new(0.0, 0.0, 2.0), Vector3::zeros(), 80.0, 64, 64);
        let b = Camera::looking_at(Vector3::new(0.3, 0.0, 2.0), Vector3::zeros(), 80.0, 64, 64);
        let (red, blue) = (flat([200.0, 0.0, 0.0]), flat([0.0, 0.0, 200.0]));
        let hidden = vec![false; 64 * 64];
        let (colours, seen) = learn_colours(
            &mesh,
            &skinned,
            &[(&a, &red, None), (&b, &blue, Some(&hidden))],
        );
        assert_eq!(seen, 4);
        for c in &colours {
            assert_eq!(
                *c,
                [200.0, 0.0, 0.0],
                "colour {c:?} mixes in the unusable view"
            );
        }
        // both views usable: every vertex mixes the two colours
        let (colours, _) = learn_colours(&mesh, &skinned, &[(&a, &red, None), (&b, &blue, None)]);
        for c in &colours {
            assert!(
                c[0] > 50.0 && c[2] > 50.0,
                "colour {c:?} should mix both views"
            );
        }
        // no usable view: nothing seen
        let (_, seen) = learn_colours(&mesh, &skinned, &[(&b, &blue, Some(&hidden))]);
        assert_eq!(seen, 0);
    }

    #[test]
    fn a_vertex_learns_the_colour_at_its_projection_regression() {
        // regression: colours were sampled with pixel centres at i + 0.5 while the cameras
        // and the rasteriser centre pixel i on i, so every texture was learnt half a pixel up
        // and left of its vertices; the start, alternating learning and search, walked the
        // puppet up by about 2 cm (0.5 px per round)
        let (mesh, skinned) = square();
        let cam = Camera::looking_at(Vector3::new(0.0, 0.0, 2.0), Vector3::zeros(), 80.0, 64, 64);
        // a linear ramp: red = 2 × column, green = 2 × row (bilinear sampling is exact)
        let ramp = Level {
            width: 64,
            height: 64,
            rgb: (0..64 * 64)
                .map(|i| [2.0 * (i % 64) as f32, 2.0 * (i / 64) as f32, 0.0])
                .collect(),
        };
        let (colours, seen) = learn_colours(&mesh, &skinned, &[(&cam, &ramp, None)]);
        assert_eq!(seen, 4);
        let mut projected = Vec::new();
        project_vertices(&cam, &skinned, &mut projected);
        for (c, p) in colours.iter().zip(&projected) {
            assert!(
                (c[0] - 2.0 * p[0]).abs() < 1e-3 && (c[1] - 2.0 * p[1]).abs() < 1e-3,
                "vertex at ({}, {}) learnt {c:?}, expected ({}, {})",
                p[0],
                p[1],
                2.0 * p[0],
                2.0 * p[1]
            );
        }
    }
}
