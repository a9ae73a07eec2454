//! Axis-aligned pixel rectangles (windows, tiles) and their overlap.

use serde::Serialize;

/// A rectangle of pixels, half-open: columns `x0..x1`, rows `y0..y1`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct Rect {
    /// First column.
    pub x0: u32,
    /// First row.
    pub y0: u32,
    /// One past the last column.
    pub x1: u32,
    /// One past the last row.
    pub y1: u32,
}

impl Rect {
    /// Columns `x0..x1`, rows `y0..y1`.
    pub const fn new(x0: u32, y0: u32, x1: u32, y1: u32) -> Self {
        Rect { x0, y0, x1, y1 }
    }

    /// Pixels covered.
    pub fn area(&self) -> u64 {
        self.x1.saturating_sub(self.x0) as u64 * self.y1.saturating_sub(self.y0) as u64
    }

    /// Pixels covered by both.
    pub fn intersection(&self, o: &Rect) -> u64 {
        let w = self.x1.min(o.x1).saturating_sub(self.x0.max(o.x0)) as u64;
        let h = self.y1.min(o.y1).saturating_sub(self.y0.max(o.y0)) as u64;
        w * h
    }

    /// Intersection over union (0 when both are empty).
    pub fn iou(&self, o: &Rect) -> f64 {
        let i = self.intersection(o);
        let u = self.area() + o.area() - i;
        if u == 0 {
            0.0
        } else {
            i as f64 / u as f64
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn iou_of_overlapping_rectangles() {
        let a = Rect {
            x0: 0,
            y0: 0,
            x1: 10,
            y1: 10,
        };
        let b = Rect {
            x0: 5,
            y0: 0,
            x1: 15,
            y1: 10,
        };
        // 50 shared of 150
        assert!((a.iou(&b) - 1.0 / 3.0).abs() < 1e-12);
        assert_eq!(a.iou(&a), 1.0);
        let c = Rect {
            x0: 10,
            y0: 10,
            x1: 20,
            y1: 20,
        };
        assert_eq!(a.iou(&c), 0.0);
    }
}
