//! Script bindings of the learned facade parse: training the pixel classifier into a folder,
//! checking a cached model, and scoring a labelled folder with it.

use std::path::{Path, PathBuf};

use rhai::{Array, Dynamic, Map, INT};

use super::convert::{count, rt_err, RResult};
use super::paths::{read_folder, read_path, write_folder};
use super::{function, modules::ApiBuilder};
use crate::facade::learned::classes::Element;
use crate::facade::learned::evaluate::{evaluate_folder, EvalOptions, Split, DEFAULT_WINDOW_BOOST};
use crate::facade::learned::model::{Model, MODEL_FILE};
use crate::facade::learned::train::{train, FeatureSet, TrainOptions};

/// A count option bounded by `max`.
fn bounded(v: &Dynamic, what: &str, min: usize, max: usize) -> RResult<usize> {
    let n = count(v, what)?;
    if n < min || n > max {
        return Err(rt_err(format!(
            "`{what}` must be in {min}..={max}, got {n}"
        )));
    }
    Ok(n)
}

fn train_options(m: &Map) -> RResult<TrainOptions> {
    let mut o = TrainOptions::default();
    for (k, v) in m {
        match k.as_str() {
            "folders" => {
                let arr = v
                    .read_lock::<Array>()
                    .ok_or_else(|| rt_err("`folders` must be an array of folder paths"))?;
                o.folders = arr
                    .iter()
                    .map(|d| {
                        let s = d
                            .clone()
                            .into_string()
                            .map_err(|_| rt_err("`folders` must hold strings"))?;
                        read_folder(&s)
                    })
                    .collect::<RResult<Vec<PathBuf>>>()?;
            }
            "max_images" => o.max_images = bounded(v, "max_images", 0, 100_000)?,
            "samples" => o.samples_per_image = bounded(v, "samples", 1, 100_000)?,
            "trees" => o.trees = bounded(v, "trees", 1, 512)?,
            "depth" => o.max_depth = bounded(v, "depth", 1, 40)?,
            "min_leaf" => o.min_leaf = bounded(v, "min_leaf", 1, 1_000_000)?,
            "seed" => o.seed = count(v, "seed")? as u64,
            "features" => {
                let s = v.clone().into_string().unwrap_or_default();
                o.features = FeatureSet::from_name(&s)
                    .ok_or_else(|| rt_err("`features` must be \"all\" or \"local\""))?;
            }
            other => {
                return Err(rt_err(format!(
                    "unknown training option `{other}` (known: folders, max_images, samples, \
                     trees, depth, min_leaf, seed, features)"
                )))
            }
        }
    }
    if o.folders.is_empty() {
        let data = crate::geometry::files::data_dir().join("facades");
        o.folders = vec![data.join("cmp_base"), data.join("labelmefacade_train")];
    }
    for f in &o.folders {
        if f.file_name().is_some_and(|n| n == "labelmefacade") {
            return Err(rt_err(format!(
                "{}: the 23 photos of labelmefacade/ are kept for evaluation and never trained on",
                f.display()
            )));
        }
    }
    Ok(o)
}

fn eval_options(m: &Map) -> RResult<EvalOptions> {
    let mut o = EvalOptions {
        split: Split::Holdout,
        structure: true,
        limit: 0,
        window_boost: DEFAULT_WINDOW_BOOST,
    };
    for (k, v) in m {
        match k.as_str() {
            "split" => {
                o.split = match v.clone().into_string().ok().as_deref() {
                    Some("all") => Split::All,
                    Some("holdout") => Split::Holdout,
                    _ => return Err(rt_err("`split` must be \"holdout\" or \"all\"")),
                }
            }
            "structure" => {
                o.structure = v
                    .as_bool()
                    .map_err(|_| rt_err("`structure` must be true or false"))?
            }
            "limit" => o.limit = count(v, "limit")?,
            "window_boost" => {
                let b = super::convert::finite(v, "window_boost")?;
                if !(0.1..=10.0).contains(&b) {
                    return Err(rt_err(format!(
                        "`window_boost` must be in 0.1..=10, got {b}"
                    )));
                }
                o.window_boost = b as f32;
            }
            other => {
                return Err(rt_err(format!(
                    "unknown evaluation option `{other}` (known: split, structure, limit, \
                     window_boost)"
                )))
            }
        }
    }
    Ok(o)
}

fn float(m: &mut Map, k: &str, v: f64) {
    m.insert(k.into(), Dynamic::from_float(v));
}

/// Registers the learned-facade functions.
pub fn register(engine: &mut ApiBuilder) {
    function!(
        engine,
        "facade::train_classifier",
        ["out: String", "options: Map", "Map"],
        "Trains the facade pixel classifier (a random forest on colour, texture, position and
repetition features) and writes it to `OUT/facade_forest.bin` (a versioned file; keep it out
of the repository: it is trained from research-only photos). Options: #{folders: [DIR, …]
(labelled folders of either layout; default the shared `facades/cmp_base`, whose held-out
quarter is skipped, and `facades/labelmefacade_train`; `labelmefacade` itself is refused),
max_images (per folder, 0 all), samples (pixels per image, 1500), trees (32), depth (18),
min_leaf (4), seed, features: \"all\" | \"local\" (colour and texture only)}. Returns #{model,
images, samples, feature_seconds, forest_seconds, nodes}.",
        |out: &str, m: Map| -> RResult<Map> {
            let opts = train_options(&m)?;
            let dir = write_folder(out)?;
            let r = train(&opts).map_err(|e| rt_err(e.to_string()))?;
            let path = dir.join(MODEL_FILE);
            r.model.save(&path).map_err(|e| rt_err(e.to_string()))?;
            let mut res = Map::new();
            res.insert("model".into(), Dynamic::from(path.display().to_string()));
            res.insert("images".into(), Dynamic::from_int(r.images as INT));
            res.insert("samples".into(), Dynamic::from_int(r.samples as INT));
            let nodes: usize = r.model.forest.trees.iter().map(|t| t.nodes.len()).sum();
            res.insert("nodes".into(), Dynamic::from_int(nodes as INT));
            float(&mut res, "feature_seconds", r.feature_seconds);
            float(&mut res, "forest_seconds", r.forest_seconds);
            Ok(res)
        }
    );
    function!(
        engine,
        "facade::model_cache",
        ["String"],
        "The folder where a trained facade model is cached by default: `out/facade_model`
under the working directory (outside the repository's tracked files; a script may write
there).",
        || -> String {
            super::paths::working_dir()
                .join("out")
                .join("facade_model")
                .display()
                .to_string()
        }
    );
    function!(
        engine,
        "facade::model_ready",
        ["path: String", "bool"],
        "Whether a trained facade model can be used from `path` (a `facade_forest.bin` or
the folder holding one): false when there is none; an error naming the file when there is
one of another version or a damaged one (train again).",
        |path: &str| -> RResult<bool> {
            let p = model_path(&read_path(path)?);
            if !p.is_file() {
                return Ok(false);
            }
            Model::load(&p).map_err(|e| rt_err(e.to_string()))?;
            Ok(true)
        }
    );
    function!(
        engine,
        "facade::evaluate_learned",
        [
            "dir: String",
            "out: String",
            "model: String",
            "options: Map",
            "Map"
        ],
        "Parses every labelled photo of `dir` (CMP index labels or LabelMeFacade colour labels,
detected from the folder) with the trained model at `model` (file or folder), writes each
parse as `OUT/pred/STEM.png` in the folder's own label format and the scores as
`OUT/facades_learned.csv` (per image and pooled: window IoU, window F1 at IoU ≥ 0.5, pixel
accuracy, per-class IoU, the all-wall and all-window baselines). Options: #{split:
\"holdout\" (default: a CMP folder's held-out quarter, every 4th photo from the 4th; all of a
LabelMeFacade folder) | \"all\", structure: true (windows as aligned rectangles, doors at
street level) | false (the classifier alone), limit: N, window_boost: factor on the window
probability (default `DEFAULT_WINDOW_BOOST`)}. Returns #{layout, images, window_iou,
f1, pixel_accuracy, all_wall_accuracy, all_window_iou, seconds_per_megapixel, csv,
iou_window, iou_door, …}.",
        |dir: &str, out: &str, model: &str, m: Map| -> RResult<Map> {
            let opts = eval_options(&m)?;
            let dir = read_folder(dir)?;
            let out = write_folder(out)?;
            let model =
                Model::load(&model_path(&read_path(model)?)).map_err(|e| rt_err(e.to_string()))?;
            let s =
                evaluate_folder(&dir, &out, &model, &opts).map_err(|e| rt_err(e.to_string()))?;
            let mut r = Map::new();
            r.insert("layout".into(), Dynamic::from(s.layout.name().to_string()));
            r.insert("images".into(), Dynamic::from_int(s.images as INT));
            r.insert("csv".into(), Dynamic::from(s.csv.display().to_string()));
            for (k, v) in [
                ("window_iou", s.window_iou),
                ("f1", s.f1),
                ("pixel_accuracy", s.pixel_accuracy),
                ("all_wall_accuracy", s.all_wall_accuracy),
                ("all_window_iou", s.all_window_iou),
                ("seconds_per_megapixel", s.seconds_per_megapixel),
            ] {
                float(&mut r, k, v);
            }
            for e in Element::ALL {
                float(&mut r, &format!("iou_{}", e.name()), s.class_iou[e.index()]);
            }
            Ok(r)
        }
    );
}

/// The model file of a path: the path itself, or `MODEL_FILE` inside it when it is a folder.
fn model_path(p: &Path) -> PathBuf {
    if p.is_dir() {
        p.join(MODEL_FILE)
    } else {
        p.to_path_buf()
    }
}
