//! Fitting a fabric's law through the virtual experiment (as Charfi & Gagalowicz fitted
//! viscosity by iterative minimisation): the rigs run on a coarse sample, the KES parameters
//! of the simulated curves are computed with the standard formulas, and the law's parameters
//! are corrected by the differences — power-law scale, linearity and friction share for
//! tension; elastic rigidity and friction threshold for shear and bending; a measured shear
//! curve point by point — until the virtual experiment reproduces the targets.

use super::calibrate::{self, LawModel, TensileModel, Tests};
use super::fabric::FabricSpec;
use super::kes_param::KesParam;
use super::parameters::interp;
use super::rig::RigMesh;
use super::rig_parameters::{branches, measured_value, simulated_params};

/// Fits the KES-parameter modes of `model` to the fabric's targets with the rigs on `mesh`.
pub fn fit(
    spec: &FabricSpec,
    model: &mut LawModel,
    mesh: RigMesh,
    rounds: usize,
    tests: Tests,
) -> Result<usize, String> {
    let mut used = 0;
    for round in 0..rounds {
        let run = calibrate::run_rigs(model, mesh, tests).map_err(|e| e.to_string())?;
        let sim = simulated_params(&run, model);
        let get = |test: &str, p: KesParam| {
            sim.iter()
                .find(|(t, _)| t == test)
                .and_then(|(_, v)| v.iter().find(|(q, _)| *q == p).map(|(_, x)| *x))
        };
        let mut worst: f64 = 0.0;
        let mut curve_worst: f64 = 0.0;
        let mut err = |test: &str, p: KesParam| -> Option<(f64, f64)> {
            let (t, s) = (measured_value(spec, test, p)?, get(test, p)?);
            if t.abs() > 1e-12 {
                worst = worst.max(((s - t) / t).abs());
            }
            Some((t, s))
        };
        for (d, test) in ["tensile_warp", "tensile_weft"].iter().enumerate() {
            if let TensileModel::Kes { em, lt, rt } = &mut model.tension[d] {
                if let Some((t, s)) = err(test, KesParam::Emt) {
                    if s > 0.0 {
                        *em *= t / s;
                    }
                }
                if let Some((t, s)) = err(test, KesParam::Lt) {
                    *lt = (*lt + t - s).clamp(0.05, 1.0);
                }
                if let Some((t, s)) = err(test, KesParam::Rt) {
                    *rt = (*rt + t - s).clamp(0.05, 1.0);
                }
            }
        }
        if model.shear_is_curve() && tests.shear {
            // measured curve: move the elastic points by the rig's shortfall at each angle
            if let Some(input) = spec.curves.shear.as_ref() {
                let (virgin, _, _) = branches(&run.shear.path);
                let meas: Vec<[f64; 2]> = input
                    .loading
                    .iter()
                    .filter(|p| p[0] >= 0.0)
                    .copied()
                    .collect();
                curve_worst =
                    model.correct_shear_curve(|x| Some(interp(&meas, x)? - interp(&virgin, x)?));
            }
        } else if model.shear_is_kes() {
            let (g, h1, h5) = (
                err("shear", KesParam::G),
                err("shear", KesParam::Hg2),
                err("shear", KesParam::Hg52),
            );
            let sh = &mut model.shear;
            if let Some((t, s)) = g {
                sh.g_el = (sh.g_el + t - s).max(1e-6);
            }
            let d1 = h1.map_or(0.0, |(t, s)| (t - s) / 2.0);
            let d5 = h5.map_or(d1, |(t, s)| (t - s) / 2.0);
            let dc = (d5 - d1) / (calibrate::deg(5.0) - calibrate::deg(0.5));
            sh.c = (sh.c + dc).max(0.0);
            sh.a = (sh.a + d1 - dc * calibrate::deg(0.5)).max(0.0);
        }
        for (d, test) in ["bending_warp", "bending_weft"].iter().enumerate() {
            if model.bending_is_kes(d) {
                if let Some((t, s)) = err(test, KesParam::B) {
                    model.bending[d].b_el = (model.bending[d].b_el + t - s).max(1e-12);
                }
                if let Some((t, s)) = err(test, KesParam::Hb2) {
                    model.bending[d].hb = (model.bending[d].hb + (t - s) / 2.0).max(0.0);
                }
            }
        }
        used = round + 1;
        if worst.max(curve_worst) < 0.002 {
            break;
        }
    }
    Ok(used)
}
