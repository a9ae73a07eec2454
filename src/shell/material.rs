//! Linear elastic laws of a Kirchhoff–Love shell, as 3×3 matrices in Voigt form (ε₁₁, ε₂₂, 2ε₁₂)
//! in the local Cartesian frame of the rest surface (e₁ along the parameter direction ξ¹, the
//! warp for cloth): membrane forces n = D_m ε (N/m) and bending moments m = D_b κ (N).
//! Isotropic from (E, ν, t); orthotropic from the cloth model's fabric parameters.

use crate::cloth::FabricParameters;

/// Membrane and bending stiffness matrices.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ShellMaterial {
    /// Membrane stiffness D_m (N/m), Voigt.
    pub membrane: [[f64; 3]; 3],
    /// Bending stiffness D_b (N·m), Voigt.
    pub bending: [[f64; 3]; 3],
    /// Mass per unit area (kg/m²), for self-weight.
    pub density: f64,
}

impl ShellMaterial {
    /// An isotropic shell: Young's modulus `e` (Pa), Poisson's ratio `nu`, thickness `t` (m),
    /// areal density `density` (kg/m²). D_m = E t/(1 − ν²) C, D_b = E t³/(12(1 − ν²)) C.
    pub fn isotropic(e: f64, nu: f64, t: f64, density: f64) -> Result<ShellMaterial, String> {
        if !(e.is_finite() && e > 0.0) {
            return Err(format!(
                "Young's modulus must be positive and finite, got {e}"
            ));
        }
        if !(nu.is_finite() && (-1.0..0.5).contains(&nu)) {
            return Err(format!("Poisson's ratio must lie in [-1, 0.5), got {nu}"));
        }
        if !(t.is_finite() && t > 0.0) {
            return Err(format!("thickness must be positive and finite, got {t}"));
        }
        if !(density.is_finite() && density >= 0.0) {
            return Err(format!("density must be finite and ≥ 0, got {density}"));
        }
        let c = e / (1.0 - nu * nu);
        let law = [
            [c, c * nu, 0.0],
            [c * nu, c, 0.0],
            [0.0, 0.0, 0.5 * c * (1.0 - nu)],
        ];
        let scale = |s: f64| law.map(|row| row.map(|v| v * s));
        Ok(ShellMaterial {
            membrane: scale(t),
            bending: scale(t * t * t / 12.0),
            density,
        })
    }

    /// The orthotropic shell of a fabric (warp along ξ¹): membrane diag(stretch warp, stretch
    /// weft, shear), no Poisson coupling (a woven's is small and the cloth model has none);
    /// bending diag(bend warp, bend weft, ½√(B_warp B_weft)), the last being the twist rigidity
    /// of a ν = 0 plate with the mean bending rigidity.
    pub fn from_fabric(f: &FabricParameters) -> Result<ShellMaterial, String> {
        f.validate()?;
        if f.stretch_warp <= 0.0 || f.stretch_weft <= 0.0 || f.shear <= 0.0 {
            return Err(
                "a shell fabric needs positive stretch_warp, stretch_weft and shear".into(),
            );
        }
        let twist = 0.5 * (f.bend_warp * f.bend_weft).sqrt();
        Ok(ShellMaterial {
            membrane: [
                [f.stretch_warp, 0.0, 0.0],
                [0.0, f.stretch_weft, 0.0],
                [0.0, 0.0, f.shear],
            ],
            bending: [
                [f.bend_warp, 0.0, 0.0],
                [0.0, f.bend_weft, 0.0],
                [0.0, 0.0, twist],
            ],
            density: f.density,
        })
    }

    /// The largest diagonal entries (membrane, bending): the stiffness scales the penalty uses.
    pub fn scales(&self) -> (f64, f64) {
        let m = (0..3).map(|i| self.membrane[i][i]).fold(0.0, f64::max);
        let b = (0..3).map(|i| self.bending[i][i]).fold(0.0, f64::max);
        (m, b)
    }
}
