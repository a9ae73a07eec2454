//! The z-buffered vertex-colour rasterizer of the vision code: the body tracker and its
//! synthetic sequences, and the face tracker, renderer, texture baker and previews.
//!
//! [`project_vertices`] maps world points through a [`Camera`] (distortion included) to pixel
//! coordinates and camera depth; [`draw_triangles`] fills triangles into a [`RasterTarget`]
//! (depth buffer plus colour buffer), nearest depth winning, colours interpolated linearly in
//! the image (Gouraud), depth interpolated as `1/z` (exact for planar triangles).
//!
//! Conventions: pixel `(x, y)` is sampled at its centre. In the coordinates of
//! [`project_vertices`] (the [`Camera`]'s: pixel `(0, 0)` is the centre of the top-left pixel)
//! that centre is the point `(x, y)`; counting pixel squares as `[x, x+1) × [y, y+1)` it is
//! `(x + 0.5, y + 0.5)`. A triangle covers a pixel when it contains the pixel's centre.
//! Vertices are snapped to 1/256 pixel and edge functions are evaluated in exact integer
//! arithmetic with the top-left fill rule, so two triangles sharing an edge never draw a pixel
//! twice and leave no gap. Both windings are drawn (no culling).
//!
//! The tracker calls [`draw_triangles`] thousands of times per frame: nothing here allocates
//! once the buffers have their size, and [`RasterTarget::clear`] only resets the box touched
//! since the previous clear.

use crate::geometry::{Camera, Vec3};

/// Depth (metres, camera frame) at or below which a projected vertex is invalid (behind the
/// camera or too close to it); [`project_vertices`] writes `z = 0` for such points.
pub const NEAR: f32 = 0.05;

/// Sub-pixel precision of the snapped vertex coordinates (1/256 pixel).
const SUBPIXEL: f64 = 256.0;

/// Largest projected coordinate magnitude (pixels) drawn; triangles reaching further are
/// skipped (they can only come from points nearly in the camera plane).
const MAX_COORD: f32 = 1.0e6;

/// A box of pixels `(x0, y0, x1, y1)`, exclusive ends.
pub type PixelBox = (usize, usize, usize, usize);

/// A depth buffer and a colour buffer of one image, with the box touched since the last
/// [`clear`](RasterTarget::clear).
#[derive(Clone, Debug)]
pub struct RasterTarget {
    /// Image width, pixels.
    pub width: usize,
    /// Image height, pixels.
    pub height: usize,
    /// Camera depth of the nearest surface per pixel, row-major; `+∞` where nothing was drawn.
    pub depth: Vec<f32>,
    /// Colour of the nearest surface per pixel, row-major, linear 0..255; `[0, 0, 0]` where
    /// nothing was drawn.
    pub rgb: Vec<[f32; 3]>,
    /// Touched box `x0, y0, x1, y1` (exclusive ends); empty when `x0 >= x1`.
    touched: (usize, usize, usize, usize),
}

impl RasterTarget {
    /// An empty target of `width × height` pixels.
    pub fn new(width: usize, height: usize) -> Self {
        RasterTarget {
            width,
            height,
            depth: vec![f32::INFINITY; width * height],
            rgb: vec![[0.0; 3]; width * height],
            touched: (0, 0, 0, 0),
        }
    }

    /// Resets depth to `+∞` and colour to black inside the box touched since the last clear
    /// (everything outside it is already clear).
    pub fn clear(&mut self) {
        let (x0, y0, x1, y1) = self.touched;
        if x0 < x1 && y0 < y1 {
            for y in y0..y1 {
                let row = y * self.width;
                self.depth[row + x0..row + x1].fill(f32::INFINITY);
                self.rgb[row + x0..row + x1].fill([0.0; 3]);
            }
        }
        self.touched = (0, 0, 0, 0);
    }

    /// The box `(x0, y0, x1, y1)` (exclusive ends) that drawing may have changed since the last
    /// clear; `None` when nothing was drawn.
    pub fn touched(&self) -> Option<(usize, usize, usize, usize)> {
        let (x0, y0, x1, y1) = self.touched;
        (x0 < x1 && y0 < y1).then_some(self.touched)
    }

    /// Makes this target equal to `base` (same size), copying only where they can differ:
    /// inside `changed` when given (the caller knows this target is `base` plus draws inside
    /// that box, e.g. the box [`draw_triangles`] returned after the last restore), else
    /// inside both touched boxes. The touched box becomes `base`'s. Targets of another size
    /// are left as they are (returns false).
    pub fn restore_from(&mut self, base: &RasterTarget, changed: Option<PixelBox>) -> bool {
        if base.width != self.width || base.height != self.height {
            return false;
        }
        let boxes = |a: PixelBox, b: PixelBox| {
            if a.0 >= a.2 || a.1 >= a.3 {
                b
            } else if b.0 >= b.2 || b.1 >= b.3 {
                a
            } else {
                (a.0.min(b.0), a.1.min(b.1), a.2.max(b.2), a.3.max(b.3))
            }
        };
        let (x0, y0, x1, y1) = changed.unwrap_or_else(|| boxes(self.touched, base.touched));
        let (x1, y1) = (x1.min(self.width), y1.min(self.height));
        if x0 < x1 && y0 < y1 {
            for y in y0..y1 {
                let row = y * self.width;
                self.depth[row + x0..row + x1].copy_from_slice(&base.depth[row + x0..row + x1]);
                self.rgb[row + x0..row + x1].copy_from_slice(&base.rgb[row + x0..row + x1]);
            }
        }
        self.touched = base.touched;
        true
    }

    /// Whether something was drawn at pixel `(x, y)` (false outside the image).
    pub fn covered(&self, x: usize, y: usize) -> bool {
        x < self.width && y < self.height && self.depth[y * self.width + x].is_finite()
    }

    fn touch(&mut self, x0: usize, y0: usize, x1: usize, y1: usize) {
        let t = &mut self.touched;
        if t.0 >= t.2 {
            *t = (x0, y0, x1, y1);
        } else {
            *t = (t.0.min(x0), t.1.min(y0), t.2.max(x1), t.3.max(y1));
        }
    }
}

/// Projects world points through `camera` into `out` (resized, reused): pixel `x`, `y` and
/// camera depth `z` (metres). Points with `z <= NEAR`, or outside the region where the radial
/// distortion is monotonic (where it would fold the image back), get `[0, 0, 0]`: invalid,
/// so the triangles using them are skipped.
pub fn project_vertices(camera: &Camera, positions: &[Vec3], out: &mut Vec<[f32; 3]>) {
    out.clear();
    out.extend(positions.iter().map(|p| {
        let pc = camera.to_camera_frame(p);
        if pc.z.is_nan() || pc.z <= NEAR as f64 {
            return [0.0; 3];
        }
        let (x, y) = (pc.x / pc.z, pc.y / pc.z);
        let r2 = x * x + y * y;
        if 1.0 + 3.0 * camera.k1 * r2 + 5.0 * camera.k2 * r2 * r2 <= 0.0 {
            return [0.0; 3];
        }
        let uv = camera.project_camera_frame_unchecked(&pc);
        if uv[0].is_finite() && uv[1].is_finite() {
            [uv[0] as f32, uv[1] as f32, pc.z as f32]
        } else {
            [0.0; 3]
        }
    }));
}

/// Whether a projected vertex can be drawn.
#[inline]
fn valid(p: &[f32; 3]) -> bool {
    p[2] > NEAR && p[0].abs() < MAX_COORD && p[1].abs() < MAX_COORD
}

/// Draws `triangles` (indices into `projected` and `colours`, which must have the same
/// length; out-of-range indices skip the triangle) into `target`: both windings, Gouraud
/// colours, nearest depth wins, top-left fill rule, clipped to the image. Triangles with an
/// invalid vertex (see [`project_vertices`]) or no area are skipped. Returns the box
/// `(x0, y0, x1, y1)` (exclusive ends) that this call may have changed, `None` when it drew
/// nothing (the target's own touched box also covers what earlier draws changed).
pub fn draw_triangles(
    target: &mut RasterTarget,
    projected: &[[f32; 3]],
    colours: &[[f32; 3]],
    triangles: &[[u32; 3]],
) -> Option<PixelBox> {
    let n = projected.len().min(colours.len());
    let mut drawn: Option<PixelBox> = None;
    for t in triangles {
        let (i0, i1, i2) = (t[0] as usize, t[1] as usize, t[2] as usize);
        if i0 >= n || i1 >= n || i2 >= n {
            continue;
        }
        if let Some(b) = draw_one(
            target,
            [&projected[i0], &projected[i1], &projected[i2]],
            [&colours[i0], &colours[i1], &colours[i2]],
        ) {
            drawn = Some(match drawn {
                None => b,
                Some(d) => (d.0.min(b.0), d.1.min(b.1), d.2.max(b.2), d.3.max(b.3)),
            });
        }
    }
    drawn
}

/// Draws one triangle (see [`draw_triangles`]).
#[inline]
fn draw_one(target: &mut RasterTarget, p: [&[f32; 3]; 3], c: [&[f32; 3]; 3]) -> Option<PixelBox> {
    if !(valid(p[0]) && valid(p[1]) && valid(p[2])) {
        return None;
    }
    let corners = p.map(|p| [p[0] as f64, p[1] as f64]);
    let scan = TriangleScan::new(corners, target.width, target.height)?;
    let (x0, y0, x1, y1) = scan.pixel_box();
    target.touch(x0, y0, x1, y1);
    let order = scan.order();
    let pz = [p[order[0]][2], p[order[1]][2], p[order[2]][2]];
    let iz = [1.0 / pz[0], 1.0 / pz[1], 1.0 / pz[2]];
    let col = [c[order[0]], c[order[1]], c[order[2]]];
    let width = target.width;
    scan.for_each(|x, y, l| {
        let inv_z = l[0] * iz[0] + l[1] * iz[1] + l[2] * iz[2];
        let z = 1.0 / inv_z;
        let i = y * width + x;
        if z < target.depth[i] {
            target.depth[i] = z;
            target.rgb[i] = [
                l[0] * col[0][0] + l[1] * col[1][0] + l[2] * col[2][0],
                l[0] * col[0][1] + l[1] * col[1][1] + l[2] * col[2][1],
                l[0] * col[0][2] + l[1] * col[1][2] + l[2] * col[2][2],
            ];
        }
    });
    Some((x0, y0, x1, y1))
}

/// The pixel traversal of one triangle, shared by every triangle fill of the crate (this
/// module's [`draw_triangles`] and the shaded pictures of [`super::picture`]): the corners
/// snapped to 1/256 pixel, integer edge functions, the top-left fill rule, pixel `(x, y)`
/// sampled at the point `(x, y)` of the corner coordinates (see the module conventions).
/// Barycentric weights are given in the scan's vertex order ([`TriangleScan::order`]), which
/// makes the triangle counter-clockwise in pixel coordinates.
#[derive(Clone, Copy, Debug)]
pub struct TriangleScan {
    /// Covered-pixel candidates `x0..x1 × y0..y1` (clipped to the image).
    bounds: (usize, usize, usize, usize),
    /// Edge functions (biased by the fill rule) at the first candidate of the first row.
    w_row: [i64; 3],
    step_x: [i64; 3],
    step_y: [i64; 3],
    /// Fill-rule bias of each edge, added back to form the weights.
    bias: [f32; 3],
    inv_area: f32,
    order: [usize; 3],
}

impl TriangleScan {
    /// Sets up the traversal of the triangle with corners `p` (pixel coordinates) in an image
    /// of `width × height` pixels. `None` when the triangle has no area once snapped, covers
    /// no pixel centre's box inside the image, or has a corner that is not finite or lies
    /// farther than 10⁶ pixels from the origin.
    pub fn new(p: [[f64; 2]; 3], width: usize, height: usize) -> Option<Self> {
        let lim = MAX_COORD as f64;
        if !p.iter().flatten().all(|c| c.abs() < lim) {
            return None;
        }
        let snap = |v: f64| (v * SUBPIXEL).round() as i64;
        let mut v = p.map(|q| (snap(q[0]), snap(q[1])));
        let mut order = [0usize, 1, 2];
        let mut area = edge(v[0], v[1], v[2]);
        if area == 0 {
            return None;
        }
        if area < 0 {
            v.swap(1, 2);
            order.swap(1, 2);
            area = -area;
        }
        // pixel range whose centres (integer coordinates) may be inside
        let s = SUBPIXEL as i64;
        let (min_x, max_x) = (
            v[0].0.min(v[1].0).min(v[2].0),
            v[0].0.max(v[1].0).max(v[2].0),
        );
        let (min_y, max_y) = (
            v[0].1.min(v[1].1).min(v[2].1),
            v[0].1.max(v[1].1).max(v[2].1),
        );
        let x0 = (min_x + s - 1).div_euclid(s).max(0);
        let y0 = (min_y + s - 1).div_euclid(s).max(0);
        let x1 = (max_x.div_euclid(s) + 1).min(width as i64);
        let y1 = (max_y.div_euclid(s) + 1).min(height as i64);
        if x0 >= x1 || y0 >= y1 {
            return None;
        }
        // edge k is opposite vertex k: w_k(q) = edge(v[k+1], v[k+2], q); a pixel on an edge
        // is inside only for top-left edges (bias −1 on the others, the test being w >= 0)
        let e = [(1usize, 2usize), (2, 0), (0, 1)];
        let mut w_row = [0i64; 3];
        let mut step_x = [0i64; 3];
        let mut step_y = [0i64; 3];
        let mut bias = [0f32; 3];
        let start = (x0 * s, y0 * s);
        for k in 0..3 {
            let (a, b) = (v[e[k].0], v[e[k].1]);
            let (dx, dy) = (b.0 - a.0, b.1 - a.1);
            let top_left = dy < 0 || (dy == 0 && dx > 0);
            w_row[k] = edge(a, b, start) - i64::from(!top_left);
            bias[k] = f32::from(u8::from(!top_left));
            step_x[k] = -dy * s;
            step_y[k] = dx * s;
        }
        Some(TriangleScan {
            bounds: (x0 as usize, y0 as usize, x1 as usize, y1 as usize),
            w_row,
            step_x,
            step_y,
            bias,
            inv_area: 1.0 / area as f32,
            order,
        })
    }

    /// The candidate pixels `(x0, y0, x1, y1)` (exclusive ends), inside the image.
    pub fn pixel_box(&self) -> (usize, usize, usize, usize) {
        self.bounds
    }

    /// Weight `k` of [`for_each`](Self::for_each) belongs to corner `order()[k]` of the
    /// corners given to [`new`](Self::new).
    pub fn order(&self) -> [usize; 3] {
        self.order
    }

    /// Calls `visit(x, y, weights)` for every covered pixel, row by row, with the barycentric
    /// weights of its centre in scan order.
    #[inline(always)]
    pub fn for_each(&self, mut visit: impl FnMut(usize, usize, [f32; 3])) {
        let (x0, y0, x1, y1) = self.bounds;
        let mut w_row = self.w_row;
        let (bias, inv_area) = (self.bias, self.inv_area);
        for y in y0..y1 {
            let mut w = w_row;
            for x in x0..x1 {
                if (w[0] | w[1] | w[2]) >= 0 {
                    // barycentric weights (the fill-rule biases added back)
                    let l = [
                        (w[0] as f32 + bias[0]) * inv_area,
                        (w[1] as f32 + bias[1]) * inv_area,
                        (w[2] as f32 + bias[2]) * inv_area,
                    ];
                    visit(x, y, l);
                }
                for k in 0..3 {
                    w[k] += self.step_x[k];
                }
            }
            for k in 0..3 {
                w_row[k] += self.step_y[k];
            }
        }
    }
}

/// Doubled signed area of `(a, b, q)` in snapped integer coordinates.
#[inline]
fn edge(a: (i64, i64), b: (i64, i64), q: (i64, i64)) -> i64 {
    (b.0 - a.0) * (q.1 - a.1) - (b.1 - a.1) * (q.0 - a.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn count(t: &RasterTarget) -> usize {
        t.depth.iter().filter(|d| d.is_finite()).count()
    }

    #[test]
    fn square_of_two_triangles_covers_its_pixels_once() {
        // square from (2.3, 1.7) to (12.3, 9.7) in projected coordinates: pixel centres with
        // x in 3..=12 and y in 2..=9 → 10 × 8 pixels, whatever the diagonal or winding
        let p = [
            [2.3, 1.7, 2.0],
            [12.3, 1.7, 2.0],
            [12.3, 9.7, 2.0],
            [2.3, 9.7, 2.0],
        ];
        let c = [[10.0, 20.0, 30.0]; 4];
        for tris in [
            [[0u32, 1, 2], [0, 2, 3]],
            [[0, 2, 1], [3, 2, 0]],
            [[0, 1, 3], [1, 2, 3]],
        ] {
            let mut t = RasterTarget::new(20, 15);
            draw_triangles(&mut t, &p, &c, &tris);
            assert_eq!(count(&t), 80);
            assert_eq!(t.touched().map(|b| (b.0, b.1)), Some((3, 2)));
            assert!(t.covered(3, 2) && t.covered(12, 9) && !t.covered(13, 9) && !t.covered(3, 10));
            let rgb = t.rgb[5 * 20 + 5];
            assert!(
                (0..3).all(|i| (rgb[i] - [10.0, 20.0, 30.0][i]).abs() < 1e-3),
                "{rgb:?}"
            );
            t.clear();
            assert_eq!(count(&t), 0);
            assert!(t.touched().is_none());
        }
        // integer-aligned edges: a 4 × 4 square from (0.5, 0.5) drawn exactly once per pixel,
        // and a mesh of 2 × 2 such squares as well (shared edges through pixel centres)
        let mut t = RasterTarget::new(10, 10);
        let q = [
            [1.0, 1.0, 1.0],
            [5.0, 1.0, 1.0],
            [5.0, 5.0, 1.0],
            [1.0, 5.0, 1.0],
            [3.0, 3.0, 1.0],
        ];
        let fan = [[0u32, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]];
        draw_triangles(&mut t, &q, &[[1.0; 3]; 5], &fan);
        assert_eq!(count(&t), 16);
    }

    #[test]
    fn nearest_depth_wins_in_any_order_and_clipping_holds() {
        let near = [[-5.0, -5.0, 2.0], [30.0, -5.0, 2.0], [-5.0, 30.0, 2.0]];
        let far = [[-5.0, -5.0, 3.0], [30.0, -5.0, 3.0], [-5.0, 30.0, 3.0]];
        let mut p = near.to_vec();
        p.extend_from_slice(&far);
        let mut c = vec![[200.0, 0.0, 0.0]; 3];
        c.extend_from_slice(&[[0.0, 0.0, 200.0]; 3]);
        for tris in [[[0u32, 1, 2], [3, 4, 5]], [[3, 4, 5], [0, 1, 2]]] {
            let mut t = RasterTarget::new(8, 6);
            draw_triangles(&mut t, &p, &c, &tris);
            assert_eq!(count(&t), 48);
            assert!(t.rgb.iter().all(|v| v[0] > 199.0 && v[2] < 1.0));
            assert!(t.depth.iter().all(|&d| (d - 2.0).abs() < 1e-5));
            assert_eq!(t.touched(), Some((0, 0, 8, 6)));
        }
        // a vertex behind the camera skips the triangle
        let mut t = RasterTarget::new(8, 6);
        let bad = [[0.0, 0.0, 2.0], [7.0, 0.0, 2.0], [0.0, 5.0, 0.0]];
        draw_triangles(&mut t, &bad, &[[1.0; 3]; 3], &[[0, 1, 2], [0, 1, 7]]);
        assert_eq!(count(&t), 0);
    }

    #[test]
    fn jittered_mesh_has_no_holes_and_no_overdraw() {
        // an 8 × 6 grid of quads over (2.3, 1.7)–(50.3, 37.7), inner vertices jittered, random
        // diagonals and windings: covers the 48 × 36 pixel centres inside, each exactly once
        let mut rng = crate::geometry::SplitMix64::new(5);
        let (nx, ny) = (8usize, 6usize);
        let mut p = Vec::new();
        for j in 0..=ny {
            for i in 0..=nx {
                let inner = i > 0 && i < nx && j > 0 && j < ny;
                let jit = |r: &mut crate::geometry::SplitMix64| {
                    if inner {
                        r.range(-2.0, 2.0)
                    } else {
                        0.0
                    }
                };
                let x = 2.3 + 6.0 * i as f32 + jit(&mut rng) as f32;
                let y = 1.7 + 6.0 * j as f32 + jit(&mut rng) as f32;
                p.push([x, y, 1.0 + 0.01 * i as f32]);
            }
        }
        let id = |i: usize, j: usize| (j * (nx + 1) + i) as u32;
        let mut tris = Vec::new();
        for j in 0..ny {
            for i in 0..nx {
                let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
                let pair = if rng.bit() {
                    [[a, b, c], [a, c, d]]
                } else {
                    [[a, b, d], [b, c, d]]
                };
                for t in pair {
                    tris.push(if rng.bit() { t } else { [t[0], t[2], t[1]] });
                }
            }
        }
        let colours = vec![[1.0; 3]; p.len()];
        let mut all = RasterTarget::new(60, 45);
        draw_triangles(&mut all, &p, &colours, &tris);
        assert_eq!(count(&all), 48 * 36);
        let mut one = RasterTarget::new(60, 45);
        let mut sum = 0;
        for t in &tris {
            one.clear();
            draw_triangles(&mut one, &p, &colours, std::slice::from_ref(t));
            sum += count(&one);
        }
        assert_eq!(sum, 48 * 36, "pixels drawn by more than one triangle");
    }

    #[test]
    fn a_target_restored_from_a_base_is_the_base_again_and_the_draw_box_is_returned() {
        let mut base = RasterTarget::new(20, 10);
        let tri = [[1.0, 1.0, 2.0], [8.0, 1.0, 2.0], [1.0, 8.0, 2.0]];
        assert_eq!(
            draw_triangles(&mut base, &tri, &[[9.0; 3]; 3], &[[0, 1, 2]]),
            Some((1, 1, 9, 9))
        );
        // a target that drew something else elsewhere, then restored in full
        let mut t = RasterTarget::new(20, 10);
        let other = [[12.0, 2.0, 1.0], [18.0, 2.0, 1.0], [12.0, 9.0, 1.0]];
        let drawn = draw_triangles(&mut t, &other, &[[5.0; 3]; 3], &[[0, 1, 2]]);
        assert_eq!(drawn, Some((12, 2, 19, 10)));
        assert!(t.restore_from(&base, None));
        assert_eq!(
            (&t.depth, &t.rgb, t.touched()),
            (&base.depth, &base.rgb, base.touched())
        );
        // a draw over the restored target, restored by its box alone
        let drawn = draw_triangles(&mut t, &other, &[[5.0; 3]; 3], &[[0, 1, 2]]);
        assert_eq!(t.touched(), Some((1, 1, 19, 10)));
        assert!(t.restore_from(&base, drawn));
        assert_eq!(
            (&t.depth, &t.rgb, t.touched()),
            (&base.depth, &base.rgb, base.touched())
        );
        // nothing drawn: no box
        assert_eq!(draw_triangles(&mut t, &other, &[[5.0; 3]; 3], &[]), None);
        assert!(!t.restore_from(&RasterTarget::new(4, 4), None));
    }
}
