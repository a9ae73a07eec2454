//! Material laws: how a fabric answers strain, shear and curvature. Every force element asks
//! its law for a stress and a tangent through the one `MaterialLaw` interface; the linear law
//! lives here, measured KES curves will implement the same trait.

use serde::{Deserialize, Serialize};

/// A fabric direction in the rest (pattern) plane.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum Direction {
    /// Along u (the warp yarns).
    Warp,
    /// Along v (the weft yarns).
    Weft,
}

/// A constitutive law per unit width of fabric. All values SI: tension in N/m, shear force in
/// N/m, bending moment in N·m/m = N; strains dimensionless, curvature in 1/m.
pub trait MaterialLaw: Send + Sync + std::fmt::Debug {
    /// Tension per unit width at `strain` along `dir`: (F, dF/dε, energy per unit area ∫F dε).
    fn tension(&self, dir: Direction, strain: f64) -> (f64, f64, f64);
    /// Shear force per unit width at shear angle `gamma` (rad): (F, dF/dγ, energy per unit area).
    fn shear(&self, gamma: f64) -> (f64, f64, f64);
    /// Bending moment per unit width at curvature `kappa` ≥ 0 (1/m) bending about an axis
    /// perpendicular to `dir`: (M, dM/dκ, energy per unit area).
    fn bending(&self, dir: Direction, kappa: f64) -> (f64, f64, f64);
    /// Internal friction of tension along `dir` (strain as the coordinate, force per width).
    fn tension_friction(&self, _dir: Direction) -> Option<Friction> {
        None
    }
    /// Internal friction of shear (shear angle in rad, force per width).
    fn shear_friction(&self) -> Option<Friction> {
        None
    }
    /// Internal friction of bending about an axis perpendicular to `dir` (curvature in 1/m,
    /// moment per width).
    fn bending_friction(&self, _dir: Direction) -> Option<Friction> {
        None
    }
    /// True when any mode has internal friction (elements then keep a friction state).
    fn has_friction(&self) -> bool {
        self.tension_friction(Direction::Warp).is_some()
            || self.tension_friction(Direction::Weft).is_some()
            || self.shear_friction().is_some()
            || self.bending_friction(Direction::Warp).is_some()
            || self.bending_friction(Direction::Weft).is_some()
    }
}

/// Rate-independent internal friction of one deformation mode: a Jenkins element (a stick
/// spring of stiffness `stick` in series with a slider) in parallel with the elastic law. The
/// slider's threshold grows with the elastic force, `base + slope · |F_el|` (yarn contact
/// pressure rises with load), which reproduces Kawabata loops whose width grows with
/// amplitude (2HG5 > 2HG) and tensile recovery below 100 % (RT).
///
/// State per element: the coordinate `x_c` and friction force `z_c` at the last evaluation.
/// An evaluation at `x` gives `z = clamp(z_c + stick (x − x_c), ±threshold)` and is then
/// committed; evaluating twice at the same `x` changes nothing.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Friction {
    /// Stiffness while sticking (force per width per unit of the coordinate).
    pub stick: f64,
    /// Slider threshold at zero elastic force (force per width).
    pub base: f64,
    /// Threshold growth per unit elastic force (dimensionless).
    pub slope: f64,
}

impl Friction {
    /// Slider threshold when the elastic force is `f_el`.
    #[inline]
    pub fn threshold(&self, f_el: f64) -> f64 {
        self.base + self.slope * f_el.abs()
    }

    /// Friction force and its tangent dz/dx at coordinate `x`, from the committed state
    /// (`xc`, `zc`), with elastic force `f_el` and elastic tangent `df_el` at `x`.
    #[inline]
    pub fn update(&self, xc: f64, zc: f64, x: f64, f_el: f64, df_el: f64) -> (f64, f64) {
        let trial = zc + self.stick * (x - xc);
        let t = self.threshold(f_el);
        if trial.abs() <= t {
            (trial, self.stick)
        } else {
            let s = trial.signum();
            (s * t, s * self.slope * f_el.signum() * df_el)
        }
    }
}

/// Linear elastic fabric: constant tensile, shear and bending rigidities.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct LinearMaterial {
    /// Tensile rigidity along the warp, dF/dε (N/m).
    pub stretch_warp: f64,
    /// Tensile rigidity along the weft (N/m).
    pub stretch_weft: f64,
    /// Shear rigidity (N/m per radian).
    pub shear: f64,
    /// Bending rigidity for curvature along the warp (N·m).
    pub bend_warp: f64,
    /// Bending rigidity for curvature along the weft (N·m).
    pub bend_weft: f64,
}

impl MaterialLaw for LinearMaterial {
    fn tension(&self, dir: Direction, strain: f64) -> (f64, f64, f64) {
        let k = match dir {
            Direction::Warp => self.stretch_warp,
            Direction::Weft => self.stretch_weft,
        };
        (k * strain, k, 0.5 * k * strain * strain)
    }
    fn shear(&self, gamma: f64) -> (f64, f64, f64) {
        (
            self.shear * gamma,
            self.shear,
            0.5 * self.shear * gamma * gamma,
        )
    }
    fn bending(&self, dir: Direction, kappa: f64) -> (f64, f64, f64) {
        let b = match dir {
            Direction::Warp => self.bend_warp,
            Direction::Weft => self.bend_weft,
        };
        (b * kappa, b, 0.5 * b * kappa * kappa)
    }
}

/// Everything that describes a fabric to the simulator, SI units. Settable field by field.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct FabricParameters {
    /// Areal density (kg/m²).
    pub density: f64,
    /// Tensile rigidity along the warp (N/m).
    pub stretch_warp: f64,
    /// Tensile rigidity along the weft (N/m).
    pub stretch_weft: f64,
    /// Shear rigidity (N/m).
    pub shear: f64,
    /// Bending rigidity, warp (N·m).
    pub bend_warp: f64,
    /// Bending rigidity, weft (N·m).
    pub bend_weft: f64,
    /// Stiffness-proportional damping of stretch and shear (s): damping force = this × stiffness × strain rate.
    pub stretch_damping: f64,
    /// Stiffness-proportional damping of bending (s).
    pub bend_damping: f64,
    /// Linear air drag per unit area (N·s/m³): force = −drag × area × velocity.
    pub air_drag: f64,
}

impl Default for FabricParameters {
    /// A cotton-like woven fabric: 150 g/m², 1000 N/m stretch, soft shear and bending.
    fn default() -> Self {
        FabricParameters {
            density: 0.15,
            stretch_warp: 1000.0,
            stretch_weft: 1000.0,
            shear: 10.0,
            bend_warp: 1e-5,
            bend_weft: 1e-5,
            stretch_damping: 1e-3,
            bend_damping: 0.0,
            air_drag: 0.1,
        }
    }
}

impl FabricParameters {
    /// Checks every field is finite and non-negative, and the density is positive.
    pub fn validate(&self) -> Result<(), String> {
        let fields = [
            ("density", self.density),
            ("stretch_warp", self.stretch_warp),
            ("stretch_weft", self.stretch_weft),
            ("shear", self.shear),
            ("bend_warp", self.bend_warp),
            ("bend_weft", self.bend_weft),
            ("stretch_damping", self.stretch_damping),
            ("bend_damping", self.bend_damping),
            ("air_drag", self.air_drag),
        ];
        for (name, v) in fields {
            if !v.is_finite() || v < 0.0 {
                return Err(format!(
                    "fabric parameter `{name}` must be finite and ≥ 0, got {v}"
                ));
            }
        }
        if self.density <= 0.0 {
            return Err(format!(
                "fabric parameter `density` must be > 0, got {}",
                self.density
            ));
        }
        Ok(())
    }

    /// The linear material law of these parameters.
    pub fn linear_law(&self) -> LinearMaterial {
        LinearMaterial {
            stretch_warp: self.stretch_warp,
            stretch_weft: self.stretch_weft,
            shear: self.shear,
            bend_warp: self.bend_warp,
            bend_weft: self.bend_weft,
        }
    }
}
