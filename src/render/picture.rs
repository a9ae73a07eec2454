//! Shaded pictures: z-buffered, perspective-correct triangles with smooth double-sided
//! Lambert shading over a light gradient background, 2 × 2 supersampled, deterministic; and
//! PNG output of the result. Triangles are filled by the crate's one traversal
//! ([`super::raster::TriangleScan`]: integer edge functions, the top-left rule), with
//! perspective-correct depth, normals and positions interpolated for shading.

use std::io::Write;
use std::path::Path;

use image::{ImageEncoder, RgbImage};

use super::raster::TriangleScan;
use super::shading::{background, shade, srgb_to_linear};
use crate::geometry::camera::look_at::{Frame, MAX_SIZE, NEAR};
use crate::geometry::camera::LookAtCamera;
use crate::geometry::files::write_atomic;
use crate::geometry::mesh::vertex_normals;
use crate::geometry::{GeometryError, Vec3};

/// A mesh to draw: borrowed positions and triangles, and a base colour (sRGB).
#[derive(Debug, Clone, Copy)]
pub struct RenderMesh<'a> {
    /// Vertex positions (m).
    pub positions: &'a [Vec3],
    /// Triangles as vertex index triples (either winding; both sides are drawn).
    pub triangles: &'a [[usize; 3]],
    /// Base colour, 8-bit sRGB.
    pub color: [u8; 3],
}

impl RenderMesh<'_> {
    /// The default fabric colour: a muted denim blue.
    pub const DEFAULT_COLOR: [u8; 3] = [72, 104, 150];
}

impl Default for RenderMesh<'_> {
    /// An empty mesh of [`RenderMesh::DEFAULT_COLOR`].
    fn default() -> Self {
        RenderMesh {
            positions: &[],
            triangles: &[],
            color: Self::DEFAULT_COLOR,
        }
    }
}

/// Supersampling factor per axis for images up to this many pixels (1 above).
const SUPERSAMPLE: usize = 2;
const SUPERSAMPLE_MAX_PIXELS: u64 = 4_000_000;

/// Renders `meshes` as seen by `camera` into an image of the camera's size (clamped to
/// 1..=[`MAX_SIZE`]): z-buffered, perspective-correct, with per-vertex (smooth) normals turned
/// toward the viewer, lit by a key and a fill light attached to the camera plus ambient light,
/// over a vertical light-grey gradient. Triangles with an out-of-range index or a non-finite
/// vertex are skipped; triangles are clipped at the near plane ([`NEAR`] in front of the eye).
/// An unusable camera (see [`render_png`]) gives the background alone. Deterministic: the
/// same input gives the same pixels.
pub fn render(meshes: &[RenderMesh], camera: &LookAtCamera) -> RgbImage {
    let (w, h) = camera.size();
    let (w, h) = (w as usize, h as usize);
    let s = if (w * h) as u64 <= SUPERSAMPLE_MAX_PIXELS {
        SUPERSAMPLE
    } else {
        1
    };
    let mut target = Target {
        w: w * s,
        h: h * s,
        depth: vec![f64::INFINITY; w * h * s * s],
        color: Vec::new(),
    };
    target.color = (0..target.h)
        .flat_map(|y| std::iter::repeat_n(background(y / s, h), target.w))
        .collect();
    if let Some(mut frame) = camera.frame() {
        frame.focal *= s as f64;
        frame.cx *= s as f64;
        frame.cy *= s as f64;
        for mesh in meshes {
            draw_mesh(&mut target, &frame, mesh);
        }
    }
    let mut img = RgbImage::new(w as u32, h as u32);
    let n = (s * s) as u32;
    for (i, px) in img.chunks_exact_mut(3).enumerate() {
        let (x, y) = (i % w, i / w);
        let mut sum = [0u32; 3];
        for sy in 0..s {
            for sx in 0..s {
                let c = target.color[(y * s + sy) * target.w + x * s + sx];
                (0..3).for_each(|k| sum[k] += u32::from(c[k]));
            }
        }
        (0..3).for_each(|k| px[k] = ((sum[k] + n / 2) / n) as u8);
    }
    img
}

/// Renders `meshes` (see [`render`]) and writes the picture as PNG to `path`, creating parent
/// folders; written to a temporary file then renamed. Fails, naming the file, when the
/// camera's width or height is outside 1..=[`MAX_SIZE`], its pixels are more than the
/// `max_pixels` limit, the camera is unusable (non-finite
/// values, eye on the target, field of view outside (0°, 180°)), or on an I/O error.
pub fn render_png(
    path: &Path,
    meshes: &[RenderMesh],
    camera: &LookAtCamera,
) -> Result<(), GeometryError> {
    let invalid = |m: String| GeometryError::Invalid(format!("{}: {m}", path.display()));
    let sizes = 1..=MAX_SIZE;
    if !sizes.contains(&camera.width) || !sizes.contains(&camera.height) {
        return Err(invalid(format!(
            "image size {} × {} must be within 1..={MAX_SIZE} pixels each way",
            camera.width, camera.height
        )));
    }
    crate::geometry::image::check_pixels("image size", camera.width.into(), camera.height.into())
        .map_err(|e| invalid(e.to_string()))?;
    if camera.frame().is_none() {
        return Err(invalid(format!(
            "unusable camera (eye {:?}, target {:?}, fov {}°): eye must differ from target, values be finite, fov within (0, 180)",
            camera.eye.as_slice(),
            camera.target.as_slice(),
            camera.fov_y_deg
        )));
    }
    let img = render(meshes, camera);
    let mut png = Vec::new();
    image::codecs::png::PngEncoder::new(&mut png)
        .write_image(
            img.as_raw(),
            img.width(),
            img.height(),
            image::ExtendedColorType::Rgb8,
        )
        .map_err(|e| invalid(format!("PNG encoding failed: {e}")))?;
    write_atomic(path, |w: &mut dyn Write| w.write_all(&png))
}

/// Sample buffers: colour (sRGB) and depth along the view axis.
struct Target {
    w: usize,
    h: usize,
    depth: Vec<f64>,
    color: Vec<[u8; 3]>,
}

/// A vertex in camera coordinates (x right, y up, z forward) with its normal.
#[derive(Debug, Clone, Copy)]
struct CamVertex {
    p: Vec3,
    n: Vec3,
}

/// Draws the valid triangles of one mesh.
fn draw_mesh(target: &mut Target, frame: &Frame, mesh: &RenderMesh) {
    let pos = mesh.positions;
    let n = pos.len();
    let ok = |i: usize| i < n && pos[i].iter().all(|c| c.is_finite());
    let valid: Vec<[usize; 3]> = mesh
        .triangles
        .iter()
        .filter(|t| t.iter().all(|&i| ok(i)))
        .copied()
        .collect();
    let normals = vertex_normals(pos, &valid);
    let base = mesh.color.map(srgb_to_linear);
    for tri in &valid {
        let v = tri.map(|i| CamVertex {
            p: frame.camera_coords(&pos[i]),
            n: frame.camera_dir(&normals[i]),
        });
        let face_n = (v[1].p - v[0].p).cross(&(v[2].p - v[0].p));
        let (poly, len) = clip_near(&v);
        for k in 1..len.saturating_sub(1) {
            raster(
                target,
                frame,
                [poly[0], poly[k], poly[k + 1]],
                &face_n,
                &base,
            );
        }
    }
}

/// Clips a triangle to the half-space z ≥ [`NEAR`]: a polygon of 0, 3 or 4 vertices.
fn clip_near(v: &[CamVertex; 3]) -> ([CamVertex; 4], usize) {
    let mut out = [v[0]; 4];
    let mut len = 0;
    for i in 0..3 {
        let (a, b) = (v[i], v[(i + 1) % 3]);
        let (ina, inb) = (a.p.z >= NEAR, b.p.z >= NEAR);
        if ina {
            out[len] = a;
            len += 1;
        }
        if ina != inb {
            let t = (NEAR - a.p.z) / (b.p.z - a.p.z);
            out[len] = CamVertex {
                p: a.p.lerp(&b.p, t),
                n: a.n.lerp(&b.n, t),
            };
            out[len].p.z = NEAR;
            len += 1;
        }
    }
    (out, len)
}

/// Rasterizes one triangle in front of the near plane into the sample buffers, through the
/// crate's one triangle traversal ([`TriangleScan`]); samples sit at pixel centres
/// `(i + 0.5, j + 0.5)` of the frame's pixel coordinates.
fn raster(t: &mut Target, frame: &Frame, v: [CamVertex; 3], face_n: &Vec3, base: &[f64; 3]) {
    let corners = v.map(|v| {
        let (x, y) = frame.pixel(&v.p);
        [x - 0.5, y - 0.5]
    });
    let Some(scan) = TriangleScan::new(corners, t.w, t.h) else {
        return;
    };
    let o = scan.order();
    let inv_z = [1.0 / v[o[0]].p.z, 1.0 / v[o[1]].p.z, 1.0 / v[o[2]].p.z];
    let v = [v[o[0]], v[o[1]], v[o[2]]];
    scan.for_each(|x, y, l| {
        let q = [
            f64::from(l[0]) * inv_z[0],
            f64::from(l[1]) * inv_z[1],
            f64::from(l[2]) * inv_z[2],
        ];
        let z = 1.0 / (q[0] + q[1] + q[2]);
        let idx = y * t.w + x;
        if z.is_nan() || z >= t.depth[idx] {
            return;
        }
        t.depth[idx] = z;
        let normal = (v[0].n * q[0] + v[1].n * q[1] + v[2].n * q[2]) * z;
        let point = (v[0].p * q[0] + v[1].p * q[1] + v[2].p * q[2]) * z;
        t.color[idx] = shade(base, &normal, face_n, &point);
    });
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{grid_mesh, mesh::bounds};

    fn mesh<'a>(g: &'a crate::geometry::TriMesh) -> RenderMesh<'a> {
        RenderMesh {
            positions: &g.positions,
            triangles: &g.triangles,
            ..Default::default()
        }
    }

    fn corners(w: u32, h: u32) -> [(u32, u32); 4] {
        [(0, 0), (w - 1, 0), (0, h - 1), (w - 1, h - 1)]
    }

    #[test]
    fn grid_from_above_covers_the_centre_not_the_corners() {
        let g = grid_mesh(1.0, 0.5, 4, 3).unwrap();
        let cam = LookAtCamera {
            eye: Vec3::new(0.0, 0.0, 1.5),
            up: Vec3::y(),
            ..LookAtCamera::default()
        };
        let img = render(&[mesh(&g)], &cam);
        let bg = render(&[], &cam);
        assert_eq!((img.width(), img.height()), (800, 600));
        assert_ne!(img.get_pixel(400, 300), bg.get_pixel(400, 300));
        for (x, y) in corners(800, 600) {
            assert_eq!(img.get_pixel(x, y), bg.get_pixel(x, y));
        }
        // Covered area matches the projected size: 1 m spans 300 / tan 20° / 1.5 pixels.
        let m = 300.0 / 20f64.to_radians().tan() / 1.5;
        let expected = (1.0 * m) * (0.5 * m);
        let covered = img
            .pixels()
            .zip(bg.pixels())
            .filter(|(a, b)| a != b)
            .count() as f64;
        assert!(
            (covered / expected - 1.0).abs() < 0.02,
            "{covered} vs {expected}"
        );
    }

    #[test]
    fn framing_camera_sees_a_draped_looking_grid() {
        let mut g = grid_mesh(1.0, 0.5, 20, 10).unwrap();
        for p in &mut g.positions {
            p.z = -0.3 * (p.x * 3.0).cos() * p.y;
        }
        let (lo, hi) = bounds(&g.positions);
        let cam = LookAtCamera::framing(lo, hi, 320, 240);
        let img = render(&[mesh(&g)], &cam);
        let bg = render(&[], &cam);
        let (x, y, _) = cam.project(Vec3::zeros()).unwrap();
        let (x, y) = (x as u32, y as u32);
        assert_ne!(img.get_pixel(x, y), bg.get_pixel(x, y));
        for (x, y) in corners(320, 240) {
            assert_eq!(img.get_pixel(x, y), bg.get_pixel(x, y));
        }
        assert_eq!(img, render(&[mesh(&g)], &cam), "not deterministic");
    }

    #[test]
    fn behind_the_camera_draws_nothing_and_straddling_is_clipped() {
        let cam = LookAtCamera::look_at(Vec3::zeros(), Vec3::x());
        let bg = render(&[], &cam);
        let behind = [
            Vec3::new(-1.0, -1.0, -1.0),
            Vec3::new(-1.0, 1.0, -1.0),
            Vec3::new(-1.0, 0.0, 1.0),
        ];
        let tri = [[0, 1, 2]];
        let m = RenderMesh {
            positions: &behind,
            triangles: &tri,
            color: [200, 0, 0],
        };
        assert_eq!(render(&[m], &cam), bg);
        // A triangle through the eye's plane shows its front part only, without panicking.
        let straddle = [
            Vec3::new(-1.0, -1.0, -0.2),
            Vec3::new(2.0, 1.0, -0.2),
            Vec3::new(2.0, -1.0, -0.2),
        ];
        let m = RenderMesh {
            positions: &straddle,
            triangles: &tri,
            color: [200, 0, 0],
        };
        assert_ne!(render(&[m], &cam), bg);
    }

    #[test]
    fn bad_input_is_skipped_and_depth_is_respected() {
        let p = [
            Vec3::new(-1.0, -1.0, 0.0),
            Vec3::new(1.0, -1.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(f64::NAN, 0.0, 0.0),
        ];
        let cam = LookAtCamera {
            eye: Vec3::new(0.0, 0.0, 4.0),
            up: Vec3::y(),
            width: 64,
            height: 48,
            ..LookAtCamera::default()
        };
        let bg = render(&[], &cam);
        let junk = [[0, 1, 3], [0, 1, 7]];
        assert_eq!(
            render(
                &[RenderMesh {
                    positions: &p,
                    triangles: &junk,
                    color: [9, 9, 9]
                }],
                &cam
            ),
            bg
        );
        // A red triangle above a blue one hides it, whatever the drawing order.
        let up: Vec<Vec3> = p[..3].iter().map(|v| v + Vec3::z() * 0.5).collect();
        let tri = [[0, 1, 2]];
        let blue = RenderMesh {
            positions: &p[..3],
            triangles: &tri,
            color: [0, 0, 255],
        };
        let red = RenderMesh {
            positions: &up,
            triangles: &tri,
            color: [255, 0, 0],
        };
        for order in [[blue, red], [red, blue]] {
            let c = render(&order, &cam).get_pixel(32, 26).0;
            assert!(c[0] > 100 && c[2] < 60, "{c:?}");
        }
        // An unusable camera gives the background and render_png refuses it.
        let still = LookAtCamera {
            target: cam.eye,
            ..cam.clone()
        };
        assert_eq!(render(&[red], &still), render(&[], &still));
        let path = std::env::temp_dir().join("emilion-never-written.png");
        assert!(render_png(&path, &[red], &still)
            .unwrap_err()
            .to_string()
            .contains("never-written"));
        let tiny = LookAtCamera { width: 0, ..cam };
        assert!(render_png(&path, &[red], &tiny).is_err());
        assert!(!path.exists());
    }

    #[test]
    fn png_round_trip() {
        let g = grid_mesh(1.0, 0.5, 4, 3).unwrap();
        let (lo, hi) = bounds(&g.positions);
        let cam = LookAtCamera::framing(lo, hi, 120, 90);
        let dir = std::env::temp_dir().join(format!("emilion-png-{}", std::process::id()));
        let path = dir.join("a").join("grid.png");
        render_png(&path, &[mesh(&g)], &cam).unwrap();
        let back = image::open(&path).unwrap().to_rgb8();
        assert_eq!(back, render(&[mesh(&g)], &cam));
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
