//! A script run's checkpoint: the long calls (simulation runs, tracking runs) the script made,
//! numbered in the order it made them, each with its progress and its state: the end state of
//! every call that finished, and the state of the call in progress at its last checkpoint. On
//! resume the script runs again from the start; a finished call takes its end state instead of
//! running, the call in progress continues from its state, and later calls run. The states'
//! encodings are their domains' ([`crate::contact::checkpoint`], the tracker's); the file is a
//! [`super::checkpoint`] container of kind `run`.

use std::path::Path;

use super::checkpoint::{self, Decoder, Encoder};
use super::GeometryError;

/// The kind of a run checkpoint file.
pub const RUN_KIND: &str = "run";

/// One long call of a script run.
#[derive(Debug, Clone, PartialEq)]
pub struct CallRecord {
    /// Its place among the script's checkpointed calls (0 first).
    pub ordinal: u64,
    /// What it was (`run_frames`, `track_body`, ...).
    pub kind: String,
    /// The fingerprint of the setup it ran on (the simulation's, the tracker's).
    pub fingerprint: u64,
    /// Whether it finished (its state is its end state).
    pub done: bool,
    /// Frames (or steps) of the call done at its state.
    pub progress: u64,
    /// The simulated time at the start of the call (s; 0 where meaningless).
    pub start_time: f64,
    /// The encoded state.
    pub state: Vec<u8>,
}

/// A run checkpoint: how often it is written and the calls so far.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct RunCheckpoint {
    /// Checkpoint every this many frames (or steps).
    pub every: u64,
    /// The calls, in order.
    pub calls: Vec<CallRecord>,
}

fn encode(every: u64, calls: &[&CallRecord]) -> Vec<u8> {
    let mut e = Encoder::new();
    e.u64(every);
    e.usize(calls.len());
    for c in calls.iter() {
        e.u64(c.ordinal);
        e.str(&c.kind);
        e.u64(c.fingerprint);
        e.bool(c.done);
        e.u64(c.progress);
        e.f64(c.start_time);
        e.bytes(&c.state);
    }
    e.buf
}

/// Writes a run checkpoint of the calls `calls` (the finished ones, then the one in progress)
/// for the run of fingerprint `run` (its script and settings), atomically.
pub fn write_run_checkpoint(
    path: &Path,
    run: u64,
    every: u64,
    calls: &[&CallRecord],
) -> Result<(), GeometryError> {
    checkpoint::write_file(path, RUN_KIND, run, &encode(every, calls))
}

/// Reads a run checkpoint; returns the fingerprint of the run that wrote it and its calls.
pub fn read_run_checkpoint(path: &Path) -> Result<(u64, RunCheckpoint), GeometryError> {
    let f = checkpoint::read_file(path, RUN_KIND)?;
    let mut d = Decoder::new(&f.payload, &path.display().to_string());
    let every = d.u64("checkpoint interval")?;
    let n = d.len(8 * 6, "calls")?;
    let mut calls = Vec::with_capacity(n);
    for _ in 0..n {
        calls.push(CallRecord {
            ordinal: d.u64("call ordinal")?,
            kind: d.str("call kind")?,
            fingerprint: d.u64("call fingerprint")?,
            done: d.bool("call finished")?,
            progress: d.u64("call progress")?,
            start_time: d.f64("call start time")?,
            state: d.bytes("call state")?.to_vec(),
        });
    }
    if !d.finished() {
        return Err(d.error("bytes left over after the calls"));
    }
    Ok((f.fingerprint, RunCheckpoint { every, calls }))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_run_checkpoint_round_trips() {
        let dir = std::env::temp_dir().join(format!("emilion_runckpt_{}", std::process::id()));
        let path = dir.join("r.ckpt");
        let calls = [
            CallRecord {
                ordinal: 0,
                kind: "run".into(),
                fingerprint: 7,
                done: true,
                progress: 12,
                start_time: 0.0,
                state: vec![1, 2, 3],
            },
            CallRecord {
                ordinal: 1,
                kind: "run_frames".into(),
                fingerprint: 7,
                done: false,
                progress: 3,
                start_time: 0.1,
                state: vec![],
            },
        ];
        write_run_checkpoint(&path, 99, 2, &calls.iter().collect::<Vec<_>>()).unwrap();
        let (fp, r) = read_run_checkpoint(&path).unwrap();
        assert_eq!((fp, r.every), (99, 2));
        assert_eq!(r.calls, calls);
        let _ = std::fs::remove_dir_all(dir);
    }
}
