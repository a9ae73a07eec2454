//! Contact as a stage of a simulation's step: [`Collisions`] implements the cloth's
//! [`StepStage`] (velocity constraints before the solve, kinetic friction inside it, friction,
//! push-out and cloth–cloth response after it), and [`SimulationContact`] reaches the contact
//! stage of a simulation. Contact's errors become the cloth's through [`ClothError::Stage`].

use std::any::Any;

use super::collisions::Collisions;
use super::ContactError;
use crate::cloth::stage::{Obstacles, StepEnd, StepStage};
use crate::cloth::{ClothError, Filter, Sewing, Simulation, StepStats};
use crate::geometry::checkpoint::{Decoder, Encoder, Fingerprint};
use crate::geometry::{GeometryError, Vec3};

impl From<ContactError> for ClothError {
    fn from(e: ContactError) -> Self {
        ClothError::Stage(Box::new(e))
    }
}

impl StepStage for Collisions {
    fn follow_sewing(&mut self, sewing: &Sewing, t: f64) {
        self.frictionless = sewing.sewing_at(t);
        if !sewing.pass_through.is_empty() {
            let zones: &[u32] = if sewing.sewing_at(t) {
                &sewing.pass_through
            } else {
                &[]
            };
            self.set_zones(zones);
        }
    }

    fn is_clear(&self, p: &Vec3) -> bool {
        let clearance = self.settings.thickness;
        self.bodies
            .iter()
            .all(|b| b.proximity(p, clearance).is_none())
    }

    fn constrain(
        &mut self,
        x: &[Vec3],
        v: &[Vec3],
        t: f64,
        dt: f64,
        filter: &mut Filter,
        _obstacles: Obstacles<'_>,
    ) {
        if self.is_active() {
            self.begin_step(x, v, t, dt, filter);
        }
    }

    fn add_forces(&mut self, b: &mut [Vec3]) {
        if self.is_active() {
            self.add_kinetic_friction(b);
        }
    }

    fn uses_impulses(&self) -> bool {
        self.is_active()
    }

    fn may_loosen(&self) -> bool {
        self.is_active() && self.holds_any()
    }

    fn loosen(&mut self, impulse: &[Vec3], filter: &mut Filter) -> bool {
        self.is_active() && self.release_pulling_holds(impulse, filter)
    }

    fn respond(&mut self, end: StepEnd<'_>) {
        if self.is_active() {
            self.end_step(
                end.x_start,
                end.x,
                end.v,
                end.impulse,
                end.mass,
                end.filter,
                end.dt,
            );
        }
    }

    fn report(&self, st: &mut StepStats) {
        if self.is_active() {
            let c = &self.stats;
            st.collision_ms = c.collision_ms;
            st.contacts = c.contacts;
            st.self_contacts = c.self_contacts;
            st.min_distance = c.min_distance;
            st.penetrating = c.penetrating;
            st.intersections = c.intersections;
        }
    }

    fn crossings(&mut self, x: &[Vec3]) -> Vec<([u32; 2], [u32; 3])> {
        self.self_intersections(x)
    }

    fn fingerprint(&self, f: &mut Fingerprint) {
        self.fingerprint_into(f);
    }

    fn save_state(&self, e: &mut Encoder) {
        self.save_into(e);
    }

    fn load_state(&mut self, d: &mut Decoder) -> Result<(), GeometryError> {
        self.load_from(d)
    }

    fn as_any(&self) -> &dyn Any {
        self
    }

    fn as_any_mut(&mut self) -> &mut dyn Any {
        self
    }
}

/// The contact stage of a [`Simulation`].
pub trait SimulationContact {
    /// Adds a contact stage (no bodies, self-collision off) for the simulation's cloth unless it
    /// has one, and returns it. Add it before any other stage: stages constrain in the order
    /// added.
    fn add_contact(&mut self) -> &mut Collisions;
    /// The contact stage. Panics without one (see [`SimulationContact::add_contact`]).
    fn contact(&self) -> &Collisions;
    /// The contact stage, mutable. Panics without one (see
    /// [`SimulationContact::add_contact`]).
    fn contact_mut(&mut self) -> &mut Collisions;
}

const NO_CONTACT: &str = "the simulation has no contact stage (add one with `add_contact`)";

impl SimulationContact for Simulation {
    fn add_contact(&mut self) -> &mut Collisions {
        if self.stage::<Collisions>().is_none() {
            let mesh = &self.model.mesh;
            let contact = Collisions::for_cloth(&mesh.triangles, &mesh.positions);
            self.add_stage(Box::new(contact));
        }
        self.contact_mut()
    }

    fn contact(&self) -> &Collisions {
        self.stage::<Collisions>().expect(NO_CONTACT)
    }

    fn contact_mut(&mut self) -> &mut Collisions {
        self.stage_mut::<Collisions>().expect(NO_CONTACT)
    }
}
