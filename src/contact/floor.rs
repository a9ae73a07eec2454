//! `Floor`: an infinite horizontal floor as a step stage. Unlike a plane [`Body`](super::Body)
//! it has no friction and no push-out: before the solve it prescribes the normal velocity of
//! the particles that will reach it, after the step it lifts those below it back onto it.

use std::any::Any;

use serde::{Deserialize, Serialize};

use crate::cloth::stage::{Obstacles, StepEnd, StepStage};
use crate::cloth::Filter;
use crate::geometry::Vec3;

/// An infinite horizontal floor at `height` (z up): particles closer than `thickness` and
/// moving down get their normal velocity set so they rest at `height + thickness`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Floor {
    /// Floor height (m).
    pub height: f64,
    /// Contact distance kept between cloth and floor (m).
    pub thickness: f64,
}

impl StepStage for Floor {
    fn constrain(
        &mut self,
        x: &[Vec3],
        v: &[Vec3],
        _t: f64,
        dt: f64,
        filter: &mut Filter,
        _obstacles: Obstacles<'_>,
    ) {
        let rest = self.height + self.thickness;
        for i in 0..x.len() {
            let gap = x[i].z - rest;
            // will it reach the contact distance during this step?
            if gap + v[i].z.min(0.0) * dt <= 0.0 {
                filter.constrain_normal(i, Vec3::z(), (-gap / dt).max(0.0));
            }
        }
    }

    fn respond(&mut self, end: StepEnd<'_>) {
        let floor = self.height;
        let (x, v) = (end.x, end.v);
        for i in 0..x.len() {
            if x[i].z < floor {
                x[i].z = floor;
                v[i].z = v[i].z.max(0.0);
            }
        }
    }

    fn as_any(&self) -> &dyn Any {
        self
    }

    fn as_any_mut(&mut self) -> &mut dyn Any {
        self
    }
}
