//! The implicit solver: the block-sparse matrix, the assembly of the system from the force
//! elements' contributions, the modified preconditioned conjugate gradient and its
//! preconditioners (geometric multigrid with line smoothing, aggregation multigrid, one V-cycle
//! driver for both), and the deterministic parallel helpers they share.

pub mod aggregation;
pub mod amg;
pub mod assembly;
pub mod bcsr;
pub(crate) mod contribution;
pub mod galerkin;
mod grid_transfer;
pub mod line_solver;
pub mod multigrid;
pub mod parallel;
pub mod pcg;
pub mod simd;
pub(crate) mod vcycle;
