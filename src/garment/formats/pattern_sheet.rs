//! Pattern sheets: the pieces of a sewing pattern laid side by side at scale, as PNG or SVG,
//! each with its name, grain line and notches, and every seam's two edges drawn in the seam's
//! colour and labelled with its number, so that a designer can check what is sewn to what.

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;

use crate::garment::{Pattern, P2};
use crate::render::plot::{
    error, register_embedded_font, series_colour, write_atomic, FONT_FAMILY,
};
use crate::render::PlotError;

/// Gap between pieces on the sheet (m).
const GAP: f64 = 0.05;

/// Where each piece goes on the sheet: its offset (m) and the sheet's size (m).
fn layout(pattern: &Pattern) -> (Vec<P2>, P2) {
    let mut x = GAP;
    let mut height: f64 = 0.0;
    let mut offsets = Vec::new();
    for piece in &pattern.pieces {
        let flat = piece.outline.flatten(5e-4);
        let (lo, hi) = flat
            .points
            .iter()
            .fold(([f64::MAX; 2], [f64::MIN; 2]), |(l, h), p| {
                (
                    [l[0].min(p.at[0]), l[1].min(p.at[1])],
                    [h[0].max(p.at[0]), h[1].max(p.at[1])],
                )
            });
        offsets.push([x - lo[0], GAP - lo[1]]);
        x += hi[0] - lo[0] + GAP;
        height = height.max(hi[1] - lo[1]);
    }
    (offsets, [x, height + 2.0 * GAP])
}

fn draw<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    pattern: &Pattern,
    scale: f64,
    offsets: &[P2],
    sheet_h: f64,
) -> Result<(), String> {
    let e = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
    root.fill(&WHITE).map_err(e)?;
    // sheet metres → pixels, y up
    let px = |k: usize, p: P2| -> (i32, i32) {
        let o = offsets[k];
        (
            ((p[0] + o[0]) * scale).round() as i32,
            ((sheet_h - (p[1] + o[1])) * scale).round() as i32,
        )
    };
    let text = |size: u32| (FONT_FAMILY, size).into_font().color(&BLACK);
    for (k, piece) in pattern.pieces.iter().enumerate() {
        let flat = piece.outline.flatten(5e-4);
        let mut pts: Vec<(i32, i32)> = flat.points.iter().map(|p| px(k, p.at)).collect();
        if let Some(&first) = pts.first() {
            pts.push(first);
        }
        root.draw(&Polygon::new(pts.clone(), RGBColor(236, 240, 246).filled()))
            .map_err(e)?;
        root.draw(&PathElement::new(pts, BLACK.stroke_width(1)))
            .map_err(e)?;
        let [g0, g1] = piece.grain;
        root.draw(&PathElement::new(
            vec![px(k, g0), px(k, g1)],
            RGBColor(90, 90, 90).stroke_width(1),
        ))
        .map_err(e)?;
        let head = px(k, g1);
        root.draw(&Circle::new(head, 3, RGBColor(90, 90, 90).filled()))
            .map_err(e)?;
        for n in &piece.notches {
            root.draw(&Circle::new(px(k, *n), 3, RED.filled()))
                .map_err(e)?;
        }
        let c = flat
            .points
            .iter()
            .fold([0.0, 0.0], |a, p| [a[0] + p.at[0], a[1] + p.at[1]]);
        let m = flat.points.len().max(1) as f64;
        let (cx, cy) = px(k, [c[0] / m, c[1] / m]);
        root.draw(&Text::new(piece.name.clone(), (cx - 20, cy), text(16)))
            .map_err(e)?;
    }
    for (number, seam) in pattern.seams.iter().enumerate() {
        let [r, g, b] = series_colour(number);
        let colour = RGBColor(r, g, b);
        for edge in [&seam.a, &seam.b] {
            let Some(k) = pattern.pieces.iter().position(|p| p.name == edge.piece) else {
                continue;
            };
            let outline = &pattern.pieces[k].outline;
            let (Some(from), Some(to)) = (
                outline.corner_index(&edge.from),
                outline.corner_index(&edge.to),
            ) else {
                continue;
            };
            let line = outline.flatten(5e-4).edge(from, to);
            let pts: Vec<(i32, i32)> = line.iter().map(|p| px(k, *p)).collect();
            root.draw(&PathElement::new(pts.clone(), colour.stroke_width(3)))
                .map_err(e)?;
            let mid = pts[pts.len() / 2];
            root.draw(&Text::new(
                format!("{}", number + 1),
                (mid.0 + 4, mid.1 - 6),
                (FONT_FAMILY, 15).into_font().color(&colour),
            ))
            .map_err(e)?;
        }
    }
    let legend: Vec<String> = pattern
        .seams
        .iter()
        .enumerate()
        .map(|(i, s)| format!("{} {}", i + 1, s.name))
        .collect();
    root.draw(&Text::new(
        format!("{}: {}", pattern.name, legend.join(", ")),
        (8, 6),
        text(13),
    ))
    .map_err(e)?;
    Ok(())
}

/// Writes the pattern sheet of `pattern` to `path` (`.png` or `.svg`) at `pixels_per_metre`,
/// creating the directory if needed.
pub fn write_pattern_sheet(
    path: &Path,
    pattern: &Pattern,
    pixels_per_metre: f64,
) -> Result<(), PlotError> {
    if !(pixels_per_metre.is_finite() && pixels_per_metre > 0.0) {
        return Err(error(
            path,
            format!("pixels per metre must be > 0, got {pixels_per_metre}"),
        ));
    }
    let (offsets, size) = layout(pattern);
    let (w, h) = (
        (size[0] * pixels_per_metre).ceil() as u32,
        (size[1] * pixels_per_metre).ceil() as u32 + 20,
    );
    if w == 0 || h == 0 || w > 20_000 || h > 20_000 {
        return Err(error(
            path,
            format!("sheet of {w}×{h} pixels is too large or empty"),
        ));
    }
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(|e| error(path, e))?;
    }
    register_embedded_font();
    let sheet_h = size[1] + 20.0 / pixels_per_metre;
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("png") => {
            let mut pixels = vec![255u8; w as usize * h as usize * 3];
            {
                let backend = BitMapBackend::<plotters::backend::RGBPixel>::with_buffer_and_format(
                    &mut pixels,
                    (w, h),
                )
                .map_err(|e| error(path, e))?;
                draw(
                    &backend.into_drawing_area(),
                    pattern,
                    pixels_per_metre,
                    &offsets,
                    sheet_h,
                )
                .map_err(|e| error(path, e))?;
            }
            let image = image::RgbImage::from_raw(w, h, pixels)
                .ok_or_else(|| error(path, "pixel buffer has the wrong size"))?;
            write_atomic(path, |tmp| {
                image
                    .save_with_format(tmp, image::ImageFormat::Png)
                    .map_err(|e| e.to_string())
            })
        }
        Some("svg") => {
            let mut text = String::new();
            {
                let root = SVGBackend::with_string(&mut text, (w, h)).into_drawing_area();
                draw(&root, pattern, pixels_per_metre, &offsets, sheet_h)
                    .map_err(|e| error(path, e))?;
            }
            write_atomic(path, |tmp| {
                std::fs::write(tmp, &text).map_err(|e| e.to_string())
            })
        }
        _ => Err(error(path, "a pattern sheet must end in .png or .svg")),
    }
}
