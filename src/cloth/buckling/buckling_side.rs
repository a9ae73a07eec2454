//! The side a Choi–Ko connection buckles to. Choi & Ko's connection is taken to have bent at
//! once into an arc when compressed, but its force acts along the chord and says nothing of
//! the arc's side: a perfectly flat cloth pushed in its plane (all particles in one plane, to
//! the last bit) gets no force out of that plane, so it stays flat and either keeps its
//! springs compressed or folds over itself within its plane. Where a compressed connection's
//! middle lies on its chord exactly (within 1e-12 of its rest length, round-off), this module
//! chooses the side the arc bulges to and starts the arc there: the middle moves by 1e-6 of
//! the rest length along the cloth's normal. The side is the one clear of the collision bodies
//! (looked for a quarter of the rest length away); otherwise one side of the cloth (front or
//! back) drawn at random once per step for all the arcs it starts, as the compression-release
//! model breaks its ties (seed report §5.4.4.1.2). Drawn for each connection on its own,
//! neighbours bulged opposite ways and a flat triangle mesh ended creased, with more energy
//! than without a model. The dynamics take it from there; a cloth already out of its plane is
//! never touched, and the same seed gives the same result bit for bit.

use crate::geometry::{SplitMix64, Vec3};

/// A Choi–Ko connection's geometry for choosing its side.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FlexionSide {
    /// The connection's two ends.
    pub ends: [usize; 2],
    /// The particles between them: the middle particle twice on a grid line, the shared edge
    /// of two triangles on a mesh.
    pub middle: [usize; 2],
    /// Two particles whose difference crosses the connection within the cloth (the middle and
    /// its neighbour across the grid line; the shared edge on a mesh).
    pub across: [usize; 2],
    /// Rest length of the connection (m).
    pub rest: f64,
    /// Whether chord × across points to the cloth's front (the side of the pattern's u × v).
    pub front: bool,
}

/// Whether the pattern turns counter-clockwise from the chord `a → b` to the segment across
/// `p → q`, in the rest coordinates `rest`: then chord × across points to the cloth's front.
pub fn turns_left(rest: &[[f64; 2]], [a, b]: [usize; 2], [p, q]: [usize; 2]) -> bool {
    let u = [rest[b][0] - rest[a][0], rest[b][1] - rest[a][1]];
    let v = [rest[q][0] - rest[p][0], rest[q][1] - rest[p][1]];
    u[0] * v[1] - u[1] * v[0] > 0.0
}

/// Below this offset of the middle from the chord (relative to the rest length) the arc has no
/// side yet.
pub const FLAT: f64 = 1e-12;
/// How far (relative to the rest length) the middle is moved to start the arc on its side.
pub const START: f64 = 1e-6;
/// How far (relative to the rest length) on either side of the middle a body is looked for:
/// an arc does not start towards a body it would run into.
pub const PROBE: f64 = 0.25;

/// The connections and the random draws.
#[derive(Debug, Clone)]
pub struct BucklingSides {
    sides: Vec<FlexionSide>,
    rng: SplitMix64,
    /// Arcs started so far.
    pub started: u64,
}

impl BucklingSides {
    /// The sides of `sides`, drawn from `seed`.
    pub fn new(sides: Vec<FlexionSide>, seed: u64) -> Self {
        BucklingSides {
            sides,
            rng: SplitMix64::new(seed),
            started: 0,
        }
    }

    /// The random generator's state (for a checkpoint).
    pub fn rng_state(&self) -> u64 {
        self.rng.state()
    }

    /// Continues the random draws from a saved [`BucklingSides::rng_state`].
    pub fn set_rng_state(&mut self, state: u64) {
        self.rng = SplitMix64::new(state);
    }

    /// Starts the arc of every compressed connection whose middle lies on its chord, moving
    /// the middle particles (except those `held`) along the cloth's normal: to the side where
    /// `clear` holds if only one does, else to the side of the cloth drawn at random for this
    /// call. Returns how many arcs were started.
    pub fn start_arcs(
        &mut self,
        x: &mut [Vec3],
        held: impl Fn(usize) -> bool,
        clear: impl Fn(&Vec3) -> bool,
    ) -> usize {
        let mut started = 0;
        let mut side = None;
        for s in &self.sides {
            let [a, b] = s.ends;
            let chord = x[b] - x[a];
            if chord.norm() >= s.rest {
                continue;
            }
            let across = x[s.across[1]] - x[s.across[0]];
            let normal = chord.cross(&across);
            let nn = normal.norm();
            if nn <= 0.0 {
                continue;
            }
            let normal = normal / nn;
            let mid = 0.5 * (x[s.middle[0]] + x[s.middle[1]]);
            let offset = (mid - 0.5 * (x[a] + x[b])).dot(&normal);
            if offset.abs() > FLAT * s.rest {
                continue;
            }
            // the side clear of the bodies; else one side for every arc started in this
            // call, drawn at the first
            let probe = normal * (PROBE * s.rest);
            let up = match (clear(&(mid + probe)), clear(&(mid - probe))) {
                (true, false) => true,
                (false, true) => false,
                _ => *side.get_or_insert_with(|| self.rng.next_u64() & 1 == 1) == s.front,
            };
            let shift = normal * if up { START * s.rest } else { -START * s.rest };
            let [m0, m1] = s.middle;
            if !held(m0) {
                x[m0] += shift;
            }
            if m1 != m0 && !held(m1) {
                x[m1] += shift;
            }
            started += 1;
        }
        self.started += started as u64;
        started
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn line(squeeze: f64) -> Vec<Vec3> {
        // a three-particle line along x and a neighbour across it, all at z = 0
        vec![
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(0.01 * squeeze, 0.0, 0.0),
            Vec3::new(0.02 * squeeze, 0.0, 0.0),
            Vec3::new(0.01 * squeeze, 0.01, 0.0),
        ]
    }

    fn side() -> FlexionSide {
        FlexionSide {
            ends: [0, 2],
            middle: [1, 1],
            across: [1, 3],
            rest: 0.02,
            front: true,
        }
    }

    #[test]
    fn a_flat_compressed_connection_starts_its_arc_out_of_the_plane() {
        let mut x = line(0.95);
        let mut s = BucklingSides::new(vec![side()], 3);
        assert_eq!(s.start_arcs(&mut x, |_| false, |_| true), 1);
        assert!((x[1].z.abs() - START * 0.02).abs() < 1e-15 && x[1].x == 0.01 * 0.95);
        // now it has a side: nothing more to do
        assert_eq!(s.start_arcs(&mut x, |_| false, |_| true), 0);
    }

    #[test]
    fn seeds_choose_both_sides_and_repeat_themselves() {
        let draw = |seed| {
            let mut x = line(0.95);
            BucklingSides::new(vec![side()], seed).start_arcs(&mut x, |_| false, |_| true);
            x[1].z
        };
        let sides: Vec<f64> = (0..16).map(draw).collect();
        assert!(sides.iter().any(|&z| z > 0.0) && sides.iter().any(|&z| z < 0.0));
        assert_eq!(draw(7).to_bits(), draw(7).to_bits());
    }

    #[test]
    fn slack_bent_or_held_connections_are_left_alone() {
        let mut s = BucklingSides::new(vec![side()], 1);
        let mut slack = line(1.0);
        assert_eq!(s.start_arcs(&mut slack, |_| false, |_| true), 0);
        let mut bent = line(0.95);
        bent[1].z = 1e-9;
        assert_eq!(s.start_arcs(&mut bent, |_| false, |_| true), 0);
        let mut held = line(0.95);
        assert_eq!(s.start_arcs(&mut held, |i| i == 1, |_| true), 1);
        assert_eq!(held[1].z, 0.0);
    }

    #[test]
    fn arcs_started_together_bulge_to_one_side_of_the_cloth_regression() {
        // two parallel lines of a flat grid whose neighbours across lie on opposite sides:
        // chord × across points up for one and down for the other, yet both start on the
        // same side of the cloth (drawn each for itself, they went opposite ways half the time)
        let rest = [
            [0.0, 0.0],
            [0.01, 0.0],
            [0.02, 0.0],
            [0.0, 0.01],
            [0.01, 0.01],
            [0.02, 0.01],
        ];
        let mut x0: Vec<Vec3> = rest
            .iter()
            .map(|p| Vec3::new(0.95 * p[0], p[1], 0.0))
            .collect();
        let lower = FlexionSide {
            ends: [0, 2],
            middle: [1, 1],
            across: [1, 4],
            rest: 0.02,
            front: turns_left(&rest, [0, 2], [1, 4]),
        };
        let upper = FlexionSide {
            ends: [3, 5],
            middle: [4, 4],
            across: [4, 1],
            rest: 0.02,
            front: turns_left(&rest, [3, 5], [4, 1]),
        };
        assert_ne!(lower.front, upper.front);
        for seed in 0..8 {
            let mut x = x0.clone();
            let mut s = BucklingSides::new(vec![lower, upper], seed);
            assert_eq!(s.start_arcs(&mut x, |_| false, |_| true), 2);
            assert!(x[1].z * x[4].z > 0.0, "seed {seed}: {} {}", x[1].z, x[4].z);
        }
        // and away from a body below the cloth, whatever the seed
        x0[1].z = 0.0;
        for seed in 0..8 {
            let mut x = x0.clone();
            let mut s = BucklingSides::new(vec![lower], seed);
            s.start_arcs(&mut x, |_| false, |p| p.z > -0.001);
            assert!(x[1].z > 0.0, "seed {seed}");
        }
    }
}
