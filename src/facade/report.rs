//! Evaluation over a folder of labelled photos: the images that have a label map, one report
//! per image, and the summary (per-image means of window IoU and F1, pooled pixel accuracy)
//! written as CSV and Markdown.

use std::path::{Path, PathBuf};

use super::error::FacadeError;
use super::labels::{Class, LabelMap};
use super::rect::Rect;
use super::score::{DetectionScore, FacadeScore, PixelScore};

/// A facade parse as the scorer sees it: a class per pixel and the window rectangles.
#[derive(Debug, Clone, PartialEq)]
pub struct FacadeParse {
    /// Class per pixel of the input image.
    pub labels: LabelMap,
    /// Window rectangles (pixels).
    pub windows: Vec<Rect>,
}

impl FacadeParse {
    /// The all-wall baseline: every pixel wall, no window.
    pub fn all_wall(width: u32, height: u32) -> Self {
        FacadeParse {
            labels: LabelMap::filled(width, height, Class::Wall),
            windows: Vec::new(),
        }
    }
}

/// One image's scores.
#[derive(Debug, Clone, PartialEq)]
pub struct ImageReport {
    /// Image name (file stem).
    pub name: String,
    /// Its scores.
    pub score: FacadeScore,
}

/// Figures over all images.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Summary {
    /// Images scored.
    pub images: usize,
    /// Mean over images of the window IoU.
    pub window_iou: f64,
    /// Mean over images of the window-detection F1 at IoU 0.5.
    pub f1: f64,
    /// Pixel accuracy of all images' pixels pooled.
    pub pixel_accuracy: f64,
    /// Window IoU of all images' pixels pooled.
    pub pooled_window_iou: f64,
    /// Window detection of all images pooled.
    pub pooled: DetectionScore,
}

/// Stems of the photos (any of the
/// [`PHOTO_EXTENSIONS`](crate::geometry::image::PHOTO_EXTENSIONS)) in `dir/images` that have
/// a label map `dir/labels/STEM.png`, sorted.
pub fn labelled_images(dir: &Path) -> Result<Vec<String>, FacadeError> {
    let images = dir.join("images");
    let err = |e: std::io::Error| FacadeError::File {
        path: images.clone(),
        message: e.to_string(),
    };
    let mut stems = Vec::new();
    for entry in std::fs::read_dir(&images).map_err(err)? {
        let p = entry.map_err(err)?.path();
        if !crate::geometry::image::is_photo(&p) {
            continue;
        }
        if let Some(stem) = p.file_stem().and_then(|s| s.to_str()) {
            if dir.join("labels").join(format!("{stem}.png")).is_file() {
                stems.push(stem.to_string());
            }
        }
    }
    stems.sort();
    Ok(stems)
}

/// The photo `dir/images/STEM.EXT` of a labelled facade, in whichever photo format it is
/// ([`photo_with_stem`](crate::geometry::image::photo_with_stem)); an error names the folder
/// and the stem when there is none.
pub fn labelled_photo(dir: &Path, stem: &str) -> Result<PathBuf, FacadeError> {
    let images = dir.join("images");
    crate::geometry::image::photo_with_stem(&images, stem).ok_or_else(|| FacadeError::File {
        path: images.join(stem),
        message: format!(
            "no photo of this stem ({})",
            crate::geometry::image::photo_formats::photo_extensions_list()
        ),
    })
}

/// Means and pooled figures of `reports`.
pub fn summarize(reports: &[ImageReport]) -> Summary {
    let k = reports.len().max(1) as f64;
    let mut pixels = PixelScore::default();
    let mut pooled = DetectionScore::default();
    for r in reports {
        pixels.add(&r.score.pixels);
        pooled.add(&r.score.windows);
    }
    Summary {
        images: reports.len(),
        window_iou: reports
            .iter()
            .map(|r| r.score.pixels.iou(Class::Window))
            .sum::<f64>()
            / k,
        f1: reports.iter().map(|r| r.score.windows.f1()).sum::<f64>() / k,
        pixel_accuracy: pixels.accuracy(),
        pooled_window_iou: pixels.iou(Class::Window),
        pooled,
    }
}

/// Writes `facades.csv` (one row per image) and `facades.md` (the same table and the
/// summary) into `dir`; returns their paths.
pub fn write_summary(
    reports: &[ImageReport],
    method: &str,
    dir: &Path,
) -> Result<(PathBuf, PathBuf), FacadeError> {
    let io = |p: &Path, e: std::io::Error| FacadeError::File {
        path: p.to_path_buf(),
        message: e.to_string(),
    };
    std::fs::create_dir_all(dir).map_err(|e| io(dir, e))?;
    let s = summarize(reports);
    let mut csv = String::from(
        "image,window_iou,pixel_accuracy,door_iou,windows_found,false_windows,missed_windows,precision,recall,f1\n",
    );
    let mut md = format!(
        "# Facade parses against labelled photos ({method})\n\n\
         | image | window IoU | pixel acc. | door IoU | found | false | missed | P | R | F1 |\n\
         |---|---|---|---|---|---|---|---|---|---|\n"
    );
    for r in reports {
        let (p, w) = (&r.score.pixels, &r.score.windows);
        let rates = [p.iou(Class::Window), p.accuracy(), p.iou(Class::Door)];
        let counts = [w.true_positives, w.false_positives, w.false_negatives];
        let prf = [w.precision(), w.recall(), w.f1()];
        let join = |v: Vec<String>, sep: &str| v.join(sep);
        let cells = |digits: [usize; 3]| -> Vec<String> {
            std::iter::once(r.name.clone())
                .chain(rates.iter().map(|v| format!("{v:.*}", digits[0])))
                .chain(counts.iter().map(|c| c.to_string()))
                .chain(prf[..2].iter().map(|v| format!("{v:.*}", digits[1])))
                .chain(std::iter::once(format!("{:.*}", digits[2], prf[2])))
                .collect()
        };
        csv += &join(cells([4, 4, 4]), ",");
        csv.push('\n');
        md += &format!("| {} |\n", join(cells([3, 2, 3]), " | "));
    }
    md += &format!(
        "\n**{} images**: mean window IoU {:.3}, mean F1@0.5 {:.3}; pooled pixel accuracy {:.3}, \
         pooled window IoU {:.3}, pooled windows found {} / false {} / missed {}.\n",
        s.images,
        s.window_iou,
        s.f1,
        s.pixel_accuracy,
        s.pooled_window_iou,
        s.pooled.true_positives,
        s.pooled.false_positives,
        s.pooled.false_negatives
    );
    let (pc, pm) = (dir.join("facades.csv"), dir.join("facades.md"));
    std::fs::write(&pc, csv).map_err(|e| io(&pc, e))?;
    std::fs::write(&pm, md).map_err(|e| io(&pm, e))?;
    Ok((pc, pm))
}
