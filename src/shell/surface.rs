//! The rest mid-surface of a shell as a map X(ξ¹, ξ²) from a rectangle of the parameter plane,
//! with its first and second derivatives: a plane, a cylinder or a sphere, parametrised by
//! arc length so that the parameter plane's distances are (nearly) the surface's own, or a
//! shallow sinusoidal arch over the plane.

use nalgebra::Vector3;

/// A 3-vector.
pub type V3 = Vector3<f64>;

/// The position and its derivatives at one parameter point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SurfacePoint {
    /// X.
    pub x: V3,
    /// X,₁ and X,₂ (covariant base vectors).
    pub d1: [V3; 2],
    /// X,₁₁, X,₁₂, X,₂₂.
    pub d2: [V3; 3],
}

/// A rest mid-surface.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum Surface {
    /// The plane z = 0: X = (ξ¹, ξ², 0).
    Plane,
    /// A cylinder of axis x and this radius, crown on +z: X = (ξ¹, R sin θ, R cos θ), θ = ξ²/R.
    Cylinder {
        /// Radius (m).
        radius: f64,
    },
    /// A sphere of this radius centred at the origin: ξ¹ = R·longitude, ξ² = R·latitude,
    /// X = R (cos φ cos λ, cos φ sin λ, sin φ).
    Sphere {
        /// Radius (m).
        radius: f64,
    },
    /// A sinusoidal arch over the plane, crown on +z: X = (ξ¹, ξ², e sin(π ξ¹ / L)) (the
    /// parameters are the plane's, not arc length: meant for shallow arches).
    SineArch {
        /// Span L (m): the arch spans ξ¹ in [0, L].
        span: f64,
        /// Rise e (m).
        rise: f64,
    },
}

impl Surface {
    /// The surface and its derivatives at (ξ¹, ξ²).
    pub fn at(&self, xi: [f64; 2]) -> SurfacePoint {
        let z = V3::zeros();
        match *self {
            Surface::Plane => SurfacePoint {
                x: V3::new(xi[0], xi[1], 0.0),
                d1: [V3::x(), V3::y()],
                d2: [z; 3],
            },
            Surface::Cylinder { radius: r } => {
                let (s, c) = (xi[1] / r).sin_cos();
                SurfacePoint {
                    x: V3::new(xi[0], r * s, r * c),
                    d1: [V3::x(), V3::new(0.0, c, -s)],
                    d2: [z, z, V3::new(0.0, -s / r, -c / r)],
                }
            }
            Surface::SineArch { span, rise } => {
                let k = std::f64::consts::PI / span;
                let (s, c) = (k * xi[0]).sin_cos();
                SurfacePoint {
                    x: V3::new(xi[0], xi[1], rise * s),
                    d1: [V3::new(1.0, 0.0, rise * k * c), V3::y()],
                    d2: [V3::new(0.0, 0.0, -rise * k * k * s), z, z],
                }
            }
            Surface::Sphere { radius: r } => {
                let (sl, cl) = (xi[0] / r).sin_cos();
                let (sp, cp) = (xi[1] / r).sin_cos();
                SurfacePoint {
                    x: V3::new(r * cp * cl, r * cp * sl, r * sp),
                    d1: [
                        V3::new(-cp * sl, cp * cl, 0.0),
                        V3::new(-sp * cl, -sp * sl, cp),
                    ],
                    d2: [
                        V3::new(-cp * cl, -cp * sl, 0.0) / r,
                        V3::new(sp * sl, -sp * cl, 0.0) / r,
                        V3::new(-cp * cl, -cp * sl, -sp) / r,
                    ],
                }
            }
        }
    }

    /// Checks the radius, span and rise (finite, > 0).
    pub fn validate(&self) -> Result<(), String> {
        match *self {
            Surface::Plane => Ok(()),
            Surface::SineArch { span, rise } => {
                if span.is_finite() && span > 0.0 && rise.is_finite() && rise > 0.0 {
                    Ok(())
                } else {
                    Err(format!(
                        "arch span and rise must be positive and finite, got {span} and {rise}"
                    ))
                }
            }
            Surface::Cylinder { radius } | Surface::Sphere { radius } => {
                if radius.is_finite() && radius > 0.0 {
                    Ok(())
                } else {
                    Err(format!(
                        "surface radius must be positive and finite, got {radius}"
                    ))
                }
            }
        }
    }
}
