//! The ranges of real fabrics: for each KES-F parameter, the areal weight, the thickness and
//! the tensile protocol's maximum load, the values (in KES units) outside which no woven or
//! knitted apparel fabric lies. A fabric file or a KES parameter outside them is refused where
//! it enters ([`super::fabric::parse_fabric`], the lab), with the parameter and the range.
//!
//! The bounds are wide on purpose (a decade or more beyond the measured fabrics): they catch
//! typing slips, unit confusions and hostile numbers (`B = 1e308`), not unusual fabrics.
//! Sources: the maths notes (`../shared/reference/kawabata-and-cloth-maths.md`) §2.2 (the 251
//! distinct Feng 2022 cantilever fabrics: B 0.0023–2.71 gf·cm²/cm, weight 15–870 g/m²), §2.5
//! (KES values quoted for suitings, cotton and stretch twills: EMT 1.2–18 %, LT 0.5–0.6,
//! RT 73–78 %, G 0.5–0.65 gf/(cm·deg), 2HG5 0.8–1.5 gf/cm), §3 (the definitions: LT, LC ≤ 1,
//! RT, RC ≤ 100 %), and the ten Wang 2011 fabrics (weight 113–324 g/m²).

use super::kes_param::KesParam;

/// A closed range `[lo, hi]`, or `(lo, hi]` when `lo_open`, in a parameter's KES unit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Range {
    /// Lower bound.
    pub lo: f64,
    /// Whether the lower bound itself is excluded.
    pub lo_open: bool,
    /// Upper bound (included).
    pub hi: f64,
    /// The KES unit the bounds are in ("%", "gf.cm2/cm", …; "-" for ratios).
    pub unit: &'static str,
}

impl Range {
    const fn closed(lo: f64, hi: f64, unit: &'static str) -> Range {
        Range {
            lo,
            lo_open: false,
            hi,
            unit,
        }
    }

    const fn open_below(lo: f64, hi: f64, unit: &'static str) -> Range {
        Range {
            lo,
            lo_open: true,
            hi,
            unit,
        }
    }

    /// Whether `v` (KES unit) lies in the range (NaN does not).
    pub fn contains(&self, v: f64) -> bool {
        let low = if self.lo_open {
            v > self.lo
        } else {
            v >= self.lo
        };
        low && v <= self.hi
    }

    /// `v` if it lies in the range, else the message: the value and the range of real fabrics.
    pub fn check(&self, v: f64) -> Result<f64, String> {
        if self.contains(v) {
            Ok(v)
        } else {
            let unit = if self.unit == "-" {
                String::new()
            } else {
                format!(" {}", self.unit)
            };
            let above = if self.lo_open { "above " } else { "" };
            Err(format!(
                "{}{unit} is outside the range of real fabrics, {above}{} … {}{unit} (docs/kes-lab.md, \"Ranges of real fabrics\")",
                shown(v),
                self.lo,
                self.hi
            ))
        }
    }
}

/// `v` for a message: plain for ordinary magnitudes, in exponent form for huge or tiny ones.
fn shown(v: f64) -> String {
    if v != 0.0 && v.is_finite() && !(1e-4..1e6).contains(&v.abs()) {
        format!("{v:e}")
    } else {
        format!("{v}")
    }
}

/// The range of real fabrics of a KES parameter, in its KES unit.
pub fn param_range(p: KesParam) -> Range {
    use KesParam::*;
    match p {
        // 0 reads (the lab then names it: no tensile law), negative or past 100 % does not
        Emt => Range::closed(0.0, 100.0, "%"),
        Lt => Range::open_below(0.0, 1.0, "-"),
        Wt => Range::closed(0.0, 500.0, "gf.cm/cm2"),
        Rt => Range::closed(0.0, 100.0, "%"),
        G => Range::closed(0.0, 50.0, "gf/(cm.deg)"),
        Hg2 | Hg52 => Range::closed(0.0, 100.0, "gf/cm"),
        B => Range::closed(1e-4, 10.0, "gf.cm2/cm"),
        Hb2 => Range::closed(0.0, 10.0, "gf.cm/cm"),
        Lc => Range::open_below(0.0, 1.0, "-"),
        Wc => Range::closed(0.0, 10.0, "gf.cm/cm2"),
        Rc => Range::closed(0.0, 100.0, "%"),
        T0 | Tm => Range::open_below(0.0, 20.0, "mm"),
        Miu => Range::closed(0.0, 2.0, "-"),
        Mmd => Range::closed(0.0, 1.0, "-"),
        Smd => Range::closed(0.0, 100.0, "um"),
    }
}

/// Areal weight of real fabrics: 0.1 … 500 mg/cm² (1 g/m² … 5 kg/m²).
pub const WEIGHT: Range = Range::closed(0.1, 500.0, "mg/cm2");

/// Thickness of real fabrics: above 0, at most 20 mm.
pub const THICKNESS: Range = Range::open_below(0.0, 20.0, "mm");

/// Maximum load of a tensile protocol: above 0, at most 5000 gf/cm (ten times the standard).
pub const TENSILE_FM: Range = Range::open_below(0.0, 5000.0, "gf/cm");

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kes::kes_param::ALL_PARAMS;

    #[test]
    fn every_range_is_in_the_parameters_kes_unit_and_holds_typical_values() {
        for p in ALL_PARAMS {
            let r = param_range(p);
            let unit = crate::kes::units::quantity_of(p).kes_unit().symbol();
            assert_eq!(r.unit, unit, "{}", p.name());
            assert!(r.lo < r.hi && !r.contains(f64::NAN) && !r.contains(-1.0));
        }
        // the maths notes' §2.2 extremes of B and the HESC suiting's RT
        assert!(
            param_range(KesParam::B).contains(0.0023) && param_range(KesParam::B).contains(2.71)
        );
        assert!(param_range(KesParam::Rt).contains(75.0));
        assert!(!param_range(KesParam::B).contains(1e308));
        let e = param_range(KesParam::Rt).check(120.0).unwrap_err();
        assert!(e.contains("100 %"), "{e}");
    }
}
