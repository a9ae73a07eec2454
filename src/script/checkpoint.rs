//! Checkpoint and resume of a script run (`emilion run SCRIPT --checkpoint EVERY
//! [--checkpoint-file FILE] [--resume FILE]`), and the `sim.checkpoint(path)` and
//! `sim.resume(path)` methods. See docs/checkpoints.md.
//!
//! A script is code, so a resumed run runs the script again from the start: its setup is cheap
//! and deterministic. The long calls (`run`, `run_steps`, `run_frames`, `track::body`) are
//! numbered in the order the script makes them. While a run is checkpointed, the call in
//! progress writes the run's checkpoint every EVERY frames (steps for `run` and `run_steps`)
//! and when it ends; the checkpoint holds the end state of every finished call and the state of
//! the call in progress (see [`crate::geometry::run_checkpoint`]). On resume, a finished call
//! takes its end state without running (no steps, no callbacks), the call in progress takes its
//! state and runs on from there (callbacks only for the frames after it), later calls run.
//!
//! This module holds the process-wide session (set once by the command line, before the
//! script runs) and the two script methods; the states are encoded by their domains.

use std::path::{Path, PathBuf};
use std::sync::Mutex;

use super::convert::{rt_err, RResult};
use super::paths::{read_path, write_path};
use super::{modules::ApiBuilder, register, SimHandle};
use crate::contact::checkpoint::{read_simulation_checkpoint, write_simulation_checkpoint};
use crate::geometry::checkpoint::Fingerprint;
use crate::geometry::run_checkpoint::{read_run_checkpoint, write_run_checkpoint, CallRecord};

/// How a script run is checkpointed (the command line's flags).
#[derive(Debug, Clone, Default)]
pub struct CheckpointSettings {
    /// Write a checkpoint every this many frames (steps for `run` and `run_steps`); 0: only
    /// when resuming, with the interval the resumed checkpoint was written with.
    pub every: u64,
    /// Where (default: the resumed file, else `out/<script name>.ckpt` under the working
    /// directory).
    pub file: Option<PathBuf>,
    /// A checkpoint to resume from.
    pub resume: Option<PathBuf>,
}

/// The checkpointing of the running script.
#[derive(Debug)]
struct Session {
    every: u64,
    file: PathBuf,
    /// Fingerprint of the run: the script's text and its `--set` values.
    run: u64,
    /// The resumed file and its calls.
    resume: Option<(String, Vec<CallRecord>)>,
    next: u64,
    /// Calls finished so far (their end states).
    done: Vec<CallRecord>,
}

static SESSION: Mutex<Option<Session>> = Mutex::new(None);

fn with_session<T>(f: impl FnOnce(&mut Option<Session>) -> T) -> T {
    match SESSION.lock() {
        Ok(mut s) => f(&mut s),
        Err(poisoned) => f(&mut poisoned.into_inner()),
    }
}

/// The fingerprint of a run of `source` with `sets`: a checkpoint resumes only the run that
/// wrote it.
fn run_fingerprint(source: &str, sets: &[(String, String)]) -> u64 {
    let mut f = Fingerprint::default();
    f.str(source);
    let mut sets = sets.to_vec();
    sets.sort();
    for (k, v) in &sets {
        f.str(k).str(v);
    }
    f.value()
}

/// Turns checkpointing on for the run of the script `script` with `sets`, as `settings` say
/// (nothing when they ask for none). Reads and checks the resumed checkpoint: another script
/// or other `--set` values are refused.
pub fn configure(
    script: &Path,
    sets: &[(String, String)],
    settings: &CheckpointSettings,
) -> Result<(), String> {
    if settings.every == 0 && settings.resume.is_none() {
        with_session(|s| *s = None);
        return Ok(());
    }
    let source = crate::limits::read_to_string(script)
        .map_err(|e| format!("{}: cannot read script: {e}", script.display()))?;
    let run = run_fingerprint(&source, sets);
    let mut every = settings.every;
    let resume = match &settings.resume {
        Some(path) => {
            let (found, r) = read_run_checkpoint(path).map_err(|e| e.to_string())?;
            if found != run {
                return Err(format!(
                    "checkpoint {} was written by another script or with other --set values \
                     than {} has now",
                    path.display(),
                    script.display()
                ));
            }
            if every == 0 {
                every = r.every.max(1);
            }
            Some((path.display().to_string(), r.calls))
        }
        None => None,
    };
    let file = settings
        .file
        .clone()
        .or_else(|| settings.resume.clone())
        .unwrap_or_else(|| {
            let stem = script
                .file_stem()
                .map_or_else(|| "script".into(), |s| s.to_string_lossy().into_owned());
            PathBuf::from("out").join(format!("{stem}.ckpt"))
        });
    with_session(|s| {
        *s = Some(Session {
            every,
            file,
            run,
            resume,
            next: 0,
            done: Vec::new(),
        })
    });
    Ok(())
}

/// What a long call does.
#[derive(Debug)]
pub enum Plan {
    /// Runs from its start.
    Run,
    /// Finished before: takes this end state and does not run.
    Finished(CallRecord),
    /// Was in progress: takes this state and runs on after its progress.
    Continue(CallRecord),
}

/// A long call of the running script, numbered.
#[derive(Debug)]
pub struct Call {
    ordinal: u64,
    kind: &'static str,
    fingerprint: u64,
    /// Checkpoint every this many frames or steps (0: never).
    every: u64,
}

/// Starts the long call `kind` on a setup of fingerprint `fingerprint` (asked only while
/// checkpointing): what it should do, as the resumed checkpoint says.
pub fn begin(kind: &'static str, fingerprint: impl FnOnce() -> u64) -> RResult<(Call, Plan)> {
    let off = Call {
        ordinal: 0,
        kind,
        fingerprint: 0,
        every: 0,
    };
    let active = with_session(|s| s.is_some());
    if !active {
        return Ok((off, Plan::Run));
    }
    let fp = fingerprint();
    with_session(|s| {
        let Some(s) = s.as_mut() else {
            return Ok((off, Plan::Run));
        };
        let ordinal = s.next;
        s.next += 1;
        let call = Call {
            ordinal,
            kind,
            fingerprint: fp,
            every: s.every,
        };
        let Some((file, calls)) = &s.resume else {
            return Ok((call, Plan::Run));
        };
        let Some(rec) = calls.iter().find(|c| c.ordinal == ordinal) else {
            return Ok((call, Plan::Run));
        };
        if rec.kind != kind || rec.fingerprint != fp {
            return Err(rt_err(format!(
                "checkpoint {file}: long call {ordinal} was a `{}` on another setup (this one is \
                 a `{kind}`; fingerprints {:016x} and {fp:016x}): the script no longer makes the \
                 calls it made",
                rec.kind, rec.fingerprint
            )));
        }
        let rec = rec.clone();
        Ok(if rec.done {
            s.done.push(rec.clone());
            (call, Plan::Finished(rec))
        } else {
            (call, Plan::Continue(rec))
        })
    })
}

impl Call {
    /// Whether a checkpoint is due after `progress` frames (or steps) of this call.
    pub fn due(&self, progress: u64) -> bool {
        self.every > 0 && progress.is_multiple_of(self.every)
    }

    /// Whether this call is checkpointed at all.
    pub fn active(&self) -> bool {
        self.every > 0
    }

    fn record(&self, done: bool, progress: u64, start_time: f64, state: Vec<u8>) -> CallRecord {
        CallRecord {
            ordinal: self.ordinal,
            kind: self.kind.to_string(),
            fingerprint: self.fingerprint,
            done,
            progress,
            start_time,
            state,
        }
    }

    /// Writes the run's checkpoint with this call in progress at `progress` (started at
    /// simulated time `start_time`) in state `state`.
    pub fn save(&self, progress: u64, start_time: f64, state: Vec<u8>) -> RResult<()> {
        let rec = self.record(false, progress, start_time, state);
        write(&rec, false)
    }

    /// Records this call as finished after `progress` in end state `state` (built only while
    /// checkpointing) and writes the run's checkpoint.
    pub fn finish(
        &self,
        progress: u64,
        start_time: f64,
        state: impl FnOnce() -> RResult<Vec<u8>>,
    ) -> RResult<()> {
        if !self.active() {
            return Ok(());
        }
        let rec = self.record(true, progress, start_time, state()?);
        write(&rec, true)
    }
}

/// Writes the run's checkpoint: the finished calls and `rec`, which joins them if `done`.
fn write(rec: &CallRecord, done: bool) -> RResult<()> {
    with_session(|s| {
        let Some(s) = s.as_mut() else { return Ok(()) };
        let calls: Vec<&CallRecord> = s.done.iter().chain([rec]).collect();
        write_run_checkpoint(&s.file, s.run, s.every, &calls)
            .map_err(|e| rt_err(format!("writing the checkpoint: {e}")))?;
        eprintln!(
            "checkpoint: call {} ({}) {} {} -> {}",
            rec.ordinal,
            rec.kind,
            if done { "finished at" } else { "at" },
            rec.progress,
            s.file.display()
        );
        if done {
            s.done.push(rec.clone());
        }
        Ok(())
    })
}

/// The resumed file's name, for messages.
pub fn resumed_file() -> String {
    with_session(|s| {
        s.as_ref()
            .and_then(|s| s.resume.as_ref())
            .map_or_else(String::new, |r| r.0.clone())
    })
}

/// Registers `sim.checkpoint(path)` and `sim.resume(path)`.
pub fn register(engine: &mut ApiBuilder) {
    register!(
        engine,
        "checkpoint",
        ["sim: Simulation", "path: String"],
        "Writes the simulation's whole state (particles, clock, solver warm start and internal
friction, pins and attachments, contact and friction memory, animated bodies, sewing,
statistics, random states, the frames of its recordings) to a checkpoint file, atomically.
`sim.resume(path)` on a simulation set up the same way continues bit for bit. See
docs/checkpoints.md.",
        |h: &mut SimHandle, path: &str| -> RResult<()> {
            let p = write_path(path)?;
            let sim = h.get()?;
            let recs =
                h.1.try_borrow()
                    .map_err(|_| rt_err("the recording is busy"))?;
            write_simulation_checkpoint(&p, &sim, &recs).map_err(|e| rt_err(e.to_string()))
        }
    );
    register!(
        engine,
        "resume",
        ["sim: Simulation", "path: String"],
        "Loads a checkpoint written by `sim.checkpoint(path)` into this simulation, which must be set
up as the one that wrote it (same cloth, bodies, stages and recordings started): another
scene, a damaged file or a format this build does not read is an error naming the file.",
        |h: &mut SimHandle, path: &str| -> RResult<()> {
            let p = read_path(path)?;
            let mut sim = h.get_mut()?;
            let mut recs = h
                .1
                .try_borrow_mut()
                .map_err(|_| rt_err("the recording is busy"))?;
            read_simulation_checkpoint(&p, &mut sim, &mut recs).map_err(|e| rt_err(e.to_string()))
        }
    );
}
