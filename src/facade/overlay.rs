//! Diagnostic overlays: the detected structure drawn over the image it was found in (floor
//! splits, tile splits, windows, their frames and sills), or, when the analysis failed, the line segments it saw, so a
//! user can tell a bad photo from a bad parameter.

use image::{Rgb, RgbImage};

use super::grammar::Leaf;
use super::labels::Class;
use super::segments::Segment;

/// Colours of the overlay.
const FLOOR: Rgb<u8> = Rgb([255, 210, 0]);
const TILE: Rgb<u8> = Rgb([0, 220, 255]);
const WINDOW: Rgb<u8> = Rgb([255, 40, 40]);
const DOOR: Rgb<u8> = Rgb([60, 255, 60]);
const MOULDING: Rgb<u8> = Rgb([255, 140, 0]);
const VERTICAL: Rgb<u8> = Rgb([60, 255, 60]);
const OTHER: Rgb<u8> = Rgb([60, 140, 255]);
const FAILED: Rgb<u8> = Rgb([255, 0, 0]);

/// Draws a line segment (clipped to the image), `width` pixels wide.
pub fn line(img: &mut RgbImage, a: [f64; 2], b: [f64; 2], colour: Rgb<u8>, width: u32) {
    let len = ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2)).sqrt();
    let steps = (len.ceil() as usize).clamp(1, 1 << 16);
    let r = width as i64 / 2;
    for k in 0..=steps {
        let t = k as f64 / steps as f64;
        let (x, y) = (a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]));
        if !(x.is_finite() && y.is_finite()) {
            return;
        }
        for dy in -r..=r {
            for dx in -r..=r {
                let (px, py) = (x.floor() as i64 + dx, y.floor() as i64 + dy);
                if px >= 0 && py >= 0 && (px as u32) < img.width() && (py as u32) < img.height() {
                    img.put_pixel(px as u32, py as u32, colour);
                }
            }
        }
    }
}

/// The outline of an axis-aligned rectangle.
fn outline(img: &mut RgbImage, x0: f64, y0: f64, x1: f64, y1: f64, colour: Rgb<u8>, width: u32) {
    line(img, [x0, y0], [x1, y0], colour, width);
    line(img, [x1, y0], [x1, y1], colour, width);
    line(img, [x1, y1], [x0, y1], colour, width);
    line(img, [x0, y1], [x0, y0], colour, width);
}

/// The parse drawn over the (rectified) photo: floor split rows in yellow, tile split columns
/// in cyan, frames and sills (wall leaves with an element) in orange, windows outlined in red,
/// doors in green.
pub fn structure(
    img: &RgbImage,
    floor_rows: &[f64],
    tile_columns: &[f64],
    leaves: &[Leaf],
) -> RgbImage {
    let mut out = img.clone();
    let (w, h) = (img.width() as f64, img.height() as f64);
    for &y in floor_rows {
        line(&mut out, [0.0, y], [w, y], FLOOR, 1);
    }
    for &x in tile_columns {
        line(&mut out, [x, 0.0], [x, h], TILE, 1);
    }
    for l in leaves
        .iter()
        .filter(|l| l.class == Class::Wall && l.element.is_some())
    {
        let s = l.scope;
        outline(&mut out, s.x0, s.y0, s.x1 - 1.0, s.y1 - 1.0, MOULDING, 1);
    }
    for l in leaves {
        let c = match l.class {
            Class::Window => WINDOW,
            Class::Door => DOOR,
            _ => continue,
        };
        let s = l.scope;
        outline(&mut out, s.x0, s.y0, s.x1 - 1.0, s.y1 - 1.0, c, 2);
    }
    out
}

/// A failed analysis: the photo with the segments it found (near-vertical green, others
/// blue) inside a red frame.
pub fn failure(img: &RgbImage, segments: &[Segment]) -> RgbImage {
    let mut out = img.clone();
    for s in segments {
        let a = s.angle();
        let vertical = (a - std::f64::consts::FRAC_PI_2).abs() < 0.5;
        line(
            &mut out,
            s.a,
            s.b,
            if vertical { VERTICAL } else { OTHER },
            1,
        );
    }
    let (w, h) = (img.width() as f64, img.height() as f64);
    outline(&mut out, 1.0, 1.0, w - 2.0, h - 2.0, FAILED, 3);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lines_are_clipped_and_drawn() {
        let mut img = RgbImage::new(10, 10);
        line(&mut img, [-5.0, 5.0], [20.0, 5.0], WINDOW, 1);
        assert!((0..10).all(|x| img.get_pixel(x, 5) == &WINDOW));
        assert_eq!(img.get_pixel(3, 3), &Rgb([0, 0, 0]));
        line(&mut img, [f64::NAN, 0.0], [3.0, 3.0], WINDOW, 1);
    }

    #[test]
    fn sills_are_drawn_and_plain_wall_is_not() {
        use crate::facade::grammar::Scope;
        let leaf = |y0: f64, y1: f64, class: Class, element: Option<usize>| {
            let scope = Scope {
                x0: 2.0,
                y0,
                x1: 8.0,
                y1,
            };
            Leaf {
                scope,
                class,
                source: scope,
                element,
            }
        };
        let img = RgbImage::new(10, 20);
        let leaves = [
            leaf(0.0, 2.0, Class::Wall, None),
            leaf(2.0, 12.0, Class::Window, None),
            leaf(12.0, 15.0, Class::Wall, Some(0)),
        ];
        let out = structure(&img, &[], &[], &leaves);
        assert_eq!(out.get_pixel(4, 0), &Rgb([0, 0, 0]), "plain wall");
        assert_eq!(out.get_pixel(4, 2), &WINDOW);
        assert_eq!(out.get_pixel(4, 14), &MOULDING, "the sill's bottom edge");
    }
}
