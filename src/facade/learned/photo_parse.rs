//! One photo through the learned parse: features at the working resolution, the forest's
//! class probabilities, the structure's corrections ([`super::rectangles`]), and the result
//! scaled back to the photo's pixels.

use std::time::Instant;

use image::RgbImage;

use super::super::rect::Rect;
use super::classes::{Element, N_CLASSES};
use super::dataset::ElementMap;
use super::features::{pixel_features, working_image};
use super::model::Model;
use super::rectangles::{argmax, corrected_classes, window_rectangles};

/// A photo's learned parse.
#[derive(Debug, Clone)]
pub struct LearnedParse {
    /// A class per photo pixel.
    pub elements: ElementMap,
    /// Window rectangles, photo pixels.
    pub windows: Vec<Rect>,
    /// Class probabilities at the working resolution (`w × h × N_CLASSES`).
    pub probabilities: Vec<f32>,
    /// Working resolution.
    pub work_size: (u32, u32),
    /// Seconds the analysis took (features, forest, structure, scaling).
    pub seconds: f64,
}

/// Parses `rgb` with `model`; `structure` applies the corrections (windows as aligned
/// rectangles, doors at street level), otherwise windows are the bounding boxes of the
/// classifier's window pieces and the classes its argmax. The window probability is
/// multiplied by `window_boost` before either (a prior shift: the forest, trained on pixels
/// drawn evenly, under-calls the minority class).
pub fn parse_photo(
    model: &Model,
    rgb: &RgbImage,
    structure: bool,
    window_boost: f32,
) -> LearnedParse {
    let t0 = Instant::now();
    let work = working_image(rgb);
    let feats = pixel_features(&work);
    let mut probs = model.probabilities(&feats);
    for p in probs.chunks_exact_mut(N_CLASSES) {
        p[Element::Window.index()] *= window_boost;
    }
    let (w, h) = (feats.width as usize, feats.height as usize);
    let (classes, rects) = if structure {
        let rects = window_rectangles(&probs, w, h);
        (corrected_classes(&probs, w, h, &rects), rects)
    } else {
        let classes = argmax(&probs);
        let mask: Vec<bool> = classes.iter().map(|c| *c == Element::Window).collect();
        let rects = crate::geometry::image::components(
            &mask,
            w,
            h,
            crate::geometry::image::Connectivity::Four,
        )
        .into_iter()
        .filter(|c| c.pixels >= 4)
        .map(|c| Rect::new(c.bbox[0], c.bbox[1], c.bbox[2], c.bbox[3]))
        .collect();
        (classes, rects)
    };
    let (pw, ph) = rgb.dimensions();
    let sx = pw as f64 / w as f64;
    let sy = ph as f64 / h as f64;
    let mut full = Vec::with_capacity(pw as usize * ph as usize);
    let cols: Vec<usize> = (0..pw)
        .map(|x| (((x as f64 + 0.5) / sx) as usize).min(w - 1))
        .collect();
    for y in 0..ph {
        let wy = (((y as f64 + 0.5) / sy) as usize).min(h - 1);
        full.extend(cols.iter().map(|&wx| classes[wy * w + wx]));
    }
    let scale = |v: u32, s: f64, max: u32| ((v as f64 * s).round() as u32).min(max);
    let windows = rects
        .iter()
        .map(|r| Rect {
            x0: scale(r.x0, sx, pw),
            y0: scale(r.y0, sy, ph),
            x1: scale(r.x1, sx, pw),
            y1: scale(r.y1, sy, ph),
        })
        .collect();
    debug_assert_eq!(probs.len(), w * h * N_CLASSES);
    LearnedParse {
        elements: ElementMap {
            width: pw,
            height: ph,
            classes: full,
        },
        windows,
        probabilities: probs,
        work_size: (w as u32, h as u32),
        seconds: t0.elapsed().as_secs_f64(),
    }
}
