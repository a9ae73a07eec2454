//! Training the pixel classifier: pixels sampled from the labelled facades of the training
//! folders (CMP Facade without its held-out quarter, LabelMeFacade's training pool; never the
//! 23 photos of `labelmefacade/`), their features binned, a forest grown, the model written
//! to the output folder.

use std::path::{Path, PathBuf};
use std::time::Instant;

use rayon::prelude::*;

use super::super::error::FacadeError;
use super::super::report::labelled_photo;
use super::classes::Element;
use super::dataset::{is_cmp_holdout, label_path, labelled_folder, read_elements, Layout};
use super::features::{pixel_features, working_image, LOCAL_FEATURES, N_FEATURES};
use super::forest::{Forest, ForestParams, Quantizer};
use super::model::Model;
use crate::geometry::SplitMix64;

/// Which features the forest may use.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FeatureSet {
    /// All of them.
    All,
    /// Colour and texture only ([`LOCAL_FEATURES`]).
    Local,
}

impl FeatureSet {
    /// The set of a name: "all" or "local".
    pub fn from_name(s: &str) -> Option<FeatureSet> {
        match s {
            "all" => Some(FeatureSet::All),
            "local" => Some(FeatureSet::Local),
            _ => None,
        }
    }

    /// Feature indices.
    pub fn indices(self) -> Vec<usize> {
        match self {
            FeatureSet::All => (0..N_FEATURES).collect(),
            FeatureSet::Local => LOCAL_FEATURES.collect(),
        }
    }
}

/// What to train on and how.
#[derive(Debug, Clone)]
pub struct TrainOptions {
    /// Labelled folders (either layout). A CMP folder's held-out quarter is skipped.
    pub folders: Vec<PathBuf>,
    /// At most this many images per folder, evenly spread over it (0: all).
    pub max_images: usize,
    /// Pixels sampled per image.
    pub samples_per_image: usize,
    /// Features used.
    pub features: FeatureSet,
    /// Trees.
    pub trees: usize,
    /// Deepest level.
    pub max_depth: usize,
    /// Fewest samples per leaf.
    pub min_leaf: usize,
    /// Seed of every random draw.
    pub seed: u64,
}

impl Default for TrainOptions {
    fn default() -> Self {
        TrainOptions {
            folders: Vec::new(),
            max_images: 0,
            samples_per_image: 1500,
            features: FeatureSet::All,
            trees: 32,
            max_depth: 18,
            min_leaf: 4,
            seed: 2026,
        }
    }
}

/// What training did.
#[derive(Debug, Clone)]
pub struct TrainReport {
    /// The model.
    pub model: Model,
    /// Images sampled.
    pub images: usize,
    /// Pixels sampled.
    pub samples: usize,
    /// Seconds reading photos and computing features.
    pub feature_seconds: f64,
    /// Seconds growing the forest.
    pub forest_seconds: f64,
}

/// The (photo, label map, layout) of every training image of `folders`: all labelled
/// photos, less CMP's held-out quarter, at most `max_images` per folder spread evenly.
pub fn training_images(
    folders: &[PathBuf],
    max_images: usize,
) -> Result<Vec<(PathBuf, PathBuf, Layout)>, FacadeError> {
    let mut out = Vec::new();
    for dir in folders {
        let (stems, layout) = labelled_folder(dir)?;
        let kept: Vec<&String> = stems
            .iter()
            .enumerate()
            .filter(|(k, _)| layout != Layout::Cmp || !is_cmp_holdout(*k))
            .map(|(_, s)| s)
            .collect();
        let n = kept.len();
        let take = if max_images == 0 {
            n
        } else {
            max_images.min(n)
        };
        for j in 0..take {
            let s = kept[j * n / take.max(1)];
            out.push((labelled_photo(dir, s)?, label_path(dir, s), layout));
        }
    }
    Ok(out)
}

/// `n` pixels of one labelled photo drawn at random (seeded): their features (`n ×
/// N_FEATURES`) and classes, the label taken at each working pixel's centre.
pub fn sample_image(
    photo: &Path,
    labels: &Path,
    layout: Layout,
    n: usize,
    seed: u64,
) -> Result<(Vec<f32>, Vec<u8>), FacadeError> {
    let rgb = crate::geometry::image::read_rgb(photo)?;
    let truth = read_elements(labels, layout)?;
    if truth.width != rgb.width() || truth.height != rgb.height() {
        return Err(FacadeError::Size {
            what: format!(
                "{} is {}×{}, its label map {} is {}×{}",
                photo.display(),
                rgb.width(),
                rgb.height(),
                labels.display(),
                truth.width,
                truth.height
            ),
        });
    }
    let work = working_image(&rgb);
    let feats = pixel_features(&work);
    let (w, h) = (feats.width as usize, feats.height as usize);
    let mut rng = SplitMix64::new(seed);
    let mut rows = Vec::with_capacity(n * N_FEATURES);
    let mut classes = Vec::with_capacity(n);
    for _ in 0..n {
        let (x, y) = (rng.below(w), rng.below(h));
        let tx = ((x as f64 + 0.5) * truth.width as f64 / w as f64) as usize;
        let ty = ((y as f64 + 0.5) * truth.height as f64 / h as f64) as usize;
        let c: Element = truth.classes[ty.min(truth.height as usize - 1) * truth.width as usize
            + tx.min(truth.width as usize - 1)];
        rows.extend_from_slice(feats.of(y * w + x));
        classes.push(c.index() as u8);
    }
    Ok((rows, classes))
}

/// Samples the training images, bins the features and grows the forest.
pub fn train(opts: &TrainOptions) -> Result<TrainReport, FacadeError> {
    let images = training_images(&opts.folders, opts.max_images)?;
    if images.is_empty() {
        return Err(FacadeError::File {
            path: opts.folders.first().cloned().unwrap_or_default(),
            message: "no training image".into(),
        });
    }
    crate::limits::check_alloc(
        "facade training samples",
        (images.len() * opts.samples_per_image * N_FEATURES) as u64,
        4,
    )
    .map_err(|e| FacadeError::File {
        path: PathBuf::new(),
        message: e.to_string(),
    })?;
    let t0 = Instant::now();
    let sampled: Vec<_> = images
        .par_iter()
        .enumerate()
        .map(|(k, (p, l, layout))| {
            crate::limits::check_cancelled().map_err(|m| FacadeError::File {
                path: p.clone(),
                message: m,
            })?;
            sample_image(p, l, *layout, opts.samples_per_image, opts.seed ^ k as u64)
        })
        .collect::<Result<_, _>>()?;
    let mut rows = Vec::new();
    let mut labels = Vec::new();
    for (r, l) in sampled {
        rows.extend(r);
        labels.extend(l);
    }
    let feature_seconds = t0.elapsed().as_secs_f64();
    let t1 = Instant::now();
    let quantizer = Quantizer::fit(&rows, N_FEATURES);
    let mut bins = vec![0u8; rows.len()];
    for (r, b) in rows
        .chunks_exact(N_FEATURES)
        .zip(bins.chunks_exact_mut(N_FEATURES))
    {
        quantizer.bins(r, b);
    }
    drop(rows);
    let features = opts.features.indices();
    let params = ForestParams {
        trees: opts.trees,
        max_depth: opts.max_depth,
        min_leaf: opts.min_leaf,
        mtry: ((features.len() as f64).sqrt().round() as usize).max(1),
        subsample: 0.7,
        features: features.clone(),
        seed: opts.seed,
    };
    let forest = Forest::grow(&bins, N_FEATURES, &labels, &params);
    let note = format!(
        "folders {:?}; {} images, {} pixels each; features {:?}; {} trees, depth {}, min leaf {}",
        opts.folders,
        images.len(),
        opts.samples_per_image,
        opts.features,
        opts.trees,
        opts.max_depth,
        opts.min_leaf
    );
    Ok(TrainReport {
        model: Model {
            quantizer,
            forest,
            features,
            note,
        },
        images: images.len(),
        samples: labels.len(),
        feature_seconds,
        forest_seconds: t1.elapsed().as_secs_f64(),
    })
}
