//! Cloth: particle state, force elements and material laws, the block-sparse implicit solver
//! (Baraff & Witkin) and the explicit one, constraints (pins, attachments, contact hook),
//! per-step statistics.

pub mod aggregation;
pub mod amg;
pub mod arc_connection;
pub mod assembly;
pub mod bcsr;
pub mod buckling_side;
pub mod choi_ko;
pub mod compression_release;
pub mod constraints;
pub mod elements;
pub mod error;
pub mod line_solver;
pub mod material;
pub mod measured;
pub mod model;
pub mod multigrid;
pub mod parallel;
pub mod pcg;
pub mod sewing;
pub mod simd;
pub mod simulation;
pub mod state;
pub mod stats;
pub mod wrinkles;

pub use constraints::{Attachment, ContactHook, Filter, Floor, Obstacles, Trajectory};
pub use error::ClothError;
pub use material::{Direction, FabricParameters, Friction, LinearMaterial, MaterialLaw};
pub use measured::{MeasuredLaw, ResponseCurve};
pub use model::ClothModel;
pub use sewing::{Separation, Sewing};
pub use simulation::{Integrator, PreconditionerKind, Simulation, SimulationParameters};
pub use state::ClothState;
pub use stats::StepStats;
