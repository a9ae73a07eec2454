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
//! 2011 bending tables at 0.4 cm⁻¹) are clipped to the data; if nothing is left, the whole
//! branch on that side is used. Loop widths outside the data count as zero.

use super::calibrate::interp;

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
/// (any order; may be empty) for maximum load `fm`. None if the loading never reaches `fm`
/// (within 0.1 %).
pub fn tensile_parameters(
    loading: &[[f64; 2]],
    unloading: &[[f64; 2]],
    fm: f64,
) -> Option<TensileParams> {
    let load = sorted(loading);
    let k = load.iter().position(|p| p[1] >= fm * 0.999)?;
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
    if em <= 0.0 {
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

/// Least-squares slope of the branch's points with x in [a, b] (clipped to the data; the
/// whole branch on that side of zero if the window misses it).
fn slope(branch: &[[f64; 2]], a: f64, b: f64) -> Option<f64> {
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
    (sxx > 0.0).then(|| sxy / sxx)
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
    let s1 = slope(&f, window.0, window.1)?;
    let s2 = slope(&b, -window.1, -window.0)?;
    let w = |x: f64| 0.5 * (width(&f, &b, x) + width(&f, &b, -x));
    Some((0.5 * (s1 + s2), w(at[0]), w(at[1])))
}

/// Shear parameters of a loop.
pub fn shear_parameters(forward: &[[f64; 2]], backward: &[[f64; 2]]) -> Option<ShearParams> {
    let d = std::f64::consts::PI / 180.0;
    let (g, hg2, hg5_2) = loop_params(forward, backward, (0.5 * d, 5.0 * d), [0.5 * d, 5.0 * d])?;
    Some(ShearParams { g, hg2, hg5_2 })
}

/// Bending parameters of a loop.
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
}
