//! The Slurm executor: an `sbatch --array=0-(N-1)%T` script with the manifest's resources as
//! `#SBATCH` lines, one array task per pending run. Task K reads line K+1 of `runs.txt`
//! (written beside the script) for its run's id and calls `emilion sweep task`, which runs
//! exactly what the local executor runs (same folder, same `emilion run` command, same
//! `done` marker). With checkpoints in the manifest a requeued task resumes its run.

use std::path::{Path, PathBuf};
use std::process::Command;

use super::error::SweepError;
use super::run_dir::{RunState, Sweep};
use crate::geometry::files::write_atomic;

/// A written array job.
#[derive(Debug, Clone, PartialEq)]
pub struct SlurmJob {
    /// The `sbatch` script.
    pub script: PathBuf,
    /// The runs list, one id per line, line K+1 for array task K.
    pub runs_list: PathBuf,
    /// Number of array tasks (pending runs).
    pub tasks: usize,
}

/// A path or word in single quotes for the shell.
fn quote(s: &str) -> String {
    format!("'{}'", s.replace('\'', r"'\''"))
}

/// The folder of the Slurm files, `<out>/<sweep>/slurm`.
pub fn slurm_dir(sweep: &Sweep) -> PathBuf {
    sweep.manifest.sweep_dir().join("slurm")
}

/// The text of the `sbatch` script for `tasks` array tasks.
pub fn script_text(sweep: &Sweep, exe: &Path, runs_list: &Path, tasks: usize) -> String {
    let m = &sweep.manifest;
    let r = &m.resources;
    let logs = slurm_dir(sweep).join("logs");
    let mut array = format!("0-{}", tasks.saturating_sub(1));
    if let Some(t) = r.throttle {
        array += &format!("%{t}");
    }
    let mut s = String::from("#!/bin/bash\n");
    s += &format!("#SBATCH --job-name={}\n", m.name);
    s += &format!("#SBATCH --array={array}\n");
    s += "#SBATCH --ntasks=1\n";
    s += &format!("#SBATCH --cpus-per-task={}\n", r.threads);
    for (flag, v) in [
        ("mem", &r.memory),
        ("time", &r.time),
        ("partition", &r.partition),
        ("account", &r.account),
    ] {
        if let Some(v) = v {
            s += &format!("#SBATCH --{flag}={v}\n");
        }
    }
    s += &format!("#SBATCH --output={}/%A_%a.out\n", logs.display());
    s += "#SBATCH --requeue\n";
    s += "#SBATCH --open-mode=append\n";
    s += &format!(
        "# Written by `emilion sweep run {} --slurm`: array task K runs the run named on\n\
         # line K+1 of the runs list, with the same `emilion run` command as a local sweep.\n",
        m.path.display()
    );
    s += "set -eu\n";
    s += &format!("RUNS={}\n", quote(&runs_list.display().to_string()));
    s += "ID=$(sed -n \"$((SLURM_ARRAY_TASK_ID + 1))p\" \"$RUNS\")\n";
    s += "if [ -z \"$ID\" ]; then\n  echo \"no run for array task $SLURM_ARRAY_TASK_ID in $RUNS\" >&2\n  exit 2\nfi\n";
    s += &format!(
        "exec {} sweep task {} --out {} --id \"$ID\"\n",
        quote(&exe.display().to_string()),
        quote(&m.path.display().to_string()),
        quote(&m.out.display().to_string())
    );
    s
}

/// Writes the runs list and the `sbatch` script for the pending runs (missing ones, and
/// failed ones with `retry_failed`); `None` when every run is complete.
pub fn write_job(
    sweep: &Sweep,
    exe: &Path,
    retry_failed: bool,
) -> Result<Option<SlurmJob>, SweepError> {
    let pending: Vec<&str> = sweep
        .runs
        .iter()
        .filter(|r| match sweep.state(r) {
            RunState::Done => false,
            RunState::Failed(_) => retry_failed,
            RunState::Missing => true,
        })
        .map(|r| r.id.as_str())
        .collect();
    if pending.is_empty() {
        return Ok(None);
    }
    let dir = slurm_dir(sweep);
    let logs = dir.join("logs");
    std::fs::create_dir_all(&logs).map_err(SweepError::io(&logs))?;
    let runs_list = dir.join("runs.txt");
    let list = pending.join("\n") + "\n";
    let io = |e: crate::geometry::GeometryError| SweepError::Other(e.to_string());
    write_atomic(&runs_list, |w| w.write_all(list.as_bytes())).map_err(io)?;
    let script = dir.join(format!("{}.sbatch", sweep.manifest.name));
    let text = script_text(sweep, exe, &runs_list, pending.len());
    write_atomic(&script, |w| w.write_all(text.as_bytes())).map_err(io)?;
    Ok(Some(SlurmJob {
        script,
        runs_list,
        tasks: pending.len(),
    }))
}

/// Runs `sbatch` with `args` and the script; its standard output, or an error with its
/// standard error.
fn sbatch(args: &[&str], script: &Path) -> Result<String, SweepError> {
    let out = Command::new("sbatch")
        .args(args)
        .arg(script)
        .output()
        .map_err(|e| SweepError::Other(format!("cannot run sbatch: {e} (is Slurm installed?)")))?;
    let text = |b: &[u8]| String::from_utf8_lossy(b).trim().to_string();
    if out.status.success() {
        // --test-only answers on standard error
        Ok(format!("{}{}", text(&out.stdout), text(&out.stderr)))
    } else {
        Err(SweepError::Other(format!(
            "sbatch {}: {}",
            script.display(),
            text(&out.stderr)
        )))
    }
}

/// Submits the job; returns its id (`sbatch --parsable`).
pub fn submit(job: &SlurmJob) -> Result<String, SweepError> {
    sbatch(&["--parsable"], &job.script)
}

/// Asks Slurm whether it would accept the script (`sbatch --test-only`), without submitting.
pub fn test_only(script: &Path) -> Result<String, SweepError> {
    sbatch(&["--test-only"], script)
}

/// True when `sbatch` can be started here.
pub fn available() -> bool {
    Command::new("sbatch")
        .arg("--version")
        .output()
        .is_ok_and(|o| o.status.success())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quotes_survive_the_shell() {
        assert_eq!(quote("a b"), "'a b'");
        assert_eq!(quote("it's"), r"'it'\''s'");
    }
}
