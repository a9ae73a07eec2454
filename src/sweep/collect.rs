//! The collector: each run's last printed `key=value` line (every word of the line a
//! `key=value` pair) into one table, `results.csv` and `summary.md` in the sweep's folder, in
//! the sweep's order, with missing and failed runs marked; the CSV files a run names in that
//! line (a value ending in `.csv`, relative to its folder) joined into `<key>.csv`; plots of
//! chosen keys against chosen parameters.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use super::error::SweepError;
use super::local::ERROR_TAIL;
use super::run_dir::{tail_lines, RunState, Sweep, STDERR, STDOUT};
use crate::geometry::files::write_atomic;
use crate::render::plot::{write_plot_pair, PlotSpec, Series, SeriesStyle};

/// What `collect` wrote.
#[derive(Debug, Clone, PartialEq)]
pub struct Collected {
    /// The table, one row per run.
    pub csv: PathBuf,
    /// The Markdown summary.
    pub md: PathBuf,
    /// Joined CSV files and plots.
    pub other: Vec<PathBuf>,
    /// Runs complete, failed, missing.
    pub counts: [usize; 3],
}

/// One row of the table.
struct Row {
    status: &'static str,
    values: BTreeMap<String, String>,
}

/// The pairs of a line made only of `key=value` words, else `None`.
pub fn key_values(line: &str) -> Option<Vec<(String, String)>> {
    let mut pairs = Vec::new();
    for word in line.split_whitespace() {
        let (k, v) = word.split_once('=')?;
        let key_ok = !k.is_empty()
            && k.chars()
                .all(|c| c.is_ascii_alphanumeric() || "_.-".contains(c));
        if !key_ok {
            return None;
        }
        pairs.push((k.to_string(), v.to_string()));
    }
    (!pairs.is_empty()).then_some(pairs)
}

/// The last `key=value` line of a run's standard output.
fn last_result(stdout: &Path) -> Option<Vec<(String, String)>> {
    let text = crate::limits::read_to_string(stdout).ok()?;
    text.lines().rev().find_map(key_values)
}

fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

fn md_field(s: &str) -> String {
    s.replace('|', "\\|")
}

fn write_text(path: &Path, text: &str) -> Result<(), SweepError> {
    write_atomic(path, |w| w.write_all(text.as_bytes()))
        .map_err(|e| SweepError::Other(e.to_string()))
}

/// Median of sorted values.
fn median(v: &[f64]) -> f64 {
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

/// Collects a sweep into `results.csv`, `summary.md`, joined CSVs and plots.
pub fn collect(sweep: &Sweep) -> Result<Collected, SweepError> {
    let m = &sweep.manifest;
    let dir = m.sweep_dir();
    let mut param_keys: Vec<String> = Vec::new();
    let mut found_keys: Vec<String> = Vec::new();
    let mut rows = Vec::new();
    let mut failures = Vec::new();
    let mut tables: BTreeMap<String, String> = BTreeMap::new();
    let mut counts = [0; 3];
    for run in &sweep.runs {
        for (k, _) in &run.sets {
            if !param_keys.contains(k) {
                param_keys.push(k.clone());
            }
        }
        let rdir = sweep.run_dir(run);
        let mut values = BTreeMap::new();
        let status = match sweep.state(run) {
            RunState::Done => {
                counts[0] += 1;
                match last_result(&rdir.join(STDOUT)) {
                    Some(pairs) => {
                        for (k, v) in pairs {
                            if !found_keys.contains(&k) {
                                found_keys.push(k.clone());
                            }
                            if v.ends_with(".csv") {
                                join_csv(&mut tables, &k, &run.id, &rdir.join(&v));
                            }
                            values.insert(k, v);
                        }
                        "done"
                    }
                    None => "done, no key=value line",
                }
            }
            RunState::Failed(why) => {
                counts[1] += 1;
                failures.push((run, why, tail_lines(&rdir.join(STDERR), ERROR_TAIL)));
                "FAILED"
            }
            RunState::Missing => {
                counts[2] += 1;
                "MISSING"
            }
        };
        rows.push(Row { status, values });
    }
    // a printed key that is also a parameter (`seed=…`) keeps the parameter's column only
    let keys = if m.collect.keys.is_empty() {
        found_keys.retain(|k| !param_keys.contains(k));
        found_keys
    } else {
        m.collect.keys.clone()
    };
    // the table
    let mut header = vec!["id".to_string(), "status".to_string()];
    header.extend(param_keys.iter().cloned());
    header.extend(keys.iter().cloned());
    let mut csv = header
        .iter()
        .map(|h| csv_field(h))
        .collect::<Vec<_>>()
        .join(",")
        + "\n";
    let mut md_rows = String::new();
    for (run, row) in sweep.runs.iter().zip(&rows) {
        let params: BTreeMap<&str, &str> = run
            .sets
            .iter()
            .map(|(k, v)| (k.as_str(), v.as_str()))
            .collect();
        let mut cells = vec![run.id.clone(), row.status.to_string()];
        cells.extend(
            param_keys
                .iter()
                .map(|k| params.get(k.as_str()).unwrap_or(&"").to_string()),
        );
        cells.extend(
            keys.iter()
                .map(|k| row.values.get(k).cloned().unwrap_or_default()),
        );
        csv += &(cells
            .iter()
            .map(|c| csv_field(c))
            .collect::<Vec<_>>()
            .join(",")
            + "\n");
        md_rows += &format!(
            "| {} |\n",
            cells
                .iter()
                .map(|c| md_field(c))
                .collect::<Vec<_>>()
                .join(" | ")
        );
    }
    let csv_path = dir.join("results.csv");
    write_text(&csv_path, &csv)?;
    // the summary
    let mut md = format!(
        "# Sweep `{}`\n\nManifest `{}`, script `{}`: {} runs, {} complete, {} failed, {} missing.\n\n",
        m.name,
        m.path.display(),
        m.script.display(),
        sweep.runs.len(),
        counts[0],
        counts[1],
        counts[2]
    );
    md += &stats_table(&keys, &rows);
    if !failures.is_empty() {
        md += "## Failed runs\n\n";
        for (run, why, tail) in &failures {
            let sets: Vec<String> = run.sets.iter().map(|(k, v)| format!("{k}={v}")).collect();
            md += &format!("- `{}` ({}): {}\n", run.id, sets.join(" "), md_field(why));
            if !tail.is_empty() {
                md += &format!("\n  ```\n  {}\n  ```\n", tail.join("\n  "));
            }
        }
        md += "\n";
    }
    md += "## Runs\n\n";
    md += &format!(
        "| {} |\n",
        header
            .iter()
            .map(|h| md_field(h))
            .collect::<Vec<_>>()
            .join(" | ")
    );
    md += &format!("|{}\n", "---|".repeat(header.len()));
    md += &md_rows;
    let md_path = dir.join("summary.md");
    write_text(&md_path, &md)?;
    let mut other = Vec::new();
    for (key, text) in &tables {
        let p = dir.join(format!("{key}.csv"));
        write_text(&p, text)?;
        other.push(p);
    }
    other.extend(plots(sweep, &rows, &dir)?);
    Ok(Collected {
        csv: csv_path,
        md: md_path,
        other,
        counts,
    })
}

/// Appends a run's CSV file to the joined table of `key`, with the run's id as first column.
fn join_csv(tables: &mut BTreeMap<String, String>, key: &str, id: &str, path: &Path) {
    let Ok(text) = crate::limits::read_to_string(path) else {
        return;
    };
    let mut lines = text.lines();
    let Some(head) = lines.next() else { return };
    let table = tables
        .entry(key.to_string())
        .or_insert_with(|| format!("run,{head}\n"));
    for l in lines.filter(|l| !l.trim().is_empty()) {
        *table += &format!("{},{l}\n", csv_field(id));
    }
}

/// Count, minimum, median and maximum of each numeric key over the complete runs.
fn stats_table(keys: &[String], rows: &[Row]) -> String {
    let mut s = String::from("| key | runs | min | median | max |\n|---|---|---|---|---|\n");
    let mut any = false;
    for k in keys {
        let mut v: Vec<f64> = rows
            .iter()
            .filter_map(|r| r.values.get(k).and_then(|x| x.parse::<f64>().ok()))
            .filter(|x| x.is_finite())
            .collect();
        if v.is_empty() {
            continue;
        }
        any = true;
        v.sort_by(f64::total_cmp);
        s += &format!(
            "| {k} | {} | {} | {} | {} |\n",
            v.len(),
            v[0],
            median(&v),
            v[v.len() - 1]
        );
    }
    if any {
        s + "\n"
    } else {
        String::new()
    }
}

/// The plots the manifest asks for, under `<sweep>/plots/`.
fn plots(sweep: &Sweep, rows: &[Row], dir: &Path) -> Result<Vec<PathBuf>, SweepError> {
    let mut out = Vec::new();
    for p in &sweep.manifest.collect.plot {
        let mut series: BTreeMap<String, Vec<[f64; 2]>> = BTreeMap::new();
        for (run, row) in sweep.runs.iter().zip(rows) {
            let param = |k: &str| {
                run.sets
                    .iter()
                    .find(|(kk, _)| kk == k)
                    .map(|(_, v)| v.clone())
            };
            let x = param(&p.x).and_then(|v| v.parse::<f64>().ok());
            let y = row.values.get(&p.y).and_then(|v| v.parse::<f64>().ok());
            let (Some(x), Some(y)) = (x, y) else { continue };
            let name = match &p.by {
                Some(b) => format!("{b}={}", param(b).unwrap_or_default()),
                None => p.y.clone(),
            };
            series.entry(name).or_default().push([x, y]);
        }
        if series.is_empty() {
            continue;
        }
        let spec = PlotSpec {
            title: format!("{}: {} against {}", sweep.manifest.name, p.y, p.x),
            x_label: p.x.clone(),
            y_label: p.y.clone(),
            series: series
                .into_iter()
                .map(|(name, mut points)| {
                    points.sort_by(|a, b| a[0].total_cmp(&b[0]));
                    Series {
                        name,
                        points,
                        style: SeriesStyle::Markers,
                    }
                })
                .collect(),
        };
        let stem = dir.join("plots").join(format!("{}_vs_{}", p.y, p.x));
        std::fs::create_dir_all(dir.join("plots")).map_err(SweepError::io(dir.join("plots")))?;
        let (png, svg) =
            write_plot_pair(&stem, &spec).map_err(|e| SweepError::Other(e.to_string()))?;
        out.push(png);
        out.push(svg);
    }
    Ok(out)
}
