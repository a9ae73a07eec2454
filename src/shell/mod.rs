//! The meshless Kirchhoff–Love shell (MLPG): a thin shell described by its mid-surface alone
//! (membrane and bending strains of the deformed surface, Green–Lagrange strain, large
//! rotations), discretised without a mesh by the meshless local Petrov–Galerkin method
//! (MLPG1: the local weak form on a circle around each sample point, tested with the weight
//! bump of that circle) over moving-least-squares shape functions (quadratic or cubic basis,
//! C¹ and more, which Kirchhoff–Love bending needs), solved by Newton's method with load
//! stepping and `faer`'s sparse LU. See `docs/shell.md`.
//!
//! Files: [`mls`] shape functions, [`neighbours`] the point grid and spacing, [`surface`] the
//! rest surfaces, [`jet`] second-order automatic differentiation, [`kinematics`] strains and
//! energy density, [`material`] the laws, [`problem`] problems and parameters,
//! [`discretisation`] sub-domains and quadrature, [`assembly`] residual and tangent,
//! [`solve`] Newton, [`benchmarks`] the shell obstacle course.

pub mod assembly;
pub mod benchmarks;
pub mod discretisation;
pub mod error;
pub mod jet;
pub mod kinematics;
pub mod material;
pub mod mls;
pub mod neighbours;
pub mod problem;
pub mod solve;
pub mod surface;

pub use discretisation::Discretisation;
pub use error::ShellError;
pub use material::ShellMaterial;
pub use mls::Basis;
pub use problem::{Constraint, Direction, ShellParameters, ShellProblem};
pub use surface::Surface;
