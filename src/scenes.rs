//! Built-in scenes: the benchmark's hanging cloth (identical to the Blender peer scene) and the
//! demo scene that `emilion` runs with no arguments.

pub mod sampling;
pub mod vibration;

use std::io::IsTerminal;
use std::path::{Path, PathBuf};

use indicatif::ProgressBar;

use crate::cloth::stats::write_csv;
use crate::cloth::{ClothError, ClothModel, FabricParameters, Simulation, SimulationParameters};
use crate::contact::{Body, Floor, SimulationContact};
use crate::geometry::mesh::bounds;
use crate::geometry::LookAtCamera;
use crate::geometry::Vec3;
use crate::geometry::{write_glb, write_obj, ExportFrame, Units};
use crate::render::{render_png, RenderMesh};

/// The peer benchmark scene: a 1 m × 1 m grid of `n` × `n` particles flat in the XY plane at
/// z = 0, the two corners of the y = +0.5 edge pinned, gravity −9.81 m/s² along z, cotton-like
/// linear fabric (0.15 kg/m², 1000 N/m stretch, soft shear and bending), 24 fps with 5 substeps
/// per frame (dt = 1/120 s).
pub fn hang(n: usize) -> Result<Simulation, ClothError> {
    let model = ClothModel::grid(1.0, 1.0, n, n, FabricParameters::default())?;
    let params = SimulationParameters {
        dt: 1.0 / 120.0,
        ..Default::default()
    };
    let mut sim = Simulation::new(model, params)?;
    sim.pin(&[(n - 1) * n, n * n - 1])?;
    Ok(sim)
}

/// The peer drape scene: the same 1 m × 1 m grid of `n` × `n` particles and fabric as
/// [`hang`], flat at z = 0.45 m, centred above a static sphere of radius 0.3 m at the origin, no
/// pins, collision distance 0.015 m, dt = 1/120 s (24 fps, 5 substeps).
pub fn drape(n: usize) -> Result<Simulation, ClothError> {
    let mut model = ClothModel::grid(1.0, 1.0, n, n, FabricParameters::default())?;
    for p in &mut model.mesh.positions {
        p.z = 0.45;
    }
    let params = SimulationParameters {
        dt: 1.0 / 120.0,
        ..Default::default()
    };
    let mut sim = Simulation::new(model, params)?;
    let contact = sim.add_contact();
    contact.settings.thickness = 0.015;
    contact.bodies.push(Body::sphere(Vec3::zeros(), 0.3)?);
    Ok(sim)
}

/// The peer hang scene ([`hang`]) with self-collision on (self distance 0.005 m: the grid's
/// diagonal half-spacing at n = 64 is 0.011 m, so Blender's 0.015 m would repel neighbours at rest).
pub fn hang_self(n: usize) -> Result<Simulation, ClothError> {
    let mut sim = hang(n)?;
    let contact = sim.add_contact();
    contact.settings.self_collision = true;
    contact.settings.self_thickness = 0.005;
    Ok(sim)
}

/// The benchmark's garment scene: the FreeSewing A-shirt (`scripts/patterns/aaron.garment.json`)
/// meshed at `edge_mm` millimetre edges, pre-positioned around the MakeHuman mannequin (from
/// [`crate::geometry::files::data_dir`]) and ready to sew and drape, with the dress defaults
/// (default fabric, self-collision on). A missing mannequin is an error naming the folder.
pub fn garment(edge_mm: usize) -> Result<Simulation, ClothError> {
    let err = |what: &str, e: &dyn std::fmt::Display| {
        ClothError::Parameter(format!("bench garment scene: {what}: {e}"))
    };
    if !(2..=100).contains(&edge_mm) {
        return Err(ClothError::Parameter(format!(
            "bench garment scene: edge {edge_mm} mm is outside 2–100 mm"
        )));
    }
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("scripts/patterns/aaron.garment.json");
    let pattern =
        crate::garment::read_garment(&file).map_err(|e| err(&file.display().to_string(), &e))?;
    let dir = crate::geometry::files::data_dir().join("bodies/makehuman");
    let man = crate::body::Mannequin::load_makehuman(&dir)
        .map_err(|e| err(&dir.display().to_string(), &e))?;
    let mut params = crate::garment::DressParameters::default();
    params.mesh.edge_length = edge_mm as f64 * 1e-3;
    let d = crate::garment::dress(
        &pattern,
        FabricParameters::default(),
        &man,
        &params,
        SimulationParameters::default(),
    )
    .map_err(|e| err("dress", &e))?;
    Ok(d.simulation)
}

/// The demo scene: a 1 m × 1 m cloth of 48 × 48 particles (default fabric) hanging from the two
/// corners of its y = +0.5 edge above a floor at z = −1.2, simulated 2 s at dt = 1/120 s with the
/// implicit integrator. Writes `demo.png` (800 × 600, framed on the final shape), `demo.obj`,
/// `demo.glb` and `demo_stats.csv` into `out_dir` and returns their paths. Shows a progress bar
/// when stderr is a terminal.
pub fn demo(out_dir: &Path) -> Result<Vec<PathBuf>, ClothError> {
    let n = 48;
    let mut sim = hang(n)?;
    sim.add_stage(Box::new(Floor {
        height: -1.2,
        thickness: 0.005,
    }));
    let steps = sim.steps_for(2.0);
    let pb = if std::io::stderr().is_terminal() {
        ProgressBar::new(steps)
    } else {
        ProgressBar::hidden()
    };
    sim.run_steps(steps, |_, _| {
        pb.inc(1);
        Ok(())
    })?;
    pb.finish_and_clear();

    let output = |path: &Path, e: &dyn std::fmt::Display| ClothError::Output {
        path: path.display().to_string(),
        message: e.to_string(),
    };
    std::fs::create_dir_all(out_dir).map_err(|e| output(out_dir, &e))?;
    let (x, tris) = (&sim.state.x, &sim.model.mesh.triangles);
    let png = out_dir.join("demo.png");
    let (lo, hi) = bounds(x);
    let mesh = RenderMesh {
        positions: x,
        triangles: tris,
        color: RenderMesh::DEFAULT_COLOR,
    };
    render_png(&png, &[mesh], &LookAtCamera::framing(lo, hi, 800, 600))?;
    let obj = out_dir.join("demo.obj");
    write_obj(
        &obj,
        x,
        tris,
        Some(&sim.model.mesh.rest),
        ExportFrame::Y_UP_METRES,
    )?;
    let glb = out_dir.join("demo.glb");
    write_glb(&glb, x, tris, Units::Metres)?;
    let csv = out_dir.join("demo_stats.csv");
    write_csv(&csv, &sim.stats)?;
    Ok(vec![png, obj, glb, csv])
}
