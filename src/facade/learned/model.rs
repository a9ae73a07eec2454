//! The trained classifier as a file: a versioned binary (magic, format version, the feature
//! set's version, the quantiser's edges, the trees), written at run time into an output or
//! cache folder, never into the repository. A file of another format or feature version is
//! refused with a clear error (train again), as is a truncated or absurd one.

use std::path::Path;

use super::super::error::FacadeError;
use super::classes::N_CLASSES;
use super::features::{PixelFeatures, N_FEATURES, WORK_SIDE};
use super::forest::{Forest, Node, Quantizer, Tree, N_BINS};

/// The file's first bytes.
pub const MAGIC: &[u8; 16] = b"EMILION-FACADE\x00\x01";

/// Version of the file layout; bumped whenever the layout, the features or the classes change.
pub const MODEL_VERSION: u32 = 2;

/// File name of the model inside its folder.
pub const MODEL_FILE: &str = "facade_forest.bin";

/// The trained pixel classifier.
#[derive(Debug, Clone, PartialEq)]
pub struct Model {
    /// How raw features are binned.
    pub quantizer: Quantizer,
    /// The trees.
    pub forest: Forest,
    /// The features the trees split on.
    pub features: Vec<usize>,
    /// What it was trained on (free text: folders, images, samples, parameters).
    pub note: String,
}

impl Model {
    /// Class probabilities of every pixel (`n × N_CLASSES`, row-major).
    pub fn probabilities(&self, feats: &PixelFeatures) -> Vec<f32> {
        use rayon::prelude::*;
        let n = feats.width as usize * feats.height as usize;
        let mut out = vec![0f32; n * N_CLASSES];
        out.par_chunks_mut(N_CLASSES * 1024)
            .enumerate()
            .for_each(|(c, chunk)| {
                let mut bins = [0u8; N_FEATURES];
                let mut p = [0f32; N_CLASSES];
                for (k, o) in chunk.chunks_mut(N_CLASSES).enumerate() {
                    self.quantizer.bins(feats.of(c * 1024 + k), &mut bins);
                    self.forest.predict(&bins, &mut p);
                    o.copy_from_slice(&p);
                }
            });
        out
    }

    /// Writes the model to `path` (atomically: a temporary file renamed).
    pub fn save(&self, path: &Path) -> Result<(), FacadeError> {
        let mut b: Vec<u8> = Vec::new();
        b.extend_from_slice(MAGIC);
        for v in [
            MODEL_VERSION,
            N_FEATURES as u32,
            N_CLASSES as u32,
            N_BINS as u32,
            WORK_SIDE,
        ] {
            b.extend_from_slice(&v.to_le_bytes());
        }
        put_u32(&mut b, self.note.len() as u32);
        b.extend_from_slice(self.note.as_bytes());
        put_u32(&mut b, self.features.len() as u32);
        for f in &self.features {
            put_u32(&mut b, *f as u32);
        }
        for e in &self.quantizer.edges {
            for v in e {
                b.extend_from_slice(&v.to_le_bytes());
            }
        }
        put_u32(&mut b, self.forest.trees.len() as u32);
        for t in &self.forest.trees {
            put_u32(&mut b, t.nodes.len() as u32);
            put_u32(&mut b, (t.dist.len() / N_CLASSES) as u32);
            for n in &t.nodes {
                b.extend_from_slice(&n.feature.to_le_bytes());
                b.push(n.threshold);
                put_u32(&mut b, n.left);
                put_u32(&mut b, n.right);
            }
            for v in &t.dist {
                b.extend_from_slice(&v.to_le_bytes());
            }
        }
        let err = |e: std::io::Error| FacadeError::File {
            path: path.to_path_buf(),
            message: e.to_string(),
        };
        if let Some(parent) = path.parent() {
            std::fs::create_dir_all(parent).map_err(err)?;
        }
        let tmp = path.with_extension("bin.tmp");
        std::fs::write(&tmp, &b).map_err(err)?;
        std::fs::rename(&tmp, path).map_err(err)
    }

    /// Reads a model written by [`Model::save`] of this version; anything else is an error
    /// naming the file and what is wrong.
    pub fn load(path: &Path) -> Result<Model, FacadeError> {
        let bytes = crate::limits::read(path).map_err(|e| FacadeError::File {
            path: path.to_path_buf(),
            message: format!("cannot read the facade model: {e}"),
        })?;
        parse(&bytes).map_err(|message| FacadeError::File {
            path: path.to_path_buf(),
            message,
        })
    }
}

fn put_u32(b: &mut Vec<u8>, v: u32) {
    b.extend_from_slice(&v.to_le_bytes());
}

/// A cursor over the file's bytes; every read checks the length left.
struct Reader<'a> {
    b: &'a [u8],
    at: usize,
}

impl Reader<'_> {
    fn take(&mut self, n: usize) -> Result<&[u8], String> {
        if self.b.len() - self.at < n {
            return Err(format!(
                "facade model truncated at byte {} (wanted {n} more of {})",
                self.at,
                self.b.len()
            ));
        }
        self.at += n;
        Ok(&self.b[self.at - n..self.at])
    }
    fn u32(&mut self) -> Result<u32, String> {
        Ok(u32::from_le_bytes(self.take(4)?.try_into().unwrap()))
    }
    fn f32(&mut self) -> Result<f32, String> {
        Ok(f32::from_le_bytes(self.take(4)?.try_into().unwrap()))
    }
    /// A count that must fit in what is left of the file at `unit` bytes each.
    fn count(&mut self, what: &str, unit: usize) -> Result<usize, String> {
        let n = self.u32()? as usize;
        if n.saturating_mul(unit) > self.b.len() - self.at {
            return Err(format!("facade model: {what} count {n} exceeds the file"));
        }
        Ok(n)
    }
}

fn parse(b: &[u8]) -> Result<Model, String> {
    let mut r = Reader { b, at: 0 };
    if r.take(MAGIC.len()).ok() != Some(&MAGIC[..]) {
        return Err("not an emilion facade model (wrong magic bytes)".into());
    }
    let version = r.u32()?;
    if version != MODEL_VERSION {
        return Err(format!(
            "facade model of format version {version}; this emilion reads version \
             {MODEL_VERSION}: train it again (scripts/facade_train.rhai)"
        ));
    }
    let dims = [r.u32()?, r.u32()?, r.u32()?, r.u32()?];
    let want = [
        N_FEATURES as u32,
        N_CLASSES as u32,
        N_BINS as u32,
        WORK_SIDE,
    ];
    if dims != want {
        return Err(format!(
            "facade model for (features, classes, bins, working side) {dims:?}, this emilion \
             uses {want:?}: train it again (scripts/facade_train.rhai)"
        ));
    }
    let n = r.count("note", 1)?;
    let note = String::from_utf8_lossy(r.take(n)?).into_owned();
    let nf = r.count("feature", 4)?;
    let mut features = Vec::with_capacity(nf);
    for _ in 0..nf {
        let f = r.u32()? as usize;
        if f >= N_FEATURES {
            return Err(format!("facade model: feature index {f} ≥ {N_FEATURES}"));
        }
        features.push(f);
    }
    let mut edges = Vec::with_capacity(N_FEATURES);
    for _ in 0..N_FEATURES {
        edges.push(
            (0..N_BINS - 1)
                .map(|_| r.f32())
                .collect::<Result<Vec<_>, _>>()?,
        );
    }
    let nt = r.count("tree", 8)?;
    let mut trees = Vec::with_capacity(nt);
    for t in 0..nt {
        let nn = r.count("node", 11)?;
        let nl = r.count("leaf", 4 * N_CLASSES)?;
        if nn == 0 || nl == 0 {
            return Err(format!("facade model: tree {t} is empty"));
        }
        let mut nodes = Vec::with_capacity(nn);
        for _ in 0..nn {
            let feature = u16::from_le_bytes(r.take(2)?.try_into().unwrap());
            let threshold = r.take(1)?[0];
            let (left, right) = (r.u32()?, r.u32()?);
            let ok = if feature == super::forest::LEAF {
                (left as usize) < nl
            } else {
                (feature as usize) < N_FEATURES
                    && (left as usize) < nn
                    && (right as usize) < nn
                    && left as usize > nodes.len()
                    && right as usize > nodes.len()
            };
            if !ok {
                return Err(format!("facade model: tree {t} has a broken node"));
            }
            nodes.push(Node {
                feature,
                threshold,
                left,
                right,
            });
        }
        let dist = (0..nl * N_CLASSES)
            .map(|_| r.f32())
            .collect::<Result<Vec<_>, _>>()?;
        trees.push(Tree { nodes, dist });
    }
    Ok(Model {
        quantizer: Quantizer { edges },
        forest: Forest { trees },
        features,
        note,
    })
}
