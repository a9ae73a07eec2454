//! Geometrically nonlinear Kirchhoff–Love kinematics at one point of the mid-surface, and the
//! strain energy density there.
//!
//! Deformed base vectors a_α = X,α + u,α and second derivatives a_αβ = X,αβ + u,αβ give the metric
//! a_αβ = a_α·a_β, the unit normal a₃ = a₁×a₂/|a₁×a₂| and the curvature b_αβ = a_αβ·a₃. The strains
//! are the Green–Lagrange membrane strain E_αβ = ½(a_α·a_β − A_αβ) and the bending strain
//! K_αβ = B_αβ − b_αβ (curvature change), capitals for the rest surface; both are turned into
//! the local Cartesian frame of the rest surface with the contravariant base vectors
//! (ε_ij = (e_i·A^α)(e_j·A^β) E_αβ) and the energy per unit rest area is
//! W = ½ εᵀ D_m ε + ½ κᵀ D_b κ (Voigt, engineering shear). Large rotations and large
//! displacements are exact; the law is linear in these strains (small strains).

use super::fabric_law::FabricLaw;
use super::jet::{cross, dot, Jet, JetVec};
use super::material::ShellMaterial;
use super::surface::{SurfacePoint, V3};

/// What the energy density needs of the rest surface at a point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RestGeometry {
    /// The rest surface's derivatives (X,α, X,αβ).
    pub point: SurfacePoint,
    /// Rest metric A₁₁, A₁₂, A₂₂.
    pub metric: [f64; 3],
    /// Rest curvature B₁₁, B₁₂, B₂₂ (with the normal X,₁×X,₂/|X,₁×X,₂|).
    pub curvature: [f64; 3],
    /// `t[i][α]` = e_i·A^α: covariant strain components → local Cartesian ones.
    pub to_local: [[f64; 2]; 2],
    /// Area element |X,₁ × X,₂| (rest area per unit parameter area).
    pub area: f64,
    /// Unit rest normal.
    pub normal: V3,
}

impl RestGeometry {
    /// The rest geometry at a surface point. None where the tangents are parallel.
    pub fn new(point: SurfacePoint) -> Option<RestGeometry> {
        let [g1, g2] = point.d1;
        let n = g1.cross(&g2);
        let area = n.norm();
        if area.is_nan() || area <= 1e-300 {
            return None;
        }
        let normal = n / area;
        let metric = [g1.dot(&g1), g1.dot(&g2), g2.dot(&g2)];
        let curvature = [
            point.d2[0].dot(&normal),
            point.d2[1].dot(&normal),
            point.d2[2].dot(&normal),
        ];
        // contravariant base vectors
        let det = metric[0] * metric[2] - metric[1] * metric[1];
        let c1 = (g1 * metric[2] - g2 * metric[1]) / det;
        let c2 = (g2 * metric[0] - g1 * metric[1]) / det;
        let e1 = g1.normalize();
        let e2 = normal.cross(&e1);
        Some(RestGeometry {
            point,
            metric,
            curvature,
            to_local: [[e1.dot(&c1), e1.dot(&c2)], [e2.dot(&c1), e2.dot(&c2)]],
            area,
            normal,
        })
    }
}

/// Covariant symmetric components (11, 12, 22) → local Voigt (11, 22, 2·12).
fn to_voigt(t: &[[f64; 2]; 2], c: [Jet; 3]) -> [Jet; 3] {
    let comp = |i: usize, j: usize| {
        c[0].scale(t[i][0] * t[j][0])
            + c[1].scale(t[i][0] * t[j][1] + t[i][1] * t[j][0])
            + c[2].scale(t[i][1] * t[j][1])
    };
    [comp(0, 0), comp(1, 1), comp(0, 1).scale(2.0)]
}

/// ½ vᵀ D v.
fn quadratic(d: &[[f64; 3]; 3], v: &[Jet; 3]) -> Jet {
    let mut w = Jet::constant(0.0);
    for i in 0..3 {
        let s = v[0].scale(d[i][0]) + v[1].scale(d[i][1]) + v[2].scale(d[i][2]);
        w = w + (v[i] * s).scale(0.5);
    }
    w
}

/// The strain energy per unit rest area as a jet in the 15 local variables
/// `locals` = (a₁, a₂, a₁₁, a₁₂, a₂₂), each a 3-vector.
pub fn energy_density(locals: &[f64; 15], rest: &RestGeometry, mat: &ShellMaterial) -> Jet {
    energy_density_law(locals, rest, mat, None)
}

/// [`energy_density`] with the fabric's nonlinear law `law` in place of the linear `mat`
/// when given ([`FabricLaw::energy`], same strains).
pub fn energy_density_law(
    locals: &[f64; 15],
    rest: &RestGeometry,
    mat: &ShellMaterial,
    law: Option<&FabricLaw>,
) -> Jet {
    let var = |k: usize| -> JetVec {
        [
            Jet::variable(locals[3 * k], 3 * k),
            Jet::variable(locals[3 * k + 1], 3 * k + 1),
            Jet::variable(locals[3 * k + 2], 3 * k + 2),
        ]
    };
    let (a1, a2) = (var(0), var(1));
    let (a11, a12, a22) = (var(2), var(3), var(4));
    let half = |j: Jet, rest: f64| (j + (-rest)).scale(0.5);
    let e = [
        half(dot(&a1, &a1), rest.metric[0]),
        half(dot(&a1, &a2), rest.metric[1]),
        half(dot(&a2, &a2), rest.metric[2]),
    ];
    let n = cross(&a1, &a2);
    let inv = dot(&n, &n).sqrt().recip();
    let curv = |a: &JetVec, rest_b: f64| -(dot(a, &n) * inv) + rest_b;
    let k = [
        curv(&a11, rest.curvature[0]),
        curv(&a12, rest.curvature[1]),
        curv(&a22, rest.curvature[2]),
    ];
    let eps = to_voigt(&rest.to_local, e);
    let kap = to_voigt(&rest.to_local, k);
    match law {
        Some(f) => f.energy(&eps, &kap),
        None => quadratic(&mat.membrane, &eps) + quadratic(&mat.bending, &kap),
    }
}

/// The rest values of the 15 local variables at a point.
pub fn rest_locals(rest: &RestGeometry) -> [f64; 15] {
    let p = &rest.point;
    let vs = [p.d1[0], p.d1[1], p.d2[0], p.d2[1], p.d2[2]];
    let mut out = [0.0; 15];
    for (k, v) in vs.iter().enumerate() {
        out[3 * k] = v.x;
        out[3 * k + 1] = v.y;
        out[3 * k + 2] = v.z;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shell::surface::Surface;

    #[test]
    fn rigid_rotation_stores_no_energy_and_bending_a_plate_stores_half_d_kappa_squared() {
        let mat = ShellMaterial::isotropic(1e9, 0.3, 0.01, 1.0).unwrap();
        let rest = RestGeometry::new(Surface::Cylinder { radius: 2.0 }.at([0.3, 0.7])).unwrap();
        // rotate the rest locals by 40° about an arbitrary axis
        let rot = nalgebra::Rotation3::from_axis_angle(
            &nalgebra::Unit::new_normalize(V3::new(1.0, 2.0, 0.5)),
            0.7,
        );
        let mut l = rest_locals(&rest);
        for k in 0..5 {
            let v = rot * V3::new(l[3 * k], l[3 * k + 1], l[3 * k + 2]);
            l[3 * k..3 * k + 3].copy_from_slice(&[v.x, v.y, v.z]);
        }
        let w = energy_density(&l, &rest, &mat);
        assert!(w.v.abs() < 1e-12, "rigid rotation stores {}", w.v);
        assert!(w.g.iter().all(|g| g.abs() < 1e-6), "{:?}", w.g);
        // a flat plate bent to curvature κ about ξ²: W = ½ D κ²
        let flat = RestGeometry::new(Surface::Plane.at([0.0, 0.0])).unwrap();
        let kappa = 0.5;
        let mut l = rest_locals(&flat);
        l[8] = kappa; // a₁₁ = (0, 0, κ): pure curvature, no stretch
        let w = energy_density(&l, &flat, &mat);
        let d = mat.bending[0][0];
        assert!(
            (w.v - 0.5 * d * kappa * kappa).abs() < 1e-12 * d,
            "{} vs {}",
            w.v,
            0.5 * d * kappa * kappa
        );
    }
}
