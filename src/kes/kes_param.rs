//! The seventeen KES-F parameters ([`KesParam`]): tensile (EMT, LT, WT, RT), shear (G, 2HG,
//! 2HG5), bending (B, 2HB), compression (LC, WC, RC, T0, TM) and surface (MIU, MMD, SMD),
//! with the names KES writes (their ranges in real fabrics: [`super::ranges`]).

/// The KES-F parameters (per direction).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum KesParam {
    /// Extension at the maximum load (%).
    Emt,
    /// Linearity of the tensile load–extension curve.
    Lt,
    /// Tensile energy.
    Wt,
    /// Tensile resilience (%).
    Rt,
    /// Shear rigidity.
    G,
    /// Shear hysteresis width at 0.5°.
    Hg2,
    /// Shear hysteresis width at 5°.
    Hg52,
    /// Bending rigidity.
    B,
    /// Bending hysteresis width at 1 cm⁻¹.
    Hb2,
    /// Linearity of compression.
    Lc,
    /// Compression energy.
    Wc,
    /// Compression resilience (%).
    Rc,
    /// Thickness at 0.5 gf/cm².
    T0,
    /// Thickness at 50 gf/cm².
    Tm,
    /// Mean friction coefficient.
    Miu,
    /// Mean deviation of friction.
    Mmd,
    /// Geometric roughness.
    Smd,
}

/// Every parameter, in file order.
pub const ALL_PARAMS: [KesParam; 17] = [
    KesParam::Emt,
    KesParam::Lt,
    KesParam::Wt,
    KesParam::Rt,
    KesParam::G,
    KesParam::Hg2,
    KesParam::Hg52,
    KesParam::B,
    KesParam::Hb2,
    KesParam::Lc,
    KesParam::Wc,
    KesParam::Rc,
    KesParam::T0,
    KesParam::Tm,
    KesParam::Miu,
    KesParam::Mmd,
    KesParam::Smd,
];

impl KesParam {
    /// The name KES uses ("EMT", "2HG5", …).
    pub fn name(&self) -> &'static str {
        use KesParam::*;
        match self {
            Emt => "EMT",
            Lt => "LT",
            Wt => "WT",
            Rt => "RT",
            G => "G",
            Hg2 => "2HG",
            Hg52 => "2HG5",
            B => "B",
            Hb2 => "2HB",
            Lc => "LC",
            Wc => "WC",
            Rc => "RC",
            T0 => "T0",
            Tm => "TM",
            Miu => "MIU",
            Mmd => "MMD",
            Smd => "SMD",
        }
    }

    /// The parameter named `name`.
    pub fn from_name(name: &str) -> Option<KesParam> {
        ALL_PARAMS.into_iter().find(|p| p.name() == name)
    }
}
