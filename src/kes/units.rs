//! KES ↔ SI units, in one place. Every conversion of the maths notes (§1) is a named factor
//! (SI value = KES value × factor); [`Unit`] parses the spellings a fabric file may use, and
//! [`to_si`] converts a number after checking that its unit suits the [`Quantity`] it
//! measures (a bending rigidity in gf/cm is an error, not a silent wrong number).
//! 1 gf = 9.80665 mN.

use std::fmt;

use super::kes_param::KesParam;

/// Gram-force in newtons: gf → N.
pub const GF: f64 = 9.80665e-3;
/// Tensile force per width (F, Fm, 2HG, 2HG5): gf/cm → N/m (0.980665).
pub const GF_PER_CM: f64 = GF / 0.01;
/// Energy per area (WT, WC): gf·cm/cm² → J/m² (0.980665).
pub const GF_CM_PER_CM2: f64 = GF * 0.01 / 1e-4;
/// Percent → fraction (0.01).
pub const PERCENT: f64 = 0.01;
/// Shear rigidity (G): gf/(cm·deg) → N/(m·rad), 0.980665 · 180/π ≈ 56.188.
pub const GF_PER_CM_DEG: f64 = GF_PER_CM * 180.0 / std::f64::consts::PI;
/// Bending rigidity per width (B): gf·cm²/cm → N·m (9.80665e-5).
pub const GF_CM2_PER_CM: f64 = GF * 1e-4 / 0.01;
/// Bending moment per width (2HB, bending curves): gf·cm/cm → N·m/m = N (9.80665e-3).
pub const GF_CM_PER_CM: f64 = GF;
/// Curvature: cm⁻¹ → m⁻¹ (100).
pub const PER_CM: f64 = 100.0;
/// Pressure (compression): gf/cm² → Pa (98.0665).
pub const GF_PER_CM2: f64 = GF / 1e-4;
/// Thickness (T0, TM): mm → m (1e-3).
pub const MM: f64 = 1e-3;
/// Areal weight (W): mg/cm² → kg/m² (0.01; 10 mg/cm² = 100 g/m²).
pub const MG_PER_CM2: f64 = 1e-6 / 1e-4;
/// Areal weight: g/m² → kg/m² (1e-3).
pub const G_PER_M2: f64 = 1e-3;
/// Surface roughness (SMD): µm → m (1e-6).
pub const MICROMETRE: f64 = 1e-6;
/// Degree → radian (π/180).
pub const DEGREE: f64 = std::f64::consts::PI / 180.0;

/// gf/cm → N/m.
pub fn gf_per_cm(v: f64) -> f64 {
    v * GF_PER_CM
}
/// gf·cm/cm² → J/m².
pub fn gf_cm_per_cm2(v: f64) -> f64 {
    v * GF_CM_PER_CM2
}
/// % → fraction.
pub fn percent(v: f64) -> f64 {
    v * PERCENT
}
/// gf/(cm·deg) → N/(m·rad).
pub fn gf_per_cm_deg(v: f64) -> f64 {
    v * GF_PER_CM_DEG
}
/// gf·cm²/cm → N·m.
pub fn gf_cm2_per_cm(v: f64) -> f64 {
    v * GF_CM2_PER_CM
}
/// gf·cm/cm → N.
pub fn gf_cm_per_cm(v: f64) -> f64 {
    v * GF_CM_PER_CM
}
/// cm⁻¹ → m⁻¹.
pub fn per_cm(v: f64) -> f64 {
    v * PER_CM
}
/// gf/cm² → Pa.
pub fn gf_per_cm2(v: f64) -> f64 {
    v * GF_PER_CM2
}
/// mm → m.
pub fn mm(v: f64) -> f64 {
    v * MM
}
/// mg/cm² → kg/m².
pub fn mg_per_cm2(v: f64) -> f64 {
    v * MG_PER_CM2
}
/// µm → m.
pub fn micrometre(v: f64) -> f64 {
    v * MICROMETRE
}
/// deg → rad.
pub fn deg(v: f64) -> f64 {
    v * DEGREE
}

/// What a number measures; each kind accepts its KES unit and its SI unit(s).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Quantity {
    /// Force per width (tensile load F, Fm, 2HG, 2HG5, shear force Hs): gf/cm, N/m.
    ForcePerWidth,
    /// Strain or a percentage (EMT, RT, RC, tensile strain): %, `-` (fraction).
    Fraction,
    /// Dimensionless ratio (LT, LC, MIU, MMD): `-`.
    Ratio,
    /// Energy per area (WT, WC): gf·cm/cm², J/m² (= N/m).
    EnergyPerArea,
    /// Shear rigidity (G): gf/(cm·deg), N/(m·rad).
    ShearRigidity,
    /// Bending rigidity per width (B): gf·cm²/cm, N·m.
    BendingRigidity,
    /// Bending moment per width (2HB, bending curves): gf·cm/cm, N (= N·m/m).
    MomentPerWidth,
    /// Curvature (bending curves): cm⁻¹, m⁻¹.
    Curvature,
    /// Angle (shear curves): deg, rad.
    Angle,
    /// Thickness (T0, TM): mm, m.
    Thickness,
    /// Roughness (SMD): µm, m.
    Roughness,
    /// Areal weight (W): mg/cm², g/m², kg/m².
    ArealWeight,
    /// Pressure (compression): gf/cm², Pa.
    Pressure,
}

impl Quantity {
    /// Every quantity kind.
    pub const ALL: [Quantity; 13] = [
        Quantity::ForcePerWidth,
        Quantity::Fraction,
        Quantity::Ratio,
        Quantity::EnergyPerArea,
        Quantity::ShearRigidity,
        Quantity::BendingRigidity,
        Quantity::MomentPerWidth,
        Quantity::Curvature,
        Quantity::Angle,
        Quantity::Thickness,
        Quantity::Roughness,
        Quantity::ArealWeight,
        Quantity::Pressure,
    ];

    /// The units valid for this quantity; the first is the KES unit (written to files).
    pub fn units(self) -> &'static [Unit] {
        use Unit::*;
        match self {
            Quantity::ForcePerWidth => &[GfPerCm, NPerM],
            Quantity::Fraction => &[Percent, One],
            Quantity::Ratio => &[One],
            Quantity::EnergyPerArea => &[GfCmPerCm2, JPerM2, NPerM],
            Quantity::ShearRigidity => &[GfPerCmDeg, NPerMRad],
            Quantity::BendingRigidity => &[GfCm2PerCm, NM],
            Quantity::MomentPerWidth => &[GfCmPerCm, N],
            Quantity::Curvature => &[PerCm, PerM],
            Quantity::Angle => &[Deg, Rad],
            Quantity::Thickness => &[Mm, M],
            Quantity::Roughness => &[Um, M],
            Quantity::ArealWeight => &[MgPerCm2, GPerM2, KgPerM2],
            Quantity::Pressure => &[GfPerCm2, Pa],
        }
    }

    /// True if `unit` is valid for this quantity.
    pub fn accepts(self, unit: Unit) -> bool {
        self.units().contains(&unit)
    }

    /// The KES unit of this quantity (the unit files are written in).
    pub fn kes_unit(self) -> Unit {
        self.units()[0]
    }
}

/// A unit as fabric files write it (KES or SI). Parse with [`Unit::parse`]; [`Unit::factor`]
/// multiplies a value in this unit into SI.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Unit {
    /// gf/cm (force per width).
    GfPerCm,
    /// gf·cm/cm² (energy per area).
    GfCmPerCm2,
    /// % (percentage).
    Percent,
    /// `-`: a pure number (fraction or ratio).
    One,
    /// gf/(cm·deg) (shear rigidity).
    GfPerCmDeg,
    /// gf·cm²/cm (bending rigidity per width).
    GfCm2PerCm,
    /// gf·cm/cm (moment per width).
    GfCmPerCm,
    /// cm⁻¹ (curvature).
    PerCm,
    /// gf/cm² (pressure).
    GfPerCm2,
    /// mm.
    Mm,
    /// mg/cm² (areal weight).
    MgPerCm2,
    /// g/m² (areal weight).
    GPerM2,
    /// µm.
    Um,
    /// Degree.
    Deg,
    /// N/m (SI force per width; also J/m² as an energy per area).
    NPerM,
    /// J/m² (SI energy per area).
    JPerM2,
    /// N/(m·rad) (SI shear rigidity).
    NPerMRad,
    /// N·m (SI bending rigidity per width).
    NM,
    /// N (SI moment per width, N·m/m).
    N,
    /// m⁻¹ (SI curvature).
    PerM,
    /// Radian.
    Rad,
    /// Metre.
    M,
    /// kg/m² (SI areal weight).
    KgPerM2,
    /// Pascal.
    Pa,
}

/// Every unit.
const ALL_UNITS: [Unit; 24] = [
    Unit::GfPerCm,
    Unit::GfCmPerCm2,
    Unit::Percent,
    Unit::One,
    Unit::GfPerCmDeg,
    Unit::GfCm2PerCm,
    Unit::GfCmPerCm,
    Unit::PerCm,
    Unit::GfPerCm2,
    Unit::Mm,
    Unit::MgPerCm2,
    Unit::GPerM2,
    Unit::Um,
    Unit::Deg,
    Unit::NPerM,
    Unit::JPerM2,
    Unit::NPerMRad,
    Unit::NM,
    Unit::N,
    Unit::PerM,
    Unit::Rad,
    Unit::M,
    Unit::KgPerM2,
    Unit::Pa,
];

impl Unit {
    /// Every unit.
    pub fn all() -> &'static [Unit] {
        &ALL_UNITS
    }

    /// The canonical ASCII spelling, written to files ("gf.cm2/cm", "1/cm", …).
    pub fn symbol(self) -> &'static str {
        use Unit::*;
        match self {
            GfPerCm => "gf/cm",
            GfCmPerCm2 => "gf.cm/cm2",
            Percent => "%",
            One => "-",
            GfPerCmDeg => "gf/(cm.deg)",
            GfCm2PerCm => "gf.cm2/cm",
            GfCmPerCm => "gf.cm/cm",
            PerCm => "1/cm",
            GfPerCm2 => "gf/cm2",
            Mm => "mm",
            MgPerCm2 => "mg/cm2",
            GPerM2 => "g/m2",
            Um => "um",
            Deg => "deg",
            NPerM => "N/m",
            JPerM2 => "J/m2",
            NPerMRad => "N/m/rad",
            NM => "N.m",
            N => "N",
            PerM => "1/m",
            Rad => "rad",
            M => "m",
            KgPerM2 => "kg/m2",
            Pa => "Pa",
        }
    }

    /// Other accepted spellings, after normalisation (see [`Unit::parse`]).
    fn aliases(self) -> &'static [&'static str] {
        use Unit::*;
        match self {
            GfCmPerCm2 => &["gf.cm.cm-2"],
            One => &["1"],
            GfPerCmDeg => &["gf/cm/deg", "gf.cm-1.deg-1"],
            PerCm => &["cm-1"],
            Um => &["micrometre", "micrometer", "micron"],
            Deg => &["degree", "degrees", "°"],
            NPerMRad => &["N/(m.rad)", "N.m-1.rad-1"],
            N => &["N.m/m"],
            PerM => &["m-1"],
            Rad => &["radian", "radians"],
            _ => &[],
        }
    }

    /// The unit written `s`. Accepts the canonical spellings of [`Unit::symbol`] and common
    /// variants: `·` or `*` for the product dot, `^` and superscript ² in powers, `µ`/`μ` for
    /// micro, `gf/cm/deg` for gf/(cm·deg), `cm-1` for 1/cm, surrounding blanks. Case matters
    /// (`mm` is not `Mm`).
    pub fn parse(s: &str) -> Option<Unit> {
        let norm: String = s
            .trim()
            .chars()
            .filter(|c| !c.is_whitespace() && *c != '^')
            .map(|c| match c {
                '·' | '*' | '⋅' => '.',
                '²' => '2',
                '⁻' => '-',
                '¹' => '1',
                'µ' | 'μ' => 'u',
                c => c,
            })
            .collect();
        ALL_UNITS
            .into_iter()
            .find(|u| u.symbol() == norm || u.aliases().contains(&norm.as_str()))
    }

    /// Multiplier from this unit into SI.
    pub fn factor(self) -> f64 {
        use Unit::*;
        match self {
            GfPerCm => GF_PER_CM,
            GfCmPerCm2 => GF_CM_PER_CM2,
            Percent => PERCENT,
            GfPerCmDeg => GF_PER_CM_DEG,
            GfCm2PerCm => GF_CM2_PER_CM,
            GfCmPerCm => GF_CM_PER_CM,
            PerCm => PER_CM,
            GfPerCm2 => GF_PER_CM2,
            Mm => MM,
            MgPerCm2 => MG_PER_CM2,
            GPerM2 => G_PER_M2,
            Um => MICROMETRE,
            Deg => DEGREE,
            One | NPerM | JPerM2 | NPerMRad | NM | N | PerM | Rad | M | KgPerM2 | Pa => 1.0,
        }
    }

    /// `value` in this unit, in SI.
    pub fn to_si(self, value: f64) -> f64 {
        value * self.factor()
    }

    /// An SI value in this unit.
    pub fn from_si(self, si: f64) -> f64 {
        si / self.factor()
    }

    /// The quantity kinds this unit can measure.
    pub fn quantities(self) -> Vec<Quantity> {
        Quantity::ALL
            .into_iter()
            .filter(|q| q.accepts(self))
            .collect()
    }
}

impl fmt::Display for Unit {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.symbol())
    }
}

/// A unit that could not be used.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum UnitError {
    /// The spelling is not a known unit.
    Unknown {
        /// The unit as written.
        unit: String,
        /// The quantity it was meant for.
        quantity: Quantity,
    },
    /// A known unit of another kind of quantity.
    WrongKind {
        /// The unit as written.
        unit: String,
        /// The quantity it was meant for.
        quantity: Quantity,
    },
}

impl fmt::Display for UnitError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let (unit, q, what) = match self {
            UnitError::Unknown { unit, quantity } => (unit, quantity, "is not a known unit"),
            UnitError::WrongKind { unit, quantity } => {
                (unit, quantity, "is a unit of another quantity")
            }
        };
        let ok: Vec<&str> = q.units().iter().map(|u| u.symbol()).collect();
        write!(
            f,
            "unit `{unit}` {what}; {q:?} takes one of {}",
            ok.join(", ")
        )
    }
}

impl std::error::Error for UnitError {}

/// The unit written `unit`, checked to be valid for quantity `q`.
pub fn unit_for(unit: &str, q: Quantity) -> Result<Unit, UnitError> {
    let u = Unit::parse(unit).ok_or_else(|| UnitError::Unknown {
        unit: unit.to_string(),
        quantity: q,
    })?;
    if q.accepts(u) {
        Ok(u)
    } else {
        Err(UnitError::WrongKind {
            unit: unit.to_string(),
            quantity: q,
        })
    }
}

/// Converts `value` written in `unit` to SI for quantity `q`; an unknown unit, or a unit of
/// another quantity, is an error naming the accepted ones.
pub fn to_si(value: f64, unit: &str, q: Quantity) -> Result<f64, UnitError> {
    unit_for(unit, q).map(|u| u.to_si(value))
}

/// The KES unit of quantity `q` and the SI → KES factor (1 / the unit's factor).
pub fn kes_unit(q: Quantity) -> (&'static str, f64) {
    let u = q.kes_unit();
    (u.symbol(), 1.0 / u.factor())
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
    let u = quantity_of(p).kes_unit();
    (u.symbol(), u.from_si(si))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_unit_parses_from_its_symbol_and_has_a_kind() {
        for &u in Unit::all() {
            assert_eq!(Unit::parse(u.symbol()), Some(u), "{u}");
            assert!(!u.quantities().is_empty(), "{u} measures nothing");
        }
        for q in Quantity::ALL {
            assert_eq!(unit_for(q.kes_unit().symbol(), q), Ok(q.kes_unit()));
        }
    }
}
