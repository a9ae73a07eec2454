//! A material law built from measurements: nonlinear tension per direction, shear and bending
//! per direction as monotone cubic curves through measured points (or curves synthesised from
//! KES parameters), plus rate-independent internal friction per mode (hysteresis). Values are
//! SI per unit width; strains and angles are dimensionless, curvatures in 1/m.

use serde::{Deserialize, Serialize};

use super::material::{Direction, Friction, MaterialLaw};

/// A monotone piecewise-cubic (Fritsch–Carlson PCHIP) curve y(x) on x ≥ 0 through given
/// points, extended linearly with its end slope beyond the last point. Keeps the cumulative
/// integral at the knots so the energy ∫₀ˣ y is exact for the cubic.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ResponseCurve {
    xs: Vec<f64>,
    ys: Vec<f64>,
    ds: Vec<f64>,
    ws: Vec<f64>,
}

impl ResponseCurve {
    /// A curve through `points` (x strictly increasing, x ≥ 0, all finite). A point at x = 0
    /// is added (y = 0) when the first point lies beyond it.
    pub fn new(points: &[[f64; 2]]) -> Result<Self, String> {
        let mut pts: Vec<[f64; 2]> = Vec::with_capacity(points.len() + 1);
        for p in points {
            if !(p[0].is_finite() && p[1].is_finite()) {
                return Err(format!("curve point ({}, {}) is not finite", p[0], p[1]));
            }
            if p[0] < 0.0 {
                continue;
            }
            if let Some(last) = pts.last() {
                if p[0] <= last[0] {
                    return Err(format!(
                        "curve abscissae must increase: {} after {}",
                        p[0], last[0]
                    ));
                }
            }
            pts.push(*p);
        }
        if pts.first().is_none_or(|p| p[0] > 0.0) {
            pts.insert(0, [0.0, 0.0]);
        }
        if pts.len() < 2 {
            return Err("a curve needs at least one point with x > 0".into());
        }
        let n = pts.len();
        let xs: Vec<f64> = pts.iter().map(|p| p[0]).collect();
        let ys: Vec<f64> = pts.iter().map(|p| p[1]).collect();
        let sec: Vec<f64> = (0..n - 1)
            .map(|k| (ys[k + 1] - ys[k]) / (xs[k + 1] - xs[k]))
            .collect();
        let mut ds = vec![0.0; n];
        ds[0] = end_slope(
            xs[1] - xs[0],
            xs.get(2).map(|x| x - xs[1]),
            sec[0],
            sec.get(1),
        );
        ds[n - 1] = end_slope(
            xs[n - 1] - xs[n - 2],
            (n > 2).then(|| xs[n - 2] - xs[n - 3]),
            sec[n - 2],
            (n > 2).then(|| &sec[n - 3]),
        );
        for k in 1..n - 1 {
            let (a, b) = (sec[k - 1], sec[k]);
            ds[k] = if a * b <= 0.0 {
                0.0
            } else {
                // weighted harmonic mean (Fritsch–Butland), keeps the cubic monotone
                let (h0, h1) = (xs[k] - xs[k - 1], xs[k + 1] - xs[k]);
                let (w1, w2) = (2.0 * h1 + h0, h1 + 2.0 * h0);
                (w1 + w2) / (w1 / a + w2 / b)
            };
        }
        let mut ws = vec![0.0; n];
        for k in 0..n - 1 {
            let h = xs[k + 1] - xs[k];
            let mid = hermite(ys[k], ys[k + 1], ds[k], ds[k + 1], h, 0.5).0;
            ws[k + 1] = ws[k] + h / 6.0 * (ys[k] + 4.0 * mid + ys[k + 1]);
        }
        Ok(ResponseCurve { xs, ys, ds, ws })
    }

    /// A straight line y = slope · x (a non-finite slope gives the zero line).
    pub fn linear(slope: f64) -> Self {
        let slope = if slope.is_finite() { slope } else { 0.0 };
        ResponseCurve {
            xs: vec![0.0, 1.0],
            ys: vec![0.0, slope],
            ds: vec![slope, slope],
            ws: vec![0.0, 0.5 * slope],
        }
    }

    /// (y, dy/dx, ∫₀ˣ y) at x ≥ 0.
    #[inline]
    pub fn eval(&self, x: f64) -> (f64, f64, f64) {
        let n = self.xs.len();
        if x >= self.xs[n - 1] {
            let d = x - self.xs[n - 1];
            let (y, s) = (self.ys[n - 1], self.ds[n - 1]);
            return (y + s * d, s, self.ws[n - 1] + y * d + 0.5 * s * d * d);
        }
        let k = self.xs.partition_point(|&v| v <= x).max(1) - 1;
        let h = self.xs[k + 1] - self.xs[k];
        let t = (x - self.xs[k]) / h;
        let (y, dy) = hermite(self.ys[k], self.ys[k + 1], self.ds[k], self.ds[k + 1], h, t);
        let mid = hermite(
            self.ys[k],
            self.ys[k + 1],
            self.ds[k],
            self.ds[k + 1],
            h,
            0.5 * t,
        )
        .0;
        // Simpson is exact for the cubic on [x_k, x]
        let w = self.ws[k] + (x - self.xs[k]) / 6.0 * (self.ys[k] + 4.0 * mid + y);
        (y, dy, w)
    }

    /// Slope at x = 0.
    pub fn initial_slope(&self) -> f64 {
        self.ds[0]
    }

    /// The last knot (x, y).
    pub fn end(&self) -> [f64; 2] {
        let n = self.xs.len();
        [self.xs[n - 1], self.ys[n - 1]]
    }
}

/// The shape-preserving three-point end derivative of PCHIP (Moler, *Numerical Computing
/// with MATLAB*): h0, δ0 the end interval and its secant, h1, δ1 the next ones.
fn end_slope(h0: f64, h1: Option<f64>, d0: f64, d1: Option<&f64>) -> f64 {
    let (Some(h1), Some(&d1)) = (h1, d1) else {
        return d0;
    };
    let d = ((2.0 * h0 + h1) * d0 - h0 * d1) / (h0 + h1);
    if d * d0 <= 0.0 {
        0.0
    } else if d0 * d1 < 0.0 && d.abs() > 3.0 * d0.abs() {
        3.0 * d0
    } else {
        d
    }
}

/// Cubic Hermite value and derivative on a segment of length h at parameter t ∈ [0, 1].
#[inline]
fn hermite(y0: f64, y1: f64, d0: f64, d1: f64, h: f64, t: f64) -> (f64, f64) {
    let (t2, t3) = (t * t, t * t * t);
    let y = (2.0 * t3 - 3.0 * t2 + 1.0) * y0
        + (t3 - 2.0 * t2 + t) * h * d0
        + (-2.0 * t3 + 3.0 * t2) * y1
        + (t3 - t2) * h * d1;
    let dy = ((6.0 * t2 - 6.0 * t) * y0 + (-6.0 * t2 + 6.0 * t) * y1) / h
        + (3.0 * t2 - 4.0 * t + 1.0) * d0
        + (3.0 * t2 - 2.0 * t) * d1;
    (y, dy)
}

/// The measured law. Tension curves hold for ε ≥ 0; in compression the fabric answers
/// linearly with `compression` stiffness (a woven buckles rather than compresses; bending
/// carries the rest). Shear and bending curves are odd in their coordinate.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MeasuredLaw {
    /// Elastic tension per width (N/m) vs strain, warp then weft.
    pub tension: [ResponseCurve; 2],
    /// Compressive stiffness (N/m), warp then weft.
    pub compression: [f64; 2],
    /// Elastic shear force per width (N/m) vs shear angle (rad).
    pub shear: ResponseCurve,
    /// Elastic bending moment per width (N) vs curvature (1/m), warp then weft.
    pub bending: [ResponseCurve; 2],
    /// Tensile friction, warp then weft.
    pub tension_friction: [Option<Friction>; 2],
    /// Shear friction.
    pub shear_friction: Option<Friction>,
    /// Bending friction, warp then weft.
    pub bending_friction: [Option<Friction>; 2],
}

fn index(dir: Direction) -> usize {
    match dir {
        Direction::Warp => 0,
        Direction::Weft => 1,
    }
}

/// Odd extension of a curve: (y, dy, energy) at signed x.
#[inline]
fn odd(c: &ResponseCurve, x: f64) -> (f64, f64, f64) {
    let (y, d, w) = c.eval(x.abs());
    (y * x.signum(), d, w)
}

impl MaterialLaw for MeasuredLaw {
    fn tension(&self, dir: Direction, strain: f64) -> (f64, f64, f64) {
        let k = index(dir);
        if strain >= 0.0 {
            self.tension[k].eval(strain)
        } else {
            let c = self.compression[k];
            (c * strain, c, 0.5 * c * strain * strain)
        }
    }
    fn shear(&self, gamma: f64) -> (f64, f64, f64) {
        odd(&self.shear, gamma)
    }
    fn bending(&self, dir: Direction, kappa: f64) -> (f64, f64, f64) {
        odd(&self.bending[index(dir)], kappa)
    }
    fn tension_friction(&self, dir: Direction) -> Option<Friction> {
        self.tension_friction[index(dir)]
    }
    fn shear_friction(&self) -> Option<Friction> {
        self.shear_friction
    }
    fn bending_friction(&self, dir: Direction) -> Option<Friction> {
        self.bending_friction[index(dir)]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pchip_through_a_parabola_is_monotone_and_integrates() {
        let pts: Vec<[f64; 2]> = (1..=20)
            .map(|k| {
                let x = k as f64 * 0.05;
                [x, x * x]
            })
            .collect();
        let c = ResponseCurve::new(&pts).unwrap();
        let mut last = -1.0;
        for k in 0..=1000 {
            let x = k as f64 * 0.001;
            let (y, d, w) = c.eval(x);
            assert!(y >= last - 1e-15, "not monotone at {x}");
            last = y;
            assert!((y - x * x).abs() < 2e-4, "y({x}) = {y}");
            assert!((w - x * x * x / 3.0).abs() < 2e-5, "W({x}) = {w}");
            if x > 0.1 && x < 0.95 {
                assert!((d - 2.0 * x).abs() < 0.02, "dy({x}) = {d}");
            }
        }
        // linear extension beyond the data
        let (y, d, _) = c.eval(2.0);
        assert!((d - c.eval(1.0).1).abs() < 1e-12 && y > 1.0);
    }

    #[test]
    fn curves_reject_bad_points() {
        assert!(ResponseCurve::new(&[[0.1, 1.0], [0.1, 2.0]]).is_err());
        assert!(ResponseCurve::new(&[[0.1, f64::NAN]]).is_err());
        assert!(ResponseCurve::new(&[]).is_err());
    }
}
