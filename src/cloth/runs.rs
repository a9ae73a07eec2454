//! Runs of a simulation: a number of steps or a simulated duration, checked against the
//! stated limits (`max_steps`) before anything runs, and stopped when the run is cancelled or
//! past its deadline.

use super::parameters::short_number;
use super::simulation::Simulation;
use super::stats::StepStats;
use super::ClothError;
use crate::limits::{self, LimitError};

/// Most step statistics reserved ahead of a run; the statistics grow past it as steps are taken.
const STATS_RESERVE_MAX: u64 = 1 << 16;

fn limit_err(e: LimitError) -> ClothError {
    ClothError::Parameter(e.to_string())
}

impl Simulation {
    /// Runs `steps` steps, calling `each` after every step; stops at the first error. A count
    /// over `limits::get().max_steps` is refused before anything runs, and the run stops with
    /// an error when it is cancelled or passes its deadline ([`limits::check_cancelled`], once
    /// per step).
    pub fn run_steps(
        &mut self,
        steps: u64,
        mut each: impl FnMut(&Simulation, &StepStats) -> Result<(), ClothError>,
    ) -> Result<(), ClothError> {
        let max = limits::get().max_steps;
        limits::check_count("the number of steps", steps, "max_steps", max).map_err(limit_err)?;
        // the statistics grow as steps are taken; reserve at most a bounded head start
        let ahead = steps.min(STATS_RESERVE_MAX);
        let bytes = std::mem::size_of::<StepStats>() as u64;
        let ahead = limits::check_alloc("step statistics", ahead, bytes).map_err(limit_err)?;
        self.stats.reserve(ahead);
        for _ in 0..steps {
            limits::check_cancelled().map_err(ClothError::Parameter)?;
            let st = self.step()?;
            each(self, &st)?;
        }
        Ok(())
    }

    /// Number of steps needed to cover `seconds` (0 for a negative or NaN duration; use
    /// [`Simulation::checked_steps_for`] for a duration that comes from input).
    pub fn steps_for(&self, seconds: f64) -> u64 {
        (seconds / self.params.dt - 1e-9).ceil().max(0.0) as u64
    }

    /// Number of steps needed to cover `seconds`, refusing a duration that is negative or not
    /// finite, or whose step count at this `dt` is over `limits::get().max_steps`.
    pub fn checked_steps_for(&self, seconds: f64) -> Result<u64, ClothError> {
        if !(seconds.is_finite() && seconds >= 0.0) {
            return Err(ClothError::Parameter(format!(
                "the duration to simulate is {seconds} s; it must be a finite number ≥ 0"
            )));
        }
        let steps = (seconds / self.params.dt - 1e-9).ceil().max(0.0);
        let max = limits::get().max_steps;
        let what = || {
            format!(
                "the number of steps for {} s at dt = {} s",
                short_number(seconds),
                short_number(self.params.dt)
            )
        };
        if steps > max as f64 {
            return Err(limit_err(LimitError {
                what: what(),
                value: short_number(steps),
                limit: "max_steps",
                max,
            }));
        }
        limits::check(&what(), steps, "max_steps", max).map_err(limit_err)
    }
}
