//! Measured fabrics: the KES-F units and their conversion to SI (in one place), the fabric
//! file format, the import of the Wang 2011 measured fabrics, and the KES parameter formulas
//! applied to measured or simulated curves.
pub mod rig;
pub mod calibrate;
pub mod damping;
