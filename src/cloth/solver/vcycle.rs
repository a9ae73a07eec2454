//! The one V-cycle driver of the two multigrid preconditioners (geometric, on grid cloths, and
//! aggregation, on any mesh): each hierarchy says how its levels smooth, transfer and solve
//! the coarsest level ([`Hierarchy`]); the driver runs the cycle and keeps its timing.

use super::bcsr::Bcsr3;
use crate::geometry::Vec3;

/// A multigrid hierarchy as the V-cycle sees it. Level 0 is the finest, whose matrix `a0`
/// the cycle is given; every level has a right-hand side `r` and a correction `e`.
pub(crate) trait Hierarchy {
    /// Number of levels.
    fn depth(&self) -> usize;
    /// The finest level's right-hand side.
    fn finest_rhs(&mut self) -> &mut [Vec3];
    /// The finest level's correction.
    fn finest_correction(&self) -> &[Vec3];
    /// Accumulated V-cycle time (s) and count.
    fn cycle_timing(&mut self) -> (&mut f64, &mut u64);
    /// Solves (or smooths hard) the coarsest level `l`.
    fn solve_coarsest(&mut self, l: usize, a0: &Bcsr3);
    /// Zeroes level `l`'s correction, pre-smooths it and forms its residual.
    fn pre_smooth(&mut self, l: usize, a0: &Bcsr3);
    /// Restricts level `l`'s residual to the right-hand side of level `l + 1`.
    fn restrict(&mut self, l: usize);
    /// Adds the prolongated correction of level `l + 1` to level `l`'s.
    fn prolong(&mut self, l: usize);
    /// Post-smooths level `l`'s correction (the adjoint of the pre-smoothing).
    fn post_smooth(&mut self, l: usize, a0: &Bcsr3);
}

/// Applies one V-cycle of `h` to residual `r` (finest matrix `a`), writing `s ≈ A⁻¹ r`.
pub(crate) fn apply<H: Hierarchy>(h: &mut H, a: &Bcsr3, r: &[Vec3], s: &mut [Vec3]) {
    let t0 = std::time::Instant::now();
    h.finest_rhs().copy_from_slice(r);
    vcycle(h, 0, a);
    s.copy_from_slice(h.finest_correction());
    let (seconds, count) = h.cycle_timing();
    *seconds += t0.elapsed().as_secs_f64();
    *count += 1;
}

/// The V-cycle from level `l` down.
fn vcycle<H: Hierarchy>(h: &mut H, l: usize, a0: &Bcsr3) {
    if l + 1 == h.depth() {
        h.solve_coarsest(l, a0);
        return;
    }
    h.pre_smooth(l, a0);
    h.restrict(l);
    vcycle(h, l + 1, a0);
    h.prolong(l);
    h.post_smooth(l, a0);
}
