//! A procedural face texture for synthetic sequences: skin with pores and blotches at several
//! scales, darker brows, lips, nostrils and eye lines painted at the landmarks' texture
//! coordinates. It gives the tracker the kind of detail a real face has (features with strong
//! edges, weak texture elsewhere), and it is deterministic for a seed.

use super::landmarks::IBUG68_TO_MEDIAPIPE;
use super::model::FaceMesh;
use super::render::Texture;
use crate::geometry::SplitMix64;

/// Base skin colour (linear 0..255).
const SKIN: [f32; 3] = [205.0, 160.0, 135.0];

/// A `size × size` face texture for `mesh` (MediaPipe vertex order), seeded.
pub fn procedural_face_texture(mesh: &FaceMesh, size: usize, seed: u64) -> Texture {
    let size = size.max(16);
    let mut tex = Texture::filled(size, size, SKIN);
    let mut rng = SplitMix64::new(seed ^ 0x5EED_FACE);
    // value noise at three scales
    for (cells, amp) in [(6usize, 14.0f32), (24, 8.0), (96, 5.0)] {
        let g: Vec<f32> = (0..(cells + 1) * (cells + 1))
            .map(|_| rng.range(-1.0, 1.0) as f32)
            .collect();
        for y in 0..size {
            for x in 0..size {
                let fx = x as f32 / size as f32 * cells as f32;
                let fy = y as f32 / size as f32 * cells as f32;
                let (ix, iy) = (fx as usize, fy as usize);
                let (tx, ty) = (fx - ix as f32, fy - iy as f32);
                let (sx, sy) = (tx * tx * (3.0 - 2.0 * tx), ty * ty * (3.0 - 2.0 * ty));
                let at = |i: usize, j: usize| g[j.min(cells) * (cells + 1) + i.min(cells)];
                let a = at(ix, iy) + (at(ix + 1, iy) - at(ix, iy)) * sx;
                let b = at(ix, iy + 1) + (at(ix + 1, iy + 1) - at(ix, iy + 1)) * sx;
                let n = (a + (b - a) * sy) * amp;
                let p = &mut tex.rgb[y * size + x];
                p[0] += n;
                p[1] += n * 0.9;
                p[2] += n * 0.8;
            }
        }
    }
    // freckles
    for _ in 0..size * size / 400 {
        let (cx, cy) = (rng.range(0.0, size as f64), rng.range(0.0, size as f64));
        let r = rng.range(0.6, 1.6) * size as f64 / 512.0;
        disc(&mut tex, [cx, cy], r.max(0.7), [150.0, 100.0, 80.0], 0.5);
    }
    let uv = |i: usize| {
        let [a, b] = IBUG68_TO_MEDIAPIPE[i];
        let (ua, ub) = (mesh.uvs[a], mesh.uvs[b]);
        let u = 0.5 * (ua[0] + ub[0]);
        let v = 0.5 * (ua[1] + ub[1]);
        [u * size as f64, (1.0 - v) * size as f64]
    };
    let px = size as f64 / 512.0;
    // lips: outer contour filled
    let lips: Vec<[f64; 2]> = (48..60).map(uv).collect();
    polygon(&mut tex, &lips, [165.0, 70.0, 75.0], 0.85);
    // the mouth's inside (dark) shows when the jaw opens and stretches these texels
    let inner: Vec<[f64; 2]> = (60..68).map(uv).collect();
    polygon(&mut tex, &inner, [60.0, 20.0, 25.0], 0.95);
    polyline(&mut tex, &inner, true, 2.0 * px, [90.0, 30.0, 35.0], 0.9);
    // brows
    for range in [17..22, 22..27] {
        let pts: Vec<[f64; 2]> = range.map(uv).collect();
        polyline(&mut tex, &pts, false, 7.0 * px, [70.0, 45.0, 35.0], 0.9);
    }
    // eye outlines and lashes
    for range in [36..42, 42..48] {
        let pts: Vec<[f64; 2]> = range.map(uv).collect();
        polygon(&mut tex, &pts, [235.0, 230.0, 225.0], 0.9);
        polyline(&mut tex, &pts, true, 2.5 * px, [40.0, 25.0, 20.0], 0.95);
        let c = pts
            .iter()
            .fold([0.0, 0.0], |a, p| [a[0] + p[0] / 6.0, a[1] + p[1] / 6.0]);
        disc(&mut tex, c, 5.0 * px, [70.0, 50.0, 40.0], 0.95);
    }
    // nostrils and the nose base line
    let base: Vec<[f64; 2]> = (31..36).map(uv).collect();
    polyline(&mut tex, &base, false, 2.5 * px, [120.0, 70.0, 60.0], 0.8);
    for k in [32, 34] {
        disc(&mut tex, uv(k), 4.0 * px, [80.0, 40.0, 35.0], 0.9);
    }
    tex
}

fn blend(p: &mut [f32; 3], c: [f32; 3], a: f32) {
    for k in 0..3 {
        p[k] += (c[k] - p[k]) * a;
    }
}

fn disc(tex: &mut Texture, c: [f64; 2], r: f64, colour: [f32; 3], alpha: f32) {
    let (w, h) = (tex.width as i64, tex.height as i64);
    let (x0, x1) = ((c[0] - r).floor() as i64, (c[0] + r).ceil() as i64);
    let (y0, y1) = ((c[1] - r).floor() as i64, (c[1] + r).ceil() as i64);
    for y in y0.max(0)..=y1.min(h - 1) {
        for x in x0.max(0)..=x1.min(w - 1) {
            let d = ((x as f64 + 0.5 - c[0]).powi(2) + (y as f64 + 0.5 - c[1]).powi(2)).sqrt();
            if d <= r {
                blend(&mut tex.rgb[(y * w + x) as usize], colour, alpha);
            }
        }
    }
}

fn polygon(tex: &mut Texture, pts: &[[f64; 2]], colour: [f32; 3], alpha: f32) {
    let (w, h) = (tex.width as i64, tex.height as i64);
    let x0 = pts
        .iter()
        .map(|p| p[0])
        .fold(f64::INFINITY, f64::min)
        .floor() as i64;
    let x1 = pts
        .iter()
        .map(|p| p[0])
        .fold(f64::NEG_INFINITY, f64::max)
        .ceil() as i64;
    let y0 = pts
        .iter()
        .map(|p| p[1])
        .fold(f64::INFINITY, f64::min)
        .floor() as i64;
    let y1 = pts
        .iter()
        .map(|p| p[1])
        .fold(f64::NEG_INFINITY, f64::max)
        .ceil() as i64;
    for y in y0.max(0)..=y1.min(h - 1) {
        for x in x0.max(0)..=x1.min(w - 1) {
            let q = [x as f64 + 0.5, y as f64 + 0.5];
            let mut inside = false;
            for i in 0..pts.len() {
                let (a, b) = (pts[i], pts[(i + 1) % pts.len()]);
                if (a[1] > q[1]) != (b[1] > q[1])
                    && q[0] < a[0] + (q[1] - a[1]) / (b[1] - a[1]) * (b[0] - a[0])
                {
                    inside = !inside;
                }
            }
            if inside {
                blend(&mut tex.rgb[(y * w + x) as usize], colour, alpha);
            }
        }
    }
}

fn polyline(
    tex: &mut Texture,
    pts: &[[f64; 2]],
    closed: bool,
    width: f64,
    colour: [f32; 3],
    alpha: f32,
) {
    let n = pts.len();
    let segs = if closed { n } else { n.saturating_sub(1) };
    let (w, h) = (tex.width as i64, tex.height as i64);
    let r = width / 2.0;
    for s in 0..segs {
        let (a, b) = (pts[s], pts[(s + 1) % n]);
        let x0 = (a[0].min(b[0]) - r).floor() as i64;
        let x1 = (a[0].max(b[0]) + r).ceil() as i64;
        let y0 = (a[1].min(b[1]) - r).floor() as i64;
        let y1 = (a[1].max(b[1]) + r).ceil() as i64;
        for y in y0.max(0)..=y1.min(h - 1) {
            for x in x0.max(0)..=x1.min(w - 1) {
                let q = [x as f64 + 0.5, y as f64 + 0.5];
                let d = [b[0] - a[0], b[1] - a[1]];
                let l2 = d[0] * d[0] + d[1] * d[1];
                let t = if l2 > 0.0 {
                    (((q[0] - a[0]) * d[0] + (q[1] - a[1]) * d[1]) / l2).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                let e = [a[0] + t * d[0] - q[0], a[1] + t * d[1] - q[1]];
                if e[0] * e[0] + e[1] * e[1] <= r * r {
                    blend(&mut tex.rgb[(y * w + x) as usize], colour, alpha);
                }
            }
        }
    }
}
