//! Choi & Ko's interlaced connection as an element of the particles it spans. The connection
//! between particles two apart (a and c) stands for the fabric between them, which is taken
//! to have bent at once into an arc when the two come closer than the fabric is long (see
//! [`super::choi_ko`]). How long is that fabric? Choi & Ko take the connection's rest length
//! L: right while the fabric between a and c is compressed or at rest (it does not contract:
//! it buckles), wrong once it is stretched. A stretched fabric bent into an arc of the rest
//! length would have to be shorter than it is, so the connection reads the stretch as less
//! bending and pushes its ends apart with at least the onset force 12 k_b/L² until the
//! stretch springs balance it: a prestress of 12 B/L² per width that grows as the grid is
//! refined, stored in stretch and shear (the cloth on a cylinder rested with 1.6–2.5 times
//! the membrane energy of the same cloth without a model) and setting the wrinkle scale
//! instead of B.
//!
//! Here the arc is as long as the fabric: the rest length L while the path from a through
//! the middle to c is no longer than at rest, L · path/path₀ once it is longer. The
//! connection then answers at the virtual length l = |c − a| · min(1, path₀/path) with
//! the force of [`crate::cloth::elements::SpringKind::Flexion`]; its gradient involves the middle
//! particles (on a grid the particle between a and c, on a mesh the shared edge, through its
//! midpoint), which take the reaction: bending, not a push on the membrane.

use super::choi_ko;
use crate::cloth::elements::material::MaterialLaw;
use crate::cloth::elements::{blend, Spring, SpringKind};
use crate::geometry::{Mat3, Vec3};

/// A Choi–Ko connection between `nodes[0]` and `nodes[1]` through the midpoint of
/// `nodes[2]` and `nodes[3]` (the same particle twice on a grid line).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ArcConnection {
    /// Ends a, c, then the two particles whose midpoint the fabric passes through.
    pub nodes: [usize; 4],
    /// The connection as a two-particle spring of kind `Flexion` (ends, rest length, area,
    /// warp weight).
    pub spring: Spring,
    /// Rest length of the path a → middle → c (m).
    pub path0: f64,
}

/// An arc connection's response: tension at the virtual length (N, negative: pushing), its
/// derivative (N/m, ≥ 0), energy (J) and the gradient of the virtual length with respect to
/// each node.
#[derive(Debug, Clone, Copy)]
pub struct ArcEval {
    /// dE/dl (N).
    pub tension: f64,
    /// d²E/dl², the stable part (N/m).
    pub axial: f64,
    /// Stored energy (J).
    pub energy: f64,
    /// ∂l/∂x for each of `nodes`.
    pub grad: [Vec3; 4],
    /// The part of ∂l/∂x_c along the chord (∂l/∂x_a's is its opposite): the matrix keeps
    /// axial · (chord part)(chord part)ᵀ on the ends, whose blocks are symmetric (the
    /// multigrid's storage needs it) and which is the whole of it while the fabric is not
    /// stretched.
    pub chord: Vec3,
    /// Stiffness of the midpoint of the middle particles (N/m; zero while the fabric is not
    /// stretched): the stabilising part of tension · ∂²l/∂m², the arc's resistance to being
    /// bent further, |T| (l/path) [(I − p₁p₁ᵀ)/|p₁| + (I − p₂p₂ᵀ)/|p₂|] with p₁, p₂ the
    /// path's legs, acting on the middle's offset from the ends' midpoint.
    pub middle: Mat3,
}

impl ArcConnection {
    /// The connection for `spring` (kind `Flexion`) through the midpoint of `middle`, whose
    /// rest path a → middle → c is `path0` long.
    pub fn new(spring: Spring, middle: [usize; 2], path0: f64) -> Self {
        debug_assert!(matches!(spring.kind, SpringKind::Flexion { .. }));
        ArcConnection {
            nodes: [spring.a, spring.b, middle[0], middle[1]],
            spring,
            path0: path0.max(spring.rest),
        }
    }

    /// The virtual length l = |c − a| · min(1, path₀/path), its gradient, the chord part of
    /// the gradient (see [`ArcEval::chord`]) and whether the fabric is stretched (path >
    /// path₀).
    pub fn virtual_length(&self, x: &[Vec3]) -> (f64, [Vec3; 4], Vec3, bool) {
        let [a, c, m0, m1] = self.nodes;
        let d = x[c] - x[a];
        let chord = d.norm();
        if chord <= 0.0 {
            return (0.0, [Vec3::zeros(); 4], Vec3::zeros(), false);
        }
        let u = d / chord;
        let mid = (x[m0] + x[m1]) * 0.5;
        let (e1, e2) = (mid - x[a], x[c] - mid);
        let (l1, l2) = (e1.norm(), e2.norm());
        let path = l1 + l2;
        if path <= self.path0 || l1 <= 0.0 || l2 <= 0.0 {
            return (chord, [-u, u, Vec3::zeros(), Vec3::zeros()], u, false);
        }
        // l = chord · path₀ / path
        let k = self.path0 / path;
        let q = chord * self.path0 / (path * path);
        let (p1, p2) = (e1 / l1, e2 / l2);
        let gm = (p2 - p1) * (0.5 * q);
        (
            chord * k,
            [-u * k + p1 * q, u * k - p2 * q, gm, gm],
            u * k,
            true,
        )
    }

    /// Evaluates the connection at `x`; `None` while it is slack (the arc straight). While
    /// the fabric between the ends is not stretched, the connection answers as Choi & Ko's
    /// (the stretch law's compression near the rest length, then the buckling force); once it
    /// is stretched, with the buckled arc's force alone: the virtual length is then the rest
    /// length exactly when the fabric is straight, where its gradient vanishes, so the force
    /// goes to zero with the bending without the stretch law's stiff onset.
    #[inline]
    pub fn eval(&self, law: &dyn MaterialLaw, x: &[Vec3]) -> Option<ArcEval> {
        let (len, grad, chord, stretched) = self.virtual_length(x);
        let rest = self.spring.rest;
        if len >= rest {
            return None;
        }
        if !stretched {
            let ev = self
                .spring
                .eval(law, &Vec3::zeros(), &Vec3::new(len, 0.0, 0.0));
            return Some(ArcEval {
                tension: ev.tension,
                axial: ev.axial,
                energy: ev.energy,
                grad,
                chord,
                middle: Mat3::zeros(),
            });
        }
        let w = match self.spring.kind {
            SpringKind::Flexion { warp_weight } => warp_weight,
            _ => 1.0,
        };
        let (tension, axial, energy) =
            choi_ko::buckled_connection(self.spring.area, rest, len, |kappa| {
                blend(w, |d| law.bending(d, kappa))
            });
        let [a, c, m0, m1] = self.nodes;
        let mid = (x[m0] + x[m1]) * 0.5;
        let (e1, e2) = (mid - x[a], x[c] - mid);
        let (l1, l2) = (e1.norm(), e2.norm());
        let (p1, p2) = (e1 / l1, e2 / l2);
        let i = Mat3::identity();
        let middle = ((i - p1 * p1.transpose()) / l1 + (i - p2 * p2.transpose()) / l2)
            * (-tension.min(0.0) * len / (l1 + l2));
        Some(ArcEval {
            tension,
            axial,
            energy,
            grad,
            chord,
            middle,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cloth::FabricParameters;

    fn arc() -> ArcConnection {
        let s = Spring {
            a: 0,
            b: 2,
            rest: 0.02,
            area: 0.02 * 0.01,
            kind: SpringKind::Flexion { warp_weight: 1.0 },
        };
        ArcConnection::new(s, [1, 1], 0.02)
    }

    #[test]
    fn the_gradient_is_that_of_the_virtual_length() {
        let c = arc();
        // stretched and bent; compressed and bent
        for squeeze in [1.05, 0.97] {
            let x = vec![
                Vec3::new(0.0, 0.0, 0.0),
                Vec3::new(0.01 * squeeze, 0.001, 0.003),
                Vec3::new(0.02 * squeeze, 0.0004, -0.001),
            ];
            let (l, g, _, _) = c.virtual_length(&x);
            let h = 1e-8;
            for (node, gn) in [0usize, 2, 1].iter().zip([g[0], g[1], g[2] + g[3]]) {
                for k in 0..3 {
                    let mut xp = x.clone();
                    xp[*node][k] += h;
                    let mut xm = x.clone();
                    xm[*node][k] -= h;
                    let fd = (c.virtual_length(&xp).0 - c.virtual_length(&xm).0) / (2.0 * h);
                    assert!(
                        (fd - gn[k]).abs() < 1e-6,
                        "{squeeze} node {node} {k}: {fd} {gn}"
                    );
                }
            }
            // translation: the gradient sums to zero
            assert!((g[0] + g[1] + g[2] + g[3]).norm() < 1e-12);
            assert!(l < 0.02);
        }
    }

    #[test]
    fn a_uniformly_stretched_arc_pushes_no_harder_than_at_rest() {
        // the regression: stretching the fabric of a bent connection used to relieve it (the
        // push fell towards the onset force), so the connection kept the membrane stretched
        let law = FabricParameters::default().linear_law();
        let c = arc();
        let bent = |s: f64| {
            vec![
                Vec3::new(0.0, 0.0, 0.0),
                Vec3::new(0.01 * s * 0.999, 0.0, 0.0005 * s),
                Vec3::new(0.02 * s * 0.999, 0.0, 0.0),
            ]
        };
        let at_rest = c.eval(&law, &bent(1.0)).unwrap();
        let stretched = c.eval(&law, &bent(1.03)).unwrap();
        // the same shape, scaled: the same bending, the same energy
        assert!((stretched.energy - at_rest.energy).abs() < 1e-9 * at_rest.energy);
        // and the reaction on the ends is balanced by the middle, not by the membrane: the
        // force on the ends along the chord nearly vanishes against the onset push
        let onset = 12.0 * (0.0002 * FabricParameters::default().bend_warp / 0.02) / 0.0004;
        let along = (stretched.grad[0].x * stretched.tension).abs();
        assert!(along < 0.1 * onset, "{along} vs {onset}");
    }
}
