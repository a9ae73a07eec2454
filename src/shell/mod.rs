//! The meshless Kirchhoff–Love shell: a thin shell described by its mid-surface alone
//! (membrane and bending strains of the deformed surface, Green–Lagrange strain, large
//! rotations), discretised without a mesh over moving-least-squares shape functions
//! (quadratic or cubic basis, C¹ and more, which Kirchhoff–Love bending needs). The weak form
//! is Galerkin, integrated by Gauss points on background cells that are not a mesh of the
//! shape functions (the local Petrov–Galerkin form, MLPG1, was tried first and could not reach
//! the plate values: `docs/shell.md`). Solved by Newton's method with load stepping and
//! `faer`'s sparse LU, its symbolic factorisation reused across steps.
//!
//! Files: [`mls`] shape functions, [`neighbours`] the point grid and spacing, [`surface`] the
//! rest surfaces, [`jet`] second-order automatic differentiation, [`kinematics`] strains and
//! energy density, [`material`] the linear laws, [`fabric_law`] a fabric's
//! measured (nonlinear) law, [`moment`] edge moments, [`problem`] problems and parameters,
//! [`discretisation`] background cells and quadrature, [`assembly`] residual and tangent,
//! [`solve`] Newton, [`arc_length`] paths through buckling and limit points, [`relax`] relaxation to a stable equilibrium (overdamped implicit steps),
//! [`dynamics`] time-accurate implicit dynamics (Newmark, backward Euler),
//! [`obstacle`] contact with a sphere, [`display`] the triangulated display surface,
//! [`benchmarks`] the shell obstacle course.

pub mod arc_length;
pub mod assembly;
pub mod benchmarks;
pub mod discretisation;
pub mod display;
pub mod dynamics;
pub mod error;
pub mod fabric_law;
pub mod jet;
pub mod kinematics;
pub mod material;
pub mod mls;
pub mod moment;
pub mod neighbours;
pub mod obstacle;
pub mod problem;
pub mod relax;
pub mod solve;
pub mod surface;

pub use discretisation::Discretisation;
pub use error::ShellError;
pub use fabric_law::FabricLaw;
pub use material::ShellMaterial;
pub use mls::Basis;
pub use problem::{Constraint, Direction, ShellParameters, ShellProblem};
pub use surface::Surface;
