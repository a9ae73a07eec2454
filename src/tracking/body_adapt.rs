//! Body adaptation from the start frame's images (the seed report's first stage: the
//! player's body envelope from static views, before tracking): a coordinate search over the
//! puppet's segment lengths and girth ([`Proportions`]) that scores each candidate body by its
//! silhouette fit in every camera after the pose has been searched again on it.
//!
//! Each candidate rebuilds the puppet and its mesh ([`Tracker::set_proportions`]) and runs the
//! tracker's annealing from the current pose at narrow moves, with the image cost of the
//! silhouettes only (colours are learnt after the body is settled). Every candidate's
//! annealing draws the same random numbers (one fixed seed), so two bodies are compared on the
//! same particles and a change is kept only when it fits better. Steps of 8, 4 and 2 % per
//! field; a field moves at most once per step size and direction tried.

use super::puppet::Proportions;
use super::tracker::{TrackError, Tracker};
use crate::geometry::SplitMix64;

/// Relative steps of the coordinate search, coarse to fine.
const STEPS: [f64; 3] = [0.08, 0.04, 0.02];
/// Seed of every candidate's annealing (common random numbers).
const EVAL_SEED: u64 = 0x0AD4_9B0D;
/// Move spreads of the pose search on a candidate body (times the tracker's spreads).
const SEARCH_SCALE: f64 = 0.15;

/// A proportion the search moves, by name.
type Field = (&'static str, fn(&mut Proportions) -> &mut f64);

/// The proportions searched: those that change a silhouette most.
const FIELDS: [Field; 6] = [
    ("torso", |p| &mut p.torso),
    ("upper_arm", |p| &mut p.upper_arm),
    ("forearm", |p| &mut p.forearm),
    ("thigh", |p| &mut p.thigh),
    ("shin", |p| &mut p.shin),
    ("girth", |p| &mut p.girth),
];

impl Tracker {
    /// Adapts the puppet's proportions to the person in the current frame, starting from
    /// pose `pose` (see the [module docs](self)); leaves the tracker on the adapted body
    /// (colours not learnt) and returns the pose searched on it and the proportions.
    pub fn adapt_body(&mut self, pose: &[f64]) -> Result<(Vec<f64>, Proportions), TrackError> {
        let mut best = self.puppet().proportions();
        let (mut best_pose, mut best_cost) = self.silhouette_fit(&best, pose)?;
        for step in STEPS {
            for (_, field) in FIELDS {
                for sign in [1.0, -1.0] {
                    let mut p = best;
                    *field(&mut p) *= 1.0 + sign * step;
                    let (q, c) = self.silhouette_fit(&p, &best_pose)?;
                    if c < best_cost {
                        (best, best_pose, best_cost) = (p, q, c);
                        break;
                    }
                }
            }
        }
        self.set_proportions(&best)?;
        self.rng = SplitMix64::new(self.options.seed ^ EVAL_SEED);
        Ok((best_pose, best))
    }

    /// [`Tracker::adapt_body`], then the start's refinement on the adapted body (colours
    /// learnt, pose searched, five rounds).
    pub fn adapt_start(&mut self, pose: &[f64]) -> Result<(Vec<f64>, Proportions), TrackError> {
        let (q, p) = self.adapt_body(pose)?;
        Ok((self.refine_start(q), p))
    }

    /// The pose searched on body `p` from `pose`, and its silhouette cost.
    fn silhouette_fit(
        &mut self,
        p: &Proportions,
        pose: &[f64],
    ) -> Result<(Vec<f64>, f64), TrackError> {
        self.set_proportions(p)?;
        self.rng = SplitMix64::new(EVAL_SEED);
        Ok(self.search(pose, SEARCH_SCALE))
    }
}
