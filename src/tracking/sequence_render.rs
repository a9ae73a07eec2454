//! Rendering and writing the frames of a synthetic multi-camera sequence, shared by the body
//! sequences ([`super::sequence`]) and the golf broadcast sequences ([`super::golf_sequence`]):
//! per camera a background photo, a static occluder, changing light and sensor noise (see the
//! [`super::sequence`] module docs for the formulas), and motion blur: a frame is the mean of
//! the scenes at several instants of the shutter's opening ([`SequenceWriter::write_frame`]).
//!
//! Every random choice comes from the sequence's seed through per-camera and per-frame
//! [`SplitMix64`] streams, so the same inputs write the same files, bit for bit, whatever the
//! number of threads.

use std::path::{Path, PathBuf};

use image::RgbImage;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::sequence_files::{cover, image_path, io_err, list_photos, write_png, SequenceError};
use super::sequence_options::SequenceOptions;
use crate::geometry::Camera;
use crate::geometry::{SplitMix64, Vec3};
use crate::render::raster::{draw_triangles, project_vertices, RasterTarget};

/// One instant of what the cameras see: coloured triangles (world frame, metres; colours
/// linear `0..255`, already shaded).
#[derive(Clone, Debug, Default)]
pub struct SceneMesh {
    /// Vertex positions.
    pub positions: Vec<Vec3>,
    /// Vertex colours.
    pub colours: Vec<[f32; 3]>,
    /// Triangles (vertex indices).
    pub triangles: Vec<[u32; 3]>,
}

/// A static occluding rectangle `[x0, x1) × [y0, y1)` in pixels.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Occluder {
    /// Left column.
    pub x0: u32,
    /// Top row.
    pub y0: u32,
    /// Right end (exclusive).
    pub x1: u32,
    /// Bottom end (exclusive).
    pub y1: u32,
}

impl Occluder {
    /// Whether pixel `(x, y)` is covered.
    pub fn contains(&self, x: u32, y: u32) -> bool {
        x >= self.x0 && x < self.x1 && y >= self.y0 && y < self.y1
    }

    /// Covered pixels.
    pub fn area(&self) -> u64 {
        u64::from(self.x1 - self.x0) * u64::from(self.y1 - self.y0)
    }
}

/// Everything fixed about one camera, and its reusable render buffers.
struct CameraSlot {
    name: String,
    camera: Camera,
    background: RgbImage,
    occluder: Option<(Occluder, RgbImage)>,
    phase: f64,
    target: RasterTarget,
    projected: Vec<[f32; 3]>,
    /// Sum over the shutter's instants of each pixel's colour before light and noise.
    sum: Vec<[f32; 3]>,
    image: RgbImage,
    noise_seed: u64,
}

/// A seed for stream `a`, `b` of `seed`.
pub(super) fn mix(seed: u64, a: u64, b: u64) -> u64 {
    let mut r = SplitMix64::new(
        seed ^ a.wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ b.wrapping_mul(0xD1B5_4A32_D192_ED03),
    );
    r.next_u64()
}

/// The occluder of one camera: `fraction` of the image, over one side of the body's image
/// region `bbox` (x0, y0, x1, y1) or over its legs, inside the image.
fn place_occluder(bbox: [f64; 4], w: u32, h: u32, fraction: f64, rng: &mut SplitMix64) -> Occluder {
    let area = fraction * w as f64 * h as f64;
    let (bw, bh) = ((bbox[2] - bbox[0]).max(4.0), (bbox[3] - bbox[1]).max(4.0));
    let legs = rng.uniform() < 0.4;
    let (ow, oh, cx, cy) = if legs {
        let ow = (1.6 * bw).clamp(area / h as f64, w as f64).round();
        let oh = (area / ow).round().min(h as f64);
        let cx = 0.5 * (bbox[0] + bbox[2]) + rng.range(-0.25, 0.25) * bw;
        (ow, oh, cx, bbox[1] + 0.78 * bh + 0.5 * oh)
    } else {
        let oh = (0.75 * bh).clamp(area / w as f64, h as f64).round();
        let ow = (area / oh).round().min(w as f64);
        // the inner edge a little past the body's middle: one side hidden, the other seen
        let (xc, half) = (0.5 * (bbox[0] + bbox[2]), (0.5 * bw).max(0.04 * w as f64));
        let inner = 0.25 * half;
        let cx = if rng.bit() {
            xc - inner - 0.5 * ow
        } else {
            xc + inner + 0.5 * ow
        };
        (
            ow,
            oh,
            cx,
            0.5 * (bbox[1] + bbox[3]) + rng.range(-0.1, 0.1) * bh,
        )
    };
    let (ow, oh) = (ow.max(1.0) as u32, oh.max(1.0) as u32);
    let x0 = (cx - 0.5 * ow as f64).round().clamp(0.0, (w - ow) as f64) as u32;
    let y0 = (cy - 0.5 * oh as f64).round().clamp(0.0, (h - oh) as f64) as u32;
    Occluder {
        x0,
        y0,
        x1: x0 + ow,
        y1: y0 + oh,
    }
}

/// 65 536 standard normal samples (Box–Muller from `seed`), shifted and scaled to mean 0 and
/// variance 1 exactly: the sensor noise draws from this table with 16 random bits, which is
/// several times faster than drawing normals per pixel.
fn normal_table(seed: u64) -> Vec<f32> {
    let mut rng = SplitMix64::new(seed);
    let mut v: Vec<f64> = (0..1 << 16).map(|_| rng.normal()).collect();
    let n = v.len() as f64;
    let mean = v.iter().sum::<f64>() / n;
    let sd = (v.iter().map(|x| (x - mean) * (x - mean)).sum::<f64>() / n).sqrt();
    v.iter_mut().for_each(|x| *x = (*x - mean) / sd);
    v.into_iter().map(|x| x as f32).collect()
}

/// Writes a sequence's files: the cameras, the clean plates and one PNG per camera and frame.
pub struct SequenceWriter {
    out: PathBuf,
    slots: Vec<CameraSlot>,
    noise: Vec<f32>,
    options: SequenceOptions,
    /// Per camera: its name, background photo and occluder (for `sequence.json`).
    pub camera_details: Vec<serde_json::Value>,
}

impl SequenceWriter {
    /// Sets up `cameras` (named `cam0`, `cam1`, …) with their backgrounds and occluders from
    /// `options` (its noise, lighting, occluder, backgrounds and seed); `points` (the body's
    /// joints over the clip) place the occluders. Creates the output folders under `out`.
    pub fn new(
        out: &Path,
        cameras: Vec<Camera>,
        points: &[Vec3],
        options: &SequenceOptions,
    ) -> Result<SequenceWriter, SequenceError> {
        let o = options;
        let photos = list_photos(&o.backgrounds)?;
        let mut order: Vec<usize> = (0..photos.len()).collect();
        let mut rng = SplitMix64::new(mix(o.seed, 1, 0));
        for i in (1..order.len()).rev() {
            order.swap(i, rng.below(i + 1));
        }
        let n = cameras.len();
        let mut slots = Vec::with_capacity(n);
        let mut details = Vec::new();
        for (c, camera) in cameras.into_iter().enumerate() {
            let (w, h) = (camera.width, camera.height);
            let mut rng = SplitMix64::new(mix(o.seed, 2, c as u64));
            let bg_index = order[c % order.len()];
            let background = cover(&photos[bg_index], w, h, &mut rng)?;
            let mut bbox = [
                f64::INFINITY,
                f64::INFINITY,
                f64::NEG_INFINITY,
                f64::NEG_INFINITY,
            ];
            for uv in points.iter().filter_map(|p| camera.project(p)) {
                bbox = [
                    bbox[0].min(uv[0]),
                    bbox[1].min(uv[1]),
                    bbox[2].max(uv[0]),
                    bbox[3].max(uv[1]),
                ];
            }
            if !bbox[0].is_finite() {
                bbox = [
                    0.25 * w as f64,
                    0.1 * h as f64,
                    0.75 * w as f64,
                    0.9 * h as f64,
                ];
            }
            let occluder = if o.occluder_fraction > 0.0 {
                let rect = place_occluder(bbox, w, h, o.occluder_fraction, &mut rng);
                let mut tex_index = order[(c + n) % order.len()];
                if tex_index == bg_index && photos.len() > 1 {
                    tex_index = order[(c + n + 1) % order.len()];
                }
                let tex = cover(
                    &photos[tex_index],
                    rect.x1 - rect.x0,
                    rect.y1 - rect.y0,
                    &mut rng,
                )?;
                Some((rect, tex, tex_index))
            } else {
                None
            };
            let name = format!("cam{c}");
            let file_name = |i: usize| {
                photos[i]
                    .file_name()
                    .map(|n| n.to_string_lossy().into_owned())
            };
            details.push(serde_json::json!({
                "name": name,
                "background": file_name(bg_index),
                "occluder": occluder.as_ref().map(|(r, _, _)| r),
                "occluder_texture": occluder.as_ref().map(|o| file_name(o.2)),
            }));
            slots.push(CameraSlot {
                name,
                target: RasterTarget::new(w as usize, h as usize),
                projected: Vec::new(),
                sum: vec![[0.0; 3]; w as usize * h as usize],
                image: RgbImage::new(w, h),
                background,
                occluder: occluder.map(|(r, t, _)| (r, t)),
                phase: std::f64::consts::TAU * c as f64 / n as f64,
                noise_seed: mix(o.seed, 3, c as u64),
                camera,
            });
        }
        for dir in [
            out.to_path_buf(),
            out.join("cameras"),
            out.join("backgrounds"),
        ]
        .into_iter()
        .chain(slots.iter().map(|s| out.join("images").join(&s.name)))
        {
            std::fs::create_dir_all(&dir).map_err(io_err(&dir))?;
        }
        Ok(SequenceWriter {
            out: out.to_path_buf(),
            slots,
            noise: normal_table(mix(o.seed, 5, 0)),
            options: o.clone(),
            camera_details: details,
        })
    }

    /// The camera names, in order.
    pub fn camera_names(&self) -> Vec<String> {
        self.slots.iter().map(|s| s.name.clone()).collect()
    }

    /// Writes `cameras/camN.json` and the clean plates `backgrounds/camN.png` (the scene
    /// without the body at frame 0's light, with noise of its own).
    pub fn write_cameras_and_plates(&mut self) -> Result<(), SequenceError> {
        for s in &self.slots {
            s.camera
                .save(self.out.join("cameras").join(format!("{}.json", s.name)))?;
        }
        let (out, noise, o) = (&self.out, &self.noise, &self.options);
        self.slots.par_iter_mut().try_for_each(|s| {
            render(s, &[], noise, 0.0, usize::MAX, o);
            write_png(
                &out.join("backgrounds").join(format!("{}.png", s.name)),
                &s.image,
            )
        })
    }

    /// Renders and writes frame `k` at time `t`: the mean over the shutter's instants
    /// `shutter` (one scene per instant; one scene = no blur), cameras in parallel.
    pub fn write_frame(
        &mut self,
        k: usize,
        t: f64,
        shutter: &[SceneMesh],
    ) -> Result<(), SequenceError> {
        let (out, noise, o) = (&self.out, &self.noise, &self.options);
        self.slots.par_iter_mut().try_for_each(|s| {
            render(s, shutter, noise, t, k, o);
            write_png(&image_path(out, &s.name, k), &s.image)
        })
    }
}

/// Renders one camera's image of the current frame into `slot.image`: each scene of
/// `shutter` composited over the background and occluder, averaged, then light and noise.
fn render(
    slot: &mut CameraSlot,
    shutter: &[SceneMesh],
    noise: &[f32],
    t: f64,
    frame: usize,
    o: &SequenceOptions,
) {
    let (w, h) = (slot.camera.width, slot.camera.height);
    let base_at = |slot: &CameraSlot, x: u32, y: u32, i: usize| -> [f32; 3] {
        match &slot.occluder {
            Some((r, tex)) if r.contains(x, y) => {
                tex.get_pixel(x - r.x0, y - r.y0).0.map(f32::from)
            }
            _ if slot.target.depth[i].is_finite() => slot.target.rgb[i],
            _ => slot.background.get_pixel(x, y).0.map(f32::from),
        }
    };
    let count = shutter.len().max(1);
    slot.sum.iter_mut().for_each(|p| *p = [0.0; 3]);
    for k in 0..count {
        slot.target.clear();
        if let Some(scene) = shutter.get(k).filter(|_| o.body) {
            project_vertices(&slot.camera, &scene.positions, &mut slot.projected);
            draw_triangles(
                &mut slot.target,
                &slot.projected,
                &scene.colours,
                &scene.triangles,
            );
        }
        for y in 0..h {
            for x in 0..w {
                let i = (y * w + x) as usize;
                let b = base_at(slot, x, y, i);
                let s = &mut slot.sum[i];
                for c in 0..3 {
                    s[c] += b[c];
                }
            }
        }
    }
    let a = o.lighting_amplitude;
    let tau = std::f64::consts::TAU;
    let gain = 1.0 + a * (tau * t / 2.0).sin();
    let slope = 0.5 * a * (tau * t / 7.0 + slot.phase).sin();
    let mut rng = SplitMix64::new(mix(slot.noise_seed, frame as u64, 7));
    let sigma = o.noise_sigma as f32;
    let inv = 1.0 / count as f32;
    for y in 0..h {
        for x in 0..w {
            let i = (y * w + x) as usize;
            let base = slot.sum[i];
            let g = (gain * (1.0 + slope * (2.0 * (x as f64 + 0.5) / w as f64 - 1.0))) as f32;
            // three 16-bit draws from the normal table, one per channel
            let bits = if sigma > 0.0 { rng.next_u64() } else { 0 };
            let mut px = [0u8; 3];
            for (c, out) in px.iter_mut().enumerate() {
                let n = if sigma > 0.0 {
                    sigma * noise[(bits >> (16 * c)) as usize & 0xFFFF]
                } else {
                    0.0
                };
                *out = (base[c] * inv * g + n).round().clamp(0.0, 255.0) as u8;
            }
            slot.image.put_pixel(x, y, image::Rgb(px));
        }
    }
}
