//! Colours of the software renderer: the background gradient, the double-sided shading of a
//! surface point under lights attached to the camera, and sRGB conversions.

use crate::geometry::Vec3;

/// Background colours at the top and the bottom of the image (sRGB).
const SKY_TOP: [f64; 3] = [240.0, 243.0, 247.0];
const SKY_BOTTOM: [f64; 3] = [192.0, 200.0, 212.0];

/// Background colour of image row `row` out of `height`.
pub(crate) fn background(row: usize, height: usize) -> [u8; 3] {
    let t = (row as f64 + 0.5) / height as f64;
    [0, 1, 2].map(|k| (SKY_TOP[k] + t * (SKY_BOTTOM[k] - SKY_TOP[k])).round() as u8)
}

/// Double-sided shading of a point (camera coordinates): ambient, key and fill Lambert lights
/// attached to the camera, and a faint highlight; the normal is turned toward the viewer.
pub(crate) fn shade(base: &[f64; 3], normal: &Vec3, face_n: &Vec3, point: &Vec3) -> [u8; 3] {
    let view = (-point).try_normalize(1e-12).unwrap_or(-Vec3::z());
    let mut n = normal
        .try_normalize(1e-9)
        .or_else(|| face_n.try_normalize(1e-300))
        .unwrap_or(view);
    if n.dot(&view) < 0.0 {
        n = -n;
    }
    // Toward the lights: key from the upper left, fill from the right, both from the camera side.
    let key = Vec3::new(-0.45, 0.65, -0.6).normalize();
    let fill = Vec3::new(0.7, -0.1, -0.7).normalize();
    let diffuse = 0.18 + 0.72 * n.dot(&key).max(0.0) + 0.22 * n.dot(&fill).max(0.0);
    let half = (key + view).normalize();
    let spec = 0.05 * n.dot(&half).max(0.0).powi(24);
    base.map(|c| linear_to_srgb(c * diffuse + spec))
}

/// 8-bit sRGB to linear.
pub(crate) fn srgb_to_linear(c: u8) -> f64 {
    let c = f64::from(c) / 255.0;
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// Linear to 8-bit sRGB, clamped.
fn linear_to_srgb(c: f64) -> u8 {
    let c = c.clamp(0.0, 1.0);
    let s = if c <= 0.003_130_8 {
        12.92 * c
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    };
    (s * 255.0).round() as u8
}
