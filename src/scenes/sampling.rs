//! The sampling-independence study of the meshless shell (the seed report's §5.4.3 claim):
//! one fabric, two static scenes, each solved by the shell and by the mass-spring cloth at
//! several sample spacings, and the quantity a textile engineer reads from each.
//!
//! - **drape**: a 1 m square laid flat on top of a sphere (radius 0.3 m, contact distance
//!   5 mm), its centre held horizontally (as a drape tester's clamp holds it), relaxed under
//!   gravity: the drape coefficient (shadow area − π R²) / (1 m² − π R²), the shadow counted on
//!   1 mm pixels;
//! - **hang**: the same square hung vertically from the two corners of its top edge: the sag of
//!   the top edge's middle below the pins.
//!
//! Both start from the same slightly perturbed state (a smooth field of a millimetre, so that
//! folds choose their places the same way at every spacing). The shell relaxes by overdamped
//! implicit steps to a static equilibrium ([`crate::shell::relax`]); the mass-spring cloth runs
//! its own dynamics with extra air drag until its mean speed falls under 0.1 mm/s. Both
//! carry the same linear fabric: the initial slopes (or small secants) of a measured fabric's
//! law ([`linear_fabric`]). The measured nonlinear law is not used here: its tangent is only
//! piecewise smooth and Newton converges linearly on it, which multiplies the shell's cost.

use std::sync::Arc;
use std::time::Instant;

use crate::cloth::{ClothModel, FabricParameters, MaterialLaw, Simulation, SimulationParameters};
use crate::contact::{Body, FrictionCoefficients, SimulationContact};
use crate::geometry::Vec3;
use crate::render::shadow::shadow_area;
use crate::shell::display::DisplaySurface;
use crate::shell::obstacle::SphereObstacle;
use crate::shell::problem::grid_nodes;
use crate::shell::relax::{relax, RelaxParameters};
use crate::shell::{Discretisation, FabricLaw, ShellMaterial, ShellParameters, ShellProblem};

/// Sphere radius of the drape (m).
pub const SPHERE_RADIUS: f64 = 0.3;
/// Contact distance kept from the sphere (m).
pub const CONTACT_DISTANCE: f64 = 0.005;

/// Which scene.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Scene {
    /// Over the sphere: the drape coefficient.
    Drape,
    /// From two corners: the sag of the top edge's middle (m).
    Hang,
    /// From two clips ([`CLIP`] square at each top corner, every point inside held): the sag
    /// of the top edge's middle (m). Unlike point pins, the support does not depend on the
    /// sampling.
    HangClips,
}

/// Side of the square clips of [`Scene::HangClips`] (m).
pub const CLIP: f64 = 0.05;

/// Whether a rest point (x, y in [−0.5, 0.5]²) lies in one of the two clips.
fn in_clip(x: f64, y: f64) -> bool {
    let e = 1e-9;
    y >= 0.5 - CLIP - e && (x <= -0.5 + CLIP + e || x >= 0.5 - CLIP - e)
}

impl Scene {
    /// "drape", "hang" or "hang_clips".
    pub fn name(self) -> &'static str {
        match self {
            Scene::Drape => "drape",
            Scene::Hang => "hang",
            Scene::HangClips => "hang_clips",
        }
    }
}

/// One model's answer at one sampling.
#[derive(Debug, Clone, PartialEq)]
pub struct SamplingRow {
    /// "shell" or "mass-spring".
    pub model: &'static str,
    /// The scene.
    pub scene: Scene,
    /// Sample points (or particles) per side.
    pub per_side: usize,
    /// Spacing (m).
    pub spacing: f64,
    /// Drape coefficient, or sag (m).
    pub value: f64,
    /// Steps: the shell's Newton iterations (one factorisation each), the mass-spring's time
    /// steps.
    pub steps: usize,
    /// Wall time (s).
    pub seconds: f64,
    /// Whether it reached equilibrium (the shell always does or errs; the mass-spring cloth
    /// may still move when its time runs out, and then its last value is reported).
    pub settled: bool,
}

/// The linear fabric of a measured law's initial slopes (or secants to 1 % strain, 0.01 rad
/// and 1 1/m: [`FabricLaw::tangent_material`]), with areal density `density` (kg/m²).
pub fn linear_fabric(law: Arc<dyn MaterialLaw>, density: f64) -> Result<FabricParameters, String> {
    let m = FabricLaw::new(law)?.tangent_material(density)?;
    let p = FabricParameters {
        density,
        stretch_warp: m.membrane[0][0],
        stretch_weft: m.membrane[1][1],
        shear: m.membrane[2][2],
        bend_warp: m.bending[0][0],
        bend_weft: m.bending[1][1],
        ..Default::default()
    };
    p.validate()?;
    Ok(p)
}

/// The shared perturbation: a smooth millimetre-scale field of the rest position (x, y) in
/// [−0.5, 0.5]², applied out of the cloth's plane (z for the drape, y for the hangs).
fn perturbation(x: f64, y: f64) -> f64 {
    let r2 = x * x + y * y;
    1e-3 * r2 * (3.0 * y.atan2(x) + 0.4).sin() + 2e-4 * (2.1 * x + 1.3 * y).sin()
}

/// The drape coefficient of a mesh's positions.
fn drape_coefficient(positions: &[[f64; 3]], triangles: &[[usize; 3]]) -> Result<f64, String> {
    let a = shadow_area(positions, triangles, 1e-3)
        .ok_or("drape: the shadow area cannot be counted (non-finite positions?)")?;
    let disc = std::f64::consts::PI * SPHERE_RADIUS * SPHERE_RADIUS;
    Ok((a - disc) / (1.0 - disc))
}

/// Checks a side count: odd (a point at the centre and at the top edge's middle), 5 to 201.
fn check_side(n: usize) -> Result<(), String> {
    if n % 2 == 1 && (5..=201).contains(&n) {
        Ok(())
    } else {
        Err(format!(
            "sampling study: points per side must be odd and lie in [5, 201], got {n}"
        ))
    }
}

/// The shell's discretisation in the study: supports of 2.6 spacings, 3 × 3 Gauss points per
/// background cell (cheaper than the benchmarks' 3.5 and 4 × 4).
pub fn study_shell_parameters() -> ShellParameters {
    ShellParameters {
        support_factor: 2.6,
        gauss: 3,
        ..Default::default()
    }
}

/// The shell's answer on `n` × `n` sample points (odd `n`) with the discretisation `params`
/// ([`study_shell_parameters`] in the study).
pub fn shell_run(
    scene: Scene,
    n: usize,
    fabric: &FabricParameters,
    params: ShellParameters,
    relax_params: &RelaxParameters,
) -> Result<SamplingRow, String> {
    check_side(n)?;
    let t0 = Instant::now();
    let domain = [-0.5, 0.5, -0.5, 0.5];
    let material = ShellMaterial::from_fabric(fabric)?;
    let g = 9.81 * fabric.density;
    let all = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    let pins = match scene {
        Scene::Drape => vec![([0.0, 0.0], all[0]), ([0.0, 0.0], all[1])],
        Scene::Hang => all
            .iter()
            .flat_map(|d| [([-0.5, 0.5], *d), ([0.5, 0.5], *d)])
            .collect(),
        // a fixed 6 × 6 lattice over each clip, whatever the sampling
        Scene::HangClips => {
            let mut pins = Vec::new();
            for x0 in [-0.5, 0.5 - CLIP] {
                for i in 0..6 {
                    for j in 0..6 {
                        let p = [x0 + CLIP * i as f64 / 5.0, 0.5 - CLIP * j as f64 / 5.0];
                        pins.extend(all.iter().map(|d| (p, *d)));
                    }
                }
            }
            pins
        }
    };
    let problem = ShellProblem {
        surface: crate::shell::Surface::Plane,
        domain,
        nodes: grid_nodes(domain, n, n),
        material,
        edges: Default::default(),
        pins,
        area_load: [0.0, 0.0, -g],
        point_loads: vec![],
    };
    let disc = Discretisation::new(problem, params).map_err(|e| e.to_string())?;
    // the start: flat (drape) or turned down about the top edge (hang), plus the perturbation;
    // a linear field is reproduced exactly by the quadratic basis, the perturbation nearly
    let mut u = Vec::with_capacity(3 * n * n);
    for p in &disc.problem.nodes {
        let w = perturbation(p[0], p[1]);
        match scene {
            Scene::Drape => u.extend_from_slice(&[0.0, 0.0, w]),
            Scene::Hang | Scene::HangClips => {
                u.extend_from_slice(&[0.0, 0.5 - p[1] + w, p[1] - 0.5])
            }
        }
    }
    let obstacle = SphereObstacle {
        centre: [0.0, 0.0, -(SPHERE_RADIUS + CONTACT_DISTANCE)],
        radius: SPHERE_RADIUS,
        distance: CONTACT_DISTANCE,
        // a millimetre of penetration under ten times the cloth's weight per area
        stiffness: 1e4 * g,
    };
    let obstacle = (scene == Scene::Drape).then_some(&obstacle);
    let report = relax(&disc, obstacle, &mut u, relax_params, &mut |_, _| {})
        .map_err(|e| format!("shell {} at {n} points per side: {e}", scene.name()))?;
    let value = match scene {
        Scene::Drape => {
            let s = DisplaySurface::new(&disc, &u, 201, 201).map_err(|e| e.to_string())?;
            drape_coefficient(&s.positions, &s.triangles)?
        }
        Scene::Hang | Scene::HangClips => {
            -disc
                .displacement_at([0.0, 0.5], &u)
                .map_err(|e| e.to_string())?
                .z
        }
    };
    Ok(SamplingRow {
        model: "shell",
        scene,
        per_side: n,
        spacing: 1.0 / (n - 1) as f64,
        value,
        steps: report.newton_iterations,
        seconds: t0.elapsed().as_secs_f64(),
        settled: true,
    })
}

/// The mass-spring cloth's answer on an `n` × `n` grid (odd `n`), run at Δt = 1/120 s until its
/// mean speed is under 0.1 mm/s (checked every 0.25 s) or `max_seconds` have passed (then
/// reported as not settled, with its last value).
pub fn mass_spring_run(
    scene: Scene,
    n: usize,
    fabric: &FabricParameters,
    max_seconds: f64,
) -> Result<SamplingRow, String> {
    check_side(n)?;
    let t0 = Instant::now();
    let params = FabricParameters {
        air_drag: 2.0,
        ..*fabric
    };
    let mut model = ClothModel::grid(1.0, 1.0, n, n, params).map_err(|e| e.to_string())?;
    for p in &mut model.mesh.positions {
        let w = perturbation(p.x, p.y);
        *p = match scene {
            Scene::Drape => Vec3::new(p.x, p.y, w),
            Scene::Hang | Scene::HangClips => Vec3::new(p.x, w, p.y - 0.5),
        };
    }
    let sim_params = SimulationParameters {
        dt: 1.0 / 120.0,
        ..Default::default()
    };
    let mut sim = Simulation::new(model, sim_params).map_err(|e| e.to_string())?;
    match scene {
        Scene::Drape => {
            let centre = (n / 2) * n + n / 2;
            sim.pin(&[centre]).map_err(|e| e.to_string())?;
            let contact = sim.add_contact();
            contact.settings.thickness = CONTACT_DISTANCE;
            let mut ball = Body::sphere(
                Vec3::new(0.0, 0.0, -(SPHERE_RADIUS + CONTACT_DISTANCE)),
                SPHERE_RADIUS,
            )
            .map_err(|e| e.to_string())?;
            ball.friction = FrictionCoefficients {
                static_: 0.0,
                kinetic: 0.0,
            };
            contact.bodies.push(ball);
        }
        Scene::Hang => {
            sim.pin(&[(n - 1) * n, n * n - 1])
                .map_err(|e| e.to_string())?;
        }
        Scene::HangClips => {
            let h = 1.0 / (n - 1) as f64;
            let held: Vec<usize> = (0..n * n)
                .filter(|&k| in_clip(-0.5 + (k % n) as f64 * h, -0.5 + (k / n) as f64 * h))
                .collect();
            sim.pin(&held).map_err(|e| e.to_string())?;
        }
    }
    let mass: f64 = sim.model.mass.iter().sum();
    let measure = |sim: &Simulation| -> Result<f64, String> {
        let x = &sim.state.x;
        match scene {
            Scene::Drape => {
                let pos: Vec<[f64; 3]> = x.iter().map(|p| [p.x, p.y, p.z]).collect();
                drape_coefficient(&pos, &sim.model.mesh.triangles)
            }
            Scene::Hang | Scene::HangClips => Ok(x[(n - 1) * n].z - x[(n - 1) * n + n / 2].z),
        }
    };
    // settled: still (mean speed under 0.1 mm/s), or the measured value steady to 1e-4
    // (relative) over the last second while the mean speed is under 5 mm/s (a frictionless
    // drape may turn slowly about its pin, which changes nothing measured)
    let check = 30;
    let mut steps = 0;
    let mut history: Vec<f64> = Vec::new();
    let mut settled = true;
    let value = loop {
        let mut kinetic = 0.0;
        for _ in 0..check {
            kinetic = sim.step().map_err(|e| e.to_string())?.kinetic;
            steps += 1;
        }
        let speed = (2.0 * kinetic / mass).sqrt();
        let v = measure(&sim)?;
        history.push(v);
        let last = &history[history.len().saturating_sub(5)..];
        let spread = last.iter().cloned().fold(f64::NEG_INFINITY, f64::max)
            - last.iter().cloned().fold(f64::INFINITY, f64::min);
        if speed < 1e-4 || (last.len() == 5 && speed < 5e-3 && spread <= 1e-4 * v.abs()) {
            break v;
        }
        if steps as f64 / 120.0 >= max_seconds {
            settled = false;
            break v;
        }
    };
    Ok(SamplingRow {
        model: "mass-spring",
        scene,
        per_side: n,
        spacing: 1.0 / (n - 1) as f64,
        value,
        steps,
        seconds: t0.elapsed().as_secs_f64(),
        settled,
    })
}
