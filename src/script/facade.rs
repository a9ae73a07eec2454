//! Script bindings of the facade evaluation: labelled photos of a folder, label maps, parses,
//! their scores and the summary files.

use rhai::{Array, Dynamic, Map, INT};

use super::convert::{rt_err, RResult};
use super::paths::{read_path, write_folder};
use super::{function, modules::ApiBuilder, register};
use crate::facade::instances::window_instances;
use crate::facade::report::{labelled_images, labelled_photo, summarize, write_summary};
use crate::facade::{Class, FacadeParse, FacadeScore, ImageReport, LabelMap};

/// A facade's label map as a script handle.
#[derive(Debug, Clone)]
pub struct Labels(pub LabelMap);

/// A rectangle as a script map #{x0, y0, x1, y1}.
fn rect_map(r: &crate::facade::Rect) -> Map {
    let mut m = Map::new();
    for (k, v) in [("x0", r.x0), ("y0", r.y0), ("x1", r.x1), ("y1", r.y1)] {
        m.insert(k.into(), Dynamic::from_int(v as INT));
    }
    m
}

/// Registers the facade functions.
pub fn register(engine: &mut ApiBuilder) {
    engine.register_type_with_name::<Labels>("FacadeLabels");
    engine.register_type_with_name::<FacadeParse>("FacadeParse");
    engine.register_type_with_name::<ImageReport>("FacadeReport");
    function!(
        engine,
        "facade::photo",
        ["dir: String", "name: String", "String"],
        "The path of the photo `dir/images/NAME.EXT` of a labelled facade (a name from
`facade::labelled`), whatever its format: `.jpg`, `.png`, `.ppm`, `.tif`, `.bmp`, `.webp`, …
(`geometry::image::PHOTO_EXTENSIONS`); an error naming it when there is none.",
        |dir: &str, name: &str| -> RResult<String> {
            labelled_photo(&read_path(dir)?, name)
                .map(|p| p.display().to_string())
                .map_err(|e| rt_err(e.to_string()))
        }
    );
    function!(
        engine,
        "facade::labelled",
        alias = "labelled_facades",
        ["dir: String", "Array"],
        "Names (file stems, sorted) of the photos in `dir/images` that have a label map
`dir/labels/NAME.png` (the LabelMeFacade layout).",
        |dir: &str| -> RResult<Array> {
            let names = labelled_images(&read_path(dir)?).map_err(|e| rt_err(e.to_string()))?;
            Ok(names.into_iter().map(Dynamic::from).collect())
        }
    );
    function!(
        engine,
        "facade::labels",
        alias = "facade_labels",
        ["path: String", "FacadeLabels"],
        "Reads a LabelMeFacade label map (PNG) into the canonical classes: window, wall
(building), door, background (sky) and ignore (various, car, vegetation, pavement, road).
A colour outside the dataset's colour map is an error naming the file and the pixel.",
        |path: &str| -> RResult<Labels> {
            LabelMap::read_labelmefacade(&read_path(path)?)
                .map(Labels)
                .map_err(|e| rt_err(e.to_string()))
        }
    );
    register!(
        engine,
        "windows",
        ["labels: FacadeLabels", "Array"],
        "The window instances of a label map, as the evaluation defines them (components of
the window mask after a 3×3 opening, specks under 0.05 % of the image dropped):
[#{x0, y0, x1, y1, dont_care}], half-open pixel rectangles; `dont_care` when half the
rectangle or more is hidden by ignored pixels.",
        |l: &mut Labels| -> Array {
            window_instances(&l.0)
                .iter()
                .map(|w| {
                    let mut m = rect_map(&w.rect);
                    m.insert("dont_care".into(), Dynamic::from_bool(w.dont_care));
                    Dynamic::from_map(m)
                })
                .collect()
        }
    );
    function!(
        engine,
        "facade::all_wall_parse",
        alias = "all_wall_parse",
        ["labels: FacadeLabels", "FacadeParse"],
        "The all-wall baseline parse for an image the size of `labels`: every pixel wall, no
window (about 0.8 pixel accuracy on street photos, window IoU 0).",
        |l: &mut Labels| -> FacadeParse { FacadeParse::all_wall(l.0.width, l.0.height) }
    );
    function!(
        engine,
        "facade::score",
        alias = "score_facade",
        [
            "name: String",
            "parse: FacadeParse",
            "truth: FacadeLabels",
            "FacadeReport"
        ],
        "Scores a parse against a label map: pixel accuracy and window IoU over the scored
classes (ignored pixels left out), and window detection (one-to-one Hungarian matching on
IoU, a hit at IoU ≥ 0.5). Sizes must match.",
        |name: &str, p: FacadeParse, t: Labels| -> RResult<ImageReport> {
            let score = FacadeScore::of(&p.labels, &p.windows, &t.0)
                .map_err(|e| rt_err(format!("{name}: {e}")))?;
            Ok(ImageReport {
                name: name.into(),
                score,
            })
        }
    );
    register!(
        engine,
        "to_map",
        ["report: FacadeReport", "Map"],
        "An image's scores: #{name, window_iou, pixel_accuracy, door_iou, found, false_windows,
missed, precision, recall, f1}.",
        |r: &mut ImageReport| -> Map {
            let (p, w) = (&r.score.pixels, &r.score.windows);
            let mut m = Map::new();
            m.insert("name".into(), Dynamic::from(r.name.clone()));
            for (k, v) in [
                ("window_iou", p.iou(Class::Window)),
                ("pixel_accuracy", p.accuracy()),
                ("door_iou", p.iou(Class::Door)),
                ("precision", w.precision()),
                ("recall", w.recall()),
                ("f1", w.f1()),
            ] {
                m.insert(k.into(), Dynamic::from_float(v));
            }
            for (k, v) in [
                ("found", w.true_positives),
                ("false_windows", w.false_positives),
                ("missed", w.false_negatives),
            ] {
                m.insert(k.into(), Dynamic::from_int(v as INT));
            }
            m
        }
    );
    function!(
        engine,
        "facade::summary",
        alias = "facade_summary",
        ["reports: Array", "method: String", "out: String", "Map"],
        "Writes `out/facades.csv` and `out/facades.md` (a row per image and the summary) and
returns #{images, window_iou, f1 (per-image means), pixel_accuracy, pooled_window_iou
(pooled over all pixels), csv, md}.",
        |reports: Array, method: &str, out: &str| -> RResult<Map> {
            let reports = reports
                .into_iter()
                .enumerate()
                .map(|(k, r)| {
                    r.try_cast::<ImageReport>()
                        .ok_or_else(|| rt_err(format!("reports[{k}] is not a facade report")))
                })
                .collect::<RResult<Vec<_>>>()?;
            let (csv, md) = write_summary(&reports, method, &write_folder(out)?)
                .map_err(|e| rt_err(e.to_string()))?;
            let s = summarize(&reports);
            let mut m = Map::new();
            m.insert("images".into(), Dynamic::from_int(s.images as INT));
            for (k, v) in [
                ("window_iou", s.window_iou),
                ("f1", s.f1),
                ("pixel_accuracy", s.pixel_accuracy),
                ("pooled_window_iou", s.pooled_window_iou),
            ] {
                m.insert(k.into(), Dynamic::from_float(v));
            }
            m.insert("csv".into(), Dynamic::from(csv.display().to_string()));
            m.insert("md".into(), Dynamic::from(md.display().to_string()));
            Ok(m)
        }
    );
}
