//! Line plots people can open: measured against simulated curves (KES hysteresis loops,
//! decays), written as PNG and SVG with plotters, and their data as CSV. Text uses the
//! embedded DejaVu Sans (`assets/fonts`, free licence).

use std::path::{Path, PathBuf};
use std::sync::Once;

use plotters::prelude::*;
use plotters::style::{register_font, FontStyle};

/// A plotting or writing failure, naming the file.
#[derive(Debug, thiserror::Error)]
#[error("{path}: {message}")]
pub struct PlotError {
    /// The file.
    pub path: String,
    /// What failed.
    pub message: String,
}

/// How a series is drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SeriesStyle {
    /// A solid line (simulations).
    Solid,
    /// A dashed line.
    Dashed,
    /// Markers only (measurements).
    Markers,
}

/// One polyline of a plot.
#[derive(Debug, Clone, PartialEq)]
pub struct Series {
    /// Legend text.
    pub name: String,
    /// Points (x, y); non-finite ones are skipped.
    pub points: Vec<[f64; 2]>,
    /// Drawing style.
    pub style: SeriesStyle,
}

/// A plot: title, axis labels, series.
#[derive(Debug, Clone, PartialEq)]
pub struct PlotSpec {
    /// Title.
    pub title: String,
    /// Label of x.
    pub x_label: String,
    /// Label of y.
    pub y_label: String,
    /// The series.
    pub series: Vec<Series>,
}

static FONT: Once = Once::new();

fn font() {
    FONT.call_once(|| {
        let bytes: &'static [u8] = include_bytes!("../../assets/fonts/DejaVuSans.ttf");
        // the embedded font is known good; a failure would only lose text
        let _ = register_font("sans-serif", FontStyle::Normal, bytes);
    });
}

const PALETTE: [RGBColor; 6] = [
    RGBColor(0, 0, 0),
    RGBColor(214, 39, 40),
    RGBColor(31, 119, 180),
    RGBColor(44, 160, 44),
    RGBColor(148, 103, 189),
    RGBColor(255, 127, 14),
];

fn err(path: &Path, e: impl std::fmt::Display) -> PlotError {
    PlotError {
        path: path.display().to_string(),
        message: e.to_string(),
    }
}

fn ranges(spec: &PlotSpec) -> ((f64, f64), (f64, f64)) {
    let mut xr = (f64::INFINITY, f64::NEG_INFINITY);
    let mut yr = (f64::INFINITY, f64::NEG_INFINITY);
    for s in &spec.series {
        for p in s.points.iter().filter(|p| p[0].is_finite() && p[1].is_finite()) {
            xr = (xr.0.min(p[0]), xr.1.max(p[0]));
            yr = (yr.0.min(p[1]), yr.1.max(p[1]));
        }
    }
    let pad = |r: (f64, f64)| {
        if !r.0.is_finite() {
            return (0.0, 1.0);
        }
        let w = (r.1 - r.0).max(1e-12 * r.0.abs().max(1.0));
        (r.0 - 0.05 * w, r.1 + 0.05 * w)
    };
    (pad(xr), pad(yr))
}

fn draw<DB: DrawingBackend>(root: DrawingArea<DB, plotters::coord::Shift>, spec: &PlotSpec) -> Result<(), String>
where
    DB::ErrorType: 'static,
{
    root.fill(&WHITE).map_err(|e| e.to_string())?;
    let ((x0, x1), (y0, y1)) = ranges(spec);
    let mut chart = ChartBuilder::on(&root)
        .caption(&spec.title, ("sans-serif", 22))
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(70)
        .build_cartesian_2d(x0..x1, y0..y1)
        .map_err(|e| e.to_string())?;
    chart
        .configure_mesh()
        .x_desc(&spec.x_label)
        .y_desc(&spec.y_label)
        .label_style(("sans-serif", 14))
        .draw()
        .map_err(|e| e.to_string())?;
    for (k, s) in spec.series.iter().enumerate() {
        let colour = PALETTE[k % PALETTE.len()];
        let pts: Vec<(f64, f64)> = s
            .points
            .iter()
            .filter(|p| p[0].is_finite() && p[1].is_finite())
            .map(|p| (p[0], p[1]))
            .collect();
        let legend_style = colour.stroke_width(2);
        match s.style {
            SeriesStyle::Markers => chart
                .draw_series(pts.iter().map(|&p| Circle::new(p, 3, colour.filled())))
                .map_err(|e| e.to_string())?
                .label(s.name.clone())
                .legend(move |(x, y)| Circle::new((x + 10, y), 3, colour.filled())),
            SeriesStyle::Solid => chart
                .draw_series(LineSeries::new(pts, colour.stroke_width(2)))
                .map_err(|e| e.to_string())?
                .label(s.name.clone())
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], legend_style)),
            SeriesStyle::Dashed => chart
                .draw_series(DashedLineSeries::new(pts, 6, 4, colour.stroke_width(2)))
                .map_err(|e| e.to_string())?
                .label(s.name.clone())
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], legend_style)),
        };
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font(("sans-serif", 14))
        .draw()
        .map_err(|e| e.to_string())?;
    root.present().map_err(|e| e.to_string())
}

/// Writes the plot as PNG or SVG (by the extension of `path`), `width` × `height` pixels.
pub fn write_plot(path: &Path, spec: &PlotSpec, width: u32, height: u32) -> Result<(), PlotError> {
    font();
    let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("");
    let tmp = path.with_extension(format!("{ext}.tmp"));
    match ext {
        "png" => {
            let mut buf = vec![255u8; (width * height * 3) as usize];
            {
                let root = BitMapBackend::with_buffer(&mut buf, (width, height)).into_drawing_area();
                draw(root, spec).map_err(|e| err(path, e))?;
            }
            let img = image::RgbImage::from_raw(width, height, buf)
                .ok_or_else(|| err(path, "image buffer size"))?;
            img.save_with_format(&tmp, image::ImageFormat::Png)
                .map_err(|e| err(path, e))?;
        }
        "svg" => {
            let mut text = String::new();
            {
                let root = SVGBackend::with_string(&mut text, (width, height)).into_drawing_area();
                draw(root, spec).map_err(|e| err(path, e))?;
            }
            std::fs::write(&tmp, text).map_err(|e| err(path, e))?;
        }
        _ => return Err(err(path, "the plot file must end in .png or .svg")),
    }
    std::fs::rename(&tmp, path).map_err(|e| err(path, e))
}

/// Writes `stem.png` (900 × 600) and `stem.svg`; returns both paths.
pub fn write_plot_pair(stem: &Path, spec: &PlotSpec) -> Result<(PathBuf, PathBuf), PlotError> {
    let (png, svg) = (stem.with_extension("png"), stem.with_extension("svg"));
    write_plot(&png, spec, 900, 600)?;
    write_plot(&svg, spec, 900, 600)?;
    Ok((png, svg))
}

/// Writes the series as CSV (`series,x,y`, one row per point), atomically.
pub fn write_series_csv(path: &Path, series: &[Series]) -> Result<(), PlotError> {
    let mut text = String::from("series,x,y\n");
    for s in series {
        let name = s.name.replace(',', ";");
        for p in &s.points {
            text += &format!("{name},{},{}\n", p[0], p[1]);
        }
    }
    let tmp = path.with_extension("csv.tmp");
    std::fs::write(&tmp, text).map_err(|e| err(path, e))?;
    std::fs::rename(&tmp, path).map_err(|e| err(path, e))
}
