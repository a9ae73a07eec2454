//! The measured-fabric module: KES units, fabric files, the Wang 2011 import, and the
//! virtual Kawabata lab against its acceptance figures (parameter recovery, curve round trip
//! on a coarse and a fine mesh, Peirce cantilever, damping fit).

use std::path::{Path, PathBuf};
use std::sync::Arc;

use emilion::cloth::{Direction, FabricParameters, LinearMaterial};
use emilion::kes::fabric::parse_fabric;
use emilion::kes::units::{self, to_si, Quantity};
use emilion::kes::{lab, read_fabric, rig, wang, write_fabric, KesParam};

fn wang_dir() -> PathBuf {
    PathBuf::from(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../shared/data/fabrics/wang2011"
    ))
}

fn repo(p: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(p)
}

fn close(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * b.abs()
}

#[test]
fn each_kes_conversion_has_its_factor() {
    // kawabata-and-cloth-maths.md §1, one row each
    let rows: [(f64, &str, Quantity, f64); 13] = [
        (1.0, "gf/cm", Quantity::ForcePerWidth, 0.980665),
        (1.0, "%", Quantity::Fraction, 0.01),
        (1.0, "gf.cm/cm2", Quantity::EnergyPerArea, 0.980665),
        (1.0, "-", Quantity::Ratio, 1.0),
        // the notes print 56.1887 with a rounding slip in the last digit; to 5 figures: 56.188
        (1.0, "gf/(cm.deg)", Quantity::ShearRigidity, 56.188),
        (1.0, "gf.cm2/cm", Quantity::BendingRigidity, 9.80665e-5),
        (1.0, "gf.cm/cm", Quantity::MomentPerWidth, 9.80665e-3),
        (1.0, "1/cm", Quantity::Curvature, 100.0),
        (1.0, "gf/cm2", Quantity::Pressure, 98.0665),
        (1.0, "mm", Quantity::Thickness, 1e-3),
        (1.0, "mg/cm2", Quantity::ArealWeight, 0.01),
        (1.0, "um", Quantity::Roughness, 1e-6),
        (1.0, "deg", Quantity::Angle, std::f64::consts::PI / 180.0),
    ];
    for (v, unit, q, factor) in rows {
        let si = to_si(v, unit, q).unwrap();
        assert!(close(si, factor, 1e-5), "{unit}: {si} vs {factor}");
    }
    // 10 mg/cm² = 100 g/m²
    assert!(close(
        to_si(10.0, "mg/cm2", Quantity::ArealWeight).unwrap(),
        0.1,
        1e-12
    ));
    // the exact shear factor is 0.980665 · 180/π
    assert!(close(
        units::GF_PER_CM_DEG,
        0.980665 * 180.0 / std::f64::consts::PI,
        1e-12
    ));
    // a unit of another quantity is refused
    assert!(to_si(1.0, "gf/cm", Quantity::BendingRigidity).is_err());
    // and the way back
    let (u, v) = units::to_kes(KesParam::B, 9.80665e-5);
    assert_eq!(u, "gf.cm2/cm");
    assert!(close(v, 1.0, 1e-12));
}

#[test]
fn bad_fabric_files_name_file_and_field() {
    let cases = [
        ("missing_weight.json", "weight"),
        ("wrong_unit.json", "kes.warp.B"),
        ("negative_g.json", "kes.weft.G"),
        ("nan_value.json", "kes.warp.EMT"),
        ("malformed.json", "malformed.json:"),
        ("bad_curve.json", "curves.shear.loading[2]"),
    ];
    for (file, field) in cases {
        let path = repo("tests/data/fabrics_bad").join(file);
        let err = read_fabric(&path).expect_err(file).to_string();
        assert!(err.contains(file), "{err}");
        assert!(err.contains(field), "{file}: {err}");
    }
}

#[test]
fn a_fabric_without_a_usable_law_is_an_error_not_a_panic() {
    // EMT = 0 is a valid number but no tensile law: the lab names the file and the field
    let path = repo("tests/data/fabrics_bad/zero_emt.json");
    let spec = read_fabric(&path).unwrap();
    let err = lab::run_fabric(&spec, &lab::LabOptions::default()).unwrap_err();
    assert!(
        err.contains("zero_emt.json") && err.contains("kes.warp.EMT"),
        "{err}"
    );
}

#[test]
fn fabric_files_round_trip_in_kes_units() {
    let spec = read_fabric(&repo("kawabata/fabrics/suiting-hesc.json")).unwrap();
    assert!(close(spec.density, 0.22, 1e-12));
    assert!(close(spec.warp.get(KesParam::Emt).unwrap(), 0.047, 1e-12));
    assert!(close(
        spec.warp.get(KesParam::B).unwrap(),
        0.10 * 9.80665e-5,
        1e-12
    ));
    let dir = std::env::temp_dir().join(format!("emilion-fabric-{}", std::process::id()));
    let out = dir.join("copy.json");
    write_fabric(&out, &spec).unwrap();
    let back = read_fabric(&out).unwrap();
    for p in [
        KesParam::Emt,
        KesParam::Lt,
        KesParam::Rt,
        KesParam::G,
        KesParam::Hg52,
        KesParam::B,
        KesParam::Hb2,
    ] {
        assert!(
            close(back.warp.get(p).unwrap(), spec.warp.get(p).unwrap(), 1e-12),
            "{p:?}"
        );
    }
    assert!(parse_fabric("{\"format\": \"x\"}", "t.json")
        .unwrap_err()
        .to_string()
        .contains("format"));
    std::fs::remove_dir_all(dir).ok();
}

#[test]
fn wang_fabrics_import_with_their_tables() {
    let dir = wang_dir();
    if !dir.exists() {
        eprintln!("skipped: {} not found", dir.display());
        return;
    }
    let out = std::env::temp_dir().join(format!("emilion-wang-{}", std::process::id()));
    let files = wang::import_wang_dir(&dir, &out).unwrap();
    assert_eq!(files.len(), 10);
    let denim = read_fabric(&out.join("11oz-black-denim.json")).unwrap();
    assert!(close(denim.density, 0.324, 1e-9));
    // small-strain slope of the warp curve = 2 c11 = 410.70 N/m
    let t = &denim.curves.tensile_warp.as_ref().unwrap().loading;
    assert_eq!(t[0], [0.0, 0.0]);
    let slope = t[1][1] / t[1][0];
    assert!(close(slope, 2.0 * 205.352005, 0.02), "{slope}");
    // weft bending (hinge row 0) at 10 1/m: 60.286175e-6 N·m × 10 1/m
    let b = &denim.curves.bending_weft.as_ref().unwrap().loading;
    let at10 = b.iter().find(|p| (p[0] - 10.0).abs() < 1e-9).unwrap();
    assert!(close(at10[1], 60.286175e-6 * 10.0, 1e-6), "{:?}", at10);
    // shear at 8°: c33(8°)/2 · φ + 10 gf/cm · tan φ, c33 between row 0 and row 3 (45°)
    let s = denim.curves.shear.as_ref().unwrap().loading.last().unwrap();
    let phi = 8f64.to_radians();
    let c33 = 53.387184 + (83.992020 - 53.387184) * (3.0 * phi);
    assert!(
        close(s[1], 0.5 * c33 * phi + 9.80665 * phi.tan(), 1e-6),
        "{s:?}"
    );
    std::fs::remove_dir_all(out).ok();
}

#[test]
fn rigs_recover_kes_parameters_within_5_percent() {
    let spec = read_fabric(&repo("kawabata/fabrics/suiting-hesc.json")).unwrap();
    let opts = lab::LabOptions {
        cantilever: false,
        ..Default::default()
    };
    let r = lab::run_fabric(&spec, &opts).unwrap();
    let names: Vec<&str> = r.params.iter().map(|p| p.param.as_str()).collect();
    for want in ["EMT", "LT", "WT", "RT", "G", "2HG", "2HG5", "B", "2HB"] {
        assert!(names.contains(&want), "{want} not compared");
    }
    for p in &r.params {
        assert!(
            p.error_pct.abs() <= 5.0,
            "{} {} {}: {:.3} vs {:.3} ({:+.2} %)",
            p.test,
            p.mesh,
            p.param,
            p.simulated,
            p.measured,
            p.error_pct
        );
    }
    // the loops are really there: widths measured from simulated loops are not zero
    let hb = r
        .params
        .iter()
        .find(|p| p.param == "2HB" && p.mesh == "fine")
        .unwrap();
    assert!(hb.simulated > 0.5 * hb.measured);
}

#[test]
fn wang_curves_round_trip_on_coarse_and_fine_meshes() {
    let dir = wang_dir();
    if !dir.exists() {
        eprintln!("skipped: {} not found", dir.display());
        return;
    }
    for name in ["11oz-black-denim", "ivory-rib-knit", "white-swim-solid"] {
        let spec = wang::import_wang(&dir.join(format!("{name}.json"))).unwrap();
        let opts = lab::LabOptions {
            cantilever: false,
            ..Default::default()
        };
        let r = lab::run_fabric(&spec, &opts).unwrap();
        assert_eq!(r.curves.len(), 10, "{name}: 5 curves × 2 meshes");
        for c in &r.curves {
            assert!(
                c.rms_pct <= 3.0,
                "{name} {} {}: {:.2} %",
                c.test,
                c.mesh,
                c.rms_pct
            );
        }
    }
}

#[test]
fn peirce_cantilever_gives_the_bending_length() {
    let b = 0.1 * 9.80665e-5; // 0.1 gf·cm²/cm
    let w = 0.15; // kg/m² (15 mg/cm²)
    let law = Arc::new(LinearMaterial {
        stretch_warp: 2000.0,
        stretch_weft: 2000.0,
        shear: 20.0,
        bend_warp: b,
        bend_weft: b,
    });
    let theory = (b / (w * 9.81)).cbrt();
    let c = rig::bending_length(law, w, Direction::Warp, theory).unwrap();
    assert!(
        close(c, theory, 0.03),
        "c = {c} m vs (B/W)^(1/3) = {theory} m"
    );
}

#[test]
fn damping_fit_recovers_stretch_damping() {
    use emilion::kes::damping::{fit_stretch_damping, free_oscillation, DecayExperiment};
    let fab = FabricParameters {
        stretch_damping: 3e-5,
        ..Default::default()
    };
    let law = Arc::new(fab.linear_law());
    let target = free_oscillation(fab, law.clone(), DecayExperiment::default()).unwrap();
    assert!(target.log_decrement > 0.01);
    let undamped = FabricParameters {
        stretch_damping: 0.0,
        ..fab
    };
    let (beta, _) = fit_stretch_damping(
        undamped,
        law,
        DecayExperiment::default(),
        target.log_decrement,
    )
    .unwrap();
    assert!(close(beta, 3e-5, 0.05), "β = {beta}");
}

/// Regression: `Simulation::energy` committed the internal-friction states its evaluation
/// passed through, so a script that printed the energy every frame drove a fabric with
/// hysteresis along another trajectory (the A-shirt's worst seam gap at 1.5 s: 0.25927 mm
/// against 0.25889 mm). Reading the energy must leave the run bit for bit as it was.
#[test]
fn reading_the_energy_leaves_a_hysteretic_cloth_on_its_trajectory() {
    use emilion::cloth::{ClothModel, Simulation, SimulationParameters};
    let spec = read_fabric(&repo("kawabata/fabrics/shirting-cotton.json")).unwrap();
    let (fabric, law) = lab::measured_fabric(&spec).unwrap();
    assert!(
        emilion::cloth::MaterialLaw::has_friction(&law),
        "the fabric has hysteresis"
    );
    let law = Arc::new(law);
    let run = |read: bool| {
        let n = 12;
        let mut model = ClothModel::grid(0.3, 0.3, n, n, fabric).unwrap();
        model.set_law(law.clone());
        let params = SimulationParameters {
            dt: 1.0 / 120.0,
            ..Default::default()
        };
        let mut sim = Simulation::new(model, params).unwrap();
        sim.pin(&[0, n - 1]).unwrap();
        let mut energies = Vec::new();
        for _ in 0..40 {
            sim.step().unwrap();
            if read {
                energies.push(sim.energy());
            }
        }
        (sim.state.x.clone(), energies)
    };
    let (quiet, _) = run(false);
    let (read, energies) = run(true);
    assert!(energies.iter().all(|e| e.2 > 0.0), "the cloth is strained");
    assert!(quiet == read, "reading the energy changed the trajectory");
}
