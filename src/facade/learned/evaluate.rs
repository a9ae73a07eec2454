//! The learned parse scored over a labelled folder of either layout: each prediction written
//! as `OUT/pred/STEM.png` in the folder's own label format, scored as written (so classes
//! the dataset lacks count as what it would call them) with the evaluation protocol of
//! [`super::super::score`] (window IoU, window-level F1 at IoU ≥ 0.5, pixel accuracy over the
//! canonical classes), per-class IoU over the element classes, the all-wall and all-window
//! baselines beside them, in `OUT/facades_learned.csv`.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use super::super::error::FacadeError;
use super::super::labels::{Class, LabelMap};
use super::super::report::labelled_photo;
use super::super::score::{FacadeScore, PixelScore};
use super::classes::{Element, N_CLASSES};
use super::dataset::{
    is_cmp_holdout, label_path, labelled_folder, read_elements, write_elements, ElementMap, Layout,
};
use super::model::Model;
use super::photo_parse::parse_photo;

/// The default factor on the window probability (chosen among 1, 1.6, 2.2 and 3 on the 23
/// LabelMeFacade photos, the tuning set; docs/facades.md).
pub const DEFAULT_WINDOW_BOOST: f32 = 2.2;

/// Which images of the folder are scored.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Split {
    /// Every image.
    All,
    /// A CMP folder's held-out quarter ([`is_cmp_holdout`]); every image of a LabelMeFacade
    /// folder.
    Holdout,
}

/// How to evaluate.
#[derive(Debug, Clone)]
pub struct EvalOptions {
    /// Which images.
    pub split: Split,
    /// Apply the structure's corrections.
    pub structure: bool,
    /// At most this many images (0: all).
    pub limit: usize,
    /// Factor on the window probability ([`parse_photo`]).
    pub window_boost: f32,
}

/// Figures over the folder.
#[derive(Debug, Clone)]
pub struct EvalSummary {
    /// The folder's layout.
    pub layout: Layout,
    /// Images scored.
    pub images: usize,
    /// Mean over images of the window IoU.
    pub window_iou: f64,
    /// Mean over images of the window-level F1 (IoU ≥ 0.5).
    pub f1: f64,
    /// Pooled pixel accuracy over the canonical classes (ignored pixels left out).
    pub pixel_accuracy: f64,
    /// The same of the all-wall baseline.
    pub all_wall_accuracy: f64,
    /// Mean window IoU of the all-window baseline.
    pub all_window_iou: f64,
    /// Pooled IoU of each element class ([`Element::ALL`] order).
    pub class_iou: [f64; N_CLASSES],
    /// Seconds of analysis per megapixel of photo (all images pooled).
    pub seconds_per_megapixel: f64,
    /// The CSV written.
    pub csv: PathBuf,
}

/// The canonical label map of an element map (`truth`: other is ignored).
pub fn canonical(map: &ElementMap, truth: bool) -> LabelMap {
    LabelMap {
        width: map.width,
        height: map.height,
        classes: map
            .classes
            .iter()
            .map(|e| {
                if truth {
                    e.canonical_truth()
                } else {
                    e.canonical_pred()
                }
            })
            .collect(),
    }
}

/// An element class as the layout can write it (LabelMeFacade has no balcony, shop or
/// ledge: they are building, i.e. wall).
pub fn as_written(e: Element, layout: Layout) -> Element {
    match layout {
        Layout::Cmp => Element::from_cmp(e.to_cmp()).unwrap_or(Element::Other),
        Layout::LabelMe => Element::from_labelmefacade(e.to_labelmefacade()).unwrap_or(e),
    }
}

fn iou(conf: &[[u64; N_CLASSES]; N_CLASSES], k: usize) -> f64 {
    let tp = conf[k][k];
    let t: u64 = conf[k].iter().sum();
    let p: u64 = (0..N_CLASSES).map(|i| conf[i][k]).sum();
    if t + p == tp {
        0.0
    } else {
        tp as f64 / (t + p - tp) as f64
    }
}

/// Parses and scores the folder's images with `model`, writing predictions and the CSV
/// under `out`.
pub fn evaluate_folder(
    dir: &Path,
    out: &Path,
    model: &Model,
    opts: &EvalOptions,
) -> Result<EvalSummary, FacadeError> {
    let (stems, layout) = labelled_folder(dir)?;
    let io = |p: &Path, e: std::io::Error| FacadeError::File {
        path: p.to_path_buf(),
        message: e.to_string(),
    };
    std::fs::create_dir_all(out.join("pred")).map_err(|e| io(out, e))?;
    let mut csv = String::from("image,window_iou,f1,precision,recall,pixel_accuracy");
    for e in Element::ALL {
        write!(csv, ",iou_{}", e.name()).unwrap();
    }
    csv.push_str(",all_wall_accuracy,all_window_iou,megapixels,seconds\n");
    let mut conf_all = [[0u64; N_CLASSES]; N_CLASSES];
    let (mut pix, mut wall_pix) = (PixelScore::default(), PixelScore::default());
    let (mut sum_iou, mut sum_f1, mut sum_allwin, mut mp, mut secs) = (0.0, 0.0, 0.0, 0.0, 0.0);
    let mut n = 0usize;
    for (k, stem) in stems.iter().enumerate() {
        if opts.split == Split::Holdout && layout == Layout::Cmp && !is_cmp_holdout(k) {
            continue;
        }
        if opts.limit > 0 && n >= opts.limit {
            break;
        }
        crate::limits::check_cancelled().map_err(|m| FacadeError::File {
            path: dir.to_path_buf(),
            message: m,
        })?;
        let photo = labelled_photo(dir, stem)?;
        let rgb = crate::geometry::image::read_rgb(&photo)?;
        let truth = read_elements(&label_path(dir, stem), layout)?;
        if (truth.width, truth.height) != rgb.dimensions() {
            return Err(FacadeError::Size {
                what: format!("{} and its label map differ in size", photo.display()),
            });
        }
        let mut parse = parse_photo(model, &rgb, opts.structure, opts.window_boost);
        for c in parse.elements.classes.iter_mut() {
            *c = as_written(*c, layout);
        }
        write_elements(
            &parse.elements,
            layout,
            &out.join("pred").join(format!("{stem}.png")),
        )?;
        let t = canonical(&truth, true);
        let score = FacadeScore::of(&canonical(&parse.elements, false), &parse.windows, &t)?;
        let wall = FacadeScore::of(&LabelMap::filled(t.width, t.height, Class::Wall), &[], &t)?;
        let win = PixelScore::of(&LabelMap::filled(t.width, t.height, Class::Window), &t)?;
        let mut conf = [[0u64; N_CLASSES]; N_CLASSES];
        for (p, q) in parse.elements.classes.iter().zip(&truth.classes) {
            conf[q.index()][p.index()] += 1;
        }
        let (wi, f1) = (score.pixels.iou(Class::Window), score.windows.f1());
        write!(
            csv,
            "{stem},{wi:.4},{f1:.4},{:.4},{:.4},{:.4}",
            score.windows.precision(),
            score.windows.recall(),
            score.pixels.accuracy()
        )
        .unwrap();
        for c in 0..N_CLASSES {
            write!(csv, ",{:.4}", iou(&conf, c)).unwrap();
        }
        let m = (rgb.width() as f64 * rgb.height() as f64) / 1e6;
        writeln!(
            csv,
            ",{:.4},{:.4},{m:.3},{:.3}",
            wall.pixels.accuracy(),
            win.iou(Class::Window),
            parse.seconds
        )
        .unwrap();
        for i in 0..N_CLASSES {
            for j in 0..N_CLASSES {
                conf_all[i][j] += conf[i][j];
            }
        }
        pix.add(&score.pixels);
        wall_pix.add(&wall.pixels);
        sum_iou += wi;
        sum_f1 += f1;
        sum_allwin += win.iou(Class::Window);
        mp += m;
        secs += parse.seconds;
        n += 1;
    }
    let k = n.max(1) as f64;
    let class_iou: [f64; N_CLASSES] = std::array::from_fn(|c| iou(&conf_all, c));
    let s = EvalSummary {
        layout,
        images: n,
        window_iou: sum_iou / k,
        f1: sum_f1 / k,
        pixel_accuracy: pix.accuracy(),
        all_wall_accuracy: wall_pix.accuracy(),
        all_window_iou: sum_allwin / k,
        class_iou,
        seconds_per_megapixel: if mp > 0.0 { secs / mp } else { 0.0 },
        csv: out.join("facades_learned.csv"),
    };
    write!(
        csv,
        "mean,{:.4},{:.4},,,{:.4}",
        s.window_iou, s.f1, s.pixel_accuracy
    )
    .unwrap();
    for v in class_iou {
        write!(csv, ",{v:.4}").unwrap();
    }
    writeln!(
        csv,
        ",{:.4},{:.4},{mp:.3},{secs:.3}",
        s.all_wall_accuracy, s.all_window_iou
    )
    .unwrap();
    writeln!(
        csv,
        "baseline_all_wall,0,0,,,{:.4}{},,,,",
        s.all_wall_accuracy,
        ",".repeat(N_CLASSES)
    )
    .unwrap();
    std::fs::write(&s.csv, csv).map_err(|e| io(&s.csv, e))?;
    Ok(s)
}
