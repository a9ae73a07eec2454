//! Pictures of a face for people to look at: the textured mesh rendered through a camera with
//! Lambert shading (a light over the viewer's shoulder), on a plain background; and the
//! expression gallery of the sliders and FAPs on the generic face.

use image::{Rgb, RgbImage};

use super::expressions::Expressions;
use super::model::FaceMesh;
use super::render::{FaceRenderer, Texture};
use super::skin::procedural_face_texture;
use super::FaceError;
use crate::geometry::Camera;
use crate::geometry::Vec3;
use crate::render::raster::{draw_triangles, project_vertices, RasterTarget};

/// A camera looking at `mesh`'s centroid from `yaw_deg` (0: in front), framing the face in a
/// `width × height` image.
pub fn preview_camera(mesh: &FaceMesh, yaw_deg: f64, width: u32, height: u32) -> Camera {
    let centre = mesh.centroid();
    let (lo, hi) = mesh.bounds();
    let size = (hi - lo).x.max((hi - lo).y);
    let yaw = yaw_deg.to_radians();
    let distance = 0.5;
    let eye = centre + distance * Vec3::new(yaw.sin(), 0.0, yaw.cos());
    let focal = 0.8 * height.min(width) as f64 * distance / (size * 1.15);
    Camera::looking_at(eye, centre, focal, width, height)
}

/// `positions` (on `mesh`'s triangles and texture coordinates) rendered with `texture` and
/// Lambert shading through `camera`, over a grey background.
pub fn shaded_render(
    mesh: &FaceMesh,
    positions: &[Vec3],
    texture: &Texture,
    camera: &Camera,
) -> RgbImage {
    let (w, h) = (camera.width as usize, camera.height as usize);
    let mut renderer = FaceRenderer::new(w, h);
    renderer.render(camera, positions, &mesh.uvs, &mesh.triangles, texture);
    // per-vertex shading, light from above the camera
    let shaped = FaceMesh {
        positions: positions.to_vec(),
        uvs: mesh.uvs.clone(),
        triangles: mesh.triangles.clone(),
    };
    let normals = shaped.vertex_normals();
    let centre = camera.center();
    let up = camera.rotation.row(1).transpose() * -1.0;
    let shade: Vec<[f32; 3]> = positions
        .iter()
        .zip(&normals)
        .map(|(p, n)| {
            let l = ((centre - p).normalize() + 0.6 * up).normalize();
            let s = (0.35 + 0.65 * n.dot(&l).max(0.0)) as f32;
            [s, s, s]
        })
        .collect();
    let mut shading = RasterTarget::new(w, h);
    let mut projected = Vec::new();
    project_vertices(camera, positions, &mut projected);
    draw_triangles(&mut shading, &projected, &shade, &mesh.triangles);
    let mut img = RgbImage::from_pixel(w as u32, h as u32, Rgb([72, 76, 84]));
    for y in 0..h {
        for x in 0..w {
            let i = y * w + x;
            if renderer.target.depth[i].is_finite() {
                let c = renderer.target.rgb[i];
                let s = shading.rgb[i][0];
                img.put_pixel(
                    x as u32,
                    y as u32,
                    Rgb(c.map(|v| (v * s).round().clamp(0.0, 255.0) as u8)),
                );
            }
        }
    }
    img
}

/// The generic face (MediaPipe canonical mesh, procedural skin) with an expression, rendered
/// frontally at `size × size`: `values` pairs a slider name of [`Expressions`] or `fap_N` (an
/// MPEG-4 FAP, in FAP units) with its value. Unknown names are an error listing the sliders.
pub fn expression_image(
    values: &[(String, f64)],
    size: u32,
    yaw_deg: f64,
) -> Result<RgbImage, FaceError> {
    let mesh = FaceMesh::mediapipe()?;
    let ex = Expressions::new(&mesh)?;
    let mut sliders = vec![0.0; ex.len()];
    let mut faps = vec![0.0; ex.faps.len()];
    for (name, v) in values {
        if !v.is_finite() {
            return Err(FaceError::parameter(name, format!("not finite: {v}")));
        }
        if let Some(n) = name.strip_prefix("fap_").and_then(|n| n.parse::<u8>().ok()) {
            let k = ex
                .faps
                .index_of(n)
                .ok_or_else(|| FaceError::parameter(name, format!("FAP {n} is not in the rig")))?;
            faps[k] += v;
        } else {
            let k = ex.index_of(name).ok_or_else(|| {
                FaceError::parameter(
                    name,
                    format!("no such slider or FAP; sliders: {}", ex.names().join(", ")),
                )
            })?;
            sliders[k] += v;
        }
    }
    let (mut a, mut b) = (Vec::new(), Vec::new());
    ex.apply(&mesh.positions, &sliders, &mut a);
    // the FAP fields add to the slider result
    ex.faps.apply(&mesh.positions, &faps, &mut b);
    for ((p, q), n) in a.iter_mut().zip(&b).zip(&mesh.positions) {
        *p += q - n;
    }
    let texture = procedural_face_texture(&mesh, 512, 1);
    let cam = preview_camera(&mesh, yaw_deg, size.max(32), size.max(32));
    Ok(shaded_render(&mesh, &a, &texture, &cam))
}
