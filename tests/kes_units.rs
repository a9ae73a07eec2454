//! KES ↔ SI conversions: one assertion per row of the table in the maths notes §1
//! (`../shared/reference/kawabata-and-cloth-maths.md`), with the factor written out; unit
//! spellings; units of the wrong kind refused.

use emilion::kes::units::{self, to_si, unit_for, Quantity, Unit, UnitError};
use emilion::kes::KesParam;

fn close(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * b.abs()
}

/// `to_si(1 unit)` equals `factor` to 1e-12 relative.
fn pin(unit: &str, q: Quantity, factor: f64) {
    let si = to_si(1.0, unit, q).unwrap_or_else(|e| panic!("{unit}: {e}"));
    assert!(close(si, factor, 1e-12), "{unit} ({q:?}): {si} vs {factor}");
}

#[test]
fn tensile_force_per_width_gf_per_cm_is_0_980665_n_per_m() {
    pin("gf/cm", Quantity::ForcePerWidth, 0.980665);
    assert!(close(units::GF_PER_CM, 0.980665, 1e-12));
    assert!(close(units::gf_per_cm(500.0), 490.3325, 1e-12));
}

#[test]
fn emt_percent_is_0_01() {
    pin("%", Quantity::Fraction, 0.01);
    assert!(close(units::percent(4.7), 0.047, 1e-12));
}

#[test]
fn energy_per_area_gf_cm_per_cm2_is_0_980665_j_per_m2() {
    pin("gf.cm/cm2", Quantity::EnergyPerArea, 0.980665);
    assert!(close(units::GF_CM_PER_CM2, 0.980665, 1e-12));
}

#[test]
fn linearity_lt_lc_is_1() {
    pin("-", Quantity::Ratio, 1.0);
}

#[test]
fn resilience_rt_rc_percent_is_0_01() {
    // RT, RC are percentages like EMT
    assert_eq!(units::quantity_of(KesParam::Rt), Quantity::Fraction);
    assert_eq!(units::quantity_of(KesParam::Rc), Quantity::Fraction);
    pin("%", Quantity::Fraction, 0.01);
}

#[test]
fn shear_rigidity_gf_per_cm_deg_is_0_980665_times_180_over_pi() {
    // 0.980665 · 180/π = 56.18797…; the notes print 56.1887, a slip in the 4th decimal
    let exact = 0.980665 * 180.0 / std::f64::consts::PI;
    pin("gf/(cm.deg)", Quantity::ShearRigidity, exact);
    assert!(close(exact, 56.18797, 1e-6), "{exact}");
    assert!(close(units::GF_PER_CM_DEG, exact, 1e-12));
}

#[test]
fn shear_hysteresis_2hg_gf_per_cm_is_0_980665_n_per_m() {
    assert_eq!(units::quantity_of(KesParam::Hg2), Quantity::ForcePerWidth);
    assert_eq!(units::quantity_of(KesParam::Hg52), Quantity::ForcePerWidth);
    pin("gf/cm", Quantity::ForcePerWidth, 0.980665);
}

#[test]
fn bending_rigidity_gf_cm2_per_cm_is_9_80665e_5_n_m() {
    pin("gf.cm2/cm", Quantity::BendingRigidity, 9.80665e-5);
    assert!(close(units::gf_cm2_per_cm(0.655), 6.4233558e-5, 1e-7));
}

#[test]
fn bending_hysteresis_2hb_gf_cm_per_cm_is_9_80665e_3_n() {
    pin("gf.cm/cm", Quantity::MomentPerWidth, 9.80665e-3);
}

#[test]
fn curvature_per_cm_is_100_per_m() {
    pin("1/cm", Quantity::Curvature, 100.0);
    pin("cm-1", Quantity::Curvature, 100.0);
}

#[test]
fn pressure_gf_per_cm2_is_98_0665_pa() {
    pin("gf/cm2", Quantity::Pressure, 98.0665);
}

#[test]
fn thickness_mm_is_1e_3_m() {
    pin("mm", Quantity::Thickness, 1e-3);
}

#[test]
fn areal_weight_mg_per_cm2_is_0_01_kg_per_m2() {
    pin("mg/cm2", Quantity::ArealWeight, 0.01);
    // 10 mg/cm² = 100 g/m² = 0.1 kg/m²
    assert!(close(
        to_si(10.0, "mg/cm2", Quantity::ArealWeight).unwrap(),
        0.1,
        1e-12
    ));
    pin("g/m2", Quantity::ArealWeight, 1e-3);
}

#[test]
fn friction_miu_mmd_is_1() {
    assert_eq!(units::quantity_of(KesParam::Miu), Quantity::Ratio);
    assert_eq!(units::quantity_of(KesParam::Mmd), Quantity::Ratio);
    pin("-", Quantity::Ratio, 1.0);
}

#[test]
fn roughness_smd_um_is_1e_6_m() {
    pin("um", Quantity::Roughness, 1e-6);
    pin("µm", Quantity::Roughness, 1e-6);
}

#[test]
fn angle_deg_is_pi_over_180_rad() {
    pin("deg", Quantity::Angle, 0.017453292519943295);
}

#[test]
fn si_units_have_factor_1() {
    for (u, q) in [
        ("N/m", Quantity::ForcePerWidth),
        ("N.m", Quantity::BendingRigidity),
        ("N", Quantity::MomentPerWidth),
        ("1/m", Quantity::Curvature),
        ("rad", Quantity::Angle),
        ("kg/m2", Quantity::ArealWeight),
        ("m", Quantity::Thickness),
        ("m", Quantity::Roughness),
        ("Pa", Quantity::Pressure),
        ("J/m2", Quantity::EnergyPerArea),
        ("N/m", Quantity::EnergyPerArea),
        ("N/m/rad", Quantity::ShearRigidity),
        ("-", Quantity::Fraction),
    ] {
        pin(u, q, 1.0);
    }
}

#[test]
fn ascii_and_typographic_spellings_parse_to_the_same_unit() {
    let same = [
        (
            Unit::GfCmPerCm2,
            &["gf.cm/cm2", "gf*cm/cm^2", "gf·cm/cm²", " gf.cm/cm2 "][..],
        ),
        (
            Unit::GfCm2PerCm,
            &["gf.cm2/cm", "gf*cm^2/cm", "gf·cm²/cm"][..],
        ),
        (
            Unit::GfPerCmDeg,
            &["gf/cm/deg", "gf/(cm.deg)", "gf/(cm·deg)"][..],
        ),
        (Unit::PerCm, &["1/cm", "cm-1", "cm^-1", "cm⁻¹"][..]),
        (Unit::Um, &["um", "µm", "μm"][..]),
        (Unit::NPerMRad, &["N/m/rad", "N/(m.rad)"][..]),
        (Unit::NM, &["N.m", "N*m", "N·m"][..]),
        (Unit::N, &["N", "N.m/m"][..]),
        (Unit::KgPerM2, &["kg/m2", "kg/m^2"][..]),
        (Unit::GfPerCm, &["gf/cm"][..]),
        (Unit::Percent, &["%"][..]),
        (Unit::One, &["-"][..]),
        (Unit::Deg, &["deg"][..]),
        (Unit::Mm, &["mm"][..]),
        (Unit::MgPerCm2, &["mg/cm2"][..]),
        (Unit::GfPerCm2, &["gf/cm2"][..]),
        (Unit::PerM, &["1/m"][..]),
        (Unit::Rad, &["rad"][..]),
        (Unit::M, &["m"][..]),
        (Unit::Pa, &["Pa"][..]),
        (Unit::JPerM2, &["J/m2"][..]),
    ];
    for (unit, spellings) in same {
        for s in spellings {
            assert_eq!(Unit::parse(s), Some(unit), "`{s}`");
        }
    }
    for bad in ["", "gf", "Mm", "inch", "gf/mm", "kg"] {
        assert_eq!(Unit::parse(bad), None, "`{bad}`");
    }
}

#[test]
fn a_unit_of_the_wrong_kind_is_an_error() {
    // B in a force per width, EMT in mm, G in N/m, 2HB in N.m, an unknown spelling
    for (u, q) in [
        ("gf/cm", Quantity::BendingRigidity),
        ("mm", Quantity::Fraction),
        ("N/m", Quantity::ShearRigidity),
        ("N.m", Quantity::MomentPerWidth),
        ("%", Quantity::Ratio),
        ("deg", Quantity::Curvature),
    ] {
        let e = to_si(1.0, u, q).unwrap_err();
        assert!(matches!(e, UnitError::WrongKind { .. }), "{u} {q:?}: {e:?}");
        let msg = e.to_string();
        assert!(
            msg.contains(u) && msg.contains(q.kes_unit().symbol()),
            "{msg}"
        );
    }
    let e = unit_for("furlong", Quantity::Thickness).unwrap_err();
    assert!(matches!(e, UnitError::Unknown { .. }), "{e:?}");
    assert!(e.to_string().contains("furlong"));
}

#[test]
fn each_kes_parameter_has_its_kes_unit_and_converts_back() {
    let expect = [
        (KesParam::Emt, "%"),
        (KesParam::Lt, "-"),
        (KesParam::Wt, "gf.cm/cm2"),
        (KesParam::Rt, "%"),
        (KesParam::G, "gf/(cm.deg)"),
        (KesParam::Hg2, "gf/cm"),
        (KesParam::Hg52, "gf/cm"),
        (KesParam::B, "gf.cm2/cm"),
        (KesParam::Hb2, "gf.cm/cm"),
        (KesParam::Lc, "-"),
        (KesParam::Wc, "gf.cm/cm2"),
        (KesParam::Rc, "%"),
        (KesParam::T0, "mm"),
        (KesParam::Tm, "mm"),
        (KesParam::Miu, "-"),
        (KesParam::Mmd, "-"),
        (KesParam::Smd, "um"),
    ];
    for (p, unit) in expect {
        let (u, v) = units::to_kes(p, to_si(1.25, unit, units::quantity_of(p)).unwrap());
        assert_eq!(u, unit, "{p:?}");
        assert!(close(v, 1.25, 1e-12), "{p:?}: {v}");
    }
    // 1 gf·cm²/cm written back from 9.80665e-5 N·m
    let (u, v) = units::to_kes(KesParam::B, 9.80665e-5);
    assert_eq!(u, "gf.cm2/cm");
    assert!(close(v, 1.0, 1e-12));
}
