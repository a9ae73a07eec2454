//! Line plots people can open: measured against simulated curves (KES hysteresis loops,
//! decays), written as PNG and SVG with plotters, and their data as CSV.
//!
//! A plot is a [`PlotSpec`]: a title, two axis labels and a list of [`Series`], each drawn
//! in its own colour from a fixed palette ([`series_colour`]) and [`SeriesStyle`] (measured
//! curves usually [`SeriesStyle::Markers`] or [`SeriesStyle::Dashed`], simulated ones
//! [`SeriesStyle::Solid`]), with a legend in the upper left corner. The axis ranges cover
//! all finite points with a 5 % margin. Points with a NaN or infinite coordinate are not
//! drawn: a line breaks there. Empty series still get a legend entry.
//!
//! [`write_plot`] picks the format from the file extension; [`write_plot_pair`] writes both;
//! [`write_series_csv`] writes the numbers behind a plot. Every file is written to a
//! temporary file beside it and renamed into place, so a reader never sees half a file.
//! Errors ([`PlotError`]) name the file.
//!
//! Text uses DejaVu Sans, embedded in the binary (`assets/fonts/DejaVuSans.ttf`, Bitstream
//! Vera licence, see `assets/fonts/LICENSE-DejaVu.txt`), so plots need no system fonts.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::sync::Once;

use plotters::coord::Shift;
use plotters::element::DashedPathElement;
use plotters::prelude::*;
use plotters::style::{register_font, FontStyle};

/// A plotting or writing failure, naming the file.
#[derive(Debug, thiserror::Error)]
#[error("{}: {message}", path.display())]
pub struct PlotError {
    /// The file that was being written.
    pub path: PathBuf,
    /// What failed.
    pub message: String,
}

/// How a series is drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SeriesStyle {
    /// A solid line (usually a simulation).
    Solid,
    /// A dashed line.
    Dashed,
    /// Filled circles at the points, no line (usually a measurement).
    Markers,
}

/// One polyline of a plot.
#[derive(Debug, Clone, PartialEq)]
pub struct Series {
    /// Legend text.
    pub name: String,
    /// Points `[x, y]` in drawing order; points with a non-finite coordinate are skipped
    /// (a line breaks there).
    pub points: Vec<[f64; 2]>,
    /// Drawing style.
    pub style: SeriesStyle,
}

/// A plot: title, axis labels, series.
#[derive(Debug, Clone, PartialEq)]
pub struct PlotSpec {
    /// Title above the plot.
    pub title: String,
    /// Label of the horizontal axis.
    pub x_label: String,
    /// Label of the vertical axis.
    pub y_label: String,
    /// The series, drawn in order (later ones on top); series `k` gets
    /// [`series_colour`]`(k)`.
    pub series: Vec<Series>,
}

/// Size of the PNG that [`write_plot_pair`] writes, in pixels (the SVG has the same
/// nominal size).
pub const PAIR_SIZE: (u32, u32) = (900, 600);

/// Smallest width and height [`write_plot`] accepts, in pixels.
pub const MIN_SIZE: u32 = 160;

/// Largest width and height [`write_plot`] accepts, in pixels.
pub const MAX_SIZE: u32 = 16_384;

/// The fixed palette (Tableau 10), as RGB: series `k` is drawn in `PALETTE[k % 10]`.
const PALETTE: [[u8; 3]; 10] = [
    [31, 119, 180],  // blue
    [255, 127, 14],  // orange
    [44, 160, 44],   // green
    [214, 39, 40],   // red
    [148, 103, 189], // purple
    [140, 86, 75],   // brown
    [227, 119, 194], // pink
    [127, 127, 127], // grey
    [188, 189, 34],  // olive
    [23, 190, 207],  // cyan
];

/// The RGB colour of the series at `index` in a [`PlotSpec`] (a fixed palette of ten
/// distinct colours, repeating after ten series).
pub fn series_colour(index: usize) -> [u8; 3] {
    PALETTE[index % PALETTE.len()]
}

pub(crate) const FONT_FAMILY: &str = "sans-serif";
static FONT: Once = Once::new();

pub(crate) fn register_embedded_font() {
    FONT.call_once(|| {
        let bytes: &'static [u8] = include_bytes!("../../assets/fonts/DejaVuSans.ttf");
        // the embedded font is a known good TTF; should it ever fail to parse, drawing
        // text reports a font error, which write_plot returns as a PlotError
        let _ = register_font(FONT_FAMILY, FontStyle::Normal, bytes);
    });
}

pub(crate) fn error(path: &Path, message: impl std::fmt::Display) -> PlotError {
    PlotError {
        path: path.to_path_buf(),
        message: message.to_string(),
    }
}

fn finite(p: &[f64; 2]) -> bool {
    p[0].is_finite() && p[1].is_finite()
}

/// A range covering `lo..=hi` with a 5 % margin each side; a degenerate range is widened,
/// an empty one (no finite value) becomes `0..1`.
fn padded(lo: f64, hi: f64) -> (f64, f64) {
    if !(lo.is_finite() && hi.is_finite()) {
        return (0.0, 1.0);
    }
    let width = hi - lo;
    let margin = if width > f64::EPSILON * lo.abs().max(hi.abs()) && width.is_finite() {
        0.05 * width
    } else if lo == 0.0 {
        1.0
    } else {
        0.1 * lo.abs()
    };
    let (a, b) = (lo - margin, hi + margin);
    // near ±f64::MAX the margin overflows; keep the data range then
    (
        if a.is_finite() { a } else { lo },
        if b.is_finite() { b } else { hi },
    )
}

/// The x and y ranges of all finite points of `spec`, with margins.
fn ranges(spec: &PlotSpec) -> ((f64, f64), (f64, f64)) {
    let mut x = (f64::INFINITY, f64::NEG_INFINITY);
    let mut y = (f64::INFINITY, f64::NEG_INFINITY);
    for p in spec
        .series
        .iter()
        .flat_map(|s| &s.points)
        .filter(|p| finite(p))
    {
        x = (x.0.min(p[0]), x.1.max(p[0]));
        y = (y.0.min(p[1]), y.1.max(p[1]));
    }
    (padded(x.0, x.1), padded(y.0, y.1))
}

/// One axis as drawn: the plotted range in units of `10^exponent` (a power of ten noted in
/// the axis label, for very large or very small values), the number of decimals of its tick
/// labels and at most how many ticks it gets.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Axis {
    lo: f64,
    hi: f64,
    exponent: i32,
    decimals: usize,
    ticks: usize,
}

impl Axis {
    /// The axis for the (padded) range `lo..hi`, at most `ticks` ticks.
    fn new((lo, hi): (f64, f64), ticks: usize) -> Axis {
        let magnitude = lo.abs().max(hi.abs());
        let e = if magnitude > 0.0 {
            magnitude.log10().floor() as i32
        } else {
            0
        };
        // plotters gives a span under f64::EPSILON a single tick: scale small values up
        let exponent = if (-3..5).contains(&e) {
            0
        } else {
            e.clamp(-300, 300)
        };
        let unit = 10f64.powi(exponent);
        let (lo, hi) = (lo / unit, hi / unit);
        // ticks are 1, 2 or 5 × 10^k apart, at least (hi - lo) / ticks
        let step = (hi - lo) / ticks as f64;
        let decimals = if step > 0.0 && step.is_finite() {
            (-step.log10().floor()).clamp(0.0, 12.0) as usize
        } else {
            1
        };
        Axis {
            lo,
            hi,
            exponent,
            decimals,
            ticks,
        }
    }

    /// A data value in plotted units.
    fn map(&self, v: f64) -> f64 {
        v / 10f64.powi(self.exponent)
    }

    /// The axis label, with the power of ten when there is one.
    fn label(&self, text: &str) -> String {
        match self.exponent {
            0 => text.to_string(),
            e => format!("{text}  [×1e{e}]"),
        }
    }

    /// A tick label (no "-0.0").
    fn tick(&self, v: f64) -> String {
        let v = if v.abs() < 0.5 * 10f64.powi(-(self.decimals as i32)) {
            0.0
        } else {
            v
        };
        format!("{:.*}", self.decimals, v)
    }

    /// About how many pixels its widest tick label needs.
    fn tick_width(&self) -> u32 {
        let chars = self.tick(self.lo).len().max(self.tick(self.hi).len());
        9 * chars as u32
    }
}

/// The runs of consecutive finite points of `points`, mapped to plotted units.
fn finite_runs(points: &[[f64; 2]], x: &Axis, y: &Axis) -> Vec<Vec<(f64, f64)>> {
    points
        .split(|p| !finite(p))
        .filter(|run| !run.is_empty())
        .map(|run| run.iter().map(|p| (x.map(p[0]), y.map(p[1]))).collect())
        .collect()
}

fn draw<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>, spec: &PlotSpec) -> Result<(), String>
where
    DB::ErrorType: 'static,
{
    let fail = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
    root.fill(&WHITE).map_err(fail)?;
    let (width, height) = root.dim_in_pixel();
    let (xr, yr) = ranges(spec);
    let x = Axis::new(xr, (width / 100).clamp(2, 10) as usize);
    let y = Axis::new(yr, (height / 60).clamp(2, 10) as usize);
    let tick_x = |v: &f64| x.tick(*v);
    let tick_y = |v: &f64| y.tick(*v);
    let mut chart = ChartBuilder::on(root)
        .caption(&spec.title, (FONT_FAMILY, 22))
        .margin(14)
        .x_label_area_size(48)
        .y_label_area_size(30 + y.tick_width())
        .build_cartesian_2d(x.lo..x.hi, y.lo..y.hi)
        .map_err(fail)?;
    chart
        .configure_mesh()
        .x_labels(x.ticks)
        .y_labels(y.ticks)
        .x_label_formatter(&tick_x)
        .y_label_formatter(&tick_y)
        .x_desc(x.label(&spec.x_label))
        .y_desc(y.label(&spec.y_label))
        .label_style((FONT_FAMILY, 14))
        .axis_desc_style((FONT_FAMILY, 16))
        .draw()
        .map_err(fail)?;

    for (k, series) in spec.series.iter().enumerate() {
        let [r, g, b] = series_colour(k);
        let colour = RGBColor(r, g, b);
        let line = colour.stroke_width(2);
        let runs = finite_runs(&series.points, &x, &y);
        let annotation = match series.style {
            SeriesStyle::Markers => {
                let points = runs.into_iter().flatten();
                chart
                    .draw_series(points.map(|p| Circle::new(p, 3, colour.filled())))
                    .map_err(fail)?
            }
            SeriesStyle::Solid | SeriesStyle::Dashed => {
                // a point with no finite neighbour would draw nothing as a line
                let lone = runs.iter().filter(|run| run.len() == 1).map(|run| run[0]);
                chart
                    .draw_series(lone.map(|p| Circle::new(p, 2, colour.filled())))
                    .map_err(fail)?;
                let lines = runs.into_iter().filter(|run| run.len() > 1);
                if series.style == SeriesStyle::Solid {
                    chart
                        .draw_series(lines.map(|run| PathElement::new(run, line)))
                        .map_err(fail)?
                } else {
                    chart
                        .draw_series(lines.map(|run| DashedPathElement::new(run, 7, 5, line)))
                        .map_err(fail)?
                }
            }
        };
        let style = series.style;
        annotation.label(series.name.as_str()).legend(
            move |(x, y)| -> DynElement<'static, DB, (i32, i32)> {
                match style {
                    SeriesStyle::Markers => Circle::new((x + 11, y), 3, colour.filled()).into_dyn(),
                    SeriesStyle::Solid => {
                        PathElement::new(vec![(x, y), (x + 22, y)], line).into_dyn()
                    }
                    SeriesStyle::Dashed => {
                        DashedPathElement::new(vec![(x, y), (x + 22, y)], 7, 5, line).into_dyn()
                    }
                }
            },
        );
    }
    if !spec.series.is_empty() {
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperLeft)
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .label_font((FONT_FAMILY, 14))
            .draw()
            .map_err(fail)?;
    }
    root.present().map_err(fail)
}

/// A temporary file beside `path`, for writing it atomically.
fn temp_beside(path: &Path) -> PathBuf {
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned());
    let name = format!(
        ".{}.{}.tmp",
        name.as_deref().unwrap_or("plot"),
        std::process::id()
    );
    path.with_file_name(name)
}

/// Writes `path` atomically: `write` fills a temporary file beside it, which is then renamed
/// to `path`; on failure the temporary file is removed and the error names `path`.
pub(crate) fn write_atomic(
    path: &Path,
    write: impl FnOnce(&Path) -> Result<(), String>,
) -> Result<(), PlotError> {
    if path.file_name().is_none() {
        return Err(error(path, "not a file path"));
    }
    let tmp = temp_beside(path);
    let result = write(&tmp).and_then(|()| std::fs::rename(&tmp, path).map_err(|e| e.to_string()));
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result.map_err(|message| error(path, message))
}

/// Writes the plot to `path`, `width` × `height` pixels, as PNG or SVG after the extension
/// of `path` (`.png` or `.svg`, any case). The directory must exist. Non-finite points are
/// skipped; empty series are allowed.
///
/// # Errors
///
/// A [`PlotError`] naming `path` when the extension is neither, a size is outside
/// [`MIN_SIZE`]`..=`[`MAX_SIZE`], drawing fails or the file cannot be written.
pub fn write_plot(path: &Path, spec: &PlotSpec, width: u32, height: u32) -> Result<(), PlotError> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    let ext = match ext.as_deref() {
        Some(ext @ ("png" | "svg")) => ext,
        _ => return Err(error(path, "a plot file must end in .png or .svg")),
    };
    let sizes = MIN_SIZE..=MAX_SIZE;
    if !sizes.contains(&width) || !sizes.contains(&height) {
        let message =
            format!("plot size {width}×{height} is outside {MIN_SIZE}..={MAX_SIZE} pixels");
        return Err(error(path, message));
    }
    register_embedded_font();
    if ext == "png" {
        let mut pixels = vec![255u8; width as usize * height as usize * 3];
        {
            let backend = BitMapBackend::<plotters::backend::RGBPixel>::with_buffer_and_format(
                &mut pixels,
                (width, height),
            )
            .map_err(|e| error(path, e))?;
            draw(&backend.into_drawing_area(), spec).map_err(|e| error(path, e))?;
        }
        let image = image::RgbImage::from_raw(width, height, pixels)
            .ok_or_else(|| error(path, "pixel buffer has the wrong size"))?;
        write_atomic(path, |tmp| {
            image
                .save_with_format(tmp, image::ImageFormat::Png)
                .map_err(|e| e.to_string())
        })
    } else {
        let mut text = String::new();
        {
            let root = SVGBackend::with_string(&mut text, (width, height)).into_drawing_area();
            draw(&root, spec).map_err(|e| error(path, e))?;
        }
        write_atomic(path, |tmp| {
            std::fs::write(tmp, &text).map_err(|e| e.to_string())
        })
    }
}

/// Writes `<stem>.png` ([`PAIR_SIZE`], 900 × 600) and `<stem>.svg`, the extension appended
/// to the whole file name of `stem` (so `out/N1.2_shear` gives `out/N1.2_shear.png`);
/// returns both paths.
///
/// # Errors
///
/// As [`write_plot`], naming the file that failed.
pub fn write_plot_pair(stem: &Path, spec: &PlotSpec) -> Result<(PathBuf, PathBuf), PlotError> {
    let with = |ext: &str| {
        let mut name = stem.as_os_str().to_owned();
        name.push(".");
        name.push(ext);
        PathBuf::from(name)
    };
    let (png, svg) = (with("png"), with("svg"));
    let (w, h) = PAIR_SIZE;
    write_plot(&png, spec, w, h)?;
    write_plot(&svg, spec, w, h)?;
    Ok((png, svg))
}

/// A CSV field: quoted (with doubled quotes) when it holds a comma, quote or line break.
fn csv_field(text: &str) -> String {
    if text.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", text.replace('"', "\"\""))
    } else {
        text.to_string()
    }
}

/// Writes the series as CSV, atomically: a header `series,x,y`, then one row per point of
/// every series in order (series name, x, y). Numbers are written with full precision;
/// non-finite ones as `NaN`, `inf` or `-inf`. Names are quoted as RFC 4180 asks when
/// needed.
///
/// # Errors
///
/// A [`PlotError`] naming `path` when the file cannot be written (a missing directory,
/// for one).
pub fn write_series_csv(path: &Path, series: &[Series]) -> Result<(), PlotError> {
    let mut text = String::from("series,x,y\n");
    for s in series {
        let name = csv_field(&s.name);
        for p in &s.points {
            // writing to a String cannot fail
            let _ = writeln!(text, "{name},{},{}", p[0], p[1]);
        }
    }
    write_atomic(path, |tmp| {
        std::fs::write(tmp, &text).map_err(|e| e.to_string())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges_have_margins_and_survive_degenerate_data() {
        assert_eq!(padded(0.0, 10.0), (-0.5, 10.5));
        assert_eq!(padded(f64::INFINITY, f64::NEG_INFINITY), (0.0, 1.0));
        assert_eq!(padded(0.0, 0.0), (-1.0, 1.0));
        let (a, b) = padded(5.0, 5.0);
        assert!(a < 5.0 && b > 5.0);
        let (a, b) = padded(-f64::MAX, f64::MAX);
        assert!(a.is_finite() && b.is_finite() && a < b);
    }

    #[test]
    fn runs_break_at_non_finite_points() {
        let axis = Axis::new((0.0, 1.0), 10);
        let points = [
            [0.0, 0.0],
            [1.0, 1.0],
            [f64::NAN, 2.0],
            [3.0, 3.0],
            [4.0, f64::INFINITY],
        ];
        let runs = finite_runs(&points, &axis, &axis);
        assert_eq!(runs, vec![vec![(0.0, 0.0), (1.0, 1.0)], vec![(3.0, 3.0)]]);
    }

    #[test]
    fn axes_scale_extreme_values_and_pick_decimals() {
        let a = Axis::new((-0.5, 10.5), 10);
        assert_eq!((a.exponent, a.decimals), (0, 0));
        assert_eq!(a.tick(4.0), "4");
        assert_eq!(a.label("x"), "x");
        let a = Axis::new((-0.275, 0.275), 10);
        assert_eq!((a.exponent, a.decimals), (0, 2));
        assert_eq!(a.tick(-1e-17), "0.00");
        let a = Axis::new((0.9e-12, 3.1e-12), 10);
        assert_eq!(a.exponent, -12);
        assert!((a.lo - 0.9).abs() < 1e-12 && (a.hi - 3.1).abs() < 1e-12);
        assert_eq!(a.tick(2.5), "2.5");
        assert_eq!(a.label("y"), "y  [×1e-12]");
        let a = Axis::new((-1.1e300, 1.1e300), 10);
        assert_eq!(a.exponent, 300);
        assert!((a.map(1e300) - 1.0).abs() < 1e-12);
        assert_eq!(Axis::new((-1.0, 1.0), 10).exponent, 0);
    }

    #[test]
    fn csv_fields_are_quoted_when_needed() {
        assert_eq!(csv_field("measured"), "measured");
        assert_eq!(csv_field("a, \"b\""), "\"a, \"\"b\"\"\"");
    }
}
