//! The sweep manifest (TOML, documented in docs/sweeps.md): the script, its `--set` values as
//! axes (cartesian `params`, zipped lists, integer ranges, files matched by a glob, seeds), the
//! output root, the resources of one run and what to collect. Reading checks every field and
//! names the file and the field; unknown fields are errors, so a misspelt one is not ignored.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde::Deserialize;

use super::error::SweepError;

/// An integer axis `start, start + step, …` below `end`.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RangeSpec {
    /// First value.
    pub start: i64,
    /// End (exclusive).
    pub end: i64,
    /// Step (default 1, must be positive).
    #[serde(default = "one")]
    pub step: i64,
}

fn one() -> i64 {
    1
}

/// Seeds: `count` values `start, start + 1, …` of the `--set` key `name`.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SeedSpec {
    /// The `--set` key (default `seed`).
    #[serde(default = "seed_name")]
    pub name: String,
    /// How many seeds.
    pub count: u64,
    /// First seed (default 0).
    #[serde(default)]
    pub start: i64,
}

fn seed_name() -> String {
    "seed".into()
}

/// What one run needs: `#SBATCH` lines for Slurm; `threads` also sets `RAYON_NUM_THREADS` of
/// local runs.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Resources {
    /// CPU threads of one run (`--cpus-per-task`), default 1.
    #[serde(default = "one_u")]
    pub threads: u32,
    /// Memory of one run (`--mem`, Slurm's syntax: `2G`, `500M`), optional.
    pub memory: Option<String>,
    /// Time limit of one run (`--time`, Slurm's syntax: `00:10:00`, `2-00:00:00`), optional.
    pub time: Option<String>,
    /// Most array tasks running at once (`--array=…%T`), optional.
    pub throttle: Option<u32>,
    /// Slurm partition (`--partition`), optional.
    pub partition: Option<String>,
    /// Slurm account (`--account`), optional.
    pub account: Option<String>,
}

fn one_u() -> u32 {
    1
}

impl Default for Resources {
    fn default() -> Self {
        Resources {
            threads: 1,
            memory: None,
            time: None,
            throttle: None,
            partition: None,
            account: None,
        }
    }
}

/// One plot of the collected table: the key `y` against the parameter `x`, one series per value
/// of the parameter `by` (if given).
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlotRequest {
    /// Parameter on the horizontal axis (numeric).
    pub x: String,
    /// Collected key on the vertical axis (numeric).
    pub y: String,
    /// Parameter whose values split the points into series, optional.
    pub by: Option<String>,
}

/// What `collect` gathers.
#[derive(Debug, Clone, Default, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CollectSpec {
    /// Keys of the last `key=value` line to keep, in this order (default: all, in the order
    /// they first appear).
    #[serde(default)]
    pub keys: Vec<String>,
    /// Plots to draw.
    #[serde(default)]
    pub plot: Vec<PlotRequest>,
}

/// The manifest as written in the file.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct ManifestFile {
    name: Option<String>,
    script: String,
    out: Option<String>,
    #[serde(default)]
    args: Vec<String>,
    checkpoint: Option<u64>,
    #[serde(default)]
    params: toml::Table,
    #[serde(default)]
    zip: toml::Table,
    #[serde(default)]
    files: BTreeMap<String, String>,
    #[serde(default)]
    ranges: BTreeMap<String, RangeSpec>,
    seeds: Option<SeedSpec>,
    #[serde(default)]
    resources: Resources,
    #[serde(default)]
    collect: CollectSpec,
}

/// A checked manifest, paths resolved.
#[derive(Debug, Clone, PartialEq)]
pub struct Manifest {
    /// The manifest file, absolute.
    pub path: PathBuf,
    /// The sweep's name (its folder under the output root).
    pub name: String,
    /// The script every run runs, absolute.
    pub script: PathBuf,
    /// The output root (the sweep's runs go to `<out>/<name>/<id>/`), absolute.
    pub out: PathBuf,
    /// Extra flags of `emilion run` (`--limit …`, `--max-seconds …`).
    pub args: Vec<String>,
    /// Checkpoint every this many frames (`--checkpoint`), 0 for none.
    pub checkpoint: u64,
    /// Cartesian axes: key → values (as `--set` text), keys sorted.
    pub params: Vec<(String, Vec<String>)>,
    /// Zipped lists: keys sorted, each with the same number of values.
    pub zip: Vec<(String, Vec<String>)>,
    /// Files matched by a glob (relative to the manifest's folder): key → pattern.
    pub files: Vec<(String, String)>,
    /// Integer ranges.
    pub ranges: Vec<(String, RangeSpec)>,
    /// Seeds, innermost axis.
    pub seeds: Option<SeedSpec>,
    /// Resources of one run.
    pub resources: Resources,
    /// What to collect.
    pub collect: CollectSpec,
}

/// Largest manifest file read, bytes.
const MAX_MANIFEST_BYTES: u64 = 16 << 20;

/// A `--set` value as text: integers and floats as Rhai reads them back (a float always with
/// a point or exponent), strings as they are, booleans as `true`/`false`.
pub fn value_text(v: &toml::Value) -> Result<String, String> {
    match v {
        toml::Value::String(s) => Ok(s.clone()),
        toml::Value::Integer(i) => Ok(i.to_string()),
        toml::Value::Boolean(b) => Ok(b.to_string()),
        toml::Value::Float(f) if f.is_finite() => {
            let t = format!("{f:?}");
            Ok(t)
        }
        toml::Value::Float(f) => Err(format!("{f} is not a finite number")),
        other => Err(format!(
            "a {} cannot be a --set value (use a number, string or bool)",
            other.type_str()
        )),
    }
}

/// A `--set` key must be a Rhai identifier.
fn check_key(key: &str) -> Result<(), String> {
    let mut chars = key.chars();
    let ok = chars
        .next()
        .is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
        && chars.all(|c| c.is_ascii_alphanumeric() || c == '_');
    if ok {
        Ok(())
    } else {
        Err(format!(
            "`{key}` is not a script constant name (letters, digits, _)"
        ))
    }
}

fn values(section: &str, key: &str, v: &toml::Value) -> Result<Vec<String>, String> {
    let list: Vec<&toml::Value> = match v {
        toml::Value::Array(a) => a.iter().collect(),
        scalar => vec![scalar],
    };
    if list.is_empty() {
        return Err(format!(
            "field `{section}.{key}`: an empty list gives no runs"
        ));
    }
    list.into_iter()
        .enumerate()
        .map(|(i, v)| value_text(v).map_err(|e| format!("field `{section}.{key}[{i}]`: {e}")))
        .collect()
}

impl Manifest {
    /// Reads and checks a manifest; relative paths are taken from its folder (the script,
    /// the globs) and from the working directory (`out`).
    pub fn load(path: &Path) -> Result<Manifest, SweepError> {
        let path = std::path::absolute(path).map_err(SweepError::io(path))?;
        let err = |message: String| SweepError::Manifest {
            path: path.clone(),
            message,
        };
        crate::limits::check_count(
            "the manifest's size in bytes",
            std::fs::metadata(&path)
                .map_err(SweepError::io(&path))?
                .len(),
            "max_file_bytes",
            MAX_MANIFEST_BYTES,
        )
        .map_err(|e| err(e.to_string()))?;
        let text = std::fs::read_to_string(&path).map_err(SweepError::io(&path))?;
        Manifest::parse(&path, &text)
    }

    /// Parses a manifest's text; `path` names it in errors and gives the folder relative paths
    /// start from.
    pub fn parse(path: &Path, text: &str) -> Result<Manifest, SweepError> {
        let err = |message: String| SweepError::Manifest {
            path: path.to_path_buf(),
            message,
        };
        let file: ManifestFile = toml::from_str(text).map_err(|e| err(e.to_string()))?;
        let dir = path.parent().unwrap_or(Path::new("."));
        let name = match file.name {
            Some(n) => n,
            None => path
                .file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_default(),
        };
        let name_ok = !name.is_empty()
            && name
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || "_-.".contains(c))
            && !name.starts_with('.');
        if !name_ok {
            return Err(err(format!(
                "field `name`: `{name}` must be letters, digits, `_`, `-`, `.` (it names a folder)"
            )));
        }
        let script = dir.join(&file.script);
        if !script.is_file() {
            return Err(err(format!(
                "field `script`: {} is not a file",
                script.display()
            )));
        }
        let out = std::path::absolute(file.out.as_deref().unwrap_or("out"))
            .map_err(|e| err(format!("field `out`: {e}")))?;
        let mut keys = BTreeMap::new();
        let mut claim = |section: &str, key: &str| -> Result<(), SweepError> {
            check_key(key).map_err(|e| err(format!("field `{section}.{key}`: {e}")))?;
            if let Some(other) = keys.insert(key.to_string(), section.to_string()) {
                return Err(err(format!(
                    "field `{section}.{key}`: `{key}` is already set by `{other}`"
                )));
            }
            Ok(())
        };
        let mut params = Vec::new();
        for (k, v) in &file.params {
            claim("params", k)?;
            params.push((k.clone(), values("params", k, v).map_err(err)?));
        }
        let mut zip = Vec::new();
        for (k, v) in &file.zip {
            claim("zip", k)?;
            let list = values("zip", k, v).map_err(err)?;
            if let Some((first, l)) = zip.first().map(|(f, l): &(String, Vec<String>)| (f, l)) {
                if l.len() != list.len() {
                    return Err(err(format!(
                        "field `zip.{k}`: {} values, but `zip.{first}` has {} (zipped lists \
                         advance together)",
                        list.len(),
                        l.len()
                    )));
                }
            }
            zip.push((k.clone(), list));
        }
        for k in file.files.keys() {
            claim("files", k)?;
        }
        for (k, r) in &file.ranges {
            claim("ranges", k)?;
            if r.step <= 0 || r.end <= r.start {
                return Err(err(format!(
                    "field `ranges.{k}`: needs start < end and step > 0, got start {} end {} \
                     step {}",
                    r.start, r.end, r.step
                )));
            }
        }
        if let Some(s) = &file.seeds {
            claim("seeds", &s.name)?;
            if s.count == 0 {
                return Err(err("field `seeds.count`: 0 seeds give no runs".into()));
            }
        }
        if file.resources.threads == 0 {
            return Err(err("field `resources.threads`: must be at least 1".into()));
        }
        if file.resources.throttle == Some(0) {
            return Err(err("field `resources.throttle`: must be at least 1".into()));
        }
        for (field, v) in [
            ("memory", &file.resources.memory),
            ("time", &file.resources.time),
            ("partition", &file.resources.partition),
            ("account", &file.resources.account),
        ] {
            if let Some(v) = v {
                let ok = !v.is_empty()
                    && v.chars()
                        .all(|c| c.is_ascii_alphanumeric() || ":-_.,".contains(c));
                if !ok {
                    return Err(err(format!(
                        "field `resources.{field}`: `{v}` is not a Slurm value (letters, digits, \
                         `:-_.,`)"
                    )));
                }
            }
        }
        for a in &file.args {
            if ["--set", "--checkpoint", "--checkpoint-file", "--resume"]
                .iter()
                .any(|f| a == f || a.starts_with(&format!("{f}=")))
            {
                return Err(err(format!(
                    "field `args`: `{a}` is set by the sweep itself (use params, checkpoint)"
                )));
            }
        }
        Ok(Manifest {
            path: path.to_path_buf(),
            name,
            script: std::path::absolute(&script).unwrap_or(script),
            out,
            args: file.args,
            checkpoint: file.checkpoint.unwrap_or(0),
            params,
            zip,
            files: file.files.into_iter().collect(),
            ranges: file.ranges.into_iter().collect(),
            seeds: file.seeds,
            resources: file.resources,
            collect: file.collect,
        })
    }

    /// The folder of the manifest (globs are relative to it).
    pub fn dir(&self) -> &Path {
        self.path.parent().unwrap_or(Path::new("."))
    }

    /// The sweep's folder, `<out>/<name>`.
    pub fn sweep_dir(&self) -> PathBuf {
        self.out.join(&self.name)
    }
}
