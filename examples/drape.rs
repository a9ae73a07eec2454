//! The peer drape scene (a 1 m cloth falling on a sphere) run for 50 frames: prints the contact
//! statistics every 10 frames and writes `out/examples/drape.png`.
//!
//! `cargo run --release --example drape -- [n] [self]`

use emilion::contact::SimulationContact;
use emilion::geometry::mesh::bounds;
use emilion::geometry::LookAtCamera;
use emilion::render::{render_png, RenderMesh};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let n: usize = args.get(1).map_or(Ok(64), |s| s.parse())?;
    let mut sim = emilion::scenes::drape(n)?;
    if std::env::var("BJ").is_ok() {
        let mut p = sim.params;
        p.preconditioner = emilion::cloth::PreconditionerKind::BlockJacobi;
        let mut s2 = emilion::cloth::Simulation::new(sim.model.clone(), p)?;
        let contact = s2.add_contact();
        contact.settings = sim.contact().settings;
        contact.bodies = sim.contact().bodies.clone();
        sim = s2;
    }
    if let Ok(mu) = std::env::var("MU") {
        let mu: f64 = mu.parse()?;
        let contact = sim.contact_mut();
        contact.settings.friction = emilion::contact::FrictionCoefficients {
            static_: mu,
            kinetic: mu,
        };
        for b in &mut contact.bodies {
            b.friction = contact.settings.friction;
        }
    }
    if args.get(2).is_some_and(|s| s == "self") {
        sim.contact_mut().settings.self_collision = true;
    }
    let frames: u32 = std::env::var("FRAMES").map_or(50, |f| f.parse().unwrap_or(50));
    for frame in 1..=frames {
        sim.run_steps(5, |_, _| Ok(()))?;
        if frame % 10 == 0 || frame == frames {
            let s = sim.stats.last().copied().unwrap_or_default();
            println!(
                "frame {frame}: step {:.1} ms (collision {:.2} ms, cg {}), contacts {}, self {}, min distance {:.4} m, penetrating {}, intersections {}",
                s.step_ms, s.collision_ms, s.cg_iterations, s.contacts, s.self_contacts, s.min_distance, s.penetrating, s.intersections
            );
        }
    }
    let (lo, hi) = bounds(&sim.state.x);
    let _ = (lo, hi);
    let mut sphere_p = Vec::new();
    let mut sphere_t = Vec::new();
    let (nu, nv) = (48, 24);
    for j in 0..=nv {
        for i in 0..nu {
            let (th, ph) = (
                std::f64::consts::PI * j as f64 / nv as f64,
                2.0 * std::f64::consts::PI * i as f64 / nu as f64,
            );
            sphere_p.push(emilion::geometry::Vec3::new(
                0.3 * th.sin() * ph.cos(),
                0.3 * th.sin() * ph.sin(),
                0.3 * th.cos(),
            ));
        }
    }
    for j in 0..nv {
        for i in 0..nu {
            let (a, b) = (j * nu + i, j * nu + (i + 1) % nu);
            sphere_t.push([a, b, a + nu]);
            sphere_t.push([b, b + nu, a + nu]);
        }
    }
    let cam = LookAtCamera::look_at(
        emilion::geometry::Vec3::new(1.2, -1.6, 1.1),
        emilion::geometry::Vec3::new(0.0, 0.0, 0.0),
    );
    std::fs::create_dir_all("out/examples")?;
    render_png(
        std::path::Path::new("out/examples/drape.png"),
        &[
            RenderMesh {
                positions: &sim.state.x,
                triangles: &sim.model.mesh.triangles,
                color: RenderMesh::DEFAULT_COLOR,
            },
            RenderMesh {
                positions: &sphere_p,
                triangles: &sphere_t,
                color: [200, 190, 170],
            },
        ],
        &cam,
    )?;
    println!("wrote out/examples/drape.png");
    Ok(())
}
