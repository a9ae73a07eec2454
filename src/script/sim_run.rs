//! Script bindings for running simulations: one step, a number of steps, simulated seconds
//! (with a closure called after every step) and frames (with a closure called per frame and
//! the recordings captured), each run call checkpointed and resumed as the command line asks
//! (see [`checkpoint`](super::checkpoint) and docs/checkpoints.md).

use std::io::IsTerminal;

use indicatif::ProgressBar;
use rhai::{Dynamic, FnPtr, Map, NativeCallContext, INT};

use super::captured::{encode_captured, restore_captured};
use super::checkpoint::{begin, resumed_file, Call, Plan};
use super::convert::{count, finite, rt_err, to_map, RResult};
use super::{modules::ApiBuilder, register, SimHandle};
use crate::cloth::Simulation;
use crate::contact::checkpoint::{decode_simulation, encode_simulation};
use crate::geometry::checkpoint::{Decoder, Encoder};
use crate::geometry::run_checkpoint::CallRecord;
use crate::geometry::GeometryError;

/// A progress bar on a terminal, a hidden one otherwise.
fn progress(len: u64) -> ProgressBar {
    if std::io::stderr().is_terminal() && len >= 100 {
        ProgressBar::new(len)
    } else {
        ProgressBar::hidden()
    }
}

/// The map handed to run callbacks.
fn frame_info(frame: u64, sim: &Simulation, h: &SimHandle) -> Map {
    let mut m = Map::new();
    m.insert("sim".into(), Dynamic::from(h.clone()));
    m.insert("frame".into(), Dynamic::from_int(frame as INT));
    m.insert("time".into(), Dynamic::from_float(sim.state.time));
    m.insert("step".into(), Dynamic::from_int(sim.state.step as INT));
    m
}

/// Calls `f(info)` with `this` bound to the simulation; a `false` result stops the run.
/// (Rhai refuses a callback that captures the variable whose method is running, so the
/// callback reaches the simulation through `this` or `info.sim`.)
fn callback(ctx: &NativeCallContext, h: &SimHandle, f: &FnPtr, info: Map) -> RResult<bool> {
    let mut this = Dynamic::from(h.clone());
    let r: Dynamic = f.call_as_method_within_context(ctx, &mut this, (Dynamic::from_map(info),))?;
    Ok(!matches!(r.as_bool(), Ok(false)))
}

/// The simulation's state, its recordings' frames and the variables the callback `f`
/// captured, encoded for a checkpoint.
fn encode(h: &SimHandle, f: Option<&FnPtr>) -> RResult<Vec<u8>> {
    let sim = h.get()?;
    let recs =
        h.1.try_borrow()
            .map_err(|_| rt_err("the recording is busy"))?;
    let mut e = Encoder::new();
    e.bytes(&encode_simulation(&sim, &recs));
    e.bytes(&encode_captured(f));
    Ok(e.buf)
}

/// Loads a call's checkpointed state into the simulation, its recordings and the variables
/// the callback `f` captured.
fn load(h: &SimHandle, rec: &CallRecord, f: Option<&FnPtr>) -> RResult<()> {
    let file = resumed_file();
    let mut d = Decoder::new(&rec.state, &file);
    let err = |e: GeometryError| rt_err(e.to_string());
    let (sim_state, captured) = (
        d.bytes("simulation").map_err(err)?,
        d.bytes("captured").map_err(err)?,
    );
    {
        let mut sim = h.get_mut()?;
        let mut recs =
            h.1.try_borrow_mut()
                .map_err(|_| rt_err("the recording is busy"))?;
        decode_simulation(sim_state, &file, &mut sim, &mut recs)
            .map_err(|e| rt_err(e.to_string()))?;
    }
    restore_captured(f, &mut Decoder::new(captured, &file)).map_err(err)
}

/// Starts a run call of `kind`: the checkpoint call, the first frame or step to run, the
/// simulated time at the call's start, or `None` when the call finished before (its end
/// state is loaded).
fn start(
    h: &SimHandle,
    kind: &'static str,
    f: Option<&FnPtr>,
) -> RResult<(Call, Option<(u64, f64)>)> {
    let (call, plan) = begin(kind, || h.get().map_or(0, |s| s.fingerprint()))?;
    Ok(match plan {
        Plan::Run => {
            let t0 = h.get()?.state.time;
            (call, Some((1, t0)))
        }
        Plan::Finished(rec) => {
            load(h, &rec, f)?;
            (call, None)
        }
        Plan::Continue(rec) => {
            load(h, &rec, f)?;
            (call, Some((rec.progress + 1, rec.start_time)))
        }
    })
}

/// Checkpoints after `k` frames or steps of `call`, if one is due.
fn after(call: &Call, h: &SimHandle, k: u64, t0: f64, f: Option<&FnPtr>) -> RResult<()> {
    if call.due(k) {
        call.save(k, t0, encode(h, f)?)?;
    }
    Ok(())
}

/// Steps `n` times, with a progress bar on a terminal (`kind`: the script method).
fn run_n(h: &SimHandle, n: u64, kind: &'static str) -> RResult<()> {
    let max = crate::limits::get().max_steps;
    crate::limits::check_count("the number of steps", n, "max_steps", max).map_err(rt_err)?;
    let (call, Some((first, t0))) = start(h, kind, None)? else {
        return Ok(());
    };
    let pb = progress(n);
    pb.inc(first - 1);
    for k in first..=n {
        crate::limits::check_cancelled().map_err(rt_err)?;
        h.get_mut()?.step()?;
        pb.inc(1);
        after(&call, h, k, t0, None)?;
    }
    pb.finish_and_clear();
    call.finish(n, t0, || encode(h, None))
}

/// Registers the `Simulation` methods that step it.
pub fn register(engine: &mut ApiBuilder) {
    register!(
        engine,
        "step",
        ["sim: Simulation", "Map"],
        "Advances one step; returns its statistics (see `stats`). A diverging step is an error.",
        |h: &mut SimHandle| -> RResult<Dynamic> { Ok(to_map(&h.get_mut()?.step()?)) }
    );
    register!(
        engine,
        "run_steps",
        ["sim: Simulation", "steps: int"],
        "Advances `steps` steps (at most the limit `max_steps`, see docs/limits.md).",
        |h: &mut SimHandle, n: INT| -> RResult<()> {
            run_n(
                h,
                count(&Dynamic::from_int(n), "steps")? as u64,
                "run_steps",
            )
        }
    );
    register!(
        engine,
        "run",
        ["sim: Simulation", "seconds: float"],
        "Advances `seconds` of simulated time (rounded up to whole steps, at most the limit\n`max_steps`, see docs/limits.md).",
        |h: &mut SimHandle, secs: Dynamic| -> RResult<()> {
            let n = h.get()?.checked_steps_for(finite(&secs, "seconds")?)?;
            run_n(h, n, "run")
        }
    );
    register!(engine, "run", ["sim: Simulation", "seconds: float", "callback: FnPtr"],
        "Advances `seconds`, calling `callback(#{frame, time, step, sim})` after every step\n(`frame` counts the steps of this run from 1). A callback returning `false` stops the run.\nInside the callback the simulation is `this` (or `t.sim`); Rhai forbids capturing `sim` itself.",
        |ctx: NativeCallContext, h: &mut SimHandle, secs: Dynamic, f: FnPtr| -> RResult<()> {
            let n = h.get()?.checked_steps_for(finite(&secs, "seconds")?)?;
            let (call, Some((first, t0))) = start(h, "run", Some(&f))? else {
                return Ok(());
            };
            let mut last = first.saturating_sub(1);
            for k in first..=n {
                crate::limits::check_cancelled().map_err(rt_err)?;
                let info = {
                    let mut s = h.get_mut()?;
                    s.step()?;
                    frame_info(k, &s, h)
                };
                last = k;
                if !callback(&ctx, h, &f, info)? {
                    break;
                }
                after(&call, h, k, t0, Some(&f))?;
            }
            call.finish(last, t0, || encode(h, Some(&f)))
        });
    register!(engine, "run_frames", ["sim: Simulation", "frames: int", "fps: float", "callback: FnPtr"],
        "Runs `frames` frames at `fps`, stepping to each frame time and then calling\n`callback(#{frame, time, step, sim})` (`frame` from 1). A callback returning `false` stops the run.\nWith a recording started (`record`), each frame is added to it and the cache is written at the end.\nInside the callback the simulation is `this` (or `t.sim`); Rhai forbids capturing `sim` itself.",
        |ctx: NativeCallContext, h: &mut SimHandle, frames: INT, fps: Dynamic, f: FnPtr| -> RResult<()> {
            let frames = count(&Dynamic::from_int(frames), "frames")? as u64;
            let max = crate::limits::get().max_frames;
            crate::limits::check_count("run_frames `frames`", frames, "max_frames", max).map_err(rt_err)?;
            let fps = finite(&fps, "fps")?;
            if fps <= 0.0 {
                return Err(rt_err(format!("`fps` must be > 0, got {fps}")));
            }
            // the whole run's steps, refused before the first one
            h.get()?.checked_steps_for(frames as f64 / fps)?;
            let (call, Some((first, t0))) = start(h, "run_frames", Some(&f))? else {
                h.write_recording()?;
                return Ok(());
            };
            let mut last = first.saturating_sub(1);
            for k in first..=frames {
                crate::limits::check_cancelled().map_err(rt_err)?;
                let info = {
                    let mut s = h.get_mut()?;
                    let n = s.steps_for(t0 + k as f64 / fps - s.state.time);
                    s.run_steps(n, |_, _| Ok(()))?;
                    frame_info(k, &s, h)
                };
                h.capture_frame()?;
                last = k;
                if !callback(&ctx, h, &f, info)? {
                    break;
                }
                after(&call, h, k, t0, Some(&f))?;
            }
            h.write_recording()?;
            call.finish(last, t0, || encode(h, Some(&f)))
        });
}
