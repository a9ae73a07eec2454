//! `StepGuard`: what an implicit step must pass before it counts, so that a step never reports
//! success on garbage. The system it solves must be finite (no force, right-hand side or
//! diagonal block that is NaN, infinite or whose square overflows); the solve's convergence is
//! judged on the true residual, recomputed from the matrix, in a norm that a zero or
//! overflowing right-hand side cannot pass; and the state it ends in must keep the cloth's
//! energy balance, its pins, and strains a fabric can have. A failing step is retried by
//! [`super::Simulation`] split into 2, 4, … [`MAX_SPLITS`]² substeps, or stops with an error.
//! The tolerances are stated here and in `docs/cloth-solver.md`.

use super::constraints::Attachment;
use super::elements::SpringKind;
use super::model::ClothModel;
use super::solver::bcsr::Bcsr3;
use crate::geometry::Vec3;

/// How many times a failing step is split in halves before the run stops: 4, down to dt/16.
pub const MAX_SPLITS: u32 = 4;

/// Largest energy gain of one step beyond the work the constraints and prescribed motions did
/// on the cloth, as a multiple of the step's energy scale (see [`EnergyRecord`]): an energy
/// blow-up. Linearised backward Euler is not exactly dissipative on large deformations: in
/// the test scenes a step gains up to 0.7 times its scale (a stiff cloth at dt = 1/30 s
/// snapping taut, a square pushed from one border), where the stiff light cloth at dt = 1 s
/// gains 2·10⁵ times it.
pub const ENERGY_TOLERANCE: f64 = 10.0;

/// Largest distance of a pinned or attached particle from its target at the end of a step,
/// as a share of the cloth's size (its initial bounding-box diagonal).
pub const PIN_TOLERANCE: f64 = 1e-6;

/// Largest stretch of a stretch spring (length / rest length − 1): 400 %, five times its
/// length, far beyond any fabric (wovens break below 50 %, knits with elastane near 200 %).
/// Not 100 %: the flat triangle mesh pushed from one border without a buckling model
/// (`tests/buckling.rs`) snaps one spring to 309 % for a step as it buckles and recovers, a
/// result its test keeps.
pub const MAX_STRETCH: f64 = 4.0;

/// A right-hand side below this share of the step's gravity impulse `h ‖M g‖` is taken as
/// round-off of an equilibrium: the true residual is judged against this floor instead.
pub const RHS_FLOOR: f64 = 1e-9;

/// The energy of one accepted (sub)step, checked against the energy at the start of the next
/// one (which that step's own assembly computes, so the check costs nothing).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EnergyRecord {
    /// Index of the step.
    pub step: u64,
    /// Start and end time of the (sub)step (s).
    pub span: (f64, f64),
    /// Total energy (kinetic + gravitational + elastic) at its start (J).
    pub total: f64,
    /// Work done on the cloth during it by constraint impulses (pins, attachments, contact
    /// and holds: Σ J·v at constrained particles) and by the stages' responses (their change
    /// of kinetic and gravitational energy) (J).
    pub work: f64,
    /// Its energy scale: kinetic + |elastic| at its start + |work| + the cloth's weight times
    /// its size + a fabric floor (J).
    pub scale: f64,
    /// The gravity it ran under (m/s²): a change of gravity changes the energy.
    pub gravity: Vec3,
}

/// The checks of a step, and the energy of the last accepted step.
#[derive(Debug, Clone)]
pub struct StepGuard {
    /// The last accepted (sub)step's energy, while the state is the one it left.
    pub record: Option<EnergyRecord>,
    /// The cloth's size: its initial bounding-box diagonal (m).
    pub size: f64,
    /// Its total mass (kg).
    pub mass: f64,
    /// The Euclidean norm of its particle masses, ‖m‖ (kg): `h ‖m‖ |g|` is the norm of a
    /// step's gravity impulse.
    pub mass_norm: f64,
    /// The energy scale of a cloth at rest without gravity: 1e-12 × its stiffest stretch
    /// rigidity × its area (J).
    pub floor: f64,
}

impl StepGuard {
    /// The guard of `model`.
    pub fn new(model: &ClothModel) -> Self {
        let (lo, hi) = crate::geometry::mesh::bounds(&model.mesh.positions);
        let f = &model.fabric;
        let area: f64 = model.area.iter().sum();
        StepGuard {
            record: None,
            size: (hi - lo).norm(),
            mass: model.mass.iter().sum(),
            mass_norm: model.mass.iter().map(|m| m * m).sum::<f64>().sqrt(),
            floor: 1e-12 * f.stretch_warp.max(f.stretch_weft).max(f.shear) * area,
        }
    }

    /// Forgets the last step's energy (the state or the model changed since).
    pub fn forget(&mut self) {
        self.record = None;
    }

    /// The energy scale of a step that starts with kinetic energy `kinetic`, elastic energy
    /// `elastic` under `gravity`, and on which `work` is done.
    pub fn scale(&self, kinetic: f64, elastic: f64, work: f64, gravity: Vec3) -> f64 {
        kinetic.abs()
            + elastic.abs()
            + work.abs()
            + self.mass * gravity.norm() * self.size
            + self.floor
    }

    /// Checks the energy `total` at the start of a (sub)step under `gravity` against the last
    /// accepted step's: it may have risen by that step's work plus [`ENERGY_TOLERANCE`] times
    /// its energy scale. Returns the failing record with the cause.
    pub fn check_energy(&self, total: f64, gravity: Vec3) -> Result<(), (EnergyRecord, String)> {
        let Some(rec) = self.record.filter(|r| r.gravity == gravity) else {
            return Ok(());
        };
        let gain = total - rec.total - rec.work;
        if gain <= ENERGY_TOLERANCE * rec.scale {
            return Ok(());
        }
        let cause = format!(
            "energy blow-up: the total energy rose from {:.4e} J to {total:.4e} J over t = {:.6}–{:.6} s, \
             {gain:.3e} J more than the {:.3e} J of work by constraints, contact and prescribed motion \
             (tolerance {ENERGY_TOLERANCE} × the step's energy scale {:.3e} J)",
            rec.total, rec.span.0, rec.span.1, rec.work, rec.scale
        );
        Err((rec, cause))
    }
}

/// Checks the implicit system of a step of length `h` before it is solved: every particle's
/// right-hand side `b` (an impulse, `h` times the force) finite with a finite square, and
/// every diagonal block of `a` finite. Names the first bad particle and its force.
pub fn check_system(a: &Bcsr3, b: &[Vec3], h: f64) -> Result<(), String> {
    for (i, bi) in b.iter().enumerate() {
        if !bi.norm_squared().is_finite() {
            let f = bi / h;
            return Err(format!(
                "non-finite or overflowing force on particle {i}: ({:.3e}, {:.3e}, {:.3e}) N \
                 (check gravity, stiffness and the other parameters' magnitudes)",
                f.x, f.y, f.z
            ));
        }
    }
    if !a.values.is_empty() || !a.sym.is_empty() {
        for (i, &k) in a.diag.iter().enumerate() {
            let d = a.block(k);
            if !d.iter().all(|c| c.is_finite()) {
                return Err(format!(
                    "non-finite or overflowing stiffness at particle {i}: diagonal block {:?} \
                     (check the stiffness and mass magnitudes)",
                    d.diagonal().as_slice()
                ));
            }
        }
    }
    Ok(())
}

/// Whether a solve whose true residual is `residual`, for a right-hand side of norm `rhs`
/// (‖S(b − Az)‖) and a step gravity impulse of norm `gravity_impulse` (h ‖M g‖), met
/// `tolerance`: `residual ≤ tolerance · max(rhs, RHS_FLOOR · gravity_impulse)`, every number
/// finite. Returns the relative residual it judged and the verdict.
pub fn judge_residual(
    residual: f64,
    rhs: f64,
    gravity_impulse: f64,
    tolerance: f64,
) -> (f64, bool) {
    let reference = rhs.max(RHS_FLOOR * gravity_impulse);
    let relative = if reference > 0.0 {
        residual / reference
    } else if residual == 0.0 {
        0.0
    } else {
        f64::INFINITY
    };
    let finite = residual.is_finite() && rhs.is_finite() && gravity_impulse.is_finite();
    (relative, finite && relative <= tolerance)
}

/// Checks that every attached particle is at its attachment's target at time `t` (within
/// [`PIN_TOLERANCE`] × `size`).
pub fn check_pins(attachments: &[Attachment], x: &[Vec3], t: f64, size: f64) -> Result<(), String> {
    let tol = PIN_TOLERANCE * size.max(1e-3);
    for at in attachments {
        let d = at.trajectory.displacement(t);
        for (k, &i) in at.particles.iter().enumerate() {
            let off = (x[i] - (Vec3::from(at.anchors[k]) + d)).norm();
            if off.is_nan() || off > tol {
                return Err(format!(
                    "particle {i} left its pin (or attachment) by {off:.3e} m (tolerance {tol:.1e} m)"
                ));
            }
        }
    }
    Ok(())
}

/// The most stretched stretch spring of `model` at `x`: (particle a, particle b, stretch).
pub fn most_stretched(model: &ClothModel, x: &[Vec3]) -> Option<(usize, usize, f64)> {
    let mut worst: Option<(usize, usize, f64)> = None;
    for s in &model.springs {
        if !matches!(s.kind, SpringKind::Stretch { .. }) || s.rest <= 0.0 {
            continue;
        }
        let stretch = (x[s.b] - x[s.a]).norm() / s.rest - 1.0;
        if worst.is_none_or(|w| stretch.is_nan() || stretch > w.2) {
            worst = Some((s.a, s.b, stretch));
        }
    }
    worst
}

/// Checks that no stretch spring of `model` at `x` is stretched beyond [`MAX_STRETCH`].
pub fn check_strain(model: &ClothModel, x: &[Vec3]) -> Result<(), String> {
    let limit2 = (1.0 + MAX_STRETCH) * (1.0 + MAX_STRETCH);
    let over = model.springs.iter().any(|s| {
        matches!(s.kind, SpringKind::Stretch { .. }) && {
            let l2 = (x[s.b] - x[s.a]).norm_squared();
            l2.is_nan() || l2 > limit2 * s.rest * s.rest
        }
    });
    if !over {
        return Ok(());
    }
    let (a, b, stretch) = most_stretched(model, x).unwrap_or((0, 0, f64::NAN));
    Err(format!(
        "the stretch spring between particles {a} and {b} is stretched by {:.0} % \
         (no fabric stretches beyond {:.0} %)",
        100.0 * stretch,
        100.0 * MAX_STRETCH
    ))
}

/// A description of where the strain is worst, for an energy failure's message.
pub fn strain_note(model: &ClothModel, x: &[Vec3]) -> String {
    match most_stretched(model, x) {
        Some((a, b, s)) => format!(
            "; most stretched: the spring between particles {a} and {b}, at {:.1} %",
            100.0 * s
        ),
        None => String::new(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_overflowing_right_hand_side_is_rejected_with_its_particle() {
        let a = Bcsr3::with_pattern(2, &[]);
        let b = vec![Vec3::zeros(), Vec3::new(0.0, 0.0, -1e160)];
        let e = check_system(&a, &b, 0.01).unwrap_err();
        assert!(e.contains("particle 1") && e.contains("-1.000e162"), "{e}");
    }

    #[test]
    fn a_zero_or_overflowing_right_hand_side_cannot_pass_the_residual_check() {
        // an exact solve of a zero system passes; anything else does not
        assert!(judge_residual(0.0, 0.0, 0.0, 1e-3).1);
        assert!(!judge_residual(1e-30, 0.0, 0.0, 1e-3).1);
        assert!(!judge_residual(1.0, f64::INFINITY, 1.0, 1e-3).1);
        assert!(!judge_residual(f64::NAN, 1.0, 1.0, 1e-3).1);
        assert!(!judge_residual(f64::INFINITY, f64::INFINITY, 1.0, 1e-3).1);
        // relative to the right-hand side, or to the gravity impulse when that is larger
        assert!(judge_residual(0.9e-3, 1.0, 1.0, 1e-3).1);
        assert!(!judge_residual(1.1e-3, 1.0, 1.0, 1e-3).1);
        assert!(judge_residual(1e-13, 1e-20, 1.0, 1e-3).1);
    }
}
