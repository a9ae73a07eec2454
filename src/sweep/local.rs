//! The local executor: the runs of a sweep on this machine, `jobs` child processes at a time,
//! with a progress bar. Complete runs are skipped; failed ones too unless `retry_failed`; runs
//! that were never started or stopped midway (a killed sweep) run. A failing run is listed
//! with its id, parameters and the last lines of its error output, and the others go on.

use std::path::PathBuf;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;

use indicatif::{ProgressBar, ProgressStyle};

use super::error::SweepError;
use super::expand::Run;
use super::run_dir::{tail_lines, RunState, Sweep, STDERR};

/// How to run a sweep locally.
#[derive(Debug, Clone)]
pub struct LocalOptions {
    /// Child processes at a time (at least 1).
    pub jobs: usize,
    /// Run failed runs again.
    pub retry_failed: bool,
    /// The `emilion` binary each run starts.
    pub exe: PathBuf,
    /// Draw a progress bar on standard error (when it is a terminal).
    pub progress: bool,
}

/// A failed run: which, with what, and why.
#[derive(Debug, Clone, PartialEq)]
pub struct FailedRun {
    /// The run.
    pub run: Run,
    /// Its exit status (or the error that kept it from starting).
    pub status: String,
    /// The last lines of its standard error.
    pub error_tail: Vec<String>,
}

/// What a local sweep did.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct LocalSummary {
    /// Runs started now.
    pub ran: usize,
    /// Runs skipped because they were complete.
    pub skipped_done: usize,
    /// Failed runs left alone (no `retry_failed`).
    pub skipped_failed: usize,
    /// Runs complete now (skipped or run).
    pub done: usize,
    /// Runs failed now (run now, or left alone), in the sweep's order.
    pub failed: Vec<FailedRun>,
}

/// Lines of a failed run's standard error kept in reports.
pub const ERROR_TAIL: usize = 5;

/// Runs the missing runs of a sweep (and the failed ones with `retry_failed`).
pub fn run_local(sweep: &Sweep, opts: &LocalOptions) -> Result<LocalSummary, SweepError> {
    let mut summary = LocalSummary::default();
    let mut todo = Vec::new();
    let mut left_failed = Vec::new();
    for run in &sweep.runs {
        match sweep.state(run) {
            RunState::Done => summary.skipped_done += 1,
            RunState::Failed(s) if !opts.retry_failed => left_failed.push((run, s)),
            _ => todo.push(run),
        }
    }
    summary.skipped_failed = left_failed.len();
    let bar = if opts.progress {
        ProgressBar::new(todo.len() as u64)
    } else {
        ProgressBar::hidden()
    };
    bar.set_style(
        ProgressStyle::with_template(
            "{bar:40} {pos}/{len} runs, {elapsed} elapsed, ETA {eta} {msg}",
        )
        .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let next = AtomicUsize::new(0);
    let results: Mutex<Vec<(usize, RunState)>> = Mutex::new(Vec::new());
    let jobs = opts.jobs.clamp(1, todo.len().max(1));
    std::thread::scope(|s| {
        for _ in 0..jobs {
            s.spawn(|| loop {
                let k = next.fetch_add(1, Ordering::SeqCst);
                let Some(run) = todo.get(k) else { break };
                let state = sweep
                    .execute(run, &opts.exe)
                    .unwrap_or_else(|e| RunState::Failed(e.to_string()));
                if let RunState::Failed(why) = &state {
                    bar.println(format!("failed: {} ({why})", run.id));
                }
                bar.inc(1);
                if let Ok(mut r) = results.lock() {
                    r.push((run.index, state));
                }
            });
        }
    });
    bar.finish_and_clear();
    let mut results = results.into_inner().unwrap_or_default();
    results.sort_by_key(|r| r.0);
    summary.ran = results.len();
    let mut failed: Vec<(usize, String)> =
        left_failed.into_iter().map(|(r, s)| (r.index, s)).collect();
    for (i, state) in results {
        match state {
            RunState::Failed(s) => failed.push((i, s)),
            RunState::Done => summary.done += 1,
            RunState::Missing => {}
        }
    }
    summary.done += summary.skipped_done;
    failed.sort_by_key(|f| f.0);
    summary.failed = failed
        .into_iter()
        .map(|(i, status)| {
            let run = sweep.runs[i].clone();
            let error_tail = tail_lines(&sweep.run_dir(&run).join(STDERR), ERROR_TAIL);
            FailedRun {
                run,
                status,
                error_tail,
            }
        })
        .collect();
    Ok(summary)
}

impl FailedRun {
    /// A report of the failure: id, parameters, status and the error's last lines.
    pub fn report(&self) -> String {
        let sets: Vec<String> = self
            .run
            .sets
            .iter()
            .map(|(k, v)| format!("{k}={v}"))
            .collect();
        let mut s = format!("{} [{}]: {}", self.run.id, sets.join(" "), self.status);
        for l in &self.error_tail {
            s += &format!("\n    {l}");
        }
        s
    }
}
