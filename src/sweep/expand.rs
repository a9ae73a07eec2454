//! Expansion of a manifest into runs: the cartesian product of its axes in a fixed order
//! (files, params, the zipped lists as one axis, ranges, seeds; the last one varies fastest),
//! each run with a stable id made from its values, so the same manifest gives the same ids in
//! the same order on every machine and every restart.

use super::error::SweepError;
use super::manifest::Manifest;

/// One run of a sweep.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Run {
    /// Position in the expansion (0-based).
    pub index: usize,
    /// Stable id, also the run's folder name: `key-value_key-value…`, with a hash of the values
    /// appended when the name had to be shortened or cleaned.
    pub id: String,
    /// The `--set` values, in axis order.
    pub sets: Vec<(String, String)>,
}

/// One axis: its values, each a list of (key, value) assignments, with a short label for ids.
struct Axis {
    entries: Vec<Vec<(String, String, String)>>,
}

/// FNV-1a, 64 bits: a hash that is the same on every platform and every build.
pub fn fnv1a(text: &str) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in text.bytes() {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x0100_0000_01b3);
    }
    h
}

/// Longest id made of the values themselves; longer ones are cut and hashed.
const MAX_SLUG: usize = 60;

/// The id of a run with these (key, label) pairs and these full values.
fn run_id(labels: &[(String, String)], sets: &[(String, String)]) -> String {
    if labels.is_empty() {
        return "run".into();
    }
    let raw: Vec<String> = labels.iter().map(|(k, v)| format!("{k}-{v}")).collect();
    let raw = raw.join("_");
    let clean: String = raw
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || "-_.+".contains(c) {
                c
            } else {
                '~'
            }
        })
        .collect();
    let exact = clean == raw && !clean.is_empty() && clean.len() <= MAX_SLUG;
    let labels_exact = labels.iter().zip(sets).all(|(l, s)| l.1 == s.1);
    if exact && labels_exact {
        return clean;
    }
    let canonical: Vec<String> = sets.iter().map(|(k, v)| format!("{k}={v}")).collect();
    let hash = fnv1a(&canonical.join("\n"));
    let cut: String = clean.chars().take(MAX_SLUG - 9).collect();
    format!("{cut}-{:08x}", (hash ^ (hash >> 32)) as u32)
}

fn glob_axis(m: &Manifest, key: &str, pattern: &str) -> Result<Axis, SweepError> {
    let err = |message: String| SweepError::Manifest {
        path: m.path.clone(),
        message,
    };
    let full = if std::path::Path::new(pattern).is_absolute() {
        pattern.to_string()
    } else {
        let dir = glob::Pattern::escape(&m.dir().display().to_string());
        format!("{dir}/{pattern}")
    };
    let paths = glob::glob(&full).map_err(|e| err(format!("field `files.{key}`: {e}")))?;
    let mut files = Vec::new();
    for p in paths {
        let p = p.map_err(|e| err(format!("field `files.{key}`: {e}")))?;
        if p.is_file() {
            files.push(p);
        }
    }
    files.sort();
    if files.is_empty() {
        return Err(err(format!(
            "field `files.{key}`: `{pattern}` matches no file (relative to {})",
            m.dir().display()
        )));
    }
    Ok(Axis {
        entries: files
            .into_iter()
            .map(|p| {
                let label = p
                    .file_stem()
                    .map(|s| s.to_string_lossy().into_owned())
                    .unwrap_or_default();
                vec![(key.to_string(), p.display().to_string(), label)]
            })
            .collect(),
    })
}

fn plain(key: &str, values: &[String]) -> Axis {
    Axis {
        entries: values
            .iter()
            .map(|v| vec![(key.to_string(), v.clone(), v.clone())])
            .collect(),
    }
}

/// The axes of a manifest, outermost first.
fn axes(m: &Manifest) -> Result<Vec<Axis>, SweepError> {
    let mut axes = Vec::new();
    for (k, pattern) in &m.files {
        axes.push(glob_axis(m, k, pattern)?);
    }
    for (k, vs) in &m.params {
        axes.push(plain(k, vs));
    }
    if let Some((_, first)) = m.zip.first() {
        axes.push(Axis {
            entries: (0..first.len())
                .map(|i| {
                    m.zip
                        .iter()
                        .map(|(k, vs)| (k.clone(), vs[i].clone(), vs[i].clone()))
                        .collect()
                })
                .collect(),
        });
    }
    let max = crate::limits::get().max_elements;
    for (k, r) in &m.ranges {
        let n = ((r.end - r.start - 1) / r.step + 1) as u64;
        crate::limits::check_count(&format!("ranges.{k}: its values"), n, "max_elements", max)
            .map_err(|e| SweepError::Manifest {
                path: m.path.clone(),
                message: e.to_string(),
            })?;
        let vs: Vec<String> = (0..n as i64)
            .map(|i| (r.start + i * r.step).to_string())
            .collect();
        axes.push(plain(k, &vs));
    }
    if let Some(s) = &m.seeds {
        crate::limits::check_count("seeds.count", s.count, "max_elements", max).map_err(|e| {
            SweepError::Manifest {
                path: m.path.clone(),
                message: e.to_string(),
            }
        })?;
        let vs: Vec<String> = (0..s.count as i64)
            .map(|i| (s.start + i).to_string())
            .collect();
        axes.push(plain(&s.name, &vs));
    }
    Ok(axes)
}

/// Every run of a manifest, in the fixed order. A manifest with no axis is one run. The
/// number of runs is bounded by the `max_elements` limit; two runs with the same values are
/// an error.
pub fn expand(m: &Manifest) -> Result<Vec<Run>, SweepError> {
    let axes = axes(m)?;
    let err = |message: String| SweepError::Manifest {
        path: m.path.clone(),
        message,
    };
    let max = crate::limits::get().max_elements;
    let total = axes
        .iter()
        .try_fold(1u64, |n, a| n.checked_mul(a.entries.len() as u64))
        .unwrap_or(u64::MAX);
    crate::limits::check_count("the sweep's number of runs", total, "max_elements", max)
        .map_err(|e| err(e.to_string()))?;
    let mut runs = Vec::with_capacity(total as usize);
    let mut seen = std::collections::HashMap::new();
    for index in 0..total as usize {
        // mixed-radix digits, last axis fastest
        let mut rest = index;
        let mut picks = vec![0; axes.len()];
        for (a, axis) in axes.iter().enumerate().rev() {
            picks[a] = rest % axis.entries.len();
            rest /= axis.entries.len();
        }
        let mut sets = Vec::new();
        let mut labels = Vec::new();
        for (axis, &p) in axes.iter().zip(&picks) {
            for (k, v, label) in &axis.entries[p] {
                sets.push((k.clone(), v.clone()));
                labels.push((k.clone(), label.clone()));
            }
        }
        let id = run_id(&labels, &sets);
        if let Some(other) = seen.insert(id.clone(), index) {
            return Err(err(format!(
                "runs {other} and {index} have the same id `{id}` (the same values twice?)"
            )));
        }
        runs.push(Run { index, id, sets });
    }
    Ok(runs)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fnv1a_matches_the_published_test_vectors() {
        // from the FNV reference test suite (Fowler, Noll, Vo)
        assert_eq!(fnv1a(""), 0xcbf29ce484222325);
        assert_eq!(fnv1a("a"), 0xaf63dc4c8601ec8c);
        assert_eq!(fnv1a("foobar"), 0x85944171f73967e8);
    }

    #[test]
    fn ids_are_the_values_when_they_are_clean() {
        let l = vec![("size".to_string(), "2".to_string())];
        assert_eq!(run_id(&l, &l), "size-2");
        let l = vec![("name".to_string(), "a/b c".to_string())];
        let id = run_id(&l, &l);
        assert!(id.starts_with("name-a~b~c-"), "{id}");
    }
}
