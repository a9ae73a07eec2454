//! The broadcast picture: tracked (and optionally ground-truth) skeletons drawn over the
//! cameras' images, the images tiled into one picture, written as PNG.
//!
//! Bones are anti-aliased lines of a few pixels between the projected joints (distortion
//! included, [`Camera::project`]), joints are filled dots; the body's left side, its right
//! side and the centre line (pelvis, spine, neck, head) each get their own colour
//! ([`SkeletonStyle`]). Joints behind a camera or not finite are skipped, with the bones
//! that touch them; everything is clipped to the image. Nothing here panics on bad input.

use std::path::Path;

use image::RgbImage;

use super::bvh_export::TrackingOutputError;
use super::joints::{JOINT_COUNT, TRACKING_JOINTS};
use crate::geometry::Camera;
use crate::geometry::Vec3;

/// Colours and sizes of a drawn skeleton.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SkeletonStyle {
    /// Colour of the centre line (pelvis, spine, neck, head) and its bones.
    pub centre: [u8; 3],
    /// Colour of the body's left side (`l_` joints and the bones to them).
    pub left: [u8; 3],
    /// Colour of the body's right side (`r_` joints and the bones to them).
    pub right: [u8; 3],
    /// Bone line width, pixels.
    pub line_width: f64,
    /// Joint dot radius, pixels.
    pub joint_radius: f64,
}

impl SkeletonStyle {
    /// Every part in `colour`, 2.5 px bones, 3.5 px dots.
    pub fn single(colour: [u8; 3]) -> Self {
        SkeletonStyle {
            centre: colour,
            left: colour,
            right: colour,
            line_width: 2.5,
            joint_radius: 3.5,
        }
    }

    /// Centre in `colour`, the left side a lighter and the right side a darker shade of it.
    pub fn shaded(colour: [u8; 3]) -> Self {
        let mix = |c: [u8; 3], t: [u8; 3], a: f64| {
            std::array::from_fn(|i| (c[i] as f64 * (1.0 - a) + t[i] as f64 * a).round() as u8)
        };
        SkeletonStyle {
            left: mix(colour, [255, 255, 255], 0.45),
            right: mix(colour, [0, 0, 0], 0.4),
            ..SkeletonStyle::single(colour)
        }
    }

    /// The tracked skeleton of the broadcast picture: yellow centre, orange left, cyan right.
    pub fn tracked() -> Self {
        SkeletonStyle {
            centre: [255, 220, 0],
            left: [255, 120, 0],
            right: [0, 200, 255],
            line_width: 3.0,
            joint_radius: 4.0,
        }
    }

    /// The ground-truth skeleton of the broadcast picture: greens, thinner.
    pub fn truth() -> Self {
        SkeletonStyle {
            centre: [40, 200, 60],
            left: [140, 255, 120],
            right: [0, 130, 40],
            line_width: 2.0,
            joint_radius: 2.5,
        }
    }

    fn colour_of(&self, joint: usize) -> [u8; 3] {
        let name = TRACKING_JOINTS[joint].name;
        if name.starts_with("l_") {
            self.left
        } else if name.starts_with("r_") {
            self.right
        } else {
            self.centre
        }
    }
}

/// Blends `colour` into pixel `(x, y)` with coverage `a` in `0..=1` (out of range: nothing).
fn blend(image: &mut RgbImage, x: i64, y: i64, colour: [u8; 3], a: f64) {
    if x < 0 || y < 0 || x >= image.width() as i64 || y >= image.height() as i64 || a <= 0.0 {
        return;
    }
    let a = a.min(1.0);
    let p = image.get_pixel_mut(x as u32, y as u32);
    for (c, &t) in p.0.iter_mut().zip(&colour) {
        *c = (*c as f64 * (1.0 - a) + t as f64 * a)
            .round()
            .clamp(0.0, 255.0) as u8;
    }
}

/// Clips the segment `a–b` to the box `[lo, hi]²` (Liang–Barsky); `None` when outside.
fn clip(a: [f64; 2], b: [f64; 2], lo: [f64; 2], hi: [f64; 2]) -> Option<([f64; 2], [f64; 2])> {
    let d = [b[0] - a[0], b[1] - a[1]];
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    for k in 0..2 {
        for (p, q) in [(-d[k], a[k] - lo[k]), (d[k], hi[k] - a[k])] {
            if p == 0.0 {
                if q < 0.0 {
                    return None;
                }
            } else {
                let r = q / p;
                if p < 0.0 {
                    t0 = t0.max(r);
                } else {
                    t1 = t1.min(r);
                }
            }
        }
    }
    (t0 <= t1).then(|| {
        (
            [a[0] + t0 * d[0], a[1] + t0 * d[1]],
            [a[0] + t1 * d[0], a[1] + t1 * d[1]],
        )
    })
}

/// Draws an anti-aliased thick segment from `a` to `b` (pixel coordinates, pixel `(i, j)`
/// covering `[i, i+1) × [j, j+1)`); a zero-length segment draws a dot of the line width.
pub fn draw_line(image: &mut RgbImage, a: [f64; 2], b: [f64; 2], width: f64, colour: [u8; 3]) {
    let half = (width.max(0.5)) * 0.5;
    if !(a.iter().chain(&b).all(|c| c.is_finite()) && half.is_finite()) {
        return;
    }
    let m = half + 1.0;
    let lo = [-m, -m];
    let hi = [image.width() as f64 + m, image.height() as f64 + m];
    let Some((a, b)) = clip(a, b, lo, hi) else {
        return;
    };
    let x0 = (a[0].min(b[0]) - m).floor().max(0.0) as i64;
    let x1 = (a[0].max(b[0]) + m).ceil().min(image.width() as f64) as i64;
    let y0 = (a[1].min(b[1]) - m).floor().max(0.0) as i64;
    let y1 = (a[1].max(b[1]) + m).ceil().min(image.height() as f64) as i64;
    let d = [b[0] - a[0], b[1] - a[1]];
    let len2 = d[0] * d[0] + d[1] * d[1];
    for y in y0..y1 {
        for x in x0..x1 {
            let p = [x as f64 + 0.5 - a[0], y as f64 + 0.5 - a[1]];
            let t = if len2 > 0.0 {
                ((p[0] * d[0] + p[1] * d[1]) / len2).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let dist = (p[0] - t * d[0]).hypot(p[1] - t * d[1]);
            blend(image, x, y, colour, half + 0.5 - dist);
        }
    }
}

/// Draws a filled anti-aliased dot of `radius` pixels centred at `c`.
pub fn draw_dot(image: &mut RgbImage, c: [f64; 2], radius: f64, colour: [u8; 3]) {
    draw_line(image, c, c, 2.0 * radius, colour);
}

/// The pixel of a joint, when it is finite and in front of the camera.
fn project(camera: &Camera, p: &Vec3) -> Option<[f64; 2]> {
    if !p.iter().all(|c| c.is_finite()) {
        return None;
    }
    camera
        .project(p)
        .filter(|uv| uv[0].is_finite() && uv[1].is_finite())
}

/// Draws the skeleton `joints` seen by `camera` onto `image` with `style`: bones first, then
/// joint dots. Bones and joints behind the camera are skipped.
pub fn draw_skeleton_styled(
    image: &mut RgbImage,
    camera: &Camera,
    joints: &[Vec3; JOINT_COUNT],
    style: &SkeletonStyle,
) {
    let px: Vec<Option<[f64; 2]>> = joints.iter().map(|p| project(camera, p)).collect();
    for (k, t) in TRACKING_JOINTS.iter().enumerate() {
        if let (Some(p), Some(b)) = (t.parent, px[k]) {
            if let Some(a) = px[p] {
                draw_line(image, a, b, style.line_width, style.colour_of(k));
            }
        }
    }
    for (k, uv) in px.iter().enumerate() {
        if let Some(uv) = uv {
            draw_dot(image, *uv, style.joint_radius, style.colour_of(k));
        }
    }
}

/// Draws the skeleton in `colour` (the centre line; the left side a lighter, the right side a
/// darker shade, [`SkeletonStyle::shaded`]).
pub fn draw_skeleton(
    image: &mut RgbImage,
    camera: &Camera,
    joints: &[Vec3; JOINT_COUNT],
    colour: [u8; 3],
) {
    draw_skeleton_styled(image, camera, joints, &SkeletonStyle::shaded(colour));
}

/// Grid `(columns, rows)` for `n` tiles: `⌈√n⌉` columns (2 × 2 for four).
pub fn grid_size(n: usize) -> (usize, usize) {
    if n == 0 {
        return (0, 0);
    }
    let mut cols = (n as f64).sqrt().floor() as usize;
    while cols * cols < n {
        cols += 1;
    }
    (cols, n.div_ceil(cols))
}

/// The broadcast picture: each camera's image with the tracked skeleton
/// ([`SkeletonStyle::tracked`]) over the ground truth ([`SkeletonStyle::truth`]) when given,
/// tiled in a [`grid_size`] grid of cells as large as the largest image (row-major, black
/// where no image). Images without a camera (more images than cameras) are tiled as they are.
/// No image gives a 0 × 0 picture.
pub fn broadcast_frame(
    images: &[RgbImage],
    cameras: &[Camera],
    tracked: &[Vec3; JOINT_COUNT],
    truth: Option<&[Vec3; JOINT_COUNT]>,
) -> RgbImage {
    broadcast_frame_with(images, cameras, tracked, truth, |_, _| {})
}

/// [`broadcast_frame`] with more drawn over each camera's tile after the skeletons:
/// `extra(tile, camera)` (the club, for one).
pub fn broadcast_frame_with(
    images: &[RgbImage],
    cameras: &[Camera],
    tracked: &[Vec3; JOINT_COUNT],
    truth: Option<&[Vec3; JOINT_COUNT]>,
    extra: impl Fn(&mut RgbImage, &Camera),
) -> RgbImage {
    let (cols, rows) = grid_size(images.len());
    let cw = images.iter().map(|i| i.width()).max().unwrap_or(0);
    let ch = images.iter().map(|i| i.height()).max().unwrap_or(0);
    let (w, h) = (cw as u64 * cols as u64, ch as u64 * rows as u64);
    if w == 0 || h == 0 || w > u32::MAX as u64 || h > u32::MAX as u64 {
        return RgbImage::new(0, 0);
    }
    let mut out = RgbImage::new(w as u32, h as u32);
    for (i, img) in images.iter().enumerate() {
        let mut tile = img.clone();
        if let Some(cam) = cameras.get(i) {
            if let Some(t) = truth {
                draw_skeleton_styled(&mut tile, cam, t, &SkeletonStyle::truth());
            }
            draw_skeleton_styled(&mut tile, cam, tracked, &SkeletonStyle::tracked());
            extra(&mut tile, cam);
        }
        let (ox, oy) = ((i % cols) as i64 * cw as i64, (i / cols) as i64 * ch as i64);
        image::imageops::replace(&mut out, &tile, ox, oy);
    }
    out
}

/// Writes [`broadcast_frame`] as a PNG to `path` and returns it.
///
/// # Errors
///
/// [`TrackingOutputError::InvalidInput`] when there is no image;
/// [`TrackingOutputError::Image`] naming `path` when it cannot be encoded or written.
pub fn write_overlay_png(
    path: &Path,
    images: &[RgbImage],
    cameras: &[Camera],
    tracked: &[Vec3; JOINT_COUNT],
    truth: Option<&[Vec3; JOINT_COUNT]>,
) -> Result<RgbImage, TrackingOutputError> {
    write_overlay_png_with(path, images, cameras, tracked, truth, |_, _| {})
}

/// [`write_overlay_png`] of [`broadcast_frame_with`].
pub fn write_overlay_png_with(
    path: &Path,
    images: &[RgbImage],
    cameras: &[Camera],
    tracked: &[Vec3; JOINT_COUNT],
    truth: Option<&[Vec3; JOINT_COUNT]>,
    extra: impl Fn(&mut RgbImage, &Camera),
) -> Result<RgbImage, TrackingOutputError> {
    let pic = broadcast_frame_with(images, cameras, tracked, truth, extra);
    if pic.width() == 0 || pic.height() == 0 {
        return Err(TrackingOutputError::InvalidInput(
            "no (non-empty) camera image to draw the overlay on".to_string(),
        ));
    }
    pic.save_with_format(path, image::ImageFormat::Png)
        .map_err(|e| TrackingOutputError::Image {
            path: path.to_path_buf(),
            message: e.to_string(),
        })?;
    Ok(pic)
}

/// Colour of the tracked club's shaft and of its head's path in the overlays.
pub const CLUB_COLOUR: [u8; 3] = [255, 150, 20];

/// Draws a club over `image` seen by `cam`: the shaft from `grip` to `head`, the head as a
/// dot, and the head's path over the frames before (`path`, oldest first) as a thin line.
pub fn draw_club(image: &mut RgbImage, cam: &Camera, grip: Vec3, head: Vec3, path: &[Vec3]) {
    let project = |p: &Vec3| cam.project(p);
    for w in path.windows(2) {
        if let (Some(a), Some(b)) = (project(&w[0]), project(&w[1])) {
            draw_line(image, a, b, 1.0, CLUB_COLOUR);
        }
    }
    if let (Some(a), Some(b)) = (project(&grip), project(&head)) {
        draw_line(image, a, b, 2.0, CLUB_COLOUR);
        draw_dot(image, b, 3.0, CLUB_COLOUR);
    }
}

/// Reads pixel `(x, y)` as `[r, g, b]`, `None` outside the image (for checks and tests).
pub fn pixel(image: &RgbImage, x: u32, y: u32) -> Option<[u8; 3]> {
    (x < image.width() && y < image.height()).then(|| image.get_pixel(x, y).0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grid() {
        assert_eq!(grid_size(4), (2, 2));
        assert_eq!(grid_size(1), (1, 1));
        assert_eq!(grid_size(5), (3, 2));
        assert_eq!(grid_size(3), (2, 2));
    }

    #[test]
    fn huge_lines_are_clipped() {
        let mut img = RgbImage::new(20, 10);
        draw_line(&mut img, [-1e15, 5.0], [1e15, 5.0], 3.0, [255, 0, 0]);
        assert_eq!(img.get_pixel(10, 5).0, [255, 0, 0]);
        assert_eq!(img.get_pixel(10, 0).0, [0, 0, 0]);
        draw_line(&mut img, [f64::NAN, 5.0], [1.0, 5.0], 3.0, [0, 255, 0]);
        draw_line(&mut img, [-50.0, -50.0], [-40.0, -60.0], 3.0, [0, 255, 0]);
    }

    #[test]
    fn the_club_is_drawn_where_it_projects() {
        let cam = Camera::looking_at_up(
            Vec3::new(0.0, -5.0, 1.0),
            Vec3::new(0.0, 0.0, 1.0),
            Vec3::z(),
            400.0,
            320,
            240,
        );
        let mut img = RgbImage::new(320, 240);
        let (grip, head) = (Vec3::new(0.0, 0.0, 1.0), Vec3::new(0.8, 0.0, 0.3));
        let path = [Vec3::new(-0.8, 0.0, 0.3), Vec3::new(0.0, 0.0, 0.0), head];
        draw_club(&mut img, &cam, grip, head, &path);
        let at = |p: Vec3| {
            let [x, y] = cam.project(&p).unwrap();
            img.get_pixel(x.round() as u32, y.round() as u32).0
        };
        assert_eq!(at(head), CLUB_COLOUR);
        assert_eq!(at(0.5 * (grip + head)), CLUB_COLOUR);
        // the path's thin line is anti-aliased: orange, if not at full strength
        let [r, g, b] = at(Vec3::new(-0.4, 0.0, 0.15));
        assert!(r >= 100 && r > g && g > b, "{:?}", [r, g, b]);
        assert_eq!(at(Vec3::new(-0.6, 0.0, 1.2)), [0, 0, 0]);
    }
}
