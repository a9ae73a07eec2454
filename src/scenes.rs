//! Built-in scenes: the benchmark's hanging cloth (identical to the Blender peer scene) and the
//! demo scene that `emilion` runs with no arguments.

use crate::cloth::{ClothError, ClothModel, FabricParameters, Simulation, SimulationParameters};

/// The peer benchmark scene: a 1 m × 1 m grid of `n` × `n` particles flat in the XY plane at
/// z = 0, the two corners of the y = +0.5 edge pinned, gravity −9.81 m/s² along z, cotton-like
/// linear fabric (0.15 kg/m², 1000 N/m stretch, soft shear and bending), 24 fps with 5 substeps
/// per frame (dt = 1/120 s).
pub fn hang(n: usize) -> Result<Simulation, ClothError> {
    let model = ClothModel::grid(1.0, 1.0, n, n, FabricParameters::default())?;
    let params = SimulationParameters { dt: 1.0 / 120.0, ..Default::default() };
    let mut sim = Simulation::new(model, params)?;
    sim.pin(&[(n - 1) * n, n * n - 1])?;
    Ok(sim)
}
