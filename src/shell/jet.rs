//! Second-order forward automatic differentiation over the 15 local variables of a shell
//! quadrature point (a₁, a₂, a₁₁, a₁₂, a₂₂: the deformed tangents and second derivatives): a
//! value with its gradient and Hessian. The strain energy density is written once with these,
//! and its exact gradient (internal forces) and Hessian (tangent stiffness) come out together.
//! Fixed-size arrays, no allocation.

use std::ops::{Add, Mul, Neg, Sub};

/// Number of local variables.
pub const NV: usize = 15;

/// A value with its gradient and Hessian in the [`NV`] local variables.
#[derive(Clone, Copy, Debug)]
pub struct Jet {
    /// Value.
    pub v: f64,
    /// Gradient.
    pub g: [f64; NV],
    /// Hessian (symmetric, stored whole).
    pub h: [[f64; NV]; NV],
}

impl Jet {
    /// A constant.
    pub fn constant(v: f64) -> Jet {
        Jet {
            v,
            g: [0.0; NV],
            h: [[0.0; NV]; NV],
        }
    }

    /// The variable number `i` with value `v`.
    pub fn variable(v: f64, i: usize) -> Jet {
        let mut j = Jet::constant(v);
        j.g[i] = 1.0;
        j
    }

    /// `self × s` for a plain number.
    pub fn scale(&self, s: f64) -> Jet {
        let mut r = *self;
        r.v *= s;
        for i in 0..NV {
            r.g[i] *= s;
            for j in 0..NV {
                r.h[i][j] *= s;
            }
        }
        r
    }

    /// f(self) for a scalar function with value f0, first derivative f1 and second f2 there.
    pub fn chain(&self, f0: f64, f1: f64, f2: f64) -> Jet {
        let mut r = Jet::constant(f0);
        for i in 0..NV {
            r.g[i] = f1 * self.g[i];
            for j in 0..NV {
                r.h[i][j] = f1 * self.h[i][j] + f2 * self.g[i] * self.g[j];
            }
        }
        r
    }

    /// Square root (of a positive value).
    pub fn sqrt(&self) -> Jet {
        let s = self.v.sqrt();
        self.chain(s, 0.5 / s, -0.25 / (s * self.v))
    }

    /// Arc sine (of a value inside (−1, 1)).
    pub fn asin(&self) -> Jet {
        let c = 1.0 - self.v * self.v;
        let r = 1.0 / c.sqrt();
        self.chain(self.v.asin(), r, self.v * r / c)
    }

    /// Reciprocal (of a non-zero value).
    pub fn recip(&self) -> Jet {
        let r = 1.0 / self.v;
        self.chain(r, -r * r, 2.0 * r * r * r)
    }
}

impl Add for Jet {
    type Output = Jet;
    fn add(mut self, o: Jet) -> Jet {
        self.v += o.v;
        for i in 0..NV {
            self.g[i] += o.g[i];
            for j in 0..NV {
                self.h[i][j] += o.h[i][j];
            }
        }
        self
    }
}

impl Sub for Jet {
    type Output = Jet;
    fn sub(self, o: Jet) -> Jet {
        self + (-o)
    }
}

impl Neg for Jet {
    type Output = Jet;
    fn neg(self) -> Jet {
        self.scale(-1.0)
    }
}

impl Add<f64> for Jet {
    type Output = Jet;
    fn add(mut self, o: f64) -> Jet {
        self.v += o;
        self
    }
}

impl Mul for Jet {
    type Output = Jet;
    fn mul(self, o: Jet) -> Jet {
        let mut r = Jet::constant(self.v * o.v);
        for i in 0..NV {
            r.g[i] = self.v * o.g[i] + o.v * self.g[i];
            for j in 0..NV {
                r.h[i][j] = self.v * o.h[i][j]
                    + o.v * self.h[i][j]
                    + self.g[i] * o.g[j]
                    + o.g[i] * self.g[j];
            }
        }
        r
    }
}

/// A 3-vector of jets.
pub type JetVec = [Jet; 3];

/// Dot product.
pub fn dot(a: &JetVec, b: &JetVec) -> Jet {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Cross product.
pub fn cross(a: &JetVec, b: &JetVec) -> JetVec {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn jet_derivatives_match_the_analytic_ones() {
        // f(x, y) = sqrt(x² + y²) / x at (3, 4): f = 5/3
        let x = Jet::variable(3.0, 0);
        let y = Jet::variable(4.0, 1);
        let f = (x * x + y * y).sqrt() * x.recip();
        assert!((f.v - 5.0 / 3.0).abs() < 1e-14);
        // ∂f/∂x = x/(r x) − r/x² = 1/5 − 5/9 ; ∂f/∂y = y/(r x) = 4/15
        assert!((f.g[0] - (0.2 - 5.0 / 9.0)).abs() < 1e-14);
        assert!((f.g[1] - 4.0 / 15.0).abs() < 1e-14);
        // ∂²f/∂y² = x²/(r³ x) = 9/(125·3)
        assert!((f.h[1][1] - 9.0 / 375.0).abs() < 1e-14);
        assert!((f.h[0][1] - f.h[1][0]).abs() < 1e-15);
    }
}
