//! Helpers shared by the facade tests: a synthetic facade with known floor height and tile
//! width (windows in frames on a textured wall, a lighting gradient from floor to floor, a
//! tree in front of the lower left).
#![allow(dead_code)]

use emilion::facade::{Class, LabelMap, Rect};
use emilion::geometry::image::Gray;
use emilion::geometry::Lcg64;

pub const FLOOR: u32 = 57;
pub const TILE: u32 = 43;
/// Window rectangle inside each tile: columns 10..34, rows 12..45.
pub const WIN_X: (u32, u32) = (10, 34);
pub const WIN_Y: (u32, u32) = (12, 45);

pub fn facade(width: u32, height: u32, seed: u64) -> Gray {
    facade_with_bars(width, height, seed, 1, &|_, _| false)
}

/// [`facade`] with every length `scale` times longer (floors, tiles, windows, frames, the
/// tree), whose windows have light bars (mullions, transoms) where `bar(x, y)` holds, (x, y)
/// in pixels from the window's top-left corner.
pub fn facade_with_bars(
    width: u32,
    height: u32,
    seed: u64,
    scale: u32,
    bar: &dyn Fn(u32, u32) -> bool,
) -> Gray {
    let mut rng = Lcg64::new(seed);
    let mut rnd = || (rng.next_u64() >> 40) as f64 / (1u64 << 24) as f64;
    let mut data = Vec::with_capacity((width * height) as usize);
    for y in 0..height {
        for x in 0..width {
            let k = scale;
            let (tx, ty) = (x % (k * TILE), y % (k * FLOOR));
            let (wx, wy) = ((k * WIN_X.0, k * WIN_X.1), (k * WIN_Y.0, k * WIN_Y.1));
            let window = (wx.0..wx.1).contains(&tx) && (wy.0..wy.1).contains(&ty);
            let frame = !window
                && (wx.0 - 2 * k..wx.1 + 2 * k).contains(&tx)
                && (wy.0 - 2 * k..wy.1 + 2 * k).contains(&ty);
            // lighter floors further up, as sun on a facade
            let light = 1.0 - 0.25 * y as f64 / height as f64;
            let base = if window && bar(tx - wx.0, ty - wy.0) {
                225.0
            } else if window {
                55.0
            } else if frame {
                225.0
            } else {
                165.0
            };
            let mut v = base * light + 24.0 * (rnd() - 0.5);
            // a tree in front of the lower left
            let (dx, dy) = (
                (x as f64 - 60.0 * k as f64) / k as f64,
                (y as f64 - height as f64 + 40.0 * k as f64) / k as f64,
            );
            if dx * dx / 900.0 + dy * dy / 2500.0 < 1.0 {
                v = 70.0 + 40.0 * rnd();
            }
            data.push(v.clamp(0.0, 255.0) as u8);
        }
    }
    Gray {
        width,
        height,
        data,
    }
}

/// The synthetic facade's own label map: its windows (frames count as wall).
pub fn window_truth(width: u32, height: u32) -> LabelMap {
    let mut m = LabelMap::filled(width, height, Class::Wall);
    for fy in 0..height.div_ceil(FLOOR) {
        for tx in 0..width.div_ceil(TILE) {
            m.paint(
                &Rect {
                    x0: tx * TILE + WIN_X.0,
                    y0: fy * FLOOR + WIN_Y.0,
                    x1: (tx * TILE + WIN_X.1).min(width),
                    y1: (fy * FLOOR + WIN_Y.1).min(height),
                },
                Class::Window,
            );
        }
    }
    m
}

/// Uniform 8-bit noise (a picture with no structure), seeded.
pub fn noise(width: u32, height: u32, seed: u64) -> Gray {
    let mut rng = Lcg64::new(seed);
    Gray {
        width,
        height,
        data: (0..width * height)
            .map(|_| (rng.next_u64() >> 56) as u8)
            .collect(),
    }
}
