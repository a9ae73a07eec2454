//! KES ↔ SI units, in one place. Every conversion of the maths notes (§1) is a named factor;
//! a fabric file names the unit of every number and [`to_si`] checks that the unit suits the
//! quantity. 1 gf = 9.80665 mN.

use super::fabric::KesParam;

/// Gram-force in newtons.
pub const GF: f64 = 9.80665e-3;
/// Tensile force per width: gf/cm → N/m.
pub const GF_PER_CM: f64 = GF / 0.01;
/// Energy per area: gf·cm/cm² → J/m².
pub const GF_CM_PER_CM2: f64 = GF * 0.01 / 1e-4;
/// Percent → fraction.
pub const PERCENT: f64 = 0.01;
/// Shear rigidity: gf/(cm·deg) → N/(m·rad).
pub const GF_PER_CM_DEG: f64 = GF_PER_CM * 180.0 / std::f64::consts::PI;
/// Bending rigidity per width: gf·cm²/cm → N·m.
pub const GF_CM2_PER_CM: f64 = GF * 1e-4 / 0.01;
/// Bending moment per width: gf·cm/cm → N.
pub const GF_CM_PER_CM: f64 = GF;
/// Curvature: 1/cm → 1/m.
pub const PER_CM: f64 = 100.0;
/// Pressure: gf/cm² → Pa.
pub const GF_PER_CM2: f64 = GF / 1e-4;
/// Thickness: mm → m.
pub const MM: f64 = 1e-3;
/// Areal weight: mg/cm² → kg/m².
pub const MG_PER_CM2: f64 = 1e-6 / 1e-4;
/// Surface roughness: µm → m.
pub const MICROMETRE: f64 = 1e-6;
/// Degree → radian.
pub const DEGREE: f64 = std::f64::consts::PI / 180.0;

/// What a number measures; each kind accepts its KES unit and its SI unit.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Quantity {
    /// Force per width (tensile load, 2HG, 2HG5).
    ForcePerWidth,
    /// Strain or a percentage (EMT, RT, RC).
    Fraction,
    /// Dimensionless ratio (LT, LC, MIU, MMD).
    Ratio,
    /// Energy per area (WT, WC).
    EnergyPerArea,
    /// Shear rigidity (G).
    ShearRigidity,
    /// Bending rigidity per width (B).
    BendingRigidity,
    /// Moment per width (2HB, bending curves).
    MomentPerWidth,
    /// Curvature.
    Curvature,
    /// Angle (shear curves).
    Angle,
    /// Thickness (T0, TM).
    Thickness,
    /// Roughness (SMD).
    Roughness,
    /// Areal weight (W).
    ArealWeight,
    /// Pressure.
    Pressure,
}

/// Units accepted for each quantity: (spelling, factor to SI). The first is the KES unit,
/// written back to files.
pub fn units_of(q: Quantity) -> &'static [(&'static str, f64)] {
    match q {
        Quantity::ForcePerWidth => &[("gf/cm", GF_PER_CM), ("N/m", 1.0)],
        Quantity::Fraction => &[("%", PERCENT), ("-", 1.0)],
        Quantity::Ratio => &[("-", 1.0)],
        Quantity::EnergyPerArea => &[
            ("gf.cm/cm2", GF_CM_PER_CM2),
            ("gf*cm/cm^2", GF_CM_PER_CM2),
            ("gf·cm/cm²", GF_CM_PER_CM2),
            ("J/m2", 1.0),
            ("N/m", 1.0),
        ],
        Quantity::ShearRigidity => &[
            ("gf/(cm.deg)", GF_PER_CM_DEG),
            ("gf/cm/deg", GF_PER_CM_DEG),
            ("gf/(cm·deg)", GF_PER_CM_DEG),
            ("N/m/rad", 1.0),
            ("N/(m.rad)", 1.0),
        ],
        Quantity::BendingRigidity => &[
            ("gf.cm2/cm", GF_CM2_PER_CM),
            ("gf*cm^2/cm", GF_CM2_PER_CM),
            ("gf·cm²/cm", GF_CM2_PER_CM),
            ("N.m", 1.0),
            ("N*m", 1.0),
        ],
        Quantity::MomentPerWidth => &[
            ("gf.cm/cm", GF_CM_PER_CM),
            ("gf*cm/cm", GF_CM_PER_CM),
            ("gf·cm/cm", GF_CM_PER_CM),
            ("N", 1.0),
            ("N.m/m", 1.0),
        ],
        Quantity::Curvature => &[("1/cm", PER_CM), ("cm-1", PER_CM), ("1/m", 1.0)],
        Quantity::Angle => &[("deg", DEGREE), ("rad", 1.0)],
        Quantity::Thickness => &[("mm", MM), ("m", 1.0)],
        Quantity::Roughness => &[("um", MICROMETRE), ("µm", MICROMETRE), ("m", 1.0)],
        Quantity::ArealWeight => &[("mg/cm2", MG_PER_CM2), ("g/m2", 1e-3), ("kg/m2", 1.0)],
        Quantity::Pressure => &[("gf/cm2", GF_PER_CM2), ("Pa", 1.0)],
    }
}

/// Converts `value` in `unit` to SI for quantity `q`; an unknown or unsuitable unit is an
/// error listing the accepted ones.
pub fn to_si(value: f64, unit: &str, q: Quantity) -> Result<f64, String> {
    let u = unit.trim();
    units_of(q)
        .iter()
        .find(|(name, _)| *name == u)
        .map(|(_, f)| value * f)
        .ok_or_else(|| {
            let ok: Vec<&str> = units_of(q).iter().map(|(n, _)| *n).collect();
            format!(
                "unit `{unit}` is not a unit of {q:?} (use one of {})",
                ok.join(", ")
            )
        })
}

/// The KES unit of quantity `q` and the SI → KES factor (1 / the unit's factor).
pub fn kes_unit(q: Quantity) -> (&'static str, f64) {
    let (name, f) = units_of(q)[0];
    (name, 1.0 / f)
}

/// The quantity a KES parameter measures.
pub fn quantity_of(p: KesParam) -> Quantity {
    use KesParam::*;
    match p {
        Emt | Rt | Rc => Quantity::Fraction,
        Lt | Lc | Miu | Mmd => Quantity::Ratio,
        Wt | Wc => Quantity::EnergyPerArea,
        G => Quantity::ShearRigidity,
        Hg2 | Hg52 => Quantity::ForcePerWidth,
        B => Quantity::BendingRigidity,
        Hb2 => Quantity::MomentPerWidth,
        T0 | Tm => Quantity::Thickness,
        Smd => Quantity::Roughness,
    }
}

/// A parameter's SI value in its KES unit: (unit, value).
pub fn to_kes(p: KesParam, si: f64) -> (&'static str, f64) {
    let (u, f) = kes_unit(quantity_of(p));
    (u, si * f)
}
