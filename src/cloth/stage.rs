//! `StepStage`: the one way something outside the cloth's own forces takes part in a step
//! (contact with bodies, cloth–cloth contact, a floor, the compression-release buckling
//! model). A simulation holds a list of stages; before the solve each constrains particles
//! through the filter (in the order the stages were added), the implicit solve takes the forces
//! they add, and after the new positions each responds (friction, push-out, self-collision), in
//! reverse order, so the first stage added wraps the others. The cloth knows no stage's type.

use std::any::Any;

use super::constraints::Filter;
use super::sewing::Sewing;
use super::stats::StepStats;
use crate::geometry::checkpoint::{Decoder, Encoder, Fingerprint};
use crate::geometry::{GeometryError, Vec3};

/// The end of a step as the stages' responses see it.
#[derive(Debug)]
pub struct StepEnd<'a> {
    /// Positions at the start of the step.
    pub x_start: &'a [Vec3],
    /// Positions at the end of the step (corrected in place).
    pub x: &'a mut [Vec3],
    /// Velocities at the end of the step (corrected in place).
    pub v: &'a mut [Vec3],
    /// Constraint impulses of the step (momentum), read from the solve's residual; meaningful
    /// only when a stage [uses them](StepStage::uses_impulses).
    pub impulse: &'a [Vec3],
    /// Particle masses.
    pub mass: &'a [f64],
    /// The step's filter.
    pub filter: &'a Filter,
    /// Length of the step (s).
    pub dt: f64,
}

/// A stage of every simulation step beside the cloth's forces. Every hook but the two `Any`
/// accessors has a default that does nothing.
pub trait StepStage: Send + Sync + std::fmt::Debug + Any {
    /// Follows a garment's sewing schedule at the start of the step at time `t`.
    fn follow_sewing(&mut self, _sewing: &Sewing, _t: f64) {}

    /// Whether `p` is clear of this stage's obstacles (default: it has none).
    fn is_clear(&self, _p: &Vec3) -> bool {
        true
    }

    /// Before the solve of the step from `t` to `t + dt`: constrains particles through the
    /// filter (normal velocity S = I − n nᵀ and z, or fixed targets). `obstacles` are those of
    /// the stages added before this one.
    fn constrain(
        &mut self,
        _x: &[Vec3],
        _v: &[Vec3],
        _t: f64,
        _dt: f64,
        _filter: &mut Filter,
        _obstacles: Obstacles<'_>,
    ) {
    }

    /// Adds forces to the right-hand side `b` (momentum) of the implicit solve, after the
    /// assembly.
    fn add_forces(&mut self, _b: &mut [Vec3]) {}

    /// Whether [`StepStage::respond`] reads the step's positions at its start and its
    /// constraint impulses (the simulation computes them only then).
    fn uses_impulses(&self) -> bool {
        false
    }

    /// Whether [`StepStage::loosen`] may change anything on this step (it holds constraints
    /// it may let go): the simulation then judges the impulses on a first solve to a looser
    /// tolerance (default: no).
    fn may_loosen(&self) -> bool {
        false
    }

    /// After a solve, before the new positions: loosens the constraints whose `impulse`
    /// (momentum, from the solve's residual) works against them, by changing the `filter`;
    /// returns whether any changed, and the step is then solved again with the new filter
    /// (default: nothing to loosen).
    fn loosen(&mut self, _impulse: &[Vec3], _filter: &mut Filter) -> bool {
        false
    }

    /// After the new positions: corrects them and the velocities (friction, push-out,
    /// cloth–cloth response).
    fn respond(&mut self, _end: StepEnd<'_>) {}

    /// Copies this stage's statistics of the last step into `st`.
    fn report(&self, _st: &mut StepStats) {}

    /// The intersecting (edge, triangle) pairs of the cloth at `x` this stage knows of (default:
    /// none).
    fn crossings(&mut self, _x: &[Vec3]) -> Vec<([u32; 2], [u32; 3])> {
        Vec::new()
    }

    /// The stage's name in checkpoints (its type's).
    fn stage_name(&self) -> &'static str {
        std::any::type_name::<Self>()
    }

    /// Feeds what a checkpoint of this stage is valid for (its setup: bodies, sizes) into a
    /// simulation's fingerprint (default: nothing beyond its name).
    fn fingerprint(&self, _f: &mut Fingerprint) {}

    /// Writes the state that carries from one step to the next into a checkpoint (default:
    /// none).
    fn save_state(&self, _e: &mut Encoder) {}

    /// Reads what [`StepStage::save_state`] wrote.
    fn load_state(&mut self, _d: &mut Decoder) -> Result<(), GeometryError> {
        Ok(())
    }

    /// The stage as `Any`, to reach its concrete type.
    fn as_any(&self) -> &dyn Any;

    /// The stage as mutable `Any`, to reach its concrete type.
    fn as_any_mut(&mut self) -> &mut dyn Any;
}

/// The obstacles of a list of stages, as a stage or a buckling model sees them.
#[derive(Debug, Clone, Copy)]
pub struct Obstacles<'a> {
    stages: &'a [Box<dyn StepStage>],
}

impl<'a> Obstacles<'a> {
    /// The obstacles of `stages`.
    pub fn of(stages: &'a [Box<dyn StepStage>]) -> Self {
        Obstacles { stages }
    }

    /// No obstacles.
    pub fn none() -> Obstacles<'static> {
        Obstacles { stages: &[] }
    }

    /// Whether `p` is clear of every obstacle.
    pub fn is_clear(&self, p: &Vec3) -> bool {
        self.stages.iter().all(|s| s.is_clear(p))
    }
}
