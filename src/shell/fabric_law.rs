//! The nonlinear fabric law of the shell: a fabric's own measured curves (the cloth model's
//! [`MaterialLaw`], e.g. a `MeasuredLaw` built from KES curves) as the shell's strain energy.
//!
//! Warp and weft are uncoupled, as in the cloth model. In the local Cartesian frame of the rest
//! surface (e₁ along ξ¹, the warp) with the Green–Lagrange strains (ε₁₁, ε₂₂, 2ε₁₂) and the
//! curvature changes (κ₁₁, κ₂₂, 2κ₁₂):
//!
//! - **tension**: the yarn stretch λ_i = √(1 + 2ε_ii) gives the engineering strain
//!   e_i = λ_i − 1 that a KES-FB1 tensile test reads, and the energy per rest area is the
//!   law's own ∫₀^e F de (warp plus weft); the force per rest width along the yarn is then
//!   exactly F(e), the measured curve;
//! - **shear**: the angle between the deformed yarns, γ = asin(2ε₁₂ / (λ₁λ₂)), with the law's
//!   shear energy ∫₀^γ F dγ;
//! - **bending**: the law's moment curve per direction, ∫₀^|κ_ii| M dκ, plus a twist term
//!   ½ D_t (2κ₁₂)² with D_t = ½√(B_warp B_weft) from the initial bending slopes (the linear
//!   fabric shell's twist, [`ShellMaterial::from_fabric`]).
//!
//! Each term is a scalar function of one strain jet, chained with the law's (value = energy,
//! first derivative = force, second = stiffness), so the gradient and the Newton tangent stay
//! exact. Only the elastic backbone is used: the law's internal friction (hysteresis) is not
//! modelled by this elastic shell.

use std::sync::Arc;

use super::jet::Jet;
use super::material::ShellMaterial;
use crate::cloth::{Direction, MaterialLaw};

/// A fabric's nonlinear law as a shell law.
#[derive(Debug, Clone)]
pub struct FabricLaw {
    /// The cloth model's law (tension, shear and bending curves per unit width, SI).
    pub law: Arc<dyn MaterialLaw>,
    /// Twist rigidity D_t (N·m) for the energy ½ D_t (2κ₁₂)².
    pub twist: f64,
}

/// Largest |sin γ| the shear angle is taken at (the yarns nearly parallel beyond).
const MAX_SIN_SHEAR: f64 = 0.999;

impl FabricLaw {
    /// The shell law of a cloth law. Errors when its initial tensile, shear or bending slopes
    /// are not positive and finite (the message names the mode).
    pub fn new(law: Arc<dyn MaterialLaw>) -> Result<FabricLaw, String> {
        let f = FabricLaw { law, twist: 0.0 };
        let m = f.tangent_material(0.0)?;
        let twist = 0.5 * (m.bending[0][0] * m.bending[1][1]).sqrt();
        Ok(FabricLaw { twist, ..f })
    }

    /// The linear shell of the law's initial slopes, or of its secants to 1 % strain, 0.01 rad
    /// and 1 1/m where larger (membrane diag(warp, weft, shear),
    /// bending diag(warp, weft, twist)) with areal density `density`: the stiffness scales the
    /// penalties of the boundary conditions use. Errors name a mode whose slope is not
    /// positive and finite.
    pub fn tangent_material(&self, density: f64) -> Result<ShellMaterial, String> {
        let l = &self.law;
        // the initial slope, or the secant to a small deformation where the curve starts flat
        // (a KES power law): 1 % strain, 0.01 rad, 1 1/m
        let slopes = [
            (
                "warp tension",
                slope(|x| l.tension(Direction::Warp, x), 0.01),
            ),
            (
                "weft tension",
                slope(|x| l.tension(Direction::Weft, x), 0.01),
            ),
            ("shear", slope(|x| l.shear(x), 0.01)),
            (
                "warp bending",
                slope(|x| l.bending(Direction::Warp, x), 1.0),
            ),
            (
                "weft bending",
                slope(|x| l.bending(Direction::Weft, x), 1.0),
            ),
        ];
        for (name, s) in slopes {
            if !(s.is_finite() && s > 0.0) {
                return Err(format!(
                    "the fabric law's initial {name} slope must be positive and finite, got {s}"
                ));
            }
        }
        let twist = 0.5 * (slopes[3].1 * slopes[4].1).sqrt();
        Ok(ShellMaterial {
            membrane: [
                [slopes[0].1, 0.0, 0.0],
                [0.0, slopes[1].1, 0.0],
                [0.0, 0.0, slopes[2].1],
            ],
            bending: [
                [slopes[3].1, 0.0, 0.0],
                [0.0, slopes[4].1, 0.0],
                [0.0, 0.0, twist],
            ],
            density,
        })
    }

    /// The strain energy per unit rest area from the local Green–Lagrange strains `eps`
    /// (ε₁₁, ε₂₂, 2ε₁₂) and curvature changes `kap` (κ₁₁, κ₂₂, 2κ₁₂), as jets.
    pub fn energy(&self, eps: &[Jet; 3], kap: &[Jet; 3]) -> Jet {
        let l = &self.law;
        let stretch = |e: &Jet| (e.scale(2.0) + 1.0).sqrt();
        let (l1, l2) = (stretch(&eps[0]), stretch(&eps[1]));
        let mut w = Jet::constant(0.0);
        for (dir, lam) in [(Direction::Warp, &l1), (Direction::Weft, &l2)] {
            let e = *lam + (-1.0);
            let (f, df, en) = l.tension(dir, e.v);
            w = w + e.chain(en, f, df);
        }
        let s = eps[2] * (l1 * l2).recip();
        let gamma = if s.v.abs() < MAX_SIN_SHEAR {
            s.asin()
        } else {
            s
        };
        w = w + odd_energy(&gamma, |x| l.shear(x));
        for (k, dir) in [(0, Direction::Warp), (1, Direction::Weft)] {
            w = w + odd_energy(&kap[k], |x| l.bending(dir, x));
        }
        w + (kap[2] * kap[2]).scale(0.5 * self.twist)
    }
}

/// The largest of a curve's slope at 0, its slope at `x` and its secant to `x`.
fn slope(curve: impl Fn(f64) -> (f64, f64, f64), x: f64) -> f64 {
    let (f, d, _) = curve(x);
    d.max(f / x).max(curve(0.0).1)
}

/// The energy of an odd law (force, stiffness, energy) = `law(|x|)` at the jet `x`: even in x,
/// its derivative the signed force.
fn odd_energy(x: &Jet, law: impl Fn(f64) -> (f64, f64, f64)) -> Jet {
    let (f, df, en) = law(x.v.abs());
    let sign = if x.v < 0.0 { -1.0 } else { 1.0 };
    x.chain(en, sign * f, df)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cloth::{LinearMaterial, MeasuredLaw};

    #[test]
    fn a_linear_fabric_law_matches_the_linear_shell_at_small_strain() {
        let lin = LinearMaterial {
            stretch_warp: 2000.0,
            stretch_weft: 1000.0,
            shear: 10.0,
            bend_warp: 1e-5,
            bend_weft: 4e-6,
        };
        let f = FabricLaw::new(Arc::new(lin)).unwrap();
        let m = f.tangent_material(0.2).unwrap();
        assert_eq!(m.membrane[0][0], 2000.0);
        assert!((f.twist - 0.5 * (4e-11f64).sqrt()).abs() < 1e-18);
        // small strains: W ≈ ½ εᵀ D ε (the stretch and angle measures agree to first order)
        let e = [1e-5, -2e-5, 3e-5];
        let k = [0.5, -0.2, 0.1];
        let zero = [Jet::constant(0.0); 3];
        // membrane: the stretch and angle measures agree with the Green strains to first order
        let w = f.energy(&e.map(Jet::constant), &zero).v;
        let lin_w = 0.5 * (2000.0 * e[0] * e[0] + 1000.0 * e[1] * e[1] + 10.0 * e[2] * e[2]);
        assert!((w - lin_w).abs() < 1e-4 * lin_w, "{w} vs {lin_w}");
        // bending: the same measure, exact
        let w = f.energy(&zero, &k.map(Jet::constant)).v;
        let lin_w = 0.5 * (1e-5 * k[0] * k[0] + 4e-6 * k[1] * k[1] + f.twist * k[2] * k[2]);
        assert!((w - lin_w).abs() < 1e-12 * lin_w, "{w} vs {lin_w}");
    }

    #[test]
    fn uniaxial_yarn_force_is_the_law_at_the_engineering_strain() {
        // a stiffening law: F = 1000 e + 1e5 e²
        let pts: Vec<[f64; 2]> = (1..=40)
            .map(|i| {
                let e = 0.005 * i as f64;
                [e, 1000.0 * e + 1e5 * e * e]
            })
            .collect();
        let c = crate::cloth::ResponseCurve::new(&pts).unwrap();
        let law = MeasuredLaw {
            tension: [c.clone(), c],
            compression: [1000.0; 2],
            shear: crate::cloth::ResponseCurve::linear(5.0),
            bending: [
                crate::cloth::ResponseCurve::linear(1e-6),
                crate::cloth::ResponseCurve::linear(1e-6),
            ],
            tension_friction: [None; 2],
            shear_friction: None,
            bending_friction: [None; 2],
        };
        let f = FabricLaw::new(Arc::new(law)).unwrap();
        // stretch λ along the warp: E₁₁ = (λ² − 1)/2; nominal force = dW/dλ = W'(E) λ
        for lam in [1.01, 1.07, 1.15] {
            let e11 = Jet::variable(0.5 * (lam * lam - 1.0), 0);
            let w = f.energy(
                &[e11, Jet::constant(0.0), Jet::constant(0.0)],
                &[Jet::constant(0.0); 3],
            );
            let force = w.g[0] * lam;
            let e = lam - 1.0;
            let want = 1000.0 * e + 1e5 * e * e;
            assert!(
                (force - want).abs() < 2e-3 * want,
                "λ {lam}: {force} vs {want}"
            );
        }
    }
}
