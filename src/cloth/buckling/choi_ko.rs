//! Choi & Ko's immediate-buckling response of a compressed connection (Choi & Ko 2002, "Stable
//! but Responsive Cloth"; the maths notes §4b). A connection of rest length L shorter than L is
//! taken to have buckled at once into a circular arc of length L, so it stores bending energy
//! instead of compressive strain energy. With λ = |x|/L and θ = sinc⁻¹(λ) (the arc's half
//! angle), the force along the connection is
//!
//! f_b = k_b (2/L)² g(λ),   g(λ) = θ² / (cos θ − sinc θ),
//!
//! negative (the particles are pushed apart), from −12 k_b/L² at the onset to −π² (2/L)² k_b
//! when the ends meet; k_b is the flexural rigidity of the width the connection stands for
//! (N·m). θ is found exactly by a bracketed Newton iteration on sin θ − λθ = 0, not by a fitted
//! polynomial, and near λ = 1 by the series of g.

/// θ ∈ [0, π] with sin θ / θ = λ, for λ ∈ [0, 1].
pub fn inverse_sinc(lambda: f64) -> f64 {
    let lambda = lambda.clamp(0.0, 1.0);
    if lambda >= 1.0 {
        return 0.0;
    }
    if lambda <= 0.0 {
        return std::f64::consts::PI;
    }
    // bracket: sinc decreases from 1 at 0 to 0 at π; start from the small-angle root
    // √(6(1 − λ)) (capped below π), safeguarded Newton
    let (mut lo, mut hi) = (0.0, std::f64::consts::PI);
    let mut t = (6.0 * (1.0 - lambda)).sqrt().min(3.0);
    for _ in 0..40 {
        let h = t.sin() - lambda * t;
        // h > 0 ⇔ sinc t > λ ⇔ t below the root
        if h > 0.0 {
            lo = t;
        } else {
            hi = t;
        }
        let dh = t.cos() - lambda;
        let mut next = if dh != 0.0 { t - h / dh } else { f64::NAN };
        if !(next > lo && next < hi) {
            next = 0.5 * (lo + hi);
        }
        if (next - t).abs() <= 4.0 * f64::EPSILON * t {
            return next;
        }
        t = next;
    }
    t
}

/// θ = sinc⁻¹(λ), g(λ) = θ²/(cos θ − sinc θ) and dg/dλ, for λ ∈ [0, 1].
pub fn arc(lambda: f64) -> (f64, f64, f64) {
    let lambda = lambda.clamp(0.0, 1.0);
    let u = 1.0 - lambda;
    if u < 1e-6 {
        // series about the onset: θ² = 6u + O(u²), g = −3 − 9/5 u + O(u²)
        return ((6.0 * u).sqrt(), -3.0 - 1.8 * u, 1.8);
    }
    let t = inverse_sinc(lambda);
    let t2 = t * t;
    // cos θ − sinc θ, by its series where the difference would cancel
    let c_s = if t < 0.1 {
        t2 * (-1.0 / 3.0 + t2 * (1.0 / 30.0 - t2 / 840.0))
    } else {
        t.cos() - t.sin() / t
    };
    let g = t2 / c_s;
    // dg/dθ = (3θ(c − s) + θ² sin θ)/(c − s)², dλ/dθ = (c − s)/θ
    let dg_dt = (3.0 * t * c_s + t2 * t.sin()) / (c_s * c_s);
    let dl_dt = c_s / t;
    (t, g, dg_dt / dl_dt)
}

/// g(λ) = θ²/(cos θ − sinc θ) and dg/dλ, for λ ∈ [0, 1].
pub fn buckling_g(lambda: f64) -> (f64, f64) {
    let (_, g, dg) = arc(lambda);
    (g, dg)
}

/// Tension (N, negative: pushing apart) and its derivative with respect to the length (N/m)
/// of a buckled connection of rest length `rest` and rigidity `k_b` (N·m) at length `len` ≤
/// `rest`.
pub fn buckling_force(k_b: f64, rest: f64, len: f64) -> (f64, f64) {
    let (g, dg) = buckling_g(len / rest);
    let c = k_b * 4.0 / (rest * rest);
    (c * g, c * dg / rest)
}

/// Energy (J) stored by a buckled connection: the arc's bending energy ½ k_b κ² L with
/// κ = 2θ/L.
pub fn buckling_energy(k_b: f64, rest: f64, len: f64) -> f64 {
    let t = inverse_sinc(len / rest);
    let kappa = 2.0 * t / rest;
    0.5 * k_b * kappa * kappa * rest
}

/// Below this λ the connection's force stays that of λ_min: g′ grows without bound as the
/// ends meet (θ → π).
pub const LAMBDA_MIN: f64 = 0.05;

/// A buckled connection of rest length `rest` at length `len` < `rest`, standing for `area`
/// (m²) of fabric whose bending law `bending(κ)` gives (M per width, dM/dκ, W per area): the
/// arc of length `rest` through the two ends has curvature κ = 2θ/L and energy `area · W(κ)`,
/// so the tension is `area · M(κ) dκ/dl`. Returns (tension N, negative; its derivative with
/// respect to the length, the stable longitudinal part, ≥ 0, N/m; energy J). For a linear law
/// M = Bκ this is Choi & Ko's `k_b (2/L)² g(λ)` with `k_b = area · B / L`.
pub fn buckled_connection(
    area: f64,
    rest: f64,
    len: f64,
    bending: impl Fn(f64) -> (f64, f64, f64),
) -> (f64, f64, f64) {
    let lambda = (len / rest).clamp(LAMBDA_MIN, 1.0);
    let (theta, g, dg) = arc(lambda);
    let kappa = 2.0 * theta / rest;
    let (m, dm, w) = bending(kappa);
    // M/κ (the secant rigidity), and h = κ dκ/dl = 4 g / L³, finite at the onset
    let s = if kappa > 1e-9 { m / kappa } else { dm };
    let h = 4.0 * g / rest.powi(3);
    let tension = area * s * h;
    // d/dl (S h) = S′ κ_l h + S h′ with κ_l = h/κ and S′ = (M′ − S)/κ
    let curved = if kappa > 1e-6 {
        (dm - s) * h * h / (kappa * kappa)
    } else {
        0.0
    };
    let dh = if len / rest > LAMBDA_MIN {
        4.0 * dg / rest.powi(4)
    } else {
        0.0
    };
    let axial = (area * (curved + s * dh)).max(0.0);
    (tension, axial, area * w)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn g_matches_the_exact_values_of_the_maths_notes() {
        // maths notes §4b: exact g(λ)
        let table = [
            (1.0, -3.0),
            (0.9, -3.193),
            (0.8, -3.418),
            (2.0 / std::f64::consts::PI, -3.875),
            (0.5, -4.387),
            (0.3, -5.513),
            (0.1, -7.687),
            (0.0, -std::f64::consts::PI.powi(2)),
        ];
        for (l, g) in table {
            let (got, _) = buckling_g(l);
            assert!((got - g).abs() < 1.5e-3, "g({l}) = {got}, expected {g}");
        }
    }

    #[test]
    fn a_linear_law_gives_choi_and_kos_force() {
        let (b, area, rest) = (3e-5, 0.01 * 0.02, 0.02);
        let kb = area * b / rest;
        for l in [0.99, 0.8, 0.5, 0.2] {
            let len = l * rest;
            let (t, k, e) =
                buckled_connection(area, rest, len, |kap| (b * kap, b, 0.5 * b * kap * kap));
            let (f, df) = buckling_force(kb, rest, len);
            assert!((t - f).abs() < 1e-12 * f.abs() && (k - df).abs() < 1e-9 * df.abs());
            assert!((e - buckling_energy(kb, rest, len)).abs() < 1e-12 * e.abs());
            // a non-linear law: the tangent is the derivative of the tension
            let law = |kap: f64| {
                (
                    b * kap + 0.1 * b * kap.powi(3),
                    b + 0.3 * b * kap * kap,
                    0.0,
                )
            };
            let h = 1e-9;
            let tp = buckled_connection(area, rest, len + h, law).0;
            let tm = buckled_connection(area, rest, len - h, law).0;
            let k = buckled_connection(area, rest, len, law).1;
            assert!((k - (tp - tm) / (2.0 * h)).abs() < 1e-4 * k, "λ {l}");
        }
    }

    #[test]
    fn derivative_and_energy_are_consistent() {
        for l in [0.999_99, 0.99, 0.9, 0.7, 0.4, 0.15] {
            let h = 1e-6;
            let (_, d) = buckling_g(l);
            let fd = (buckling_g(l + h).0 - buckling_g(l - h).0) / (2.0 * h);
            assert!(
                (d - fd).abs() < 1e-4 * fd.abs().max(1.0),
                "λ {l}: {d} vs {fd}"
            );
            // the force is the derivative of the arc's energy with respect to the chord
            let (kb, rest) = (2e-5, 0.01);
            let len = l * rest;
            let (f, _) = buckling_force(kb, rest, len);
            let dl = 1e-9;
            let de = (buckling_energy(kb, rest, len + dl) - buckling_energy(kb, rest, len - dl))
                / (2.0 * dl);
            assert!(
                (f - de).abs() < 1e-4 * f.abs(),
                "λ {l}: f {f} vs dE/dl {de}"
            );
        }
        // the onset series and the exact branch meet where they switch
        let (u_in, u_out) = (0.999e-6, 1.001e-6);
        let (gs, ge) = (buckling_g(1.0 - u_in).0, buckling_g(1.0 - u_out).0);
        assert!((gs - ge).abs() < 1e-6, "series {gs} vs exact {ge}");
        assert_eq!(inverse_sinc(1.0), 0.0);
        let t = inverse_sinc(0.5);
        assert!((t.sin() / t - 0.5).abs() < 1e-14);
    }
}
