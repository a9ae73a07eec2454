//! Measures of a compressed cloth: how many stretch springs stay compressed (a cloth without a
//! buckling model gets stuck compressed instead of wrinkling), and the wrinkles along a line of
//! a grid cloth (half-waves, wavelength, amplitude).

use crate::cloth::elements::SpringKind;
use crate::cloth::model::ClothModel;
use crate::geometry::Vec3;

/// Compressed stretch springs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Compression {
    /// Stretch springs in the model.
    pub springs: usize,
    /// Those shorter than (1 − strain) × their rest length.
    pub compressed: usize,
}

impl Compression {
    /// Share of the stretch springs compressed (0–1).
    pub fn fraction(&self) -> f64 {
        self.compressed as f64 / self.springs.max(1) as f64
    }
}

/// Counts the stretch springs of `model` at positions `x` compressed by more than `strain`.
pub fn compressed_springs(model: &ClothModel, x: &[Vec3], strain: f64) -> Compression {
    let mut c = Compression {
        springs: 0,
        compressed: 0,
    };
    for s in &model.springs {
        if let SpringKind::Stretch { .. } = s.kind {
            c.springs += 1;
            if (x[s.b] - x[s.a]).norm() < (1.0 - strain) * s.rest {
                c.compressed += 1;
            }
        }
    }
    c
}

/// Wrinkles along one line of particles.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Wrinkles {
    /// Half-waves: runs of the height profile above or below its mean by more than the
    /// threshold (a crest or a trough each).
    pub half_waves: usize,
    /// Mean wavelength (m): twice the line's span over the half-waves; infinite if none.
    pub wavelength: f64,
    /// Half the height range of the profile (m).
    pub amplitude: f64,
}

/// The wrinkles along the line of particles `line` (in order), heights measured along `up`:
/// the profile's deviation from its mean is followed with hysteresis `threshold` (m), so
/// ripples smaller than it do not count.
pub fn wrinkles_along(x: &[Vec3], line: &[usize], up: Vec3, threshold: f64) -> Wrinkles {
    if line.len() < 2 {
        return Wrinkles {
            half_waves: 0,
            wavelength: f64::INFINITY,
            amplitude: 0.0,
        };
    }
    let h: Vec<f64> = line.iter().map(|&i| x[i].dot(&up)).collect();
    let mean = h.iter().sum::<f64>() / h.len() as f64;
    let (lo, hi) = h
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        });
    // state: 0 undecided, +1 above, −1 below
    let mut state = 0;
    let mut half_waves = 0;
    for v in &h {
        let d = v - mean;
        let next = if d > threshold {
            1
        } else if d < -threshold {
            -1
        } else {
            state
        };
        if next != state && next != 0 {
            half_waves += 1;
            state = next;
        }
    }
    let ends = (x[line[line.len() - 1]] - x[line[0]]).norm();
    Wrinkles {
        half_waves,
        wavelength: if half_waves > 0 {
            2.0 * ends / half_waves as f64
        } else {
            f64::INFINITY
        },
        amplitude: 0.5 * (hi - lo),
    }
}

/// Elastic energy of a cloth split by what stores it (J).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct EnergyParts {
    /// Warp and weft stretch springs (and seam threads).
    pub stretch: f64,
    /// Shear (shear springs and shear cells).
    pub shear: f64,
    /// Bending lines and hinges.
    pub bending: f64,
    /// Choi–Ko's buckled interlaced connections.
    pub flexion: f64,
}

impl EnergyParts {
    /// The sum of the parts.
    pub fn total(&self) -> f64 {
        self.stretch + self.shear + self.bending + self.flexion
    }
}

/// The elastic energy of `model` at positions `x`, element by element (elastic part of the
/// laws: friction states are not included).
pub fn energy_parts(model: &ClothModel, x: &[Vec3]) -> EnergyParts {
    let law = &*model.law;
    let mut e = EnergyParts::default();
    for s in &model.springs {
        let w = s.eval(law, &x[s.a], &x[s.b]).energy;
        match s.kind {
            SpringKind::Stretch { .. } | SpringKind::Seam { .. } => e.stretch += w,
            SpringKind::Shear => e.shear += w,
            SpringKind::Flexion { .. } => e.flexion += w,
        }
    }
    for c in &model.arcs {
        if let Some(ev) = c.eval(law, x) {
            e.flexion += ev.energy;
        }
    }
    for q in &model.shear_quads {
        e.shear += q.area * law.shear(q.measure(x).gamma).2;
    }
    for b in &model.bend_lines {
        let kappa = b.geometry(x).qn.norm();
        e.bending += b.area * law.bending(b.dir, kappa).2;
    }
    for h in &model.hinges {
        if let Some((theta, _)) = h.angle_and_gradient(x) {
            let kappa = theta.abs() * h.edge / h.area;
            e.bending += h.area * h.law(law, kappa).2;
        }
    }
    e
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_sine_profile_gives_its_wavelength() {
        // three full waves over 0.3 m, amplitude 5 mm
        let x: Vec<Vec3> = (0..301)
            .map(|k| {
                let s = k as f64 * 0.001;
                Vec3::new(s, 0.0, 0.005 * (2.0 * std::f64::consts::PI * s / 0.1).sin())
            })
            .collect();
        let line: Vec<usize> = (0..x.len()).collect();
        let w = wrinkles_along(&x, &line, Vec3::z(), 0.001);
        assert_eq!(w.half_waves, 6);
        assert!((w.wavelength - 0.1).abs() < 1e-9);
        assert!((w.amplitude - 0.005).abs() < 1e-6);
        // ripples below the threshold are no wrinkles
        assert_eq!(wrinkles_along(&x, &line, Vec3::z(), 0.01).half_waves, 0);
    }

    #[test]
    fn energy_parts_add_up_to_the_assembled_energy() {
        use crate::cloth::elements::material::FabricParameters;
        use crate::cloth::solver::assembly::{Assembly, AssemblyInputs};
        let fabric = FabricParameters::default();
        let mut m = ClothModel::grid(0.3, 0.2, 7, 5, fabric).unwrap();
        m.perturb(Vec3::new(0.3, -0.2, 1.0), 0.02, 7);
        m.prestrain(-0.03, 0.02);
        let x = m.mesh.positions.clone();
        let v = vec![Vec3::zeros(); x.len()];
        let inp = AssemblyInputs {
            dt: 0.01,
            gravity: Vec3::zeros(),
            matrix: false,
        };
        for choi_ko in [false, true] {
            if choi_ko {
                m.enable_choi_ko();
            }
            let e = energy_parts(&m, &x);
            let assembled = Assembly::new(&m).assemble(&m, &x, &v, inp);
            assert!(e.stretch > 0.0 && e.shear > 0.0);
            assert_eq!(e.bending > 0.0, !choi_ko);
            assert_eq!(e.flexion > 0.0, choi_ko);
            assert!(
                (e.total() - assembled).abs() <= 1e-12 * assembled,
                "{e:?} against {assembled}"
            );
        }
    }
}
