//! A garment from its pattern files to a draped garment on the MakeHuman mannequin, without
//! scripting: reads `scripts/patterns/<name>.garment.json`, meshes, pre-positions, sews and
//! drapes, printing the figures on the way, and writes front/side/back PNGs to
//! `out/examples/<name>_*.png`.
//!
//! `cargo run --release --example dress -- [aaron|penelope|paco] [seconds] [edge_m]`
//!
//! Environment knobs for experiments: `RELAX` (relaxation sweeps), `SEAM_FORCE` (N),
//! `SELF` (`0` turns self-collision off), `SEW_G` (share of gravity while sewing), `STITCH`
//! (stitched seam stiffness, N/m), `PRECOND` (`aggregation`, `block_jacobi`: the solve's
//! preconditioner), `FABRIC` (a fabric file, as the scripts' `kes_fabric`), `DT` (the step, s); diagnostics: `DIAG` (per-seam gaps while running, the
//! worst pair of each seam at the end, self-intersections by pair of pieces), `EVERY` (a line
//! per step with the largest displacement).

use std::path::{Path, PathBuf};
use std::time::Instant;

use emilion::body::Mannequin;
use emilion::cloth::{FabricParameters, SimulationParameters};
use emilion::contact::{Shape, SimulationContact};
use emilion::garment::{dress, read_garment, DressParameters};
use emilion::geometry::LookAtCamera;
use emilion::geometry::Vec3;
use emilion::render::{render_png, RenderMesh};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let name = args.get(1).map_or("aaron", |s| s.as_str());
    let seconds: f64 = args.get(2).map_or(Ok(2.0), |s| s.parse())?;
    let edge: f64 = args.get(3).map_or(Ok(0.015), |s| s.parse())?;
    let t0 = Instant::now();
    let pattern = read_garment(format!("scripts/patterns/{name}.garment.json"))?;
    let data = PathBuf::from("../shared/data/bodies/makehuman");
    let man = Mannequin::load_makehuman(&data)?;
    let mut params = DressParameters::default();
    params.mesh.edge_length = edge;
    if let Ok(r) = std::env::var("RELAX") {
        params.preposition.relax_iterations = r.parse()?;
    }
    if let Ok(f) = std::env::var("SEAM_FORCE") {
        params.seam_max_force = f.parse()?;
    }
    if let Ok(f) = std::env::var("SEAM_HINGES") {
        params.seam_hinges = f == "1";
    }
    if let Ok(f) = std::env::var("SELF") {
        params.contact.self_collision = f == "1";
    }
    let mut sim_params = SimulationParameters::default();
    if let Ok(dt) = std::env::var("DT") {
        sim_params.dt = dt
            .parse()
            .map_err(|e| format!("DT={dt:?}: not a step in seconds ({e})"))?;
    }
    if let Ok(p) = std::env::var("PRECOND") {
        sim_params.preconditioner = serde_json::from_value(serde_json::Value::String(p))?;
    }
    let (fabric, law) = match std::env::var("FABRIC") {
        Ok(path) => {
            let spec = emilion::kes::fabric::read_fabric(Path::new(&path))?;
            let (f, law) = emilion::kes::lab::measured_fabric(&spec)?;
            (f, Some(std::sync::Arc::new(law)))
        }
        Err(_) => (FabricParameters::default(), None),
    };
    let mut d = dress(&pattern, fabric, &man, &params, sim_params)?;
    if let Some(law) = law {
        d.simulation.set_material(law)?;
    }
    println!("{}", serde_json::to_string(&d.report)?);
    println!("set up in {:.2} s", t0.elapsed().as_secs_f64());
    for s in &d.garment.seams {
        let x = &d.simulation.state.x;
        let gaps: Vec<f64> = s.pairs.iter().map(|&(a, b)| (x[a] - x[b]).norm()).collect();
        println!(
            "seam {}: {} pairs, gap {:.1}–{:.1} mm",
            s.name,
            gaps.len(),
            gaps.iter().cloned().fold(f64::MAX, f64::min) * 1e3,
            gaps.iter().cloned().fold(0.0, f64::max) * 1e3
        );
    }
    let sim = &mut d.simulation;
    if let (Ok(g), Some(sew)) = (std::env::var("SEW_G"), sim.sewing.as_mut()) {
        sew.sewing_gravity = g.parse()?;
    }
    if let (Ok(k), Some(sep)) = (
        std::env::var("SEP_STEP"),
        sim.sewing.as_mut().and_then(|s| s.separation.as_mut()),
    ) {
        sep.step = k.parse()?;
    }
    if let (Ok(k), Some(sew)) = (std::env::var("SETTLE"), sim.sewing.as_mut()) {
        sew.settle = k.parse()?;
    }
    if let (Ok(k), Some(sew)) = (std::env::var("STITCH"), sim.sewing.as_mut()) {
        sew.stitched.0 = k.parse()?;
    }
    let steps = sim.steps_for(seconds);
    let mut worst_inside = 0;
    for k in 0..steps {
        let before = sim.state.x.clone();
        let st = sim.step()?;
        if std::env::var("EVERY").is_ok() {
            let (i, d) = sim
                .state
                .x
                .iter()
                .zip(&before)
                .map(|(a, b)| (a - b).norm())
                .enumerate()
                .fold((0, 0.0), |w, (i, d)| if d > w.1 { (i, d) } else { w });
            let jumped = sim
                .state
                .x
                .iter()
                .zip(&before)
                .filter(|(a, b)| (*a - *b).norm() > 0.02)
                .count();
            println!(
                "step {k}: largest move {:.1} mm at vertex {i} from {:.3?} to {:.3?}; {jumped} moved > 2 cm",
                d * 1e3,
                before[i].as_slice(),
                sim.state.x[i].as_slice()
            );
        }
        worst_inside = worst_inside.max(st.penetrating);
        if k % 24 == 0 || k + 1 == steps || std::env::var("EVERY").is_ok() {
            let gap = sim
                .sewing
                .as_ref()
                .map_or(0.0, |s| s.max_gap(&sim.model, &sim.state.x));
            if std::env::var("DIAG").is_ok() {
                for s in &d.garment.seams {
                    let x = &sim.state.x;
                    let g = s
                        .pairs
                        .iter()
                        .map(|&(a, b)| (x[a] - x[b]).norm())
                        .fold(0.0, f64::max);
                    print!("{}:{:.1} ", s.name, g * 1e3);
                }
                let x = sim.state.x.clone();
                let list = sim.contact_mut().self_intersections(&x);
                let crossings = list.len();
                let mut by: std::collections::BTreeMap<(usize, usize), usize> = Default::default();
                for (e, t) in &list {
                    let piece = |v: u32| {
                        d.garment
                            .pieces
                            .iter()
                            .position(|p| p.vertices.contains(&(v as usize)))
                            .unwrap_or(0)
                    };
                    let (a, b) = (piece(e[0]), piece(t[0]));
                    *by.entry((a.min(b), a.max(b))).or_default() += 1;
                }
                for ((a, b), c) in by {
                    print!(
                        "[{}x{} {c}] ",
                        d.garment.pieces[a].name, d.garment.pieces[b].name
                    );
                }
                let sewing = sim
                    .sewing
                    .as_ref()
                    .is_some_and(|s| s.sewing_at(sim.state.time));
                println!("crossings {crossings} sewing {sewing}");
            }
            println!(
                "t {:.3} s: step {:.1} ms (assemble {:.1}, solve {:.1}, collision {:.1}), cg {}, seam gap {:.2} mm, contacts {}, self {}, min distance {:.4}, penetrating {}",
                sim.state.time, st.step_ms, st.assemble_ms, st.solve_ms, st.collision_ms, st.cg_iterations, gap * 1e3, st.contacts, st.self_contacts, st.min_distance, st.penetrating
            );
        }
    }
    for s in &d.garment.seams {
        let x = &sim.state.x;
        let gaps: Vec<f64> = s.pairs.iter().map(|&(a, b)| (x[a] - x[b]).norm()).collect();
        let worst = gaps
            .iter()
            .cloned()
            .enumerate()
            .fold((0, 0.0), |w, (i, g)| if g > w.1 { (i, g) } else { w });
        println!(
            "end seam {}: worst gap {:.1} mm at pair {} of {}",
            s.name,
            worst.1 * 1e3,
            worst.0,
            gaps.len()
        );
        if std::env::var("DIAG").is_ok() && worst.1 > 1e-3 {
            let (a, b) = s.pairs[worst.0];
            if let Shape::Mesh(m) = &sim.contact().bodies[0].shape {
                for v in [a, b] {
                    let dist = m.proximity(&x[v], 1.0).map_or(f64::NAN, |q| q.distance);
                    println!(
                        "   vertex {v} at {:.4} {:.4} {:.4}, skin {:.2} mm, speed {:.2e}",
                        x[v].x,
                        x[v].y,
                        x[v].z,
                        dist * 1e3,
                        sim.state.v[v].norm()
                    );
                }
            }
        }
    }
    if let Shape::Mesh(m) = &sim.contact().bodies[0].shape {
        let mut inside: Vec<(f64, usize)> = sim
            .state
            .x
            .iter()
            .enumerate()
            .filter_map(|(i, p)| {
                m.proximity(p, 1.0)
                    .filter(|q| q.distance < 0.0)
                    .map(|q| (q.distance, i))
            })
            .collect();
        inside.sort_by(|a, b| a.0.total_cmp(&b.0));
        for (dist, i) in inside.iter().take(8) {
            let p = sim.state.x[*i];
            println!(
                "inside {:.1} mm: vertex {i} at ({:.3}, {:.3}, {:.3})",
                dist * 1e3,
                p.x,
                p.y,
                p.z
            );
        }
    }
    let x = sim.state.x.clone();
    let n = sim.contact_mut().report(&x).intersections;
    if std::env::var("DIAG").is_ok() {
        let mut owner = vec![0usize; sim.state.x.len()];
        for (k, p) in d.garment.pieces.iter().enumerate() {
            for v in p.vertices.clone() {
                owner[v] = k;
            }
        }
        let mut by: std::collections::BTreeMap<(String, String), (usize, Vec3)> =
            Default::default();
        for (e, t) in sim.contact_mut().self_intersections(&x) {
            let (a, b) = (owner[e[0] as usize], owner[t[0] as usize]);
            let key = (
                d.garment.pieces[a.min(b)].name.clone(),
                d.garment.pieces[a.max(b)].name.clone(),
            );
            let entry = by.entry(key).or_insert((0, Vec3::zeros()));
            entry.0 += 1;
            entry.1 = sim.state.x[e[0] as usize];
            if let Some(sep) = sim.sewing.as_ref().and_then(|s| s.separation.as_ref()) {
                println!(
                    "  sides edge {:?} tri {:?}",
                    e.map(|v| sep.side[v as usize]),
                    t.map(|v| sep.side[v as usize])
                );
            }
            if a == b && entry.0 <= 4 {
                let zones = sim
                    .sewing
                    .as_ref()
                    .map(|s| s.pass_through.clone())
                    .unwrap_or_default();
                let zone = |v: u32| zones.get(v as usize).copied().unwrap_or(0);
                println!(
                    "  {} through itself: edge {:?} (zones {:?}) at {:?}, triangle {:?} (zones {:?})",
                    d.garment.pieces[a].name,
                    e,
                    e.map(zone),
                    sim.state.x[e[0] as usize].as_slice(),
                    t,
                    t.map(zone)
                );
            }
            if a != b && entry.0 <= 3 {
                let f = |v: u32| d.garment.flat[v as usize];
                let x = |v: u32| sim.state.x[v as usize];
                println!(
                    "  edge of {} flat {:?} {:?} at {:?} {:?}; tri of {} flat {:?} at {:?}",
                    d.garment.pieces[a].name,
                    f(e[0]),
                    f(e[1]),
                    x(e[0]),
                    x(e[1]),
                    d.garment.pieces[b].name,
                    f(t[0]),
                    x(t[0])
                );
            }
        }
        for ((a, b), (c, p)) in by {
            println!(
                "intersections {a} x {b}: {c} (one at {:.3} {:.3} {:.3})",
                p.x, p.y, p.z
            );
        }
    }
    println!(
        "total {:.1} s; self-intersections {n}; worst penetrating {worst_inside}",
        t0.elapsed().as_secs_f64()
    );
    let steps = sim.stats.len().max(1) as f64;
    let mean =
        |f: fn(&emilion::cloth::StepStats) -> f64| sim.stats.iter().map(f).sum::<f64>() / steps;
    print!(
        "per step: {:.1} ms (assemble {:.1}, solve {:.1}, collision {:.1}), cg {:.1}",
        mean(|s| s.step_ms),
        mean(|s| s.assemble_ms),
        mean(|s| s.solve_ms),
        mean(|s| s.collision_ms),
        mean(|s| f64::from(s.cg_iterations))
    );
    match sim.multigrid_timing() {
        Some((setup, apply, count)) => println!(
            "; {} multigrid levels: setup {:.2} ms per step, V-cycle {:.3} ms",
            sim.multigrid_levels(),
            setup * 1e3 / steps,
            apply * 1e3 / count.max(1) as f64
        ),
        None => println!("; block-Jacobi"),
    }
    std::fs::create_dir_all("out/examples")?;
    let (bp, bt) = match &sim.contact().bodies[0].shape {
        Shape::Mesh(m) => (m.positions().to_vec(), m.triangles().to_vec()),
        _ => unreachable!(),
    };
    let target = Vec3::new(0.0, 0.0, if name == "aaron" { 1.15 } else { 0.8 });
    for (view, eye) in [
        ("front", Vec3::new(0.0, -1.7, 1.25)),
        ("side", Vec3::new(1.7, 0.0, 1.25)),
        ("back", Vec3::new(0.0, 1.7, 1.25)),
    ] {
        let path = format!("out/examples/{name}_{view}.png");
        render_png(
            Path::new(&path),
            &[
                RenderMesh {
                    positions: &sim.state.x,
                    triangles: &sim.model.mesh.triangles,
                    color: RenderMesh::DEFAULT_COLOR,
                },
                RenderMesh {
                    positions: &bp,
                    triangles: &bt,
                    color: [200, 190, 170],
                },
            ],
            &LookAtCamera::look_at(eye, target),
        )?;
        println!("wrote {path}");
    }
    if let Ok(at) = std::env::var("CLOSE") {
        // close-ups of a point (`CLOSE=x,y,z`), garment only, one colour per piece
        let c: Vec<f64> = at.split(',').map(|v| v.parse()).collect::<Result<_, _>>()?;
        let target = Vec3::new(c[0], c[1], c[2]);
        let colours = [
            [220, 80, 60],
            [60, 140, 220],
            [90, 190, 90],
            [220, 190, 60],
            [170, 90, 200],
            [80, 200, 200],
        ];
        let mut tris: Vec<Vec<[usize; 3]>> = vec![Vec::new(); d.garment.pieces.len()];
        for t in &sim.model.mesh.triangles {
            let k = d
                .garment
                .pieces
                .iter()
                .position(|p| p.vertices.contains(&t[0]))
                .unwrap_or(0);
            tris[k].push(*t);
        }
        let meshes: Vec<RenderMesh> = tris
            .iter()
            .enumerate()
            .map(|(k, t)| RenderMesh {
                positions: &sim.state.x,
                triangles: t,
                color: colours[k % colours.len()],
            })
            .collect();
        for (view, eye) in [
            ("close_front", Vec3::new(0.0, -0.12, -0.05)),
            ("close_back", Vec3::new(0.0, 0.12, -0.05)),
            ("close_below", Vec3::new(0.02, 0.0, -0.15)),
        ] {
            let path = format!("out/examples/{name}_{view}.png");
            render_png(
                Path::new(&path),
                &meshes,
                &LookAtCamera::look_at(target + eye, target),
            )?;
            println!("wrote {path}");
        }
    }
    Ok(())
}
