//! The signed error map between two face surfaces (seed report §5.2, figure 8): how far, and
//! on which side, each vertex of one mesh lies from the other surface, coloured and rendered.
//!
//! This file owns:
//! - [`signed_distances`]: per vertex of `a`, the distance to the closest point of surface `b`
//!   (exact point–triangle distance, every triangle tried, pruned by bounding boxes; parallel
//!   over vertices), positive when the vertex lies outside `b` (on the side of `b`'s outward
//!   normal, interpolated from its vertex normals at the closest point);
//! - [`ErrorStats`]: mean absolute, RMS and largest absolute distance;
//! - [`error_colours`]: the figure's colours — red for negative, green for positive, black at
//!   zero, brightness proportional to `|d| / scale` (saturating at `scale`);
//! - [`error_map_image`] and [`render_error_map`]: the mesh rendered through a camera with
//!   those per-vertex colours (Gouraud, z-buffered, on white) above a legend strip: the colour
//!   bar from `−scale` to `+scale`, labelled in millimetres.

use std::path::Path;

use image::RgbImage;
use plotters::prelude::*;
use rayon::prelude::*;

use super::{FaceError, FaceMesh};
use crate::geometry::Camera;
use crate::geometry::Vec3;
use crate::render::plot::{register_embedded_font, FONT_FAMILY};
use crate::render::raster::{draw_triangles, project_vertices, RasterTarget};

/// Height in pixels of the legend strip [`error_map_image`] adds below the render.
pub const LEGEND_HEIGHT: u32 = 48;

/// Largest image side [`error_map_image`] renders, pixels.
pub const MAX_IMAGE_SIZE: u32 = 8192;

/// Background of the rendered error map (white, so that black, zero error, shows).
const BACKGROUND: [u8; 3] = [255, 255, 255];

/// Summary of signed distances (non-finite values ignored).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ErrorStats {
    /// Number of finite distances summarised.
    pub count: usize,
    /// Mean signed distance (m).
    pub mean: f64,
    /// Mean absolute distance (m).
    pub mean_abs: f64,
    /// Root mean square distance (m).
    pub rms: f64,
    /// Largest absolute distance (m).
    pub max_abs: f64,
}

impl ErrorStats {
    /// The statistics of `distances`; all zero when none is finite.
    pub fn of(distances: &[f64]) -> ErrorStats {
        let finite = distances.iter().copied().filter(|d| d.is_finite());
        let (mut s, mut sa, mut s2, mut max, mut n) = (0.0, 0.0, 0.0, 0.0f64, 0usize);
        for d in finite {
            s += d;
            sa += d.abs();
            s2 += d * d;
            max = max.max(d.abs());
            n += 1;
        }
        if n == 0 {
            return ErrorStats::default();
        }
        let nf = n as f64;
        ErrorStats {
            count: n,
            mean: s / nf,
            mean_abs: sa / nf,
            rms: (s2 / nf).sqrt(),
            max_abs: max,
        }
    }
}

/// The closest point to `p` on triangle `(a, b, c)` as barycentric coordinates (Ericson,
/// *Real-Time Collision Detection*, §5.1.5).
fn closest_on_triangle(p: &Vec3, a: &Vec3, b: &Vec3, c: &Vec3) -> [f64; 3] {
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(&ap), ac.dot(&ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return [1.0, 0.0, 0.0];
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(&bp), ac.dot(&bp));
    if d3 >= 0.0 && d4 <= d3 {
        return [0.0, 1.0, 0.0];
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return [1.0 - v, v, 0.0];
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(&cp), ac.dot(&cp));
    if d6 >= 0.0 && d5 <= d6 {
        return [0.0, 0.0, 1.0];
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return [1.0 - w, 0.0, w];
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return [0.0, 1.0 - w, w];
    }
    let denom = va + vb + vc;
    if denom == 0.0 || denom.is_nan() {
        return [1.0, 0.0, 0.0];
    }
    let (v, w) = (vb / denom, vc / denom);
    [1.0 - v - w, v, w]
}

/// Signed distance (m) from each vertex of `a` to the surface of `b`: the distance to the
/// closest point of `b`'s triangles, positive when the vertex lies on the outer side of `b`
/// (along `b`'s outward normal there, interpolated from its vertex normals), negative inside.
///
/// Triangles of `b` with out-of-range indices or non-finite vertices are skipped; vertices of
/// `a` get `NaN` when `b` has no usable triangle or the vertex is not finite.
pub fn signed_distances(a: &FaceMesh, b: &FaceMesh) -> Vec<f64> {
    let nb = b.positions.len();
    let normals = b.vertex_normals();
    // usable triangles with their bounding boxes
    let tris: Vec<([usize; 3], Vec3, Vec3)> = b
        .triangles
        .iter()
        .filter_map(|t| {
            let t = t.map(|i| i as usize);
            if t.iter().any(|&i| i >= nb) {
                return None;
            }
            let [p, q, r] = t.map(|i| b.positions[i]);
            if ![p, q, r].iter().all(|v| v.iter().all(|c| c.is_finite())) {
                return None;
            }
            Some((t, p.inf(&q).inf(&r), p.sup(&q).sup(&r)))
        })
        .collect();
    a.positions
        .par_iter()
        .map(|p| {
            if !p.iter().all(|c| c.is_finite()) {
                return f64::NAN;
            }
            let mut best = (f64::INFINITY, None);
            for (t, lo, hi) in &tris {
                // distance to the box is a lower bound of the distance to the triangle
                let gap = (lo - p).sup(&(p - hi)).sup(&Vec3::zeros());
                if gap.norm_squared() >= best.0 {
                    continue;
                }
                let [x, y, z] = t.map(|i| b.positions[i]);
                let bc = closest_on_triangle(p, &x, &y, &z);
                let q = x * bc[0] + y * bc[1] + z * bc[2];
                let d2 = (p - q).norm_squared();
                if d2 < best.0 {
                    best = (d2, Some((*t, bc, q)));
                }
            }
            let Some((t, bc, q)) = best.1 else {
                return f64::NAN;
            };
            let dist = best.0.sqrt();
            let n = normals[t[0]] * bc[0] + normals[t[1]] * bc[1] + normals[t[2]] * bc[2];
            let n = if n.norm() > 1e-12 {
                n
            } else {
                let [x, y, z] = t.map(|i| b.positions[i]);
                (y - x).cross(&(z - x))
            };
            if (p - q).dot(&n) < 0.0 {
                -dist
            } else {
                dist
            }
        })
        .collect()
}

/// Colours (linear 0..255) of signed distances: black at zero, green for positive, red for
/// negative, the channel proportional to `|d| / scale` and saturating at `scale` (m). A
/// non-finite distance, or a `scale` that is not finite and positive, gives mid grey.
pub fn error_colours(distances: &[f64], scale: f64) -> Vec<[f32; 3]> {
    let ok = scale.is_finite() && scale > 0.0;
    distances
        .iter()
        .map(|&d| {
            if !(ok && d.is_finite()) {
                return [128.0; 3];
            }
            let t = (d.abs() / scale).min(1.0) as f32 * 255.0;
            if d >= 0.0 {
                [0.0, t, 0.0]
            } else {
                [t, 0.0, 0.0]
            }
        })
        .collect()
}

/// Renders the error map: `mesh` through `camera` with the per-vertex colours of
/// [`error_colours`]`(distances, scale)`, on white, above a legend strip of [`LEGEND_HEIGHT`]
/// pixels holding the colour bar from `−scale` to `+scale` labelled in millimetres. The image
/// is `camera.width × (camera.height + LEGEND_HEIGHT)`.
///
/// Fails, naming the parameter, when `distances` does not have one value per vertex, `scale`
/// is not finite and positive, or the camera image is empty or larger than
/// [`MAX_IMAGE_SIZE`].
pub fn error_map_image(
    mesh: &FaceMesh,
    distances: &[f64],
    camera: &Camera,
    scale: f64,
) -> Result<RgbImage, FaceError> {
    if distances.len() != mesh.positions.len() {
        return Err(FaceError::parameter(
            "distances",
            format!(
                "{} values for {} vertices",
                distances.len(),
                mesh.positions.len()
            ),
        ));
    }
    if !(scale.is_finite() && scale > 0.0) {
        return Err(FaceError::parameter(
            "scale",
            format!("must be finite and positive, got {scale}"),
        ));
    }
    let (w, h) = (camera.width, camera.height);
    if w == 0 || h == 0 || w > MAX_IMAGE_SIZE || h > MAX_IMAGE_SIZE {
        return Err(FaceError::parameter(
            "camera",
            format!("image {w}×{h} is outside 1..={MAX_IMAGE_SIZE} pixels a side"),
        ));
    }
    let mut target = RasterTarget::new(w as usize, h as usize);
    let mut projected = Vec::new();
    project_vertices(camera, &mesh.positions, &mut projected);
    let colours = error_colours(distances, scale);
    draw_triangles(&mut target, &projected, &colours, &mesh.triangles);

    let (wu, hu, lh) = (w as usize, h as usize, LEGEND_HEIGHT as usize);
    let mut pixels = vec![0u8; wu * (hu + lh) * 3];
    for (i, px) in pixels.chunks_exact_mut(3).enumerate() {
        let c = if i < wu * hu && target.depth[i].is_finite() {
            target.rgb[i].map(|v| v.round().clamp(0.0, 255.0) as u8)
        } else {
            BACKGROUND
        };
        px.copy_from_slice(&c);
    }
    // colour bar: 8 px margins, 14 px high, 6 px below the render
    let margin = 8.min(wu / 4);
    let (bar_x0, bar_x1) = (margin, wu - margin);
    let (bar_y0, bar_y1) = (hu + 6, hu + 20);
    let span = (bar_x1 - bar_x0).max(2) - 1;
    for x in bar_x0..bar_x1 {
        let d = scale * (2.0 * (x - bar_x0) as f64 / span as f64 - 1.0);
        let c = error_colours(&[d], scale)[0].map(|v| v.round() as u8);
        for y in bar_y0..bar_y1 {
            let i = (y * wu + x) * 3;
            pixels[i..i + 3].copy_from_slice(&c);
        }
    }
    register_embedded_font();
    {
        let text_error = |e: String| FaceError::Failed(format!("error map legend: {e}"));
        let backend = BitMapBackend::<plotters::backend::RGBPixel>::with_buffer_and_format(
            &mut pixels,
            (w, h + LEGEND_HEIGHT),
        )
        .map_err(|e| text_error(e.to_string()))?;
        let area = backend.into_drawing_area();
        let mm = scale * 1000.0;
        let label = if mm >= 10.0 {
            format!("{mm:.0}")
        } else if mm >= 0.1 {
            format!("{mm:.1}")
        } else {
            format!("{mm:.3}")
        };
        let y = (hu + 24) as i32;
        let style = |pos| {
            TextStyle::from((FONT_FAMILY, 14).into_font())
                .color(&BLACK)
                .pos(pos)
        };
        use plotters::style::text_anchor::{HPos, Pos, VPos};
        let texts = [
            (format!("−{label} mm"), bar_x0 as i32, HPos::Left),
            ("0".to_string(), (wu / 2) as i32, HPos::Center),
            (format!("+{label} mm"), bar_x1 as i32, HPos::Right),
        ];
        for (text, x, hpos) in texts {
            area.draw_text(&text, &style(Pos::new(hpos, VPos::Top)), (x, y))
                .map_err(|e| text_error(e.to_string()))?;
        }
        area.present().map_err(|e| text_error(e.to_string()))?;
    }
    RgbImage::from_raw(w, h + LEGEND_HEIGHT, pixels)
        .ok_or_else(|| FaceError::Failed("error map: pixel buffer has the wrong size".into()))
}

/// Renders the error map ([`error_map_image`]) and writes it as PNG to `path`, whose folder
/// must exist. Returns the [`ErrorStats`] of `distances`.
///
/// Fails as [`error_map_image`], or naming the file on an I/O error.
pub fn render_error_map(
    mesh: &FaceMesh,
    distances: &[f64],
    camera: &Camera,
    path: &Path,
    scale: f64,
) -> Result<ErrorStats, FaceError> {
    let image = error_map_image(mesh, distances, camera, scale)?;
    image
        .save_with_format(path, image::ImageFormat::Png)
        .map_err(|e| FaceError::io(path, e))?;
    Ok(ErrorStats::of(distances))
}
