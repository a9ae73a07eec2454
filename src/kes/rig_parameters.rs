//! The KES parameters of a virtual experiment: a rig path split into its loading and
//! hysteresis branches ([`branches`]), the standard formulas applied to them per test
//! (`simulated_params`), and the measured value each is compared with (`measured_value`).
//! Shared by the fitting of a law ([`super::fit`]) and the lab ([`super::lab`]).

use super::calibrate::{LawModel, RigRun};
use super::fabric::FabricSpec;
use super::kes_param::KesParam;
use super::parameters::{bending_parameters, shear_parameters, tensile_parameters};

/// A curve branch: (x, y) points.
pub type Branch = Vec<[f64; 2]>;

/// Splits a rig path into its first rising run (virgin loading) and, for cycles, the
/// backward (x decreasing from the maximum) and forward (x increasing from the minimum)
/// branches, each sorted by x.
pub fn branches(path: &[[f64; 2]]) -> (Branch, Branch, Branch) {
    if path.is_empty() {
        return (Vec::new(), Vec::new(), Vec::new());
    }
    let imax = (0..path.len())
        .max_by(|&a, &b| path[a][0].total_cmp(&path[b][0]))
        .unwrap_or(0);
    let imax = (0..path.len())
        .find(|&i| path[i][0] >= path[imax][0])
        .unwrap_or(imax);
    let virgin = path[..=imax.min(path.len().saturating_sub(1))].to_vec();
    let rest = &path[imax..];
    let imin = (0..rest.len())
        .min_by(|&a, &b| rest[a][0].total_cmp(&rest[b][0]))
        .unwrap_or(0);
    let mut back = rest[..=imin.min(rest.len().saturating_sub(1))].to_vec();
    let mut fwd = rest[imin..].to_vec();
    back.sort_by(|a, b| a[0].total_cmp(&b[0]));
    fwd.sort_by(|a, b| a[0].total_cmp(&b[0]));
    (virgin, back, fwd)
}

/// KES parameters (SI) of the simulated curves, as (test, [(param, value)]).
pub(crate) fn simulated_params(
    run: &RigRun,
    model: &LawModel,
) -> Vec<(String, Vec<(KesParam, f64)>)> {
    let mut out = Vec::new();
    for (d, name) in ["tensile_warp", "tensile_weft"].iter().enumerate() {
        let (load, back, _) = branches(&run.tensile[d].path);
        let mut v = Vec::new();
        if let Some(p) = tensile_parameters(&load, &back, model.protocol.tensile_fm[d]) {
            v.extend([
                (KesParam::Emt, p.emt),
                (KesParam::Lt, p.lt),
                (KesParam::Wt, p.wt),
            ]);
            if let Some(rt) = p.rt {
                v.push((KesParam::Rt, rt));
            }
        }
        out.push((name.to_string(), v));
    }
    let (_, back, fwd) = branches(&run.shear.path);
    let mut v = Vec::new();
    if let Some(p) = shear_parameters(&fwd, &back) {
        v.extend([
            (KesParam::G, p.g),
            (KesParam::Hg2, p.hg2),
            (KesParam::Hg52, p.hg5_2),
        ]);
    }
    out.push(("shear".into(), v));
    for (d, name) in ["bending_warp", "bending_weft"].iter().enumerate() {
        let (_, back, fwd) = branches(&run.bending[d].path);
        let mut v = Vec::new();
        if let Some(p) = bending_parameters(&fwd, &back) {
            v.extend([(KesParam::B, p.b), (KesParam::Hb2, p.hb2)]);
        }
        out.push((name.to_string(), v));
    }
    out
}

/// The measured value of `param` for `test`: the file's KES value, else none.
pub(crate) fn measured_value(spec: &FabricSpec, test: &str, param: KesParam) -> Option<f64> {
    let dir_of = |t: &str| {
        if t.ends_with("weft") {
            &spec.weft
        } else {
            &spec.warp
        }
    };
    if test == "shear" {
        return match (spec.warp.get(param), spec.weft.get(param)) {
            (Some(a), Some(b)) => Some(0.5 * (a + b)),
            (a, b) => a.or(b),
        };
    }
    dir_of(test).get(param)
}
