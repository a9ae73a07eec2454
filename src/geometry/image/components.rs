//! Connected components of a mask (row-major `bool`s), four- or eight-connected: the bounding
//! box and pixel count of each, in the order of their first pixel (row-major). Labels come
//! from `imageproc`'s two-pass union-find labelling, which numbers the components in that
//! same order.

use image::GrayImage;
use imageproc::region_labelling::connected_components;

pub use imageproc::region_labelling::Connectivity;

/// One connected component.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Component {
    /// Bounding box, half-open: columns `x0..x1`, rows `y0..y1`.
    pub bbox: [u32; 4],
    /// Pixels in the component.
    pub pixels: u64,
}

/// The connected components of the set pixels of `mask` (`w × h`, row-major), in the order
/// of their first pixel.
pub fn components(mask: &[bool], w: usize, h: usize, connectivity: Connectivity) -> Vec<Component> {
    let bytes: Vec<u8> = mask.iter().map(|&m| m as u8).collect();
    let image = GrayImage::from_raw(w as u32, h as u32, bytes).expect("a mask of w × h pixels");
    let labels = connected_components(&image, connectivity, image::Luma([0]));
    let mut out: Vec<Component> = Vec::new();
    for (i, &label) in labels.as_raw().iter().enumerate() {
        if label == 0 {
            continue;
        }
        let (x, y) = ((i % w) as u32, (i / w) as u32);
        let k = label as usize - 1;
        if k == out.len() {
            out.push(Component {
                bbox: [x, y, x + 1, y + 1],
                pixels: 0,
            });
        }
        let c = &mut out[k];
        c.bbox = [
            c.bbox[0].min(x),
            c.bbox[1].min(y),
            c.bbox[2].max(x + 1),
            c.bbox[3].max(y + 1),
        ];
        c.pixels += 1;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn diagonal_pixels_join_only_when_eight_connected() {
        // ■ . ■
        // . ■ .
        // . . ■
        let m = [true, false, true, false, true, false, false, false, true];
        let four = components(&m, 3, 3, Connectivity::Four);
        assert_eq!(four.len(), 4);
        assert_eq!(
            four[1].bbox,
            [2, 0, 3, 1],
            "in the order of the first pixel"
        );
        let eight = components(&m, 3, 3, Connectivity::Eight);
        assert_eq!(
            eight,
            vec![Component {
                bbox: [0, 0, 3, 3],
                pixels: 4
            }]
        );
    }

    #[test]
    fn a_u_shape_is_one_component_first_seen_at_its_left_arm() {
        // ■ . ■ ■
        // ■ . ■ .
        // ■ ■ ■ .
        let m = [
            true, false, true, true, true, false, true, false, true, true, true, false,
        ];
        let c = components(&m, 4, 3, Connectivity::Four);
        assert_eq!(
            c,
            vec![Component {
                bbox: [0, 0, 4, 3],
                pixels: 8
            }]
        );
    }
}
