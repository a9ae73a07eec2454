//! Pre-positioning of the tracking puppet: the least-squares fit of its pose parameters to
//! 3D tracking joints, within the joint limits ([`Puppet::fit_to_joints`]). A child module of
//! [`super`] (declared there with a `path` attribute), so it reaches the puppet's fields.

use nalgebra::{DMatrix, DVector, Matrix3, UnitQuaternion};

use super::{Puppet, PARAM_COUNT};
use crate::body::Pose;
use crate::geometry::least_squares::{
    self, BoundedDifferences, DampingUpdate, DiagonalDamping, LeastSquares, Schedule, Tries,
};
use crate::geometry::Vec3;
use crate::tracking::joints::JOINT_COUNT;

/// The damping of the puppet's Levenberg–Marquardt fits (the joint fit and the marker fit):
/// initial λ, the shifted diagonal, and λ ÷3 after an accepted step, ×4 after a rejected one.
pub(crate) const PUPPET_DAMPING: (f64, DiagonalDamping, DampingUpdate) = (
    1e-3,
    DiagonalDamping::Shifted { floor: 1e-6 },
    DampingUpdate::Factors {
        down: 3.0,
        min: 1e-9,
        up: 4.0,
        singular: 4.0,
    },
);

/// Tracking joints used to place the trunk first: pelvis, spine, neck, shoulders, hips.
const TRUNK: [usize; 7] = [0, 1, 2, 4, 7, 10, 13];

/// Weight (metres per radian) pulling limb and trunk rotations toward the start values, so
/// rotations no tracking joint sees (twists, hands, feet) stay put.
const PRIOR: f64 = 0.01;

/// Best rigid motion `x ↦ r x + t` taking the first points onto the second (Kabsch).
pub(crate) fn kabsch(pairs: &[(Vec3, Vec3)]) -> Option<(UnitQuaternion<f64>, Vec3)> {
    let n = pairs.len() as f64;
    let ca = pairs.iter().map(|p| p.0).sum::<Vec3>() / n;
    let cb = pairs.iter().map(|p| p.1).sum::<Vec3>() / n;
    let h: Matrix3<f64> = pairs
        .iter()
        .map(|(a, b)| (a - ca) * (b - cb).transpose())
        .sum();
    let svd = h.try_svd(true, true, 1e-12, 100)?;
    let (u, vt) = (svd.u?, svd.v_t?);
    let mut d = Matrix3::identity();
    if (vt.transpose() * u.transpose()).determinant() < 0.0 {
        d[(2, 2)] = -1.0;
    }
    let r = vt.transpose() * d * u.transpose();
    let q = UnitQuaternion::from_matrix(&r);
    Some((q, cb - q * ca))
}

impl Puppet {
    /// Pre-positioning: the parameters, within the limits, whose tracking joints are closest
    /// (least squares) to `target`, starting from `start` (padded with zeros if short).
    /// First the root is placed by a rigid fit of the trunk joints (kept only if better than
    /// `start`), then root and chest are refined on the trunk joints, then all parameters on
    /// all joints (projected Levenberg–Marquardt, forward-difference Jacobian), with a weak
    /// pull toward `start` for what no joint sees. Non-finite target joints are ignored.
    pub fn fit_to_joints(&self, target: &[Vec3; JOINT_COUNT], start: &[f64]) -> Vec<f64> {
        let mut p: Vec<f64> = (0..PARAM_COUNT)
            .map(|i| start.get(i).copied().unwrap_or(0.0))
            .collect();
        self.clamp(&mut p);
        let valid: Vec<usize> = (0..JOINT_COUNT)
            .filter(|&k| target[k].iter().all(|x| x.is_finite()))
            .collect();
        let trunk: Vec<usize> = TRUNK
            .iter()
            .copied()
            .filter(|k| valid.contains(k))
            .collect();
        if valid.is_empty() {
            return p;
        }
        let mut pose = Pose::identity(self.heads.len());
        let prior = p.clone();
        if trunk.len() >= 3 {
            let mut q = p.clone();
            q[0..6].fill(0.0);
            self.pose_into(&q, &mut pose);
            let j = self.joints(&pose);
            let pairs: Vec<(Vec3, Vec3)> = trunk.iter().map(|&k| (j[k], target[k])).collect();
            if let Some((r, t)) = kabsch(&pairs) {
                // x ↦ r x + t as a root motion x ↦ R (x − h) + h + d
                let h = self.heads[self.root];
                let d = t + r * h - h;
                q[0..3].copy_from_slice(d.as_slice());
                q[3..6].copy_from_slice(r.scaled_axis().as_slice());
                self.clamp(&mut q);
                let cost = |x: &[f64], pose: &mut Pose| {
                    self.pose_into(x, pose);
                    let j = self.joints(pose);
                    trunk
                        .iter()
                        .map(|&k| (j[k] - target[k]).norm_squared())
                        .sum::<f64>()
                };
                if cost(&q, &mut pose) < cost(&p, &mut pose) {
                    p = q;
                }
            }
            let torso: Vec<usize> = (0..9).collect();
            self.levenberg_marquardt(&mut p, &torso, &trunk, target, &prior, &mut pose, 30);
        }
        let all: Vec<usize> = (0..PARAM_COUNT).collect();
        self.levenberg_marquardt(&mut p, &all, &valid, target, &prior, &mut pose, 100);
        p
    }

    /// Residuals: joint offsets, then `PRIOR`-weighted pulls of active non-root parameters.
    #[allow(clippy::too_many_arguments)]
    fn residual(
        &self,
        p: &[f64],
        active: &[usize],
        joints: &[usize],
        target: &[Vec3; JOINT_COUNT],
        prior: &[f64],
        pose: &mut Pose,
        out: &mut DVector<f64>,
    ) {
        self.pose_into(p, pose);
        let j = self.joints(pose);
        for (r, &k) in joints.iter().enumerate() {
            let e = j[k] - target[k];
            out.fixed_rows_mut::<3>(3 * r).copy_from(&e);
        }
        let pulls = active.iter().filter(|&&i| i >= 6);
        for (r, &i) in (3 * joints.len()..).zip(pulls) {
            out[r] = PRIOR * (p[i] - prior[i]);
        }
    }

    /// Projected Levenberg–Marquardt ([`least_squares::minimize`]) of the `active`
    /// parameters of `p` on the residuals of [`residual`](Self::residual): forward
    /// differences of ±1e-6 (backwards at an upper limit), steps clamped to the limits,
    /// damping `μ (JᵀJ_kk + 1e-6)` from μ = 1e-3, divided by 3 (not below 1e-9) after an
    /// accepted step, times 4 otherwise, 12 tries per iteration; stops when a step gains
    /// less than 1e-14 of the cost.
    #[allow(clippy::too_many_arguments)]
    fn levenberg_marquardt(
        &self,
        p: &mut [f64],
        active: &[usize],
        joints: &[usize],
        target: &[Vec3; JOINT_COUNT],
        prior: &[f64],
        pose: &mut Pose,
        iterations: usize,
    ) {
        let mut problem = JointFit {
            puppet: self,
            active,
            joints,
            target,
            prior,
            pose,
            rows: 3 * joints.len() + active.iter().filter(|&&i| i >= 6).count(),
        };
        let schedule = Schedule {
            iterations,
            damping: PUPPET_DAMPING,
            tries: Tries::Count(12),
            // on the full squared norm 2·cost (exact doubling): a gain above 1e-14 of it
            progress: |old, new| 2.0 * (old - new) > 1e-14 * (2.0 * old).max(1e-12),
        };
        let m = least_squares::minimize(&mut problem, p.to_vec(), &schedule);
        p.copy_from_slice(&m.state);
    }
}

/// The puppet's joint fit as a least-squares problem: the parameters `active` of the full
/// parameter vector, the residuals of [`Puppet::residual`].
struct JointFit<'a> {
    puppet: &'a Puppet,
    active: &'a [usize],
    joints: &'a [usize],
    target: &'a [Vec3; JOINT_COUNT],
    prior: &'a [f64],
    /// Scratch pose.
    pose: &'a mut Pose,
    /// Number of residuals.
    rows: usize,
}

impl LeastSquares for JointFit<'_> {
    type State = Vec<f64>;

    fn parameter_count(&self) -> usize {
        self.active.len()
    }

    fn residuals(&mut self, p: &Vec<f64>, out: &mut DVector<f64>) {
        if out.len() != self.rows {
            *out = DVector::zeros(self.rows);
        }
        let (active, joints) = (self.active, self.joints);
        self.puppet
            .residual(p, active, joints, self.target, self.prior, self.pose, out);
    }

    fn jacobian(&mut self, p: &Vec<f64>, r: &DVector<f64>, jac: &mut DMatrix<f64>) {
        let mut differences = BoundedDifferences::new(self.rows);
        for c in 0..self.active.len() {
            let i = self.active[c];
            let hi = self.puppet.params[i].hi;
            jac.set_column(
                c,
                differences.column(p, i, hi, r, |q, out| self.residuals(q, out)),
            );
        }
    }

    fn step(&mut self, p: &Vec<f64>, delta: &DVector<f64>) -> Vec<f64> {
        let mut q = p.clone();
        for (c, &i) in self.active.iter().enumerate() {
            q[i] += delta[c];
        }
        self.puppet.clamp(&mut q);
        q
    }
}
