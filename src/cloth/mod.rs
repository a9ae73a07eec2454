//! Cloth: particle state, force elements and material laws ([`elements`]), the block-sparse
//! implicit solver (Baraff & Witkin, [`solver`]) and the explicit one, the buckling models
//! ([`buckling`]), constraints (pins, attachments, the filter), the step stages through which
//! contact takes part in a step, per-step statistics.

pub mod buckling;
pub mod checkpoint;
pub mod constraints;
pub mod elements;
pub mod error;
pub mod model;
pub mod parameters;
pub mod runs;
pub mod sewing;
pub mod simulation;
pub mod solver;
pub mod stage;
pub mod state;
pub mod stats;
pub mod step_guard;

pub use constraints::{Attachment, Filter, Trajectory};
pub use elements::material::{Direction, FabricParameters, Friction, LinearMaterial, MaterialLaw};
pub use elements::measured::{MeasuredLaw, ResponseCurve};
pub use error::ClothError;
pub use model::ClothModel;
pub use parameters::{
    Integrator, PreconditionerKind, SimulationParameters, MAX_DT, MAX_EXPLICIT_SUBSTEPS, MIN_DT,
};
pub use sewing::{Separation, Sewing};
pub use simulation::Simulation;
pub use stage::{Obstacles, StepEnd, StepStage};
pub use state::ClothState;
pub use stats::StepStats;
