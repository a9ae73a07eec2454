//! Measured fabrics: the KES-F units and their conversion to SI (in one place), the fabric
//! file format, the import of the Wang 2011 measured fabrics, the KES parameter formulas
//! applied to measured or simulated curves, the virtual Kawabata rigs, the law built from
//! measurements and its fitting, the tensile and bending rigs on the meshless shell, damping from free oscillation, and the lab that runs it all.

pub mod calibrate;
pub mod compression;
pub mod damping;
pub mod error;
pub mod fabric;
pub mod feng;
pub mod fit;
pub mod kes_param;
pub mod lab;
pub mod parameters;
pub(crate) mod quasi_static;
pub mod ranges;
pub mod rig;
pub mod rig_parameters;
pub mod shell_rigs;
pub mod units;
pub mod wang;

pub use error::KesError;
pub use fabric::{
    read_fabric, read_fabric_dir, write_fabric, Curve, FabricCurves, FabricSpec, KesValues,
};
pub use kes_param::KesParam;
pub use parameters::{
    bending_parameters, shear_parameters, split_branches, tensile_parameters, BendingParams,
    ShearParams, TensileParams,
};
pub use units::{Quantity, Unit, UnitError};
pub use wang::{import_wang, import_wang_dir};
