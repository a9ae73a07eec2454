//! Contact: collision bodies (sphere, box, plane, static or animated triangle meshes with
//! parry's BVH), the per-step contact stage of a simulation (Baraff–Witkin velocity
//! constraints, Coulomb friction from the solve's contact impulses, Provot push-out), cloth
//! self-collision (repulsion, continuous detection, impact zones) over a spatial hash, and the
//! exact geometric primitives they rest on.

pub mod body;
pub mod body_pin;
pub mod ccd;
pub mod character;
pub mod checkpoint;
pub mod collisions;
pub mod contact_settings;
pub mod error;
pub mod floor;
pub mod impact_zone;
pub mod mesh_body;
pub mod primitives;
pub mod proximity;
pub mod recording;
pub mod self_collision;
pub mod spatial_hash;
pub mod stage;
pub mod tessellate;

pub use body::{Body, FrictionCoefficients, Shape};
pub use collisions::{Collisions, ContactSettings, ContactStats};
pub use error::ContactError;
pub use floor::Floor;
pub use mesh_body::{BodyAnimation, MeshBody};
pub use proximity::Proximity;
pub use self_collision::{SelfCollision, SelfCollisionReport};
pub use stage::SimulationContact;
