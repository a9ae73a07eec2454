//! `Sewing`: the schedule of seam threads while a garment is sewn. Seam springs
//! ([`SpringKind::Seam`]) join matching vertices of two pieces; their rest lengths start at
//! the pre-positioned gaps and shrink at the sewing speed, so that the edges are drawn together
//! gently instead of snapping. Gravity is held off and the motion damped until every thread
//! has reached rest length 0, every seam has closed and the pieces have settled (`settle`
//! seconds), or at the latest until `max_time`; from then on the
//! threads keep rest length 0 and stiffen ([`Sewing::stitched`]): a stitched seam, stiff enough
//! that the gap stays well under a millimetre, and the garment drapes.

use std::ops::Range;

use super::elements::SpringKind;
use super::model::ClothModel;
use crate::geometry::Vec3;

/// Pieces that belong on the two sides of a plane (the halves of a crotch seam, laid crossing
/// each other by pre-positioning): while sewing, the vertices of every intersecting
/// edge–triangle pair of opposite sides step towards their own side, so the crossing undoes
/// itself inside the pass-through zone instead of being sewn in.
#[derive(Debug, Clone)]
pub struct Separation {
    /// The plane's unit normal (towards side +1).
    pub normal: Vec3,
    /// Per particle: +1, −1, or 0 (free: not on such a piece, or on the seam itself).
    pub side: Vec<i8>,
    /// How far a crossing vertex moves per step (m).
    pub step: f64,
}

impl Separation {
    /// Moves the vertices of each crossing in `crossings` (edge, triangle) whose edge and
    /// triangle lie on opposite sides towards their own side, each vertex once; returns how
    /// many crossings were acted on.
    pub fn apply(&self, crossings: &[([u32; 2], [u32; 3])], x: &mut [Vec3]) -> usize {
        let mut acted = 0;
        let mut moved = std::collections::BTreeSet::new();
        let side_of = |vs: &[u32]| {
            vs.iter()
                .map(|&v| self.side[v as usize])
                .find(|&s| s != 0)
                .unwrap_or(0)
        };
        for (e, t) in crossings {
            let (se, st) = (side_of(e), side_of(t));
            if se == 0 || st == 0 || se == st {
                continue;
            }
            acted += 1;
            for &v in e.iter().chain(t.iter()) {
                let s = self.side[v as usize];
                if s != 0 && moved.insert(v) {
                    x[v as usize] += self.normal * (f64::from(s) * self.step);
                }
            }
        }
        acted
    }
}

/// A sewing schedule over a range of seam springs of a model.
#[derive(Debug, Clone)]
pub struct Sewing {
    /// The seam springs in `model.springs`.
    pub springs: Range<usize>,
    /// Their rest lengths at the start (the pre-positioned gaps, m).
    pub initial: Vec<f64>,
    /// How fast the threads shorten (m/s).
    pub speed: f64,
    /// Time left after the last thread reaches zero before gravity comes on (s).
    pub settle: f64,
    /// Velocity kept per step while sewing (1 = undamped).
    pub damping: f64,
    /// Largest particle speed while sewing (m/s): sewing is slow, so that contact with the
    /// body, which looks one step ahead, always sees the cloth coming.
    pub max_speed: f64,
    /// Share of the simulation's gravity acting while sewing (0: none; all of it once sewn).
    pub sewing_gravity: f64,
    /// A seam counts as closed when no sewn pair is further apart than this (m).
    pub closed_gap: f64,
    /// Gravity comes on at this time even if a seam is still open (s).
    pub max_time: f64,
    /// When every seam closed (s), once it has.
    pub sewn_at: Option<f64>,
    /// Stiffness (N/m) and largest pull (N) of the threads once the sewing phase is over:
    /// the stitched seam, stiffer than the threads that drew the edges together so that the
    /// fabric's tension across it opens no visible gap.
    pub stitched: (f64, f64),
    /// The hinges across seams in `model.hinges` (see `garment::seam_hinges`), off while
    /// sewing and on once stitched.
    pub hinges: Range<usize>,
    /// Pieces kept to the two sides of a plane while sewing (none: `None`).
    pub separation: Option<Separation>,
    /// Self-collision pass-through zones while sewing, one id per particle (0: none; empty:
    /// no zones): pieces drawn together along a seam may pass through each other near it.
    pub pass_through: Vec<u32>,
}

impl Sewing {
    /// Adds a seam spring of `stiffness` (N/m), pulling at most with `max_force` (N), between
    /// each pair of particles at positions `x`, with the pair's present distance as its first
    /// rest length.
    pub fn add_to(
        model: &mut ClothModel,
        pairs: &[(usize, usize)],
        x: &[Vec3],
        (stiffness, max_force): (f64, f64),
        speed: f64,
    ) -> Sewing {
        let start = model.springs.len();
        let mut initial = Vec::with_capacity(pairs.len());
        for &(a, b) in pairs {
            let gap = (x[a] - x[b]).norm();
            initial.push(gap);
            model.springs.push(super::elements::Spring {
                a,
                b,
                rest: gap,
                area: 0.0,
                kind: SpringKind::Seam {
                    stiffness,
                    max_force,
                },
            });
        }
        Sewing {
            springs: start..model.springs.len(),
            initial,
            speed,
            settle: 0.1,
            damping: 0.9,
            max_speed: 2.0 * speed,
            sewing_gravity: 0.0,
            closed_gap: 0.002,
            max_time: 3.0,
            sewn_at: None,
            stitched: (10.0 * stiffness, 10.0 * max_force),
            pass_through: Vec::new(),
            hinges: 0..0,
            separation: None,
        }
    }

    /// Adds `hinges` across the seams to `model`, off until the seams are stitched.
    pub fn add_hinges(&mut self, model: &mut ClothModel, hinges: Vec<super::elements::Hinge>) {
        let start = model.hinges.len();
        model.hinges.extend(hinges.into_iter().map(|mut h| {
            h.weight = 0.0;
            h
        }));
        self.hinges = start..model.hinges.len();
    }

    /// When every thread has reached rest length 0 (s).
    pub fn closing_time(&self) -> f64 {
        let widest = self.initial.iter().fold(0.0f64, |a, &g| a.max(g));
        if self.speed > 0.0 {
            widest / self.speed
        } else {
            0.0
        }
    }

    /// Whether time `t` is still in the sewing phase: threads shortening, seams not yet
    /// closed, or settling after they closed (never past `max_time`).
    pub fn sewing_at(&self, t: f64) -> bool {
        if t >= self.max_time {
            return false;
        }
        match self.sewn_at {
            Some(s) => t < s + self.settle,
            None => true,
        }
    }

    /// Sets the threads' rest lengths for time `t` (the cloth at `x`), notes when the seams
    /// have closed, and returns the share of the simulation's gravity that acts.
    pub fn update(&mut self, model: &mut ClothModel, t: f64, x: &[Vec3]) -> f64 {
        for (k, s) in model.springs[self.springs.clone()].iter_mut().enumerate() {
            s.rest = (self.initial[k] - self.speed * t).max(0.0);
        }
        if self.sewn_at.is_none()
            && t >= self.closing_time()
            && self.max_gap(model, x) <= self.closed_gap
        {
            self.sewn_at = Some(t);
        }
        if self.sewn_at.is_some() || !self.sewing_at(t) {
            // stitched from the moment the seams closed: the settling that follows, still
            // frictionless and without full gravity, pulls the last gaps shut
            let (stiffness, max_force) = self.stitched;
            for s in &mut model.springs[self.springs.clone()] {
                s.kind = SpringKind::Seam {
                    stiffness,
                    max_force,
                };
            }
            for h in &mut model.hinges[self.hinges.clone()] {
                h.weight = 1.0;
            }
        }
        if self.sewing_at(t) {
            self.sewing_gravity
        } else {
            1.0
        }
    }

    /// Damps and caps the velocities `v` while sewing at time `t`.
    pub fn slow_down(&self, t: f64, v: &mut [Vec3]) {
        if !self.sewing_at(t) {
            return;
        }
        for vi in v.iter_mut() {
            *vi *= self.damping;
            let s = vi.norm();
            if s > self.max_speed {
                *vi *= self.max_speed / s;
            }
        }
    }

    /// The largest distance between sewn particles at positions `x` (m).
    pub fn max_gap(&self, model: &ClothModel, x: &[Vec3]) -> f64 {
        model.springs[self.springs.clone()]
            .iter()
            .map(|s| (x[s.a] - x[s.b]).norm())
            .fold(0.0, f64::max)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_crossing_between_opposite_sides_steps_each_vertex_towards_its_own_side_once() {
        // an edge of a left piece (0, 1) through a triangle of a right piece (2, 3, 4), the
        // triangle's first vertex on the seam (free); vertex 5 is on the left, crossing nothing
        let sep = Separation {
            normal: Vec3::new(1.0, 0.0, 0.0),
            side: vec![1, 1, 0, -1, -1, 1],
            step: 0.002,
        };
        let mut x = vec![Vec3::zeros(); 6];
        let crossings = [([0, 1], [2, 3, 4]), ([1, 0], [4, 3, 2])];
        assert_eq!(sep.apply(&crossings, &mut x), 2);
        for (v, want) in [
            (0, 0.002),
            (1, 0.002),
            (2, 0.0),
            (3, -0.002),
            (4, -0.002),
            (5, 0.0),
        ] {
            assert_eq!(x[v].x, want, "vertex {v}");
        }
        // pieces of one side are left alone
        let same = [([0, 1], [5, 1, 0])];
        assert_eq!(sep.apply(&same, &mut x), 0);
        assert_eq!(x[5].x, 0.0);
    }
}
