//! The virtual Kawabata lab: runs every rig on a fabric (after fitting its law to the fabric's
//! KES parameters), computes the KES parameters of the simulated curves with the standard
//! formulas, compares them and the curves with the measurements, and writes per-fabric CSV
//! and plots plus a summary table (CSV and Markdown).

use std::path::{Path, PathBuf};

use super::calibrate::{self, LawModel, Measurements, ModeData, RigRun, Tests};
use super::fabric::{Curve, FabricSpec};
use super::kes_param::KesParam;
use super::parameters::{bending_parameters, interp, shear_parameters, tensile_parameters};
use super::rig::{self, RigCurve, RigMesh};
use super::rig_parameters::{branches, measured_value, simulated_params};
use super::units;
use crate::cloth::{Direction, MaterialLaw};
use crate::render::plot::{write_plot_pair, write_series_csv, PlotSpec, Series, SeriesStyle};

/// Options of a lab run.
#[derive(Debug, Clone, PartialEq)]
pub struct LabOptions {
    /// Sample meshes to run (the first is also used for fitting).
    pub meshes: Vec<(String, RigMesh)>,
    /// Fit KES-parameter modes before the final runs.
    pub fit: bool,
    /// Fitting rounds at most.
    pub fit_rounds: usize,
    /// Run the Peirce cantilever too.
    pub cantilever: bool,
    /// Which rigs to run.
    pub tests: Tests,
}

impl Default for LabOptions {
    fn default() -> Self {
        LabOptions {
            meshes: vec![
                ("coarse".into(), RigMesh::COARSE),
                ("fine".into(), RigMesh::FINE),
            ],
            fit: true,
            fit_rounds: 8,
            cantilever: true,
            tests: Tests::ALL,
        }
    }
}

/// One compared KES parameter, in KES units.
#[derive(Debug, Clone, PartialEq)]
pub struct ParamRow {
    /// Test name (tensile_warp, shear, bending_weft, …).
    pub test: String,
    /// Mesh name.
    pub mesh: String,
    /// KES name (EMT, LT, …).
    pub param: String,
    /// KES unit.
    pub unit: String,
    /// From the fabric file (or computed from its measured curves).
    pub measured: f64,
    /// From the simulated curve.
    pub simulated: f64,
    /// Relative error (%).
    pub error_pct: f64,
}

/// Curve agreement of one test.
#[derive(Debug, Clone, PartialEq)]
pub struct CurveRow {
    /// Test name.
    pub test: String,
    /// Mesh name.
    pub mesh: String,
    /// RMS difference as a percentage of the measured curve's range.
    pub rms_pct: f64,
}

/// Everything the lab found for one fabric.
#[derive(Debug, Clone, PartialEq)]
pub struct FabricReport {
    /// Fabric name.
    pub name: String,
    /// Compared parameters.
    pub params: Vec<ParamRow>,
    /// Compared curves.
    pub curves: Vec<CurveRow>,
    /// The runs, per mesh name.
    pub runs: Vec<(String, RigRun)>,
    /// Measured curves (SI loading branches) per test, for plots.
    pub inputs: Vec<(String, Vec<[f64; 2]>)>,
    /// Fitting rounds used.
    pub fit_rounds: usize,
    /// Bending length (m), simulated and (B/W)^(1/3), warp.
    pub bending_length: Option<(f64, f64)>,
    /// The fitted law model.
    pub model: LawModel,
}

impl FabricReport {
    /// Largest curve RMS (%), or 0 without measured curves.
    pub fn worst_curve(&self) -> f64 {
        self.curves.iter().map(|c| c.rms_pct).fold(0.0, f64::max)
    }
    /// Rig increments, over all runs, whose equilibrium stopped at the iteration cap.
    pub fn unconverged(&self) -> usize {
        self.runs
            .iter()
            .map(|(_, r)| {
                r.tensile.iter().map(|c| c.unconverged).sum::<usize>()
                    + r.shear.unconverged
                    + r.bending.iter().map(|c| c.unconverged).sum::<usize>()
            })
            .sum()
    }

    /// Largest parameter error (%).
    pub fn worst_param(&self) -> f64 {
        self.params
            .iter()
            .map(|p| p.error_pct.abs())
            .fold(0.0, f64::max)
    }
}

fn mode(c: &Option<Curve>) -> Option<ModeData> {
    c.as_ref().map(|c| ModeData {
        loading: c.loading.clone(),
        unloading: c.unloading.clone(),
    })
}

/// The material law of a fabric file straight from its measurements (KES parameters or
/// curves), before any calibration against the virtual rigs, and the fabric's linear
/// parameters with its areal density, for simulations of garments in that fabric. Errors name
/// the file.
pub fn measured_fabric(
    spec: &FabricSpec,
) -> Result<(crate::cloth::FabricParameters, crate::cloth::MeasuredLaw), String> {
    let model =
        LawModel::new(&measurements(spec)).map_err(|e| format!("{}: {e}", display_path(spec)))?;
    let params = crate::cloth::FabricParameters {
        density: spec.density,
        ..Default::default()
    };
    Ok((params, model.law()))
}

/// The measurements of a fabric file in the calibration's terms.
pub fn measurements(spec: &FabricSpec) -> Measurements {
    let kes = |d: usize, p: KesParam| {
        if d == 0 {
            spec.warp.get(p)
        } else {
            spec.weft.get(p)
        }
    };
    let mean = |p: KesParam| match (spec.warp.get(p), spec.weft.get(p)) {
        (Some(a), Some(b)) => Some(0.5 * (a + b)),
        (a, b) => a.or(b),
    };
    let c = &spec.curves;
    Measurements {
        density: spec.density,
        tensile_fm: spec.tensile_fm,
        tensile_curve: [mode(&c.tensile_warp), mode(&c.tensile_weft)],
        tensile_kes: [0, 1].map(|d| {
            (
                kes(d, KesParam::Emt),
                kes(d, KesParam::Lt),
                kes(d, KesParam::Rt),
            )
        }),
        shear_curve: mode(&c.shear),
        shear_kes: (mean(KesParam::G), mean(KesParam::Hg2), mean(KesParam::Hg52)),
        bending_curve: [mode(&c.bending_warp), mode(&c.bending_weft)],
        bending_kes: [0, 1].map(|d| (kes(d, KesParam::B), kes(d, KesParam::Hb2))),
    }
}

/// RMS difference (% of the measured range) between a measured loading branch and the
/// simulated one, over the measured points the simulation covers (x ≥ 0).
pub fn curve_rms_pct(measured: &[[f64; 2]], simulated: &[[f64; 2]]) -> Option<f64> {
    let pts: Vec<&[f64; 2]> = measured.iter().filter(|p| p[0] >= 0.0).collect();
    let (lo, hi) = pts
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), p| {
            (l.min(p[1]), h.max(p[1]))
        });
    let mut sim = simulated.to_vec();
    sim.sort_by(|a, b| a[0].total_cmp(&b[0]));
    let (mut sum, mut n) = (0.0, 0usize);
    for p in pts {
        if let Some(y) = interp(&sim, p[0]) {
            sum += (y - p[1]).powi(2);
            n += 1;
        }
    }
    (n > 0 && hi > lo).then(|| 100.0 * (sum / n as f64).sqrt() / (hi - lo))
}

/// KES name and unit of a parameter, and its value converted from SI to KES units.
fn kes_units(p: KesParam, si: f64) -> (String, String, f64) {
    let (unit, v) = units::to_kes(p, si);
    (p.name().to_string(), unit.to_string(), v)
}

/// Runs the lab on one fabric.
pub fn run_fabric(spec: &FabricSpec, opts: &LabOptions) -> Result<FabricReport, String> {
    super::fabric::check_ranges(spec)
        .map_err(|(field, m)| format!("{}: field `{field}`: {m}", display_path(spec)))?;
    let meas = measurements(spec);
    let mut model = LawModel::new(&meas).map_err(|e| format!("{}: {e}", display_path(spec)))?;
    let mut rounds = 0;
    if opts.fit && model.has_kes_modes() {
        let mesh = opts.meshes.first().map_or(RigMesh::COARSE, |m| m.1);
        rounds = super::fit::fit(spec, &mut model, mesh, opts.fit_rounds, opts.tests)
            .map_err(|e| format!("{}: fitting: {e}", display_path(spec)))?;
    }
    let mut report = FabricReport {
        name: spec.name.clone(),
        params: Vec::new(),
        curves: Vec::new(),
        runs: Vec::new(),
        inputs: Vec::new(),
        fit_rounds: rounds,
        bending_length: None,
        model: model.clone(),
    };
    let c = &spec.curves;
    let inputs: [(&str, &Option<Curve>); 5] = [
        ("tensile_warp", &c.tensile_warp),
        ("tensile_weft", &c.tensile_weft),
        ("shear", &c.shear),
        ("bending_warp", &c.bending_warp),
        ("bending_weft", &c.bending_weft),
    ];
    for (test, curve) in inputs {
        if let Some(cv) = curve {
            report.inputs.push((test.to_string(), cv.loading.clone()));
        }
    }
    for (mesh_name, mesh) in &opts.meshes {
        let run = calibrate::run_rigs(&model, *mesh, opts.tests)
            .map_err(|e| format!("{}: {e}", display_path(spec)))?;
        for (test, v) in simulated_params(&run, &model) {
            for (p, s) in v {
                let measured = measured_value(spec, &test, p)
                    .or_else(|| curve_param(&report.inputs, &test, p, &model));
                let Some(m) = measured else { continue };
                let (name, unit, mk) = kes_units(p, m);
                let (_, _, sk) = kes_units(p, s);
                if mk.abs() < 1e-9 {
                    continue;
                }
                report.params.push(ParamRow {
                    test: test.clone(),
                    mesh: mesh_name.clone(),
                    param: name,
                    unit,
                    measured: mk,
                    simulated: sk,
                    error_pct: 100.0 * (sk - mk) / mk,
                });
            }
        }
        for (test, input) in &report.inputs {
            let path = test_path(&run, test);
            if path.path.is_empty() {
                continue;
            }
            let (virgin, _, _) = branches(&path.path);
            if let Some(rms) = curve_rms_pct(input, &virgin) {
                report.curves.push(CurveRow {
                    test: test.clone(),
                    mesh: mesh_name.clone(),
                    rms_pct: rms,
                });
            }
        }
        report.runs.push((mesh_name.clone(), run));
    }
    if opts.cantilever {
        // the Peirce test of the elastic backbone (friction would hold a monotonically loaded
        // strip up by its threshold moment, as in real cantilever tests)
        let mut elastic = model.law();
        elastic.bending_friction = [None, None];
        elastic.tension_friction = [None, None];
        elastic.shear_friction = None;
        let law = std::sync::Arc::new(elastic);
        let b = law.bending(Direction::Warp, 1e-3).1;
        let q = spec.density * 9.81;
        let theory = (b / q).cbrt();
        let sim = rig::bending_length(law, spec.density, Direction::Warp, theory)
            .map_err(|e| format!("{}: cantilever: {e}", display_path(spec)))?;
        report.bending_length = Some((sim, theory));
    }
    Ok(report)
}

/// For fabrics given by curves only: the parameter computed from the measured loading curve
/// with the same formula as for the simulated one (elastic curves: forward = backward).
fn curve_param(
    inputs: &[(String, Vec<[f64; 2]>)],
    test: &str,
    p: KesParam,
    model: &LawModel,
) -> Option<f64> {
    let (_, curve) = inputs.iter().find(|(t, _)| t == test)?;
    let odd: Vec<[f64; 2]> = {
        let mut v: Vec<[f64; 2]> = curve
            .iter()
            .filter(|q| q[0] > 0.0)
            .map(|q| [-q[0], -q[1]])
            .collect();
        v.extend(curve.iter().filter(|q| q[0] >= 0.0).copied());
        v.sort_by(|a, b| a[0].total_cmp(&b[0]));
        v
    };
    match (test, p) {
        ("tensile_warp" | "tensile_weft", _) => {
            let d = usize::from(test.ends_with("weft"));
            let t = tensile_parameters(curve, &[], model.protocol.tensile_fm[d])?;
            match p {
                KesParam::Emt => Some(t.emt),
                KesParam::Lt => Some(t.lt),
                KesParam::Wt => Some(t.wt),
                _ => None,
            }
        }
        ("shear", KesParam::G) => shear_parameters(&odd, &odd).map(|s| s.g),
        ("bending_warp" | "bending_weft", KesParam::B) => {
            bending_parameters(&odd, &odd).map(|s| s.b)
        }
        _ => None,
    }
}

fn test_path<'a>(run: &'a RigRun, test: &str) -> &'a RigCurve {
    match test {
        "tensile_warp" => &run.tensile[0],
        "tensile_weft" => &run.tensile[1],
        "shear" => &run.shear,
        "bending_warp" => &run.bending[0],
        _ => &run.bending[1],
    }
}

fn display_path(spec: &FabricSpec) -> String {
    if spec.path.is_empty() {
        spec.name.clone()
    } else {
        spec.path.clone()
    }
}

/// Axis labels and the SI → plotted-unit factors of a test.
fn axes(test: &str) -> (&'static str, &'static str, f64, f64) {
    match test {
        t if t.starts_with("tensile") => ("strain (%)", "force (gf/cm)", 100.0, 1.0 / 0.980665),
        "shear" => (
            "shear angle (deg)",
            "shear force (gf/cm)",
            180.0 / std::f64::consts::PI,
            1.0 / 0.980665,
        ),
        _ => (
            "curvature (1/cm)",
            "moment (gf·cm/cm)",
            0.01,
            1.0 / 9.80665e-3,
        ),
    }
}

/// Writes `<dir>/<fabric>_<test>.csv`, `.png`, `.svg` for every test of `report`.
pub fn write_fabric_outputs(report: &FabricReport, dir: &Path) -> Result<Vec<PathBuf>, String> {
    std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let mut written = Vec::new();
    for test in [
        "tensile_warp",
        "tensile_weft",
        "shear",
        "bending_warp",
        "bending_weft",
    ] {
        if report
            .runs
            .iter()
            .all(|(_, r)| test_path(r, test).path.is_empty())
        {
            continue;
        }
        let (xl, yl, fx, fy) = axes(test);
        let scale = |pts: &[[f64; 2]]| -> Vec<[f64; 2]> {
            pts.iter().map(|p| [p[0] * fx, p[1] * fy]).collect()
        };
        let mut series = Vec::new();
        if let Some((_, input)) = report.inputs.iter().find(|(t, _)| t == test) {
            series.push(Series {
                name: "measured".into(),
                points: scale(input),
                style: SeriesStyle::Markers,
            });
        }
        for (mesh, run) in &report.runs {
            series.push(Series {
                name: format!("simulated ({mesh} mesh)"),
                points: scale(&test_path(run, test).path),
                style: SeriesStyle::Solid,
            });
        }
        let stem = dir.join(format!("{}_{test}", report.name));
        write_series_csv(&stem.with_extension("csv"), &series).map_err(|e| e.to_string())?;
        let spec = PlotSpec {
            title: format!("{} — {test}", report.name),
            x_label: xl.into(),
            y_label: yl.into(),
            series,
        };
        let (png, svg) = write_plot_pair(&stem, &spec).map_err(|e| e.to_string())?;
        written.extend([stem.with_extension("csv"), png, svg]);
    }
    Ok(written)
}

/// Writes `summary.csv` and `summary.md` (measured vs simulated parameters, curve errors)
/// for all reports into `dir`; returns their paths.
pub fn write_summary(reports: &[FabricReport], dir: &Path) -> Result<(PathBuf, PathBuf), String> {
    std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let mut csv = String::from("fabric,test,mesh,parameter,unit,measured,simulated,error_pct\n");
    let mut md = String::from(
        "# Virtual Kawabata lab: measured vs simulated\n\n\
         KES parameters computed with the standard formulas from the simulated curves, next to\n\
         the fabric file's values (or the same formulas applied to its measured curves).\n\n\
         | fabric | test | mesh | parameter | unit | measured | simulated | error % |\n\
         |---|---|---|---|---|---|---|---|\n",
    );
    for r in reports {
        for p in &r.params {
            csv += &format!(
                "{},{},{},{},{},{:.6},{:.6},{:.3}\n",
                r.name, p.test, p.mesh, p.param, p.unit, p.measured, p.simulated, p.error_pct
            );
            md += &format!(
                "| {} | {} | {} | {} | {} | {:.4} | {:.4} | {:+.2} |\n",
                r.name, p.test, p.mesh, p.param, p.unit, p.measured, p.simulated, p.error_pct
            );
        }
    }
    md += "\n## Curves (RMS difference, % of the measured range)\n\n| fabric | test | mesh | RMS % |\n|---|---|---|---|\n";
    for r in reports {
        for c in &r.curves {
            csv += &format!(
                "{},{},{},curve_rms,%,,,{:.3}\n",
                r.name, c.test, c.mesh, c.rms_pct
            );
            md += &format!(
                "| {} | {} | {} | {:.2} |\n",
                r.name, c.test, c.mesh, c.rms_pct
            );
        }
    }
    md += "\n## Peirce cantilever (warp)\n\n| fabric | bending length (cm) | (B/W)^(1/3) (cm) | error % |\n|---|---|---|---|\n";
    for r in reports {
        if let Some((s, t)) = r.bending_length {
            md += &format!(
                "| {} | {:.3} | {:.3} | {:+.2} |\n",
                r.name,
                s * 100.0,
                t * 100.0,
                100.0 * (s - t) / t
            );
        }
    }
    md += "\n## Equilibrium\n\nRig increments whose Newton iterations stopped at the cap before a relative force residual of 1e-6:\n\n| fabric | increments |\n|---|---|\n";
    for r in reports {
        md += &format!("| {} | {} |\n", r.name, r.unconverged());
    }
    let (pc, pm) = (dir.join("summary.csv"), dir.join("summary.md"));
    std::fs::write(&pc, csv).map_err(|e| format!("{}: {e}", pc.display()))?;
    std::fs::write(&pm, md).map_err(|e| format!("{}: {e}", pm.display()))?;
    Ok((pc, pm))
}
