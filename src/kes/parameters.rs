//! The KES parameter formulas (Kawabata 1980; recipe of the maths notes §3.7), applied to
//! curves in SI units — measured or simulated alike:
//! - tensile: εm = first crossing of Fm on the loading branch; WT = ∫₀^εm F dε; LT = WT /
//!   (Fm εm / 2); RT = (∫ unloading F dε) / WT;
//! - shear: G = mean of the least-squares slopes of the forward branch on [0.5°, 5°] and of
//!   the backward branch on [−5°, −0.5°]; 2HG, 2HG5 = mean loop widths at ±0.5°, ±5°;
//! - bending: B = mean least-squares slopes on K ∈ [0.5, 1.5] cm⁻¹ (forward) and
//!   [−1.5, −0.5] cm⁻¹ (backward); 2HB = mean loop width at K = ±1 cm⁻¹.
//!
//! Windows that lie beyond a curve's data (measured curves that stop early, such as the Wang
//! 2011 bending tables at 0.4 cm⁻¹) are clipped to the data; if fewer than two points are
//! left, the whole branch on that side of zero is used. Loop widths outside the data count
//! as zero.
//!
//! Elastic curves (a loading branch only, as the Wang 2011 conversions give) go through
//! [`elastic_shear_rigidity`], [`elastic_bending_rigidity`] and [`tensile_parameters`] with an
//! empty unloading branch: an elastic curve is its own forward and (mirrored) backward branch,
//! so G and B are the least-squares slopes over the standard window clipped to the data (or
//! over the whole positive range if the window lies beyond it) and the loop widths are zero.
//! A recorded cycle is cut into its branches by [`split_branches`].

/// Tensile parameters, SI.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TensileParams {
    /// Strain at Fm (fraction).
    pub emt: f64,
    /// Linearity.
    pub lt: f64,
    /// Tensile energy (J/m²).
    pub wt: f64,
    /// Resilience (fraction), when an unloading branch is given.
    pub rt: Option<f64>,
}

/// Shear parameters, SI.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShearParams {
    /// Shear rigidity (N/(m·rad)).
    pub g: f64,
    /// Loop width at ±0.5° (N/m).
    pub hg2: f64,
    /// Loop width at ±5° (N/m).
    pub hg5_2: f64,
}

/// Bending parameters, SI.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BendingParams {
    /// Bending rigidity (N·m).
    pub b: f64,
    /// Loop width at ±1 cm⁻¹ (N).
    pub hb2: f64,
}

/// Linear interpolation of `y(x)` on a branch sorted by x; None outside its x range or with
/// fewer than 2 points.
pub fn interp(branch: &[[f64; 2]], x: f64) -> Option<f64> {
    if branch.len() < 2 || !(x >= branch[0][0] && x <= branch[branch.len() - 1][0]) {
        return None;
    }
    let k = branch
        .partition_point(|p| p[0] <= x)
        .clamp(1, branch.len() - 1);
    let (a, b) = (branch[k - 1], branch[k]);
    let t = if b[0] > a[0] {
        (x - a[0]) / (b[0] - a[0])
    } else {
        0.0
    };
    Some(a[1] + t * (b[1] - a[1]))
}

/// ∫ y dx by trapezoids over a branch sorted by x, between `a` and `b`.
fn integrate(branch: &[[f64; 2]], a: f64, b: f64) -> f64 {
    let mut s = 0.0;
    for w in branch.windows(2) {
        let (x0, x1) = (w[0][0].max(a), w[1][0].min(b));
        if x1 <= x0 {
            continue;
        }
        let y0 = interp(branch, x0).unwrap_or(w[0][1]);
        let y1 = interp(branch, x1).unwrap_or(w[1][1]);
        s += 0.5 * (y0 + y1) * (x1 - x0);
    }
    s
}

fn sorted(v: &[[f64; 2]]) -> Vec<[f64; 2]> {
    let mut v = v.to_vec();
    v.sort_by(|a, b| a[0].total_cmp(&b[0]));
    v
}

/// Tensile parameters of a loading branch (from ε = 0, x increasing) and an unloading branch
/// (any order; may be empty) for maximum load `fm` (N/m): εm = first crossing of `fm` on the
/// loading branch (linear interpolation), WT = trapezoid ∫ F dε over [0, εm], LT = WT /
/// (Fm εm / 2), RT = (∫ unloading F dε from its lowest strain to εm) / WT — `rt` is None when
/// the unloading branch has fewer than 2 points (an elastic curve has no resilience to
/// report). None if the loading never reaches `fm` (within 0.1 %), if `fm` is not positive
/// and finite, or if εm ≤ 0.
pub fn tensile_parameters(
    loading: &[[f64; 2]],
    unloading: &[[f64; 2]],
    fm: f64,
) -> Option<TensileParams> {
    if !(fm.is_finite() && fm > 0.0) {
        return None;
    }
    let load = sorted(loading);
    // the first point at or above Fm; a rig that stops just short of Fm (within 0.1 %)
    // counts as reaching it at its first point that close
    let k = load
        .iter()
        .position(|p| p[1] >= fm)
        .or_else(|| load.iter().position(|p| p[1] >= fm * 0.999))?;
    let em = if k == 0 {
        load[0][0]
    } else {
        let (a, b) = (load[k - 1], load[k]);
        if b[1] > a[1] {
            a[0] + (fm.min(b[1]) - a[1]) / (b[1] - a[1]) * (b[0] - a[0])
        } else {
            b[0]
        }
    };
    if !(em > 0.0 && em.is_finite()) {
        return None;
    }
    let wt = integrate(&load, 0.0, em);
    let lt = wt / (0.5 * fm * em);
    let rt = (unloading.len() >= 2).then(|| {
        let un = sorted(unloading);
        integrate(&un, un[0][0], em) / wt
    });
    Some(TensileParams {
        emt: em,
        lt,
        wt,
        rt,
    })
}

/// Least-squares slope of the points of `branch` with x in [a, b]; None with fewer than two
/// such points or no spread in x.
pub fn least_squares_slope(branch: &[[f64; 2]], a: f64, b: f64) -> Option<f64> {
    let pts: Vec<[f64; 2]> = branch
        .iter()
        .filter(|p| p[0] >= a - 1e-12 && p[0] <= b + 1e-12)
        .copied()
        .collect();
    lsq(&pts)
}

fn lsq(pts: &[[f64; 2]]) -> Option<f64> {
    if pts.len() < 2 {
        return None;
    }
    let n = pts.len() as f64;
    let (mx, my) = (
        pts.iter().map(|p| p[0]).sum::<f64>() / n,
        pts.iter().map(|p| p[1]).sum::<f64>() / n,
    );
    let (sxy, sxx) = pts.iter().fold((0.0, 0.0), |(sxy, sxx), p| {
        (sxy + (p[0] - mx) * (p[1] - my), sxx + (p[0] - mx).powi(2))
    });
    let s = sxy / sxx;
    (sxx > 0.0 && s.is_finite()).then_some(s)
}

/// Secant slope (y(x1) − y(x0)) / (x1 − x0) of a branch (sorted by x, linear interpolation);
/// None if x0 or x1 lies outside the data or x0 = x1.
pub fn secant_slope(curve: &[[f64; 2]], x0: f64, x1: f64) -> Option<f64> {
    let c = sorted(curve);
    let (y0, y1) = (interp(&c, x0)?, interp(&c, x1)?);
    let s = (y1 - y0) / (x1 - x0);
    s.is_finite().then_some(s)
}

/// G (N/(m·rad)) of an elastic shear curve (a loading branch only, x in rad ≥ 0, the curve
/// taken as odd): [`clipped_slope`] on [0.5°, 5°].
pub fn elastic_shear_rigidity(loading: &[[f64; 2]]) -> Option<f64> {
    let d = std::f64::consts::PI / 180.0;
    let c = sorted(loading);
    clipped_slope(&c, 0.5 * d, 5.0 * d)
}

/// B (N·m) of an elastic bending curve (a loading branch only, x in 1/m ≥ 0, the curve taken
/// as odd): [`clipped_slope`] on [0.5, 1.5] cm⁻¹ = [50, 150] m⁻¹.
pub fn elastic_bending_rigidity(loading: &[[f64; 2]]) -> Option<f64> {
    let c = sorted(loading);
    clipped_slope(&c, 50.0, 150.0)
}

/// Splits a recorded cycle (points in recording order) into its x-increasing and
/// x-decreasing runs: (increasing, decreasing), each sorted by x. A turning point belongs to
/// both runs; steps with no change in x keep the sense of the step before. Runs of the same
/// sense are concatenated; where a later run covers part of the x range of earlier ones, the
/// earlier points there are dropped (the later run is the settled loop: for the KES cycle
/// 0 → +8° → −8° → +8° the increasing branch is the last −8° → +8° run, for 0 → +8° → −8° → 0
/// it is −8° → 0 followed by the virgin 0 → +8°).
pub fn split_branches(path: &[[f64; 2]]) -> (Vec<[f64; 2]>, Vec<[f64; 2]>) {
    // runs: (increasing?, points)
    let mut runs: Vec<(bool, Vec<[f64; 2]>)> = Vec::new();
    let mut sense: Option<bool> = None;
    for w in path.windows(2) {
        let dx = w[1][0] - w[0][0];
        let s = if dx > 0.0 {
            true
        } else if dx < 0.0 {
            false
        } else {
            match sense {
                Some(s) => s,
                None => continue,
            }
        };
        match runs.last_mut() {
            Some((rs, pts)) if *rs == s && sense == Some(s) => pts.push(w[1]),
            _ => runs.push((s, vec![w[0], w[1]])),
        }
        sense = Some(s);
    }
    let merge = |want: bool| -> Vec<[f64; 2]> {
        let mut out: Vec<[f64; 2]> = Vec::new();
        for (_, pts) in runs.iter().filter(|(s, _)| *s == want) {
            let (lo, hi) = pts
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), p| {
                    (l.min(p[0]), h.max(p[0]))
                });
            out.retain(|p| p[0] < lo || p[0] > hi);
            out.extend(pts.iter().copied());
        }
        sorted(&out)
    };
    (merge(true), merge(false))
}

/// Least-squares slope over the window [a, b] clipped to the data, or over the whole part of
/// the branch on the window's side of zero if fewer than two points fall in the window (the
/// choice for curves that stop before the standard window, such as the Wang 2011 bending
/// curves at 0.4 cm⁻¹).
/// `branch` sorted by x or not.
pub fn clipped_slope(branch: &[[f64; 2]], a: f64, b: f64) -> Option<f64> {
    let pick = |lo: f64, hi: f64| -> Vec<[f64; 2]> {
        branch
            .iter()
            .filter(|p| p[0] >= lo - 1e-12 && p[0] <= hi + 1e-12)
            .copied()
            .collect()
    };
    let mut pts = pick(a, b);
    if pts.len() < 2 {
        pts = if b > 0.0 {
            pick(0.0, f64::INFINITY)
        } else {
            pick(f64::NEG_INFINITY, 0.0)
        };
    }
    lsq(&pts)
}

fn width(fwd: &[[f64; 2]], bwd: &[[f64; 2]], x: f64) -> f64 {
    match (interp(fwd, x), interp(bwd, x)) {
        (Some(a), Some(b)) => (a - b).abs(),
        _ => 0.0,
    }
}

/// Slope windows and widths of a loop (forward = x increasing, backward = x decreasing).
fn loop_params(
    forward: &[[f64; 2]],
    backward: &[[f64; 2]],
    window: (f64, f64),
    at: [f64; 2],
) -> Option<(f64, f64, f64)> {
    let (f, b) = (sorted(forward), sorted(backward));
    let s1 = clipped_slope(&f, window.0, window.1)?;
    let s2 = clipped_slope(&b, -window.1, -window.0)?;
    let w = |x: f64| 0.5 * (width(&f, &b, x) + width(&f, &b, -x));
    Some((0.5 * (s1 + s2), w(at[0]), w(at[1])))
}

/// Shear parameters of a loop, SI (x in rad, y in N/m): `forward` is the branch with φ
/// increasing (−8° → +8°), `backward` the one with φ decreasing, each in any order. G = mean of
/// the least-squares slopes of forward on [0.5°, 5°] and backward on [−5°, −0.5°] (windows
/// clipped, see the module doc); 2HG, 2HG5 = mean of the loop widths |H_fwd − H_bwd| at ±0.5°
/// and ±5° (linear interpolation on each branch; 0 where a branch does not reach). None if a
/// slope cannot be computed.
pub fn shear_parameters(forward: &[[f64; 2]], backward: &[[f64; 2]]) -> Option<ShearParams> {
    let d = std::f64::consts::PI / 180.0;
    let (g, hg2, hg5_2) = loop_params(forward, backward, (0.5 * d, 5.0 * d), [0.5 * d, 5.0 * d])?;
    Some(ShearParams { g, hg2, hg5_2 })
}

/// Bending parameters of a loop, SI (x in 1/m, y in N): `forward` is the branch with K
/// increasing, `backward` the one with K decreasing. B = mean of the least-squares slopes of
/// forward on K ∈ [0.5, 1.5] cm⁻¹ and backward on [−1.5, −0.5] cm⁻¹; 2HB = mean of |M_fwd −
/// M_bwd| at K = ±1 cm⁻¹. None if a slope cannot be computed.
pub fn bending_parameters(forward: &[[f64; 2]], backward: &[[f64; 2]]) -> Option<BendingParams> {
    let (b, hb2, _) = loop_params(forward, backward, (50.0, 150.0), [100.0, 100.0])?;
    Some(BendingParams { b, hb2 })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn power_law_linearity() {
        // F = Fm (ε/εm)^p ⇒ LT = 2/(p+1), WT = Fm εm/(p+1)
        let (fm, em, p) = (490.0, 0.05, 3.0);
        let load: Vec<[f64; 2]> = (0..=2000)
            .map(|k| {
                let e = 0.06 * k as f64 / 2000.0;
                [e, fm * (e / em).powf(p)]
            })
            .collect();
        let t = tensile_parameters(&load, &[], fm).unwrap();
        assert!((t.emt - em).abs() < 1e-5, "{}", t.emt);
        assert!((t.lt - 0.5).abs() < 1e-3, "{}", t.lt);
        assert!((t.wt - fm * em / 4.0).abs() < 1e-3 * fm * em, "{}", t.wt);
        assert!(t.rt.is_none());
        // unloading at (1−μ)/(1+μ) of the loading ⇒ RT = (1−μ)/(1+μ)
        let r = 0.6;
        let un: Vec<[f64; 2]> = load
            .iter()
            .filter(|q| q[0] <= em)
            .map(|q| [q[0], r * q[1]])
            .collect();
        let t = tensile_parameters(&load, &un, fm).unwrap();
        assert!((t.rt.unwrap() - r).abs() < 2e-3, "{:?}", t.rt);
    }

    #[test]
    fn linear_loops_give_slope_and_width() {
        // M = B K ± HB
        let (b, hb) = (1e-5, 2e-4);
        let ks: Vec<f64> = (-250..=250).map(|k| k as f64).collect();
        let fwd: Vec<[f64; 2]> = ks.iter().map(|&k| [k, b * k + hb]).collect();
        let bwd: Vec<[f64; 2]> = ks.iter().map(|&k| [k, b * k - hb]).collect();
        let p = bending_parameters(&fwd, &bwd).unwrap();
        assert!((p.b - b).abs() < 1e-9 * b.max(1.0), "{}", p.b);
        assert!((p.hb2 - 2.0 * hb).abs() < 1e-12, "{}", p.hb2);
        // shear: H = G φ ± h(φ), h growing with |φ|
        let d = std::f64::consts::PI / 180.0;
        let g = 30.0;
        let h = |phi: f64| 0.5 + 3.0 * phi.abs();
        let phis: Vec<f64> = (-80..=80).map(|k| k as f64 * 0.1 * d).collect();
        let fwd: Vec<[f64; 2]> = phis.iter().map(|&f| [f, g * f + h(f)]).collect();
        let bwd: Vec<[f64; 2]> = phis.iter().map(|&f| [f, g * f - h(f)]).collect();
        let s = shear_parameters(&fwd, &bwd).unwrap();
        assert!((s.hg2 - 2.0 * h(0.5 * d)).abs() < 1e-9, "{}", s.hg2);
        assert!((s.hg5_2 - 2.0 * h(5.0 * d)).abs() < 1e-9, "{}", s.hg5_2);
        // forward slope g + 3 on [0.5°, 5°], backward slope g + 3 on [−5°, −0.5°]
        assert!((s.g - (g + 3.0)).abs() < 1e-9, "{}", s.g);
    }

    #[test]
    fn linearity_of_power_laws() {
        // LT = 2/(p+1) for p = 1, 1.5, 2 (trapezoids on 4000 steps)
        let (fm, em) = (490.33, 0.04);
        for (p, lt) in [(1.0, 1.0), (1.5, 0.8), (2.0, 2.0 / 3.0)] {
            let load: Vec<[f64; 2]> = (0..=4000)
                .map(|k| {
                    let e = 0.05 * k as f64 / 4000.0;
                    [e, fm * (e / em).powf(p)]
                })
                .collect();
            let t = tensile_parameters(&load, &[], fm).unwrap();
            assert!((t.lt - lt).abs() < 1e-4, "p = {p}: LT {}", t.lt);
            assert!((t.emt - em).abs() < 1e-6, "p = {p}: EMT {}", t.emt);
        }
        // never reaching Fm, or a bad Fm: no parameters
        let load = [[0.0, 0.0], [0.1, 100.0]];
        assert!(tensile_parameters(&load, &[], 490.0).is_none());
        assert!(tensile_parameters(&load, &[], f64::NAN).is_none());
        assert!(tensile_parameters(&[], &[], 490.0).is_none());
    }

    #[test]
    fn a_recorded_shear_cycle_splits_into_its_branches() {
        // 0 → +8° → −8° → +8° on H = G φ ± h: the increasing branch is the last run (+h), the
        // decreasing one −h; the virgin run is dropped where the last run covers it
        let d = std::f64::consts::PI / 180.0;
        let (g, h) = (40.0, 0.3);
        let mut path: Vec<[f64; 2]> = Vec::new();
        for k in 0..=80 {
            let f = k as f64 * 0.1 * d;
            path.push([f, g * f]);
        }
        for k in (-80..80).rev() {
            let f = k as f64 * 0.1 * d;
            path.push([f, g * f - h]);
        }
        for k in -79..=80 {
            let f = k as f64 * 0.1 * d;
            path.push([f, g * f + h]);
        }
        let (fwd, bwd) = split_branches(&path);
        assert!(fwd.windows(2).all(|w| w[0][0] <= w[1][0]));
        assert!(bwd.windows(2).all(|w| w[0][0] <= w[1][0]));
        // 161 points from −8° to +8° on each branch (the turning point at −8° is shared)
        assert_eq!(fwd.len(), 161, "{fwd:?}");
        assert!((fwd[80][1] - (g * fwd[80][0] + h)).abs() < 1e-12);
        let s = shear_parameters(&fwd, &bwd).unwrap();
        assert!((s.g - g).abs() < 1e-9, "{}", s.g);
        assert!((s.hg2 - 2.0 * h).abs() < 1e-9, "{}", s.hg2);
        assert!((s.hg5_2 - 2.0 * h).abs() < 1e-9, "{}", s.hg5_2);
        assert_eq!(split_branches(&[]), (Vec::new(), Vec::new()));
        assert_eq!(split_branches(&[[1.0, 2.0]]), (Vec::new(), Vec::new()));
    }

    #[test]
    fn elastic_curves_use_the_window_clipped_to_their_data() {
        // bending M = B K + c K³ to 0.4 1/cm (40 1/m): the window [50, 150] 1/m lies beyond
        // the data, so the slope is the least-squares slope of the whole curve
        let (b, c) = (6e-5, 1e-9);
        let curve: Vec<[f64; 2]> = (0..=16)
            .map(|k| {
                let x = 2.5 * k as f64;
                [x, b * x + c * x * x * x]
            })
            .collect();
        let whole = least_squares_slope(&curve, 0.0, 40.0).unwrap();
        assert_eq!(elastic_bending_rigidity(&curve), Some(whole));
        assert!(whole > b && whole < b + c * 1600.0);
        // a linear curve to 2.5 1/cm: exactly B
        let lin: Vec<[f64; 2]> = (0..=25)
            .map(|k| [10.0 * k as f64, b * 10.0 * k as f64])
            .collect();
        assert!((elastic_bending_rigidity(&lin).unwrap() - b).abs() < 1e-15);
        // shear H = G φ (1 + φ) to 8°: the slope on [0.5°, 5°] only
        let d = std::f64::consts::PI / 180.0;
        let sh: Vec<[f64; 2]> = (0..=16)
            .map(|k| {
                let f = 0.5 * d * k as f64;
                [f, 30.0 * f * (1.0 + f)]
            })
            .collect();
        let g = elastic_shear_rigidity(&sh).unwrap();
        assert_eq!(Some(g), least_squares_slope(&sh, 0.5 * d, 5.0 * d));
        // secant slope of y = x² between 1 and 3 on a fine grid: 4
        let sq: Vec<[f64; 2]> = (0..=400)
            .map(|k| [k as f64 * 0.01, (k as f64 * 0.01).powi(2)])
            .collect();
        assert!((secant_slope(&sq, 1.0, 3.0).unwrap() - 4.0).abs() < 1e-3);
        assert!(secant_slope(&sq, 1.0, 5.0).is_none());
        assert!(secant_slope(&sq, 1.0, 1.0).is_none());
    }
}
