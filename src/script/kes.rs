//! Script bindings of the virtual Kawabata lab: fabric files, the Wang 2011 import, lab runs
//! and their reports and tables, and damping fitted from free oscillation. Only conversion and
//! registration here; the work is in [`crate::kes`].

use std::path::PathBuf;
use std::sync::Arc;

use rhai::{Array, Dynamic, Map};

use super::convert::{num, rt_err, RResult};
use super::fabric::Fabric;
use super::paths::{read_folder, read_path, write_folder};
use super::{function, modules::ApiBuilder, register};
use crate::kes::calibrate::Tests;
use crate::kes::damping::{fit_stretch_damping, free_oscillation, DecayExperiment};
use crate::kes::lab::{self, FabricReport, LabOptions};
use crate::kes::rig::RigMesh;
use crate::kes::{feng, read_fabric, read_fabric_dir, wang, FabricSpec};

/// A fabric read from a fabric file (KES parameters and/or curves).
#[derive(Debug, Clone)]
pub struct KesFabric(pub Arc<FabricSpec>);

/// The report of a lab run on one fabric.
#[derive(Debug, Clone)]
pub struct KesReport(pub Arc<FabricReport>);

fn paths(v: Vec<PathBuf>) -> Array {
    v.into_iter()
        .map(|p| Dynamic::from(p.display().to_string()))
        .collect()
}

/// An array of strings, or one comma-separated string, as a list.
fn string_list(v: &Dynamic) -> Vec<String> {
    if let Some(a) = v.read_lock::<Array>() {
        a.iter().map(|x| x.to_string()).collect()
    } else {
        v.to_string()
            .split(',')
            .map(|s| s.trim().to_string())
            .collect()
    }
}

fn options(m: &Map) -> RResult<LabOptions> {
    let mut o = LabOptions::default();
    for (k, v) in m {
        match k.as_str() {
            "meshes" => {
                let names = string_list(v);
                o.meshes = names
                    .into_iter()
                    .map(|n| match n.as_str() {
                        "coarse" => Ok((n, RigMesh::COARSE)),
                        "fine" => Ok((n, RigMesh::FINE)),
                        _ => Err(rt_err(format!(
                            "lab option `meshes`: unknown mesh `{n}` (use coarse, fine)"
                        ))),
                    })
                    .collect::<RResult<_>>()?;
            }
            "fit" => {
                o.fit = v
                    .as_bool()
                    .map_err(|_| rt_err("lab option `fit` must be a bool"))?
            }
            "cantilever" => {
                o.cantilever = v
                    .as_bool()
                    .map_err(|_| rt_err("lab option `cantilever` must be a bool"))?
            }
            "tests" => {
                let names = string_list(v);
                let mut t = Tests {
                    tensile: false,
                    shear: false,
                    bending: false,
                };
                for n in names {
                    match n.as_str() {
                        "tensile" => t.tensile = true,
                        "shear" => t.shear = true,
                        "bending" => t.bending = true,
                        _ => {
                            return Err(rt_err(format!(
                            "lab option `tests`: unknown test `{n}` (use tensile, shear, bending)"
                        )))
                        }
                    }
                }
                o.tests = t;
            }
            _ => {
                return Err(rt_err(format!(
                    "unknown lab option `{k}` (use meshes, fit, cantilever, tests)"
                )))
            }
        }
    }
    Ok(o)
}

fn param_maps(r: &FabricReport) -> Array {
    r.params
        .iter()
        .map(|p| {
            let mut m = Map::new();
            m.insert("test".into(), p.test.clone().into());
            m.insert("mesh".into(), p.mesh.clone().into());
            m.insert("param".into(), p.param.clone().into());
            m.insert("unit".into(), p.unit.clone().into());
            m.insert("measured".into(), p.measured.into());
            m.insert("simulated".into(), p.simulated.into());
            m.insert("error_pct".into(), p.error_pct.into());
            Dynamic::from_map(m)
        })
        .collect()
}

/// Registers the lab's functions.
pub fn register(engine: &mut ApiBuilder) {
    engine.register_type_with_name::<KesFabric>("KesFabric");
    engine.register_type_with_name::<KesReport>("KesReport");

    function!(engine, "kes::fabric", alias = "kes_fabric", ["path: String", "KesFabric"],
        "Reads a fabric file (format `emilion-fabric-1`, see kawabata/FORMAT.md). Errors name the\nfile and the field.",
        |path: &str| -> RResult<KesFabric> {
            Ok(KesFabric(Arc::new(read_fabric(&read_path(path)?).map_err(rt_err)?)))
        });
    function!(
        engine,
        "kes::fabrics",
        alias = "kes_fabrics",
        ["dir: String", "Array"],
        "Reads every `*.json` fabric file of a folder, sorted by name.",
        |dir: &str| -> RResult<Array> {
            Ok(read_fabric_dir(&read_folder(dir)?)
                .map_err(rt_err)?
                .into_iter()
                .map(|f| Dynamic::from(KesFabric(Arc::new(f))))
                .collect())
        }
    );
    function!(engine, "kes::import_wang", alias = "kes_import_wang", ["dir: String", "out_dir: String", "Array"],
        "Converts the Wang 2011 (ARCSim) material files of `dir` into fabric files in `out_dir`;\nreturns the written paths. (Their licence forbids redistribution: convert at run time.)",
        |dir: &str, out: &str| -> RResult<Array> {
            Ok(paths(wang::import_wang_dir(&read_folder(dir)?, &write_folder(out)?).map_err(rt_err)?))
        });
    register!(
        engine,
        "name",
        ["fabric: KesFabric", "String"],
        "The fabric's name.",
        |f: &mut KesFabric| f.0.name.clone()
    );
    register!(
        engine,
        "to_string",
        ["fabric: KesFabric", "String"],
        "One-line summary of a fabric file.",
        |f: &mut KesFabric| format!(
            "KesFabric({}, {:.3} kg/m², {})",
            f.0.name, f.0.density, f.0.path
        )
    );

    function!(engine, "kes::lab", alias = "kes_lab", ["fabric: KesFabric", "options: Map", "KesReport"],
        "Runs the virtual Kawabata lab on a fabric: fits the law to its KES parameters (if any),\nruns the rigs and compares. Options: `meshes` (\"coarse\", \"fine\"), `fit` (bool),\n`cantilever` (bool), `tests` (\"tensile\", \"shear\", \"bending\"); defaults: both meshes,\nfit, cantilever, every test.",
        |f: KesFabric, opts: Map| -> RResult<KesReport> {
            let o = options(&opts)?;
            Ok(KesReport(Arc::new(lab::run_fabric(&f.0, &o).map_err(rt_err)?)))
        });
    register!(engine, "kes_params", ["report: KesReport", "Array"],
        "The compared KES parameters: maps with test, mesh, param, unit, measured, simulated,\nerror_pct (KES units).",
        |r: &mut KesReport| param_maps(&r.0));
    register!(engine, "kes_table", ["report: KesReport", "test: String", "String"],
        "A side-by-side text table (measured vs simulated) of the parameters of the tests whose\nname starts with `test` (\"\" for all).",
        |r: &mut KesReport, test: &str| -> String {
            let mut s = format!("{:<14} {:<6} {:<5} {:>12} {:>12} {:>8}  unit\n", "test", "mesh", "param", "measured", "simulated", "err %");
            for p in r.0.params.iter().filter(|p| p.test.starts_with(test)) {
                s += &format!("{:<14} {:<6} {:<5} {:>12.5} {:>12.5} {:>+8.2}  {}\n", p.test, p.mesh, p.param, p.measured, p.simulated, p.error_pct, p.unit);
            }
            for c in r.0.curves.iter().filter(|c| c.test.starts_with(test)) {
                s += &format!("{:<14} {:<6} curve RMS {:.2} % of range\n", c.test, c.mesh, c.rms_pct);
            }
            s
        });
    register!(engine, "worst_curve_rms_pct", ["report: KesReport", "float"],
        "The largest curve RMS difference of the report (% of the measured range; 0 without curves).",
        |r: &mut KesReport| r.0.worst_curve());
    register!(
        engine,
        "worst_param_err_pct",
        ["report: KesReport", "float"],
        "The largest relative parameter error of the report (%).",
        |r: &mut KesReport| r.0.worst_param()
    );
    register!(engine, "bending_length", ["report: KesReport", "Map"],
        "The Peirce cantilever result: #{simulated, theory} bending lengths (m), theory = (B/W)^(1/3);\nempty when the cantilever was not run.",
        |r: &mut KesReport| -> Map {
            let mut m = Map::new();
            if let Some((s, t)) = r.0.bending_length {
                m.insert("simulated".into(), s.into());
                m.insert("theory".into(), t.into());
            }
            m
        });
    register!(engine, "kes_write", ["report: KesReport", "dir: String", "Array"],
        "Writes the report's curves as CSV and plots (PNG, SVG: measured vs simulated, loops\nvisible) into `dir`; returns the paths.",
        |r: &mut KesReport, dir: &str| -> RResult<Array> {
            Ok(paths(lab::write_fabric_outputs(&r.0, &write_folder(dir)?).map_err(rt_err)?))
        });
    function!(engine, "kes::summary", alias = "kes_summary", ["reports: Array", "dir: String", "Map"],
        "Writes `summary.csv` and `summary.md` (measured vs simulated parameters, curve errors,\ncantilever) for a list of reports; returns #{csv, md, worst_curve_rms_pct,\nworst_param_err_pct, fabrics}.",
        |reports: Array, dir: &str| -> RResult<Map> {
            let rs: Vec<FabricReport> = reports
                .iter()
                .map(|d| {
                    d.read_lock::<KesReport>()
                        .map(|r| (*r.0).clone())
                        .ok_or_else(|| rt_err("kes_summary: every element must be a KesReport"))
                })
                .collect::<RResult<_>>()?;
            let (csv, md) = lab::write_summary(&rs, &write_folder(dir)?).map_err(rt_err)?;
            let mut m = Map::new();
            m.insert("csv".into(), csv.display().to_string().into());
            m.insert("md".into(), md.display().to_string().into());
            m.insert("worst_curve_rms_pct".into(), rs.iter().map(|r| r.worst_curve()).fold(0.0, f64::max).into());
            m.insert("worst_param_err_pct".into(), rs.iter().map(|r| r.worst_param()).fold(0.0, f64::max).into());
            m.insert("fabrics".into(), (rs.len() as rhai::INT).into());
            Ok(m)
        });
    function!(engine, "kes::feng_count", alias = "feng_count", ["path: String", "int"],
        "The number of fabrics in a Feng 2022 bending CSV (`data_dir() +\n\"/fabrics/feng2022_bending.csv\"`).",
        |path: &str| -> RResult<rhai::INT> {
            Ok(feng::read_feng(&read_path(path)?).map_err(rt_err)?.len() as rhai::INT)
        });
    function!(engine, "kes::feng_bending", alias = "feng_bending", ["path: String", "row: int", "Map"],
        "Runs the virtual bending rig (coarse mesh, warp and weft) on the fabric of data row `row`\n(0-based) of a Feng 2022 bending CSV, its measured curve M = k1 κ + k2 κ² as the law, and\nfits k1, k2 to the rig's reading: #{row, density, k1_warp, k1_warp_fit, k2_warp,\nk2_warp_fit, (same for weft), kappa_max_warp, kappa_max_weft, curve_rms_pct_warp,\ncurve_rms_pct_weft, unconverged} (SI: N·m, N·m², 1/m).",
        |path: &str, row: rhai::INT| -> RResult<Map> {
            let row = usize::try_from(row).map_err(|_| rt_err(format!("feng_bending: row {row} is negative")))?;
            let f = feng::read_feng_row(&read_path(path)?, row).map_err(rt_err)?;
            let c = feng::compare(&f, RigMesh::COARSE).map_err(rt_err)?;
            let mut m = Map::new();
            m.insert("row".into(), (row as rhai::INT).into());
            m.insert("density".into(), f.density.into());
            for (d, dir) in ["warp", "weft"].iter().enumerate() {
                m.insert(format!("k1_{dir}").into(), f.k1[d].into());
                m.insert(format!("k1_{dir}_fit").into(), c.k1_fit[d].into());
                m.insert(format!("k2_{dir}").into(), f.k2[d].into());
                m.insert(format!("k2_{dir}_fit").into(), c.k2_fit[d].into());
                m.insert(format!("kappa_max_{dir}").into(), f.kappa_max(d).into());
                m.insert(format!("curve_rms_pct_{dir}").into(), c.curve_rms_pct[d].into());
            }
            m.insert("unconverged".into(), (c.unconverged as rhai::INT).into());
            Ok(m)
        });
    function!(engine, "kes::free_oscillation", alias = "free_oscillation", ["fabric: Fabric", "Map"],
        "Free axial oscillation of a 20 cm strip stretched 1 % and released (explicit\nintegrator): #{log_decrement, period, peaks}.",
        |f: Fabric| -> RResult<Map> {
            let d = free_oscillation(f.0, Arc::new(f.0.linear_law()), DecayExperiment::default())?;
            let mut m = Map::new();
            m.insert("log_decrement".into(), d.log_decrement.into());
            m.insert("period".into(), d.period.into());
            m.insert("peaks".into(), d.peaks.iter().map(|&p| Dynamic::from(p)).collect::<Array>().into());
            Ok(m)
        });
    function!(engine, "kes::fit_damping", alias = "fit_damping", ["fabric: Fabric", "log_decrement: float", "Map"],
        "Fits the stiffness-proportional damping (`stretch_damping`, s) so that the free\noscillation decays with the given logarithmic decrement: #{stretch_damping,\nlog_decrement, period}.",
        |f: Fabric, target: Dynamic| -> RResult<Map> {
            let target = num(&target, "log_decrement")?;
            let (beta, d) = fit_stretch_damping(f.0, Arc::new(f.0.linear_law()), DecayExperiment::default(), target)?;
            let mut m = Map::new();
            m.insert("stretch_damping".into(), beta.into());
            m.insert("log_decrement".into(), d.log_decrement.into());
            m.insert("period".into(), d.period.into());
            Ok(m)
        });
}
