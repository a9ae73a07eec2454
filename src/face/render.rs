//! Textured, z-buffered rendering of a face mesh through a [`Camera`], and the texture image.
//!
//! [`FaceRenderer::render`] reuses the tracker's rasterizer
//! ([`crate::render::raster::draw_triangles`]): texture coordinates travel
//! as the interpolated "colour" of each vertex (affine in the image, which for a face's small
//! triangles differs from perspective-correct interpolation by far less than a texel), then
//! every covered pixel samples the [`Texture`] bilinearly. The result stays in the renderer's
//! [`RasterTarget`]: `rgb` holds the texture colour, `depth` the camera depth, `+∞` where the
//! face is not. Unshaded: the texture, taken from photos, already carries the shading.
//!
//! Nothing allocates per call once the buffers have their size, so a tracker can render
//! thousands of candidates; one renderer per thread.

use std::path::Path;

use image::{Rgb, RgbImage};

use super::FaceError;
use crate::geometry::Camera;
use crate::geometry::Vec3;
use crate::render::raster::{draw_triangles, project_vertices, RasterTarget};

/// An RGB texture, linear 0..255 floats, row 0 at the top of the image (`v = 1`).
#[derive(Clone, Debug, PartialEq)]
pub struct Texture {
    /// Width, texels.
    pub width: usize,
    /// Height, texels.
    pub height: usize,
    /// Texels, row-major from the top row.
    pub rgb: Vec<[f32; 3]>,
}

impl Texture {
    /// A texture of one colour.
    pub fn filled(width: usize, height: usize, colour: [f32; 3]) -> Texture {
        Texture {
            width,
            height,
            rgb: vec![colour; width * height],
        }
    }

    /// From an 8-bit image.
    pub fn from_image(img: &RgbImage) -> Texture {
        Texture {
            width: img.width() as usize,
            height: img.height() as usize,
            rgb: img
                .pixels()
                .map(|p| [p[0] as f32, p[1] as f32, p[2] as f32])
                .collect(),
        }
    }

    /// As an 8-bit image (rounded, clamped).
    pub fn to_image(&self) -> RgbImage {
        let mut img = RgbImage::new(self.width as u32, self.height as u32);
        for (i, p) in img.pixels_mut().enumerate() {
            let c = self.rgb[i];
            *p = Rgb(c.map(|v| v.round().clamp(0.0, 255.0) as u8));
        }
        img
    }

    /// Reads an image in any of the photo formats
    /// ([`PHOTO_EXTENSIONS`](crate::geometry::image::PHOTO_EXTENSIONS)); errors name the file.
    pub fn load(path: &Path) -> Result<Texture, FaceError> {
        let img = crate::geometry::image::read_photo(path)?;
        Ok(Texture::from_image(&img))
    }

    /// Writes a PNG; errors name the file.
    pub fn save(&self, path: &Path) -> Result<(), FaceError> {
        self.to_image()
            .save(path)
            .map_err(|e| FaceError::io(path, e))
    }

    /// Bilinear sample at texture coordinates `(u, v)` (`v` up), clamped to the edge; black
    /// for an empty texture.
    #[inline]
    pub fn sample(&self, u: f32, v: f32) -> [f32; 3] {
        if self.width == 0 || self.height == 0 || self.rgb.len() < self.width * self.height {
            return [0.0; 3];
        }
        let x = (u * self.width as f32 - 0.5).clamp(0.0, (self.width - 1) as f32);
        let y = ((1.0 - v) * self.height as f32 - 0.5).clamp(0.0, (self.height - 1) as f32);
        let (x0, y0) = (x as usize, y as usize);
        let (x1, y1) = ((x0 + 1).min(self.width - 1), (y0 + 1).min(self.height - 1));
        let (fx, fy) = (x - x0 as f32, y - y0 as f32);
        let at = |xx: usize, yy: usize| self.rgb[yy * self.width + xx];
        let (a, b, c, d) = (at(x0, y0), at(x1, y0), at(x0, y1), at(x1, y1));
        let mut out = [0.0; 3];
        for k in 0..3 {
            let top = a[k] + (b[k] - a[k]) * fx;
            let bottom = c[k] + (d[k] - c[k]) * fx;
            out[k] = top + (bottom - top) * fy;
        }
        out
    }
}

/// Buffers to render a textured mesh repeatedly without allocating.
#[derive(Clone, Debug)]
pub struct FaceRenderer {
    /// Depth and colour of the last render (see the [module docs](self)).
    pub target: RasterTarget,
    projected: Vec<[f32; 3]>,
    uv_colours: Vec<[f32; 3]>,
}

impl FaceRenderer {
    /// A renderer for images of `width × height`.
    pub fn new(width: usize, height: usize) -> FaceRenderer {
        FaceRenderer {
            target: RasterTarget::new(width, height),
            projected: Vec::new(),
            uv_colours: Vec::new(),
        }
    }

    /// Renders `positions` (one per texture coordinate in `uvs`) with `triangles` and
    /// `texture` through `camera` into [`target`](Self::target), after clearing it.
    pub fn render(
        &mut self,
        camera: &Camera,
        positions: &[Vec3],
        uvs: &[[f64; 2]],
        triangles: &[[u32; 3]],
        texture: &Texture,
    ) {
        self.target.clear();
        project_vertices(camera, positions, &mut self.projected);
        self.uv_colours.clear();
        self.uv_colours
            .extend(uvs.iter().map(|uv| [uv[0] as f32, uv[1] as f32, 0.0]));
        draw_triangles(
            &mut self.target,
            &self.projected,
            &self.uv_colours,
            triangles,
        );
        if let Some((x0, y0, x1, y1)) = self.target.touched() {
            let w = self.target.width;
            for y in y0..y1 {
                for x in x0..x1 {
                    let i = y * w + x;
                    if self.target.depth[i].is_finite() {
                        let c = self.target.rgb[i];
                        self.target.rgb[i] = texture.sample(c[0], c[1]);
                    }
                }
            }
        }
    }

    /// The projected vertices of the last render (pixel x, y and camera depth; zero where a
    /// vertex could not be projected).
    pub fn projected(&self) -> &[[f32; 3]] {
        &self.projected
    }

    /// The last render over `background` (same size): face pixels from the render, others from
    /// the background.
    pub fn composite(&self, background: &RgbImage) -> Result<RgbImage, FaceError> {
        let (w, h) = (self.target.width, self.target.height);
        if background.width() as usize != w || background.height() as usize != h {
            return Err(FaceError::Failed(format!(
                "background is {}×{}, the render {w}×{h}",
                background.width(),
                background.height()
            )));
        }
        let mut out = background.clone();
        for y in 0..h {
            for x in 0..w {
                let i = y * w + x;
                if self.target.depth[i].is_finite() {
                    let c = self.target.rgb[i];
                    out.put_pixel(
                        x as u32,
                        y as u32,
                        Rgb(c.map(|v| v.round().clamp(0.0, 255.0) as u8)),
                    );
                }
            }
        }
        Ok(out)
    }
}
