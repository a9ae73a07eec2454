//! Force elements of a cloth model: springs (stretch and shear), bending lines (three
//! consecutive particles along a warp or weft line of a grid) and dihedral hinges (two
//! triangles sharing an edge, for any triangle mesh). Each element evaluates its energy,
//! forces and stiffness blocks from a `MaterialLaw` ([`material`]; measured laws in
//! [`measured`]).

pub mod material;
pub mod measured;

use self::material::{Direction, Friction, MaterialLaw};
use super::buckling::choi_ko;
use crate::geometry::{Mat3, Vec3};

/// What a spring resists.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SpringKind {
    /// Stretch along a fabric direction; `warp_weight` = cos² of the angle to the warp
    /// (1 for a warp spring, 0 for a weft spring), the tension blends the two laws.
    Stretch {
        /// cos² of the angle between the rest edge and the warp.
        warp_weight: f64,
    },
    /// Shear, measured through the stretch of a quad diagonal: γ = 2ε.
    Shear,
    /// Choi–Ko's interlaced connection between particles two apart along a grid line, or
    /// between the opposite vertices of two triangles sharing an edge: slack in tension (the
    /// stretch springs carry it), and compressed it takes the buckling force of an arc of its
    /// rest length bent by the bending law (see [`super::buckling::choi_ko`]), capped near the onset by
    /// the stretch law's compression so the force is continuous at the rest length.
    Flexion {
        /// Weight of the warp laws (cos² of the angle between the connection and the warp).
        warp_weight: f64,
    },
    /// A sewing thread between two pieces: a linear spring of `stiffness` (N/m) that pulls
    /// when longer than its rest length (which may be 0), at most with `max_force` (N), and is
    /// slack when shorter. Not a fabric law: `area` is unused.
    Seam {
        /// Stiffness (N/m).
        stiffness: f64,
        /// Largest pull (N): a thread drawing pieces together from far never yanks them.
        max_force: f64,
    },
}

/// A two-particle spring. Its energy is `area · W(s)` with `s = gain · (L/L0 − 1)`, where
/// W is the law's energy density (gain 1 for stretch, 2 for shear).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Spring {
    /// First particle.
    pub a: usize,
    /// Second particle.
    pub b: usize,
    /// Rest length L0 (m).
    pub rest: f64,
    /// Area of fabric the spring stands for (m²).
    pub area: f64,
    /// Which law answers.
    pub kind: SpringKind,
}

/// Result of evaluating a spring: scalar force along the unit direction and its tangents.
#[derive(Debug, Clone, Copy)]
pub struct SpringEval {
    /// Unit direction from a to b.
    pub dir: Vec3,
    /// Tension (N), positive when stretched; the force on a is `+tension · dir`.
    pub tension: f64,
    /// Axial stiffness d(tension)/dL (N/m).
    pub axial: f64,
    /// Transverse stiffness tension/L (N/m), clamped at 0 so the Jacobian stays definite.
    pub transverse: f64,
    /// Stored energy (J).
    pub energy: f64,
}

impl Spring {
    /// Evaluates the spring at positions `xa`, `xb`.
    #[inline(always)]
    pub fn eval(&self, law: &dyn MaterialLaw, xa: &Vec3, xb: &Vec3) -> SpringEval {
        let d = xb - xa;
        let len = d.norm();
        let dir = if len > 0.0 { d / len } else { Vec3::zeros() };
        if let SpringKind::Seam {
            stiffness,
            max_force,
        } = self.kind
        {
            let stretch = (len - self.rest).max(0.0);
            let tension = (stiffness * stretch).min(max_force);
            let pulling = stretch > 0.0 && tension < max_force;
            return SpringEval {
                dir,
                tension,
                axial: if pulling { stiffness } else { 0.0 },
                transverse: if len > 0.0 { tension / len } else { 0.0 },
                energy: 0.5 * stiffness * stretch * stretch,
            };
        }
        let eps = len / self.rest - 1.0;
        let stretch = |w: f64| blend(w, |d| law.tension(d, eps));
        let buckled = |w: f64| {
            choi_ko::buckled_connection(self.area, self.rest, len, |kappa| {
                blend(w, |d| law.bending(d, kappa))
            })
        };
        if let SpringKind::Flexion { warp_weight } = self.kind {
            if eps >= 0.0 {
                return SpringEval {
                    dir,
                    tension: 0.0,
                    axial: 0.0,
                    transverse: 0.0,
                    energy: 0.0,
                };
            }
            let (f, df, w) = stretch(warp_weight);
            return self.softer_of(dir, (f, df, w), buckled(warp_weight));
        }
        let (f, df, w) = match self.kind {
            SpringKind::Stretch { warp_weight } => stretch(warp_weight),
            SpringKind::Shear => {
                let (f, df, w) = law.shear(2.0 * eps);
                (2.0 * f, 4.0 * df, w)
            }
            // returned above
            SpringKind::Seam { .. } | SpringKind::Flexion { .. } => (0.0, 0.0, 0.0),
        };
        let tension = self.area * f / self.rest;
        let axial = self.area * df / (self.rest * self.rest);
        let transverse = if len > 0.0 {
            (tension / len).max(0.0)
        } else {
            0.0
        };
        SpringEval {
            dir,
            tension,
            axial,
            transverse,
            energy: self.area * w,
        }
    }
}

/// A law's (value, derivative, energy) blended between the warp and the weft:
/// `w · warp + (1 − w) · weft`, the weft not asked when `w` is 1.
#[inline]
pub(crate) fn blend(w: f64, law: impl Fn(Direction) -> (f64, f64, f64)) -> (f64, f64, f64) {
    let (fu, dfu, wu) = law(Direction::Warp);
    let ww = 1.0 - w;
    if ww == 0.0 {
        return (fu, dfu, wu);
    }
    let (fv, dfv, wv) = law(Direction::Weft);
    (w * fu + ww * fv, w * dfu + ww * dfv, w * wu + ww * wv)
}

impl Spring {
    /// The compressed spring's response, the smaller in magnitude of the stretch law's
    /// compression `(F, dF/dε, W)` (per width) and the buckled arc's `(tension N, d/dL N/m,
    /// energy J)`: stiff just below the rest length, then the buckling force.
    #[inline]
    fn softer_of(
        &self,
        dir: Vec3,
        stretch: (f64, f64, f64),
        buckled: (f64, f64, f64),
    ) -> SpringEval {
        let ts = self.area * stretch.0 / self.rest;
        let (tension, axial, energy) = if ts >= buckled.0 {
            (
                ts,
                self.area * stretch.1 / (self.rest * self.rest),
                self.area * stretch.2,
            )
        } else {
            buckled
        };
        SpringEval {
            dir,
            tension,
            axial,
            // compressed: the destabilising transverse term is left out (Choi & Ko)
            transverse: 0.0,
            energy,
        }
    }

    /// Adds internal friction to an evaluation `ev` of this spring at (`xa`, `xb`), updating
    /// and committing the friction state `st` = (coordinate, friction force per width). The
    /// coordinate is the strain for stretch springs and the shear angle 2ε for shear springs.
    #[inline]
    pub fn add_friction(
        &self,
        f: &Friction,
        st: &mut [f64; 2],
        xa: &Vec3,
        xb: &Vec3,
        ev: &mut SpringEval,
    ) {
        let len = (xb - xa).norm();
        let gain = match self.kind {
            SpringKind::Stretch { .. } => 1.0,
            SpringKind::Shear => 2.0,
            SpringKind::Seam { .. } | SpringKind::Flexion { .. } => return,
        };
        let coord = gain * (len / self.rest - 1.0);
        if st[0].is_nan() {
            *st = [coord, 0.0];
        }
        // elastic force per width and tangent in the mode's own coordinate
        let f_el = ev.tension * self.rest / self.area / gain;
        let df_el = ev.axial * self.rest * self.rest / self.area / (gain * gain);
        let (z, dz) = f.update(st[0], st[1], coord, f_el, df_el);
        *st = [coord, z];
        ev.tension += self.area * z * gain / self.rest;
        ev.axial += self.area * dz * gain * gain / (self.rest * self.rest);
        ev.transverse = if len > 0.0 {
            (ev.tension / len).max(0.0)
        } else {
            0.0
        };
    }
}

impl SpringEval {
    /// Stiffness block K = −∂f_a/∂x_a (symmetric, positive semi-definite).
    #[inline]
    pub fn stiffness(&self) -> Mat3 {
        let ddt = self.dir * self.dir.transpose();
        ddt * (self.axial - self.transverse) + Mat3::identity() * self.transverse
    }
}

/// Bending along a grid line: particles a, b, c consecutive along the warp or the weft.
/// Curvature vector q = Σ c_m x_m (a second difference), energy `length · W(|q|)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BendLine {
    /// The three particles, in line order.
    pub nodes: [usize; 3],
    /// Second-difference weights (1/m²).
    pub coef: [f64; 3],
    /// Area of fabric this element stands for (m²).
    pub area: f64,
    /// Direction of the curvature it measures.
    pub dir: Direction,
    /// Product of the rest spacings d1 d2 (m²).
    pub rest_product: f64,
}

impl BendLine {
    /// Builds the element from rest spacings `d1` (a–b) and `d2` (b–c) and the width it stands for.
    pub fn new(nodes: [usize; 3], d1: f64, d2: f64, width: f64, dir: Direction) -> Self {
        let ca = 2.0 / (d1 * (d1 + d2));
        let cc = 2.0 / (d2 * (d1 + d2));
        BendLine {
            nodes,
            coef: [ca, -(ca + cc), cc],
            area: width * 0.5 * (d1 + d2),
            dir,
            rest_product: d1 * d2,
        }
    }

    /// The curvature vector q = Σ c_m x_m (1/m).
    #[inline]
    pub fn curvature(&self, x: &[Vec3]) -> Vec3 {
        let [a, b, c] = self.nodes;
        x[a] * self.coef[0] + x[b] * self.coef[1] + x[c] * self.coef[2]
    }

    /// Curvature of the line, normalised by the current segment lengths so that stretching
    /// does not read as bending: q' = q · d1 d2 / (l1 l2), with q the second difference,
    /// d the rest and l the current spacings (points on a circle give |q'| = 1/R exactly,
    /// whatever their spacing).
    #[inline(always)]
    pub fn geometry(&self, x: &[Vec3]) -> BendGeometry {
        let [a, b, c] = self.nodes;
        let q = self.curvature(x);
        let (e1, e2) = (x[b] - x[a], x[c] - x[b]);
        let (l1, l2) = (e1.norm().max(1e-300), e2.norm().max(1e-300));
        let len = l1 * l2;
        let s = self.rest_product / len;
        let (u1, u2) = (e1 / l1, e2 / l2);
        BendGeometry {
            qn: q * s,
            scale: s,
            len,
            dlen: [-u1 * l2, u1 * l2 - u2 * l1, u2 * l1],
        }
    }

    /// Forces on the three nodes of a moment vector `mv` (per width, in the space of q'):
    /// f_m = −area (∂q'/∂x_m)ᵀ mv.
    #[inline]
    pub fn forces(&self, g: &BendGeometry, mv: &Vec3) -> [Vec3; 3] {
        let t = g.qn.dot(mv) / g.len;
        let f = |m: usize| -(mv * (g.scale * self.coef[m]) - g.dlen[m] * t) * self.area;
        [f(0), f(1), f(2)]
    }

    /// Elastic moment vector and stiffness of the line at `g` for law (M, dM/dκ) at κ = |q'|:
    /// (M q̂, S) with S the 3×3 factor of the blocks c_m c_n S (lengths held fixed in the
    /// tangent, which keeps the blocks symmetric), before the area and scale factors.
    #[inline]
    pub fn elastic(g: &BendGeometry, m: f64, dm: f64) -> (Vec3, Mat3) {
        let kappa = g.qn.norm();
        if kappa < 1e-12 {
            return (g.qn * dm, Mat3::identity() * dm);
        }
        let qh = g.qn / kappa;
        let ratio = m / kappa;
        (
            qh * m,
            qh * qh.transpose() * (dm - ratio) + Mat3::identity() * ratio,
        )
    }
}

/// Current shape of a bending line (see [`BendLine::geometry`]).
#[derive(Debug, Clone, Copy)]
pub struct BendGeometry {
    /// Normalised curvature vector q' (1/m).
    pub qn: Vec3,
    /// d1 d2 / (l1 l2).
    pub scale: f64,
    /// l1 l2 (m²).
    pub len: f64,
    /// ∂(l1 l2)/∂x_m for the three nodes.
    pub dlen: [Vec3; 3],
}

/// Shear of one grid cell, measured by its two diagonals d1 = x₁ − x₀ and d2 = x₃ − x₂ of a
/// cell of rest sides a × b: with A = |d1|², B = |d2|²,
/// `γ = (A − B)/(A + B) · (a² + b²)/(2ab)`, the sine of the shear angle for a cell stretched
/// equally along both sides and nearly so otherwise (the ratio removes the stretch, so a knit
/// pre-stretched by the shear test's tension does not read its stretch as shear). Pure stretch
/// along the yarns leaves γ = 0, so tensile tests see no shear stiffness (unlike independent
/// diagonal springs). Energy `area · W(γ)`.
///
/// Its stiffness is approximated per diagonal, spring-like (symmetric 3×3 blocks, as the
/// multigrid smoother needs): `2·area·W''·g_k g_kᵀ` plus the positive part of the
/// `area·W'·∂²γ/∂d_k²` term, with g_k = ∂γ/∂d_k. This is exact for pure shear of a square cell
/// and over-stiff only for dilation, which keeps the implicit step stable.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShearQuad {
    /// Diagonal 1 (from, to) then diagonal 2 (from, to).
    pub nodes: [usize; 4],
    /// (a² + b²)/(2ab).
    pub inv: f64,
    /// Rest area ab of fabric the element stands for (m²).
    pub area: f64,
}

/// Current shape of a shear cell (see [`ShearQuad::measure`]).
#[derive(Debug, Clone, Copy)]
pub struct ShearMeasure {
    /// The diagonals.
    pub d: [Vec3; 2],
    /// Shear γ.
    pub gamma: f64,
    /// ∂γ/∂(|d_k|²) for k = 1, 2.
    pub dg: [f64; 2],
}

impl ShearQuad {
    /// A cell of rest sides `a` × `b` with the given diagonal node pairs.
    pub fn new(nodes: [usize; 4], a: f64, b: f64) -> Self {
        ShearQuad {
            nodes,
            inv: (a * a + b * b) / (2.0 * a * b),
            area: a * b,
        }
    }

    /// The diagonals, γ and its derivatives at positions `x`.
    #[inline(always)]
    pub fn measure(&self, x: &[Vec3]) -> ShearMeasure {
        let [a1, b1, a2, b2] = self.nodes;
        let d1 = x[b1] - x[a1];
        let d2 = x[b2] - x[a2];
        let (p, q) = (d1.norm_squared(), d2.norm_squared());
        let s = (p + q).max(1e-300);
        ShearMeasure {
            d: [d1, d2],
            gamma: (p - q) / s * self.inv,
            dg: [2.0 * q / (s * s) * self.inv, -2.0 * p / (s * s) * self.inv],
        }
    }
}

/// Vector Jenkins friction of a bending line: the friction moment z (a vector in curvature
/// space) sticks with stiffness `stick` and slides on the sphere |z| = threshold. Returns the
/// friction moment per width and its (symmetric) tangent. `qc`, `zc`: committed state.
#[inline]
pub fn bend_friction(f: &Friction, qc: &Vec3, zc: &Vec3, q: &Vec3, m_el: f64) -> (Vec3, Mat3) {
    let trial = zc + (q - qc) * f.stick;
    let t = f.threshold(m_el);
    let n = trial.norm();
    if n <= t {
        (trial, Mat3::identity() * f.stick)
    } else {
        let zh = trial / n;
        (
            zh * t,
            (Mat3::identity() - zh * zh.transpose()) * (f.stick * t / n),
        )
    }
}

/// A dihedral hinge on edge (a, b) with opposite vertices c (first triangle) and d (second).
/// Curvature κ = |θ| · |e0| / A0 with A0 the summed rest area of the two triangles, energy
/// `A0 · W(κ)`: for a linear law `(B/2) θ² |e0|²/A0`, exact for a right-triangle grid.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hinge {
    /// Edge vertices a, b and opposite vertices c, d.
    pub nodes: [usize; 4],
    /// Rest edge length (m).
    pub edge: f64,
    /// Summed rest area of the two triangles (m²).
    pub area: f64,
    /// Weight of the warp law (cos² of the angle between the warp and the curvature direction).
    pub warp_weight: f64,
    /// Share of the bending law the hinge carries: 1 for the fabric's own hinges; a hinge
    /// across a seam is 0 while the seam is sewn and 1 once it is stitched.
    pub weight: f64,
    /// Whether the hinge spans a seam (its wings lie on two pieces).
    pub seam: bool,
}

impl Hinge {
    /// Dihedral angle θ (signed, 0 when flat) and its gradient with respect to a, b, c, d.
    #[inline]
    pub fn angle_and_gradient(&self, x: &[Vec3]) -> Option<(f64, [Vec3; 4])> {
        let [a, b, c, d] = self.nodes;
        let (xa, xb, xc, xd) = (x[a], x[b], x[c], x[d]);
        let e = xb - xa;
        let el = e.norm();
        let n1 = (xc - xa).cross(&(xc - xb));
        let n2 = (xd - xb).cross(&(xd - xa));
        let (l1, l2) = (n1.norm_squared(), n2.norm_squared());
        if el < 1e-14 || l1 < 1e-28 || l2 < 1e-28 {
            return None;
        }
        let (n1h, n2h) = (n1 / l1.sqrt(), n2 / l2.sqrt());
        let sin = n1h.cross(&n2h).dot(&(e / el));
        let cos = n1h.dot(&n2h);
        // sign chosen so that the gradients below are those of θ
        let theta = -sin.atan2(cos);
        let gc = n1 * (el / l1);
        let gd = n2 * (el / l2);
        let ga = n1 * ((xc - xb).dot(&e) / el / l1) + n2 * ((xd - xb).dot(&e) / el / l2);
        let gb = -(n1 * ((xc - xa).dot(&e) / el / l1) + n2 * ((xd - xa).dot(&e) / el / l2));
        Some((theta, [ga, gb, gc, gd]))
    }

    /// Bending (M, dM/dκ, energy) at curvature κ, blending the warp and weft laws.
    #[inline]
    pub fn law(&self, law: &dyn MaterialLaw, kappa: f64) -> (f64, f64, f64) {
        let (mu, du, wu) = law.bending(Direction::Warp, kappa);
        let (mv, dv, wv) = law.bending(Direction::Weft, kappa);
        let (p, q) = (self.warp_weight, 1.0 - self.warp_weight);
        (p * mu + q * mv, p * du + q * dv, p * wu + q * wv)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hinge_gradient_matches_finite_differences() {
        let h = Hinge {
            nodes: [0, 1, 2, 3],
            edge: 1.0,
            area: 1.0,
            warp_weight: 1.0,
            weight: 1.0,
            seam: false,
        };
        let x = vec![
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.1, 0.0),
            Vec3::new(0.4, 0.8, 0.2),
            Vec3::new(0.6, -0.7, 0.3),
        ];
        let (_, g) = h.angle_and_gradient(&x).unwrap();
        for m in 0..4 {
            for k in 0..3 {
                let mut xp = x.clone();
                let mut xm = x.clone();
                xp[m][k] += 1e-6;
                xm[m][k] -= 1e-6;
                let fd = (h.angle_and_gradient(&xp).unwrap().0
                    - h.angle_and_gradient(&xm).unwrap().0)
                    / 2e-6;
                assert!(
                    (fd - g[m][k]).abs() < 1e-6,
                    "node {m} axis {k}: fd {fd} vs {}",
                    g[m][k]
                );
            }
        }
    }

    #[test]
    fn bend_line_curvature_of_a_circle() {
        // three points on a circle of radius 2 with arc spacing 0.01: |q| ≈ 1/2
        let r = 2.0;
        let d = 0.01;
        let x: Vec<Vec3> = (0..3)
            .map(|i| {
                let t = (i as f64 - 1.0) * d / r;
                Vec3::new(r * t.sin(), r * (1.0 - t.cos()), 0.0)
            })
            .collect();
        let e = BendLine::new([0, 1, 2], d, d, 1.0, Direction::Warp);
        let q = x[0] * e.coef[0] + x[1] * e.coef[1] + x[2] * e.coef[2];
        assert!((q.norm() - 0.5).abs() < 1e-4, "{}", q.norm());
    }
}
