//! One texture image of a face from all its photos (seed report §5.2: "texturing from all the
//! photos available").
//!
//! This file owns the texture baking: the rasterization of the mesh's UV layout into texels
//! ([`rasterize_uv`]), the per-texel blend of every calibrated photo that sees the texel
//! ([`bake_texture`], [`bake_texture_with`]), and the filling of texels no photo sees
//! (push-pull) plus the padding around the UV islands.
//!
//! For every texel whose centre lies inside a UV triangle, the barycentric coordinates give the
//! 3D surface point `P` and the interpolated vertex normal `N`. A view `(camera, photo)`
//! contributes when
//! - `P` faces the camera: `cos θ = N · (C − P) / |C − P| > min_cos` (`C` the camera centre);
//! - `P` is not occluded: the mesh is z-buffered in that view ([`draw_triangles`]) and the
//!   depth of each of the four pixels around `P`'s projection is within a tolerance of `P`'s
//!   camera depth (so no photo pixel showing an occluder, the background or another surface
//!   enters the blend). The tolerance is `depth_tolerance + 2 · (z / fx) · tan θ`: a fixed
//!   part plus the depth change across two pixels of a surface seen at angle `θ`;
//! - `P` projects inside the photo, away from its last row and column.
//!
//! Its weight is `cos^weight_exponent θ` (default `cos² θ`: foreshortening shrinks the photo's
//! sampling density as `cos θ`, and the square favours frontal views more firmly), and its
//! colour the photo sampled bilinearly at `P`'s projection. The texel is the weighted mean.
//!
//! Texels inside the layout that no view sees are filled by push-pull (weighted averages on
//! an image pyramid, then blended back down), so renders show no black holes; the
//! [`BakedTexture::coverage`] counts only real samples. Finally the colours are dilated
//! `padding` texels outside the UV islands, so bilinear and mipmapped lookups near island
//! borders do not pick the background. Texels further out keep the push-pull colour.
//!
//! Rows of texels are processed in parallel (rayon); every texel depends only on the inputs,
//! so the result is deterministic.

use image::RgbImage;
use rayon::prelude::*;

use super::render::Texture;
use super::{FaceError, FaceMesh};
use crate::geometry::Camera;
use crate::geometry::Vec3;
use crate::render::raster::{draw_triangles, project_vertices, RasterTarget, NEAR};

/// Largest texture side accepted by the baker, texels.
pub const MAX_TEXTURE_SIZE: usize = 4096;

/// Settings of [`bake_texture_with`]; [`Default`] gives those of [`bake_texture`].
#[derive(Clone, Debug, PartialEq)]
pub struct BakeOptions {
    /// Exponent of `cos θ` in a view's weight (default 2).
    pub weight_exponent: f64,
    /// Views seeing a texel at `cos θ ≤ min_cos` are ignored (default 0.1, θ ≈ 84°).
    pub min_cos: f64,
    /// Fixed part of the depth tolerance of the visibility test, metres (default 0.002).
    pub depth_tolerance: f64,
    /// Texels of colour dilated outside the UV islands (default 4).
    pub padding: usize,
}

impl Default for BakeOptions {
    fn default() -> Self {
        BakeOptions {
            weight_exponent: 2.0,
            min_cos: 0.1,
            depth_tolerance: 0.002,
            padding: 4,
        }
    }
}

/// A baked texture and how well the photos covered it.
#[derive(Clone, Debug, PartialEq)]
pub struct BakedTexture {
    /// The texture (row 0 at the top, `v = 1`), holes filled and islands padded.
    pub texture: Texture,
    /// Total view weight per texel (same layout as the texture); `0` where no view sampled the
    /// texel (outside the layout, hidden, or seen only at grazing angles).
    pub weight: Vec<f32>,
    /// Fraction of the texels inside the UV layout that got a colour from at least one view.
    pub coverage: f64,
}

/// A texel inside the UV layout: the triangle containing its centre and the barycentric
/// coordinates of the centre in it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UvTexel {
    /// Index of the triangle in [`FaceMesh::triangles`].
    pub triangle: u32,
    /// Barycentric coordinates of the texel centre, summing to 1.
    pub bary: [f64; 3],
}

/// Checks that a mesh is usable for texturing: one UV per vertex, valid indices, finite values.
fn check_mesh(mesh: &FaceMesh) -> Result<(), FaceError> {
    let n = mesh.positions.len();
    if mesh.uvs.len() != n {
        return Err(FaceError::parameter(
            "mesh",
            format!("{n} positions but {} texture coordinates", mesh.uvs.len()),
        ));
    }
    if mesh.triangles.is_empty() {
        return Err(FaceError::parameter("mesh", "no triangles"));
    }
    if let Some(t) = mesh
        .triangles
        .iter()
        .position(|t| t.iter().any(|&i| i as usize >= n))
    {
        return Err(FaceError::parameter(
            "mesh",
            format!("triangle {t} has a vertex index beyond the {n} vertices"),
        ));
    }
    if let Some(i) = mesh
        .positions
        .iter()
        .position(|p| !p.iter().all(|c| c.is_finite()))
    {
        return Err(FaceError::parameter(
            "mesh",
            format!("vertex {i} has a non-finite position"),
        ));
    }
    if let Some(i) = mesh
        .uvs
        .iter()
        .position(|uv| !uv.iter().all(|c| c.is_finite()))
    {
        return Err(FaceError::parameter(
            "mesh",
            format!("vertex {i} has a non-finite texture coordinate"),
        ));
    }
    Ok(())
}

/// Rasterizes the UV layout of `mesh` into a `size × size` grid of texels (row 0 at the top,
/// `v = 1`; texel `(x, y)` has its centre at `u = (x + ½)/size`, `v = 1 − (y + ½)/size`): for
/// each texel whose centre lies in a UV triangle (edges included), that triangle and the
/// barycentric coordinates; `None` elsewhere. Where UV triangles overlap the last one wins.
///
/// Fails on a `size` outside `1..=`[`MAX_TEXTURE_SIZE`] or a mesh without one finite texture
/// coordinate per vertex, with out-of-range indices or without triangles.
pub fn rasterize_uv(mesh: &FaceMesh, size: usize) -> Result<Vec<Option<UvTexel>>, FaceError> {
    if !(1..=MAX_TEXTURE_SIZE).contains(&size) {
        return Err(FaceError::parameter(
            "size",
            format!("must be in 1..={MAX_TEXTURE_SIZE}, got {size}"),
        ));
    }
    check_mesh(mesh)?;
    let s = size as f64;
    let mut out = vec![None; size * size];
    for (ti, t) in mesh.triangles.iter().enumerate() {
        // texel coordinates: x = u·s − ½, y = (1 − v)·s − ½ (texel centres at integers)
        let q = t.map(|i| {
            let uv = mesh.uvs[i as usize];
            [uv[0] * s - 0.5, (1.0 - uv[1]) * s - 0.5]
        });
        let area =
            (q[1][0] - q[0][0]) * (q[2][1] - q[0][1]) - (q[1][1] - q[0][1]) * (q[2][0] - q[0][0]);
        if area.abs() < 1e-12 {
            continue;
        }
        let lo_x = q.iter().map(|p| p[0]).fold(f64::INFINITY, f64::min);
        let hi_x = q.iter().map(|p| p[0]).fold(f64::NEG_INFINITY, f64::max);
        let lo_y = q.iter().map(|p| p[1]).fold(f64::INFINITY, f64::min);
        let hi_y = q.iter().map(|p| p[1]).fold(f64::NEG_INFINITY, f64::max);
        let x0 = lo_x.ceil().max(0.0) as usize;
        let y0 = lo_y.ceil().max(0.0) as usize;
        let x1 = (hi_x.floor().min(s - 1.0)).max(-1.0);
        let y1 = (hi_y.floor().min(s - 1.0)).max(-1.0);
        if x1 < 0.0 || y1 < 0.0 {
            continue;
        }
        let (x1, y1) = (x1 as usize, y1 as usize);
        let edge = |a: [f64; 2], b: [f64; 2], p: [f64; 2]| {
            (b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0])
        };
        for y in y0..=y1 {
            for x in x0..=x1 {
                let p = [x as f64, y as f64];
                let b = [
                    edge(q[1], q[2], p) / area,
                    edge(q[2], q[0], p) / area,
                    edge(q[0], q[1], p) / area,
                ];
                if b.iter().all(|&w| w >= -1e-9) {
                    let sum = b[0] + b[1] + b[2];
                    out[y * size + x] = Some(UvTexel {
                        triangle: ti as u32,
                        bary: b.map(|w| w.max(0.0) / sum),
                    });
                }
            }
        }
    }
    Ok(out)
}

/// [`bake_texture_with`] and the [`BakeOptions::default`] settings.
pub fn bake_texture(
    mesh: &FaceMesh,
    views: &[(&Camera, &RgbImage)],
    size: usize,
) -> Result<BakedTexture, FaceError> {
    bake_texture_with(mesh, views, size, &BakeOptions::default())
}

/// One view ready for sampling: its camera, photo, z-buffer and centre.
struct PreparedView<'a> {
    camera: &'a Camera,
    photo: &'a RgbImage,
    depth: Vec<f32>,
    centre: Vec3,
}

/// Bakes a `size × size` texture of `mesh` from calibrated photos `views` (each photo the size
/// its camera says), as the [module docs](self) describe.
///
/// Fails, naming the parameter, on a bad `size` or mesh (see [`rasterize_uv`]), no views, a
/// photo whose size differs from its camera's, a camera with non-finite or non-positive focal
/// lengths, or options out of range.
pub fn bake_texture_with(
    mesh: &FaceMesh,
    views: &[(&Camera, &RgbImage)],
    size: usize,
    options: &BakeOptions,
) -> Result<BakedTexture, FaceError> {
    let o = options;
    if !(o.weight_exponent.is_finite() && o.weight_exponent > 0.0) {
        return Err(FaceError::parameter(
            "weight_exponent",
            format!("must be finite and positive, got {}", o.weight_exponent),
        ));
    }
    if !(o.min_cos.is_finite() && (0.0..1.0).contains(&o.min_cos)) {
        return Err(FaceError::parameter(
            "min_cos",
            format!("must be in [0, 1), got {}", o.min_cos),
        ));
    }
    if !(o.depth_tolerance.is_finite() && o.depth_tolerance >= 0.0) {
        return Err(FaceError::parameter(
            "depth_tolerance",
            format!("must be finite and non-negative, got {}", o.depth_tolerance),
        ));
    }
    if views.is_empty() {
        return Err(FaceError::parameter("views", "no view to bake from"));
    }
    let layout = rasterize_uv(mesh, size)?;
    let normals = mesh.vertex_normals();
    let mut prepared = Vec::with_capacity(views.len());
    let mut projected = Vec::new();
    let zeros = vec![[0.0f32; 3]; mesh.positions.len()];
    for (k, &(camera, photo)) in views.iter().enumerate() {
        let name = format!("views[{k}]");
        if photo.width() != camera.width || photo.height() != camera.height {
            return Err(FaceError::parameter(
                &name,
                format!(
                    "photo is {}×{} but its camera is {}×{}",
                    photo.width(),
                    photo.height(),
                    camera.width,
                    camera.height
                ),
            ));
        }
        let focal_ok = |f: f64| f.is_finite() && f > 0.0;
        if !(focal_ok(camera.fx) && focal_ok(camera.fy))
            || photo.width() == 0
            || photo.height() == 0
        {
            return Err(FaceError::parameter(
                &name,
                "camera focal lengths must be finite and positive, the photo not empty",
            ));
        }
        let (w, h) = (photo.width() as usize, photo.height() as usize);
        if w.saturating_mul(h) > 1 << 28 {
            return Err(FaceError::parameter(
                &name,
                format!("photo {w}×{h} too large"),
            ));
        }
        let mut target = RasterTarget::new(w, h);
        project_vertices(camera, &mesh.positions, &mut projected);
        draw_triangles(&mut target, &projected, &zeros, &mesh.triangles);
        prepared.push(PreparedView {
            camera,
            photo,
            depth: target.depth,
            centre: camera.center(),
        });
    }

    // real samples, row-parallel
    let mut colour = vec![[0.0f32; 3]; size * size];
    let mut weight = vec![0.0f32; size * size];
    colour
        .par_chunks_mut(size)
        .zip(weight.par_chunks_mut(size))
        .enumerate()
        .for_each(|(y, (crow, wrow))| {
            for x in 0..size {
                let Some(texel) = layout[y * size + x] else {
                    continue;
                };
                let t = mesh.triangles[texel.triangle as usize].map(|i| i as usize);
                let b = texel.bary;
                let p = mesh.positions[t[0]] * b[0]
                    + mesh.positions[t[1]] * b[1]
                    + mesh.positions[t[2]] * b[2];
                let mut n = normals[t[0]] * b[0] + normals[t[1]] * b[1] + normals[t[2]] * b[2];
                if n.norm() < 1e-12 {
                    let [a, bb, c] = t.map(|i| mesh.positions[i]);
                    n = (bb - a).cross(&(c - a));
                }
                let n = n.normalize();
                if !n.iter().all(|c| c.is_finite()) {
                    continue;
                }
                let (mut sum, mut wsum) = ([0.0f64; 3], 0.0f64);
                for v in &prepared {
                    if let Some((c, w)) = sample_view(v, &p, &n, o) {
                        for k in 0..3 {
                            sum[k] += w * c[k];
                        }
                        wsum += w;
                    }
                }
                if wsum > 0.0 {
                    crow[x] = sum.map(|s| (s / wsum) as f32);
                    wrow[x] = wsum as f32;
                }
            }
        });

    let inside = layout.iter().filter(|t| t.is_some()).count();
    let sampled = weight.iter().filter(|&&w| w > 0.0).count();
    let coverage = if inside > 0 {
        sampled as f64 / inside as f64
    } else {
        0.0
    };
    let known: Vec<bool> = weight.iter().map(|&w| w > 0.0).collect();
    push_pull(size, size, &mut colour, &known);
    let inside_mask: Vec<bool> = layout.iter().map(Option::is_some).collect();
    pad(size, size, &mut colour, &inside_mask, o.padding);
    Ok(BakedTexture {
        texture: Texture {
            width: size,
            height: size,
            rgb: colour,
        },
        weight,
        coverage,
    })
}

/// The colour and weight one view gives the surface point `p` of unit normal `n`, or `None`
/// when the view does not see it (see the [module docs](self)).
fn sample_view(v: &PreparedView, p: &Vec3, n: &Vec3, o: &BakeOptions) -> Option<([f64; 3], f64)> {
    let to_cam = v.centre - p;
    let dist = to_cam.norm();
    if dist <= 0.0 {
        return None;
    }
    let cos = n.dot(&to_cam) / dist;
    if cos.is_nan() || cos <= o.min_cos {
        return None;
    }
    let z = v.camera.to_camera_frame(p).z;
    if z.is_nan() || z <= NEAR as f64 {
        return None;
    }
    let [px, py] = v.camera.project(p)?;
    let (w, h) = (v.photo.width() as usize, v.photo.height() as usize);
    if !(px >= 0.0 && py >= 0.0 && px < (w - 1) as f64 && py < (h - 1) as f64) {
        return None;
    }
    let (x0, y0) = (px as usize, py as usize);
    let tan = ((1.0 - cos * cos).max(0.0).sqrt() / cos).min(20.0);
    let tol = o.depth_tolerance + 2.0 * z / v.camera.fx * tan;
    for (x, y) in [(x0, y0), (x0 + 1, y0), (x0, y0 + 1), (x0 + 1, y0 + 1)] {
        let d = v.depth[y * w + x] as f64;
        if !(d.is_finite() && (d - z).abs() <= tol) {
            return None;
        }
    }
    let (fx, fy) = (px - x0 as f64, py - y0 as f64);
    let at = |x: usize, y: usize| v.photo.get_pixel(x as u32, y as u32).0.map(f64::from);
    let (a, b, c, d) = (
        at(x0, y0),
        at(x0 + 1, y0),
        at(x0, y0 + 1),
        at(x0 + 1, y0 + 1),
    );
    let mut out = [0.0; 3];
    for k in 0..3 {
        let top = a[k] + (b[k] - a[k]) * fx;
        let bottom = c[k] + (d[k] - c[k]) * fx;
        out[k] = top + (bottom - top) * fy;
    }
    Some((out, cos.powf(o.weight_exponent)))
}

/// One level of the push-pull pyramid: width, height, premultiplied colours, weights.
type Level = (usize, usize, Vec<[f32; 3]>, Vec<f32>);

/// Fills the texels not `known` by push-pull: a pyramid of weighted means (weights capped at
/// 1 per coarse texel) built up, then each level's holes blended from the bilinearly upsampled
/// coarser level. Known texels keep their colour exactly. Without any known texel everything
/// becomes mid grey.
fn push_pull(width: usize, height: usize, colour: &mut [[f32; 3]], known: &[bool]) {
    if known.iter().all(|&k| k) {
        return;
    }
    if !known.iter().any(|&k| k) {
        colour.fill([128.0; 3]);
        return;
    }
    // levels of (width, height, premultiplied colour, weight in [0, 1])
    let mut levels: Vec<Level> = vec![(
        width,
        height,
        colour
            .iter()
            .zip(known)
            .map(|(c, &k)| if k { *c } else { [0.0; 3] })
            .collect(),
        known.iter().map(|&k| if k { 1.0 } else { 0.0 }).collect(),
    )];
    while let Some((w, h, c, wt)) = levels.last().filter(|l| l.0 > 1 || l.1 > 1) {
        let (nw, nh) = (w.div_ceil(2), h.div_ceil(2));
        let mut nc = vec![[0.0f32; 3]; nw * nh];
        let mut nwt = vec![0.0f32; nw * nh];
        for y in 0..nh {
            for x in 0..nw {
                let (mut s, mut sw) = ([0.0f32; 3], 0.0f32);
                for yy in 2 * y..(2 * y + 2).min(*h) {
                    for xx in 2 * x..(2 * x + 2).min(*w) {
                        let i = yy * w + xx;
                        for k in 0..3 {
                            s[k] += c[i][k];
                        }
                        sw += wt[i];
                    }
                }
                if sw > 0.0 {
                    let capped = sw.min(1.0);
                    nc[y * nw + x] = s.map(|v| v / sw * capped);
                    nwt[y * nw + x] = capped;
                }
            }
        }
        levels.push((nw, nh, nc, nwt));
    }
    // push: full colours from the top down
    let Some((_, _, top_c, top_w)) = levels.last() else {
        return;
    };
    let mut full: Vec<[f32; 3]> = top_c
        .iter()
        .zip(top_w)
        .map(|(c, &w)| {
            if w > 0.0 {
                c.map(|v| v / w)
            } else {
                [128.0; 3]
            }
        })
        .collect();
    let (mut fw, mut fh) = (
        levels.last().map_or(1, |l| l.0),
        levels.last().map_or(1, |l| l.1),
    );
    for (w, h, c, wt) in levels.iter().rev().skip(1) {
        let mut next = vec![[0.0f32; 3]; w * h];
        for y in 0..*h {
            let cy = ((y as f32 + 0.5) / 2.0 - 0.5).clamp(0.0, (fh - 1) as f32);
            let (y0, ty) = (cy as usize, cy.fract());
            let y1 = (y0 + 1).min(fh - 1);
            for x in 0..*w {
                let cx = ((x as f32 + 0.5) / 2.0 - 0.5).clamp(0.0, (fw - 1) as f32);
                let (x0, tx) = (cx as usize, cx.fract());
                let x1 = (x0 + 1).min(fw - 1);
                let i = y * w + x;
                let mut out = [0.0f32; 3];
                for k in 0..3 {
                    let top = full[y0 * fw + x0][k] * (1.0 - tx) + full[y0 * fw + x1][k] * tx;
                    let bot = full[y1 * fw + x0][k] * (1.0 - tx) + full[y1 * fw + x1][k] * tx;
                    let up = top * (1.0 - ty) + bot * ty;
                    out[k] = c[i][k] + (1.0 - wt[i]) * up;
                }
                next[i] = out;
            }
        }
        full = next;
        (fw, fh) = (*w, *h);
    }
    for (i, c) in colour.iter_mut().enumerate() {
        if !known[i] {
            *c = full[i];
        }
    }
}

/// Dilates the colours of the `inside` texels `rings` texels outwards: each ring's texels
/// take the mean of their 8-neighbours already inside or dilated.
fn pad(width: usize, height: usize, colour: &mut [[f32; 3]], inside: &[bool], rings: usize) {
    let mut filled = inside.to_vec();
    for _ in 0..rings {
        let mut updates = Vec::new();
        for y in 0..height {
            for x in 0..width {
                if filled[y * width + x] {
                    continue;
                }
                let (mut s, mut count) = ([0.0f32; 3], 0u32);
                for yy in y.saturating_sub(1)..(y + 2).min(height) {
                    for xx in x.saturating_sub(1)..(x + 2).min(width) {
                        let j = yy * width + xx;
                        if filled[j] {
                            for k in 0..3 {
                                s[k] += colour[j][k];
                            }
                            count += 1;
                        }
                    }
                }
                if count > 0 {
                    updates.push((y * width + x, s.map(|v| v / count as f32)));
                }
            }
        }
        if updates.is_empty() {
            break;
        }
        for (i, c) in updates {
            colour[i] = c;
            filled[i] = true;
        }
    }
}
