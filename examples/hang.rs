//! The hanging-cloth scene from Rust, without scripting: a 1 m × 1 m cloth pinned at two
//! corners, 2 s of simulation, then an OBJ, a glTF, a PNG and the per-step statistics.
//! `cargo run --release --example hang -- out/example`

use std::path::PathBuf;

use emilion::cloth::{stats, ClothModel, FabricParameters, Simulation, SimulationParameters};
use emilion::geometry::LookAtCamera;
use emilion::geometry::{mesh::bounds, write_glb, write_obj, ExportFrame, Units};
use emilion::render::{render_png, RenderMesh};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let out = PathBuf::from(
        std::env::args()
            .nth(1)
            .unwrap_or_else(|| "out/example".into()),
    );
    let n = 48;
    let model = ClothModel::grid(1.0, 1.0, n, n, FabricParameters::default())?;
    let mut sim = Simulation::new(model, SimulationParameters::default())?;
    sim.pin(&[(n - 1) * n, n * n - 1])?;
    let steps = sim.steps_for(2.0);
    sim.run_steps(steps, |_, _| Ok(()))?;
    let tris = &sim.model.mesh.triangles;
    write_obj(
        &out.join("hang.obj"),
        &sim.state.x,
        tris,
        Some(&sim.model.mesh.rest),
        ExportFrame::Y_UP_METRES,
    )?;
    write_glb(&out.join("hang.glb"), &sim.state.x, tris, Units::Metres)?;
    let (lo, hi) = bounds(&sim.state.x);
    let camera = LookAtCamera::framing(lo, hi, 800, 600);
    let mesh = RenderMesh {
        positions: &sim.state.x,
        triangles: tris,
        ..Default::default()
    };
    render_png(&out.join("hang.png"), &[mesh], &camera)?;
    stats::write_csv(&out.join("hang_stats.csv"), &sim.stats)?;
    let iters: u32 = sim.stats.iter().map(|s| s.cg_iterations).sum();
    println!(
        "{steps} steps, {:.2} CG iterations per step, lowest point z = {:.3} m; wrote {}",
        iters as f64 / steps as f64,
        lo.z,
        out.display()
    );
    Ok(())
}
