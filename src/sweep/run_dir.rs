//! A run's folder, `<out>/<sweep>/<id>/`, and running one run into it: `params.json` (its
//! `--set` values), `stdout.log` and `stderr.log`, `status.json` (exit status, seconds) and,
//! written last and atomically, the `done` marker. The child is `emilion run SCRIPT --set k=v …`
//! started in the run's folder (so the script's `out_dir()` lies inside it), with
//! `--checkpoint`/`--resume` on the run's own checkpoint file when the manifest asks, so a run
//! that was killed or requeued continues where it stopped.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::Instant;

use super::error::SweepError;
use super::expand::{expand, Run};
use super::manifest::Manifest;
use crate::geometry::files::write_atomic;

/// The marker file of a complete run.
pub const DONE: &str = "done";
/// The exit status file of a finished (complete or failed) run.
pub const STATUS: &str = "status.json";
/// The run's parameters.
pub const PARAMS: &str = "params.json";
/// The run's standard output.
pub const STDOUT: &str = "stdout.log";
/// The run's standard error.
pub const STDERR: &str = "stderr.log";
/// The run's checkpoint (when the manifest asks for checkpoints).
pub const CHECKPOINT: &str = "run.ckpt";

/// Where a run stands.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum RunState {
    /// Never started, or stopped before it ended (killed, preempted).
    Missing,
    /// Ended with a non-zero exit status (or a signal): the status text.
    Failed(String),
    /// Complete (the `done` marker is there).
    Done,
}

/// A manifest with its runs expanded.
#[derive(Debug, Clone)]
pub struct Sweep {
    /// The manifest.
    pub manifest: Manifest,
    /// Its runs, in the fixed order.
    pub runs: Vec<Run>,
}

fn atomic_text(path: &Path, text: &str) -> Result<(), SweepError> {
    write_atomic(path, |w| w.write_all(text.as_bytes()))
        .map_err(|e| SweepError::Other(e.to_string()))
}

impl Sweep {
    /// Reads a manifest and expands it; `out` replaces the manifest's output root.
    pub fn load(path: &Path, out: Option<&Path>) -> Result<Sweep, SweepError> {
        let mut manifest = Manifest::load(path)?;
        if let Some(o) = out {
            manifest.out = std::path::absolute(o).map_err(SweepError::io(o))?;
        }
        let runs = expand(&manifest)?;
        Ok(Sweep { manifest, runs })
    }

    /// The folder of a run.
    pub fn run_dir(&self, run: &Run) -> PathBuf {
        self.manifest.sweep_dir().join(&run.id)
    }

    /// Where a run stands, from its folder.
    pub fn state(&self, run: &Run) -> RunState {
        let dir = self.run_dir(run);
        if dir.join(DONE).is_file() {
            return RunState::Done;
        }
        match std::fs::read_to_string(dir.join(STATUS)) {
            Ok(text) => {
                let v: serde_json::Value = serde_json::from_str(&text).unwrap_or_default();
                let status = v["status"]
                    .as_str()
                    .unwrap_or("unreadable status")
                    .to_string();
                RunState::Failed(status)
            }
            Err(_) => RunState::Missing,
        }
    }

    /// The run with this id.
    pub fn find(&self, id: &str) -> Result<&Run, SweepError> {
        self.runs.iter().find(|r| r.id == id).ok_or_else(|| {
            SweepError::Other(format!(
                "{}: no run `{id}` in this sweep",
                self.manifest.path.display()
            ))
        })
    }

    /// The `emilion` arguments of a run (after the program name), for a run in `dir`.
    pub fn run_args(&self, run: &Run, dir: &Path) -> Vec<String> {
        let m = &self.manifest;
        let mut a = vec!["run".to_string(), m.script.display().to_string()];
        for (k, v) in &run.sets {
            a.push("--set".into());
            a.push(format!("{k}={v}"));
        }
        a.extend(m.args.iter().cloned());
        if m.checkpoint > 0 {
            let ckpt = dir.join(CHECKPOINT);
            a.push("--checkpoint".into());
            a.push(m.checkpoint.to_string());
            a.push("--checkpoint-file".into());
            a.push(ckpt.display().to_string());
            if ckpt.is_file() {
                a.push("--resume".into());
                a.push(ckpt.display().to_string());
            }
        }
        a
    }

    /// Runs one run with the `emilion` binary `exe` and records it in its folder; returns
    /// its state. A failing script is a [`RunState::Failed`], not an error; errors are
    /// folders that cannot be written or a binary that cannot be started.
    pub fn execute(&self, run: &Run, exe: &Path) -> Result<RunState, SweepError> {
        let dir = self.run_dir(run);
        std::fs::create_dir_all(&dir).map_err(SweepError::io(&dir))?;
        for stale in [DONE, STATUS] {
            let p = dir.join(stale);
            if p.exists() {
                std::fs::remove_file(&p).map_err(SweepError::io(&p))?;
            }
        }
        let params: serde_json::Map<String, serde_json::Value> = run
            .sets
            .iter()
            .map(|(k, v)| (k.clone(), serde_json::Value::String(v.clone())))
            .collect();
        let params = serde_json::json!({
            "sweep": self.manifest.name,
            "id": run.id,
            "index": run.index,
            "script": self.manifest.script.display().to_string(),
            "params": params,
        });
        atomic_text(&dir.join(PARAMS), &format!("{params:#}\n"))?;
        let open = |name: &str| {
            let p = dir.join(name);
            std::fs::File::create(&p).map_err(SweepError::io(p))
        };
        let (out, err) = (open(STDOUT)?, open(STDERR)?);
        let start = Instant::now();
        let mut cmd = Command::new(exe);
        die_with_parent(&mut cmd);
        let status = cmd
            .args(self.run_args(run, &dir))
            .current_dir(&dir)
            .env(
                "RAYON_NUM_THREADS",
                self.manifest.resources.threads.to_string(),
            )
            .stdin(Stdio::null())
            .stdout(out)
            .stderr(err)
            .status()
            .map_err(|e| SweepError::Other(format!("cannot start {}: {e}", exe.display())))?;
        let seconds = start.elapsed().as_secs_f64();
        let text = match (status.code(), status.success()) {
            (_, true) => "ok".to_string(),
            (Some(c), false) => format!("exit status {c}"),
            (None, false) => format!("killed ({status})"),
        };
        let record = serde_json::json!({
            "status": text,
            "exit_code": status.code(),
            "seconds": (seconds * 1000.0).round() / 1000.0,
        });
        atomic_text(&dir.join(STATUS), &format!("{record:#}\n"))?;
        if status.success() {
            atomic_text(&dir.join(DONE), &format!("{}\n", run.id))?;
            Ok(RunState::Done)
        } else {
            Ok(RunState::Failed(text))
        }
    }
}

/// Makes the child die (SIGKILL) when the thread that started it dies, so a killed sweep
/// leaves no orphan runs writing into their folders: on Linux, `PR_SET_PDEATHSIG` set between
/// fork and exec (and the child exits at once if the sweep died before that). The thread that
/// starts a run waits for it, so it lives as long as the run. Elsewhere a no-op.
#[cfg(target_os = "linux")]
fn die_with_parent(cmd: &mut Command) {
    use std::os::unix::process::CommandExt;
    let parent = std::process::id() as libc::pid_t;
    // SAFETY: the closure runs in the forked child before exec and calls only the
    // async-signal-safe `prctl`, `getppid` and `_exit`, allocating nothing.
    unsafe {
        cmd.pre_exec(move || {
            if libc::prctl(libc::PR_SET_PDEATHSIG, libc::SIGKILL, 0, 0, 0) != 0 {
                return Err(std::io::Error::last_os_error());
            }
            if libc::getppid() != parent {
                libc::_exit(137);
            }
            Ok(())
        });
    }
}

/// Elsewhere the children outlive a killed sweep (no parent-death signal).
#[cfg(not(target_os = "linux"))]
fn die_with_parent(_cmd: &mut Command) {}

/// The last `n` non-empty lines of a text file (empty when it cannot be read), read within
/// the `max_file_bytes` limit.
pub fn tail_lines(path: &Path, n: usize) -> Vec<String> {
    let Ok(text) = crate::limits::read_to_string(path) else {
        return Vec::new();
    };
    let lines: Vec<&str> = text.lines().filter(|l| !l.trim().is_empty()).collect();
    lines[lines.len().saturating_sub(n)..]
        .iter()
        .map(|s| s.to_string())
        .collect()
}
