//! Script bindings that read a simulation out: positions, bounds, energies, statistics, and
//! the files people open (OBJ and binary glTF meshes, CSV/JSON statistics, PNG pictures).

use std::path::Path;

use rhai::{Array, Dynamic, Engine, Map, INT};

use super::convert::{arr3, count, export_frame, finite, rt_err, to_map, RResult};
use super::paths::{write_path, write_text};
use super::{register, SimHandle};
use crate::cloth::{stats, Simulation};
use crate::contact::recording::{CacheFormat, Recording};
use crate::contact::tessellate::body_mesh;
use crate::contact::SimulationContact;
use crate::geometry::image::check_pixels;
use crate::geometry::LookAtCamera;
use crate::geometry::{mesh::bounds, write_glb, write_obj, ExportFrame, UpAxis};
use crate::render::{render_png, RenderMesh};

/// Creates the parent folder of an output file.
fn parent_dir(path: &str) -> RResult<()> {
    match Path::new(path)
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
    {
        Some(d) => std::fs::create_dir_all(d).map_err(|e| rt_err(format!("{}: {e}", d.display()))),
        None => Ok(()),
    }
}

/// A camera that frames the simulation's current bounds.
fn auto_camera(sim: &Simulation, width: u32, height: u32) -> LookAtCamera {
    let (lo, hi) = bounds(&sim.state.x);
    LookAtCamera::framing(lo, hi, width, height)
}

/// A camera from `#{eye, target, up, fov, width, height}`; eye and target default to framing.
fn camera(sim: &Simulation, m: &Map) -> RResult<LookAtCamera> {
    const KEYS: [&str; 6] = ["eye", "target", "up", "fov", "width", "height"];
    if let Some(k) = m.keys().find(|k| !KEYS.contains(&k.as_str())) {
        return Err(rt_err(format!(
            "unknown camera key `{k}` (known: {})",
            KEYS.join(", ")
        )));
    }
    let size = |k: &str, d: u32| -> RResult<u32> {
        match m.get(k) {
            Some(v) => match count(v, k)? {
                0 => Err(rt_err(format!("render camera `{k}` must be ≥ 1 pixel"))),
                n => u32::try_from(n)
                    .map_err(|_| rt_err(format!("render camera `{k}` {n} is too large"))),
            },
            None => Ok(d),
        }
    };
    let (width, height) = (size("width", 800)?, size("height", 600)?);
    check_pixels(
        "render camera `width` × `height`",
        width.into(),
        height.into(),
    )
    .map_err(|e| rt_err(e.to_string()))?;
    let mut cam = auto_camera(sim, width, height);
    if let Some(v) = m.get("eye") {
        cam.eye = super::convert::vec3(v, "eye")?.into();
    }
    if let Some(v) = m.get("target") {
        cam.target = super::convert::vec3(v, "target")?.into();
    }
    if let Some(v) = m.get("up") {
        cam.up = super::convert::vec3(v, "up")?.into();
    }
    if let Some(v) = m.get("fov") {
        cam.fov_y_deg = finite(v, "fov")?;
    }
    Ok(cam)
}

/// Colour of collision bodies in pictures.
const BODY_COLOR: [u8; 3] = [206, 196, 178];

/// Renders the cloth's current shape and the collision bodies to a PNG file.
fn render(sim: &Simulation, path: &str, cam: &LookAtCamera) -> RResult<()> {
    let path = write_text(path)?;
    let path = path.as_str();
    parent_dir(path)?;
    let (lo, hi) = bounds(&sim.state.x);
    let bodies: Vec<_> = sim
        .contact()
        .bodies
        .iter()
        .map(|b| body_mesh(b, &lo, &hi))
        .collect();
    let mut meshes = vec![RenderMesh {
        positions: &sim.state.x,
        triangles: &sim.model.mesh.triangles,
        color: RenderMesh::DEFAULT_COLOR,
    }];
    meshes.extend(bodies.iter().map(|(p, t)| RenderMesh {
        positions: p,
        triangles: t,
        color: BODY_COLOR,
    }));
    render_png(Path::new(path), &meshes, cam)?;
    Ok(())
}

/// Writes the cloth as OBJ in `frame`.
fn save_obj(s: &Simulation, path: &str, frame: ExportFrame) -> RResult<()> {
    let path = write_text(path)?;
    let path = path.as_str();
    parent_dir(path)?;
    let (x, m) = (&s.state.x, &s.model.mesh);
    write_obj(Path::new(path), x, &m.triangles, Some(&m.rest), frame)?;
    Ok(())
}

/// Writes the cloth as binary glTF in `frame` (which must be +Y up).
fn save_glb(s: &Simulation, path: &str, frame: ExportFrame) -> RResult<()> {
    let path = write_text(path)?;
    let path = path.as_str();
    if frame.up != UpAxis::Y {
        return Err(rt_err(format!(
            "{path}: glTF is +Y up by its specification"
        )));
    }
    parent_dir(path)?;
    write_glb(
        Path::new(path),
        &s.state.x,
        &s.model.mesh.triangles,
        frame.units,
    )?;
    Ok(())
}

/// Starts recording `h` into `path` with `#{format, fps, up, units}` (see `record`).
fn record(h: &SimHandle, path: &str, m: &Map) -> RResult<()> {
    let path = write_text(path)?;
    let path = path.as_str();
    let mut frame_opts = m.clone();
    let format = match frame_opts.remove("format") {
        Some(f) => {
            let f = f
                .into_string()
                .map_err(|_| rt_err("`format` must be a string"))?;
            CacheFormat::parse(&f).map_err(rt_err)?
        }
        None => CacheFormat::from_path(Path::new(path)).ok_or_else(|| {
            rt_err(format!(
                "{path}: give `format` (\"usd\", \"pc2\" or \"glb\") or a .usda, .pc2 or .glb path"
            ))
        })?,
    };
    let fps = match frame_opts.remove("fps") {
        Some(v) => finite(&v, "fps")?,
        None => 24.0,
    };
    let frame = export_frame(&frame_opts)?;
    let frame = match (format, frame_opts.contains_key("up")) {
        // USD declares its up axis: the engine's own frame unless asked otherwise
        (CacheFormat::Usd, false) => ExportFrame {
            up: UpAxis::Z,
            ..frame
        },
        _ => frame,
    };
    parent_dir(path)?;
    let rec = Recording::start(&*h.get()?, path.into(), format, frame, fps)?;
    let mut recs =
        h.1.try_borrow_mut()
            .map_err(|_| rt_err("the recording is busy"))?;
    recs.retain(|r| r.path != rec.path);
    recs.push(rec);
    Ok(())
}

/// Registers the read-out and output methods of `Simulation`.
pub fn register(engine: &mut Engine) {
    register!(
        engine,
        "position",
        ["sim: Simulation", "i: int", "Array"],
        "Position [x, y, z] (m) of particle `i`.",
        |h: &mut SimHandle, i: INT| -> RResult<Dynamic> {
            let s = h.get()?;
            let i = count(&Dynamic::from_int(i), "i")?;
            let p = s.state.x.get(i).ok_or_else(|| {
                rt_err(format!(
                    "particle {i} out of range (cloth has {})",
                    s.particle_count()
                ))
            })?;
            Ok(arr3([p.x, p.y, p.z]))
        }
    );
    register!(engine, "positions", ["sim: Simulation", "Array"],
        "All positions as an array of [x, y, z] (for small cloths: about 0.5 µs per value in script).",
        |h: &mut SimHandle| -> RResult<Array> { Ok(h.get()?.state.x.iter().map(|p| arr3([p.x, p.y, p.z])).collect()) });
    register!(
        engine,
        "bounds",
        ["sim: Simulation", "Map"],
        "Axis-aligned bounds of the current positions: #{min: [x, y, z], max: [x, y, z]}.",
        |h: &mut SimHandle| -> RResult<Map> {
            let (lo, hi) = bounds(&h.get()?.state.x);
            let mut m = Map::new();
            m.insert("min".into(), arr3([lo.x, lo.y, lo.z]));
            m.insert("max".into(), arr3([hi.x, hi.y, hi.z]));
            Ok(m)
        }
    );
    register!(
        engine,
        "energy",
        ["sim: Simulation", "Map"],
        "Energies of the current state (J): #{kinetic, gravity, elastic, total}.",
        |h: &mut SimHandle| -> RResult<Map> {
            let (k, g, e) = h.get_mut()?.energy();
            let mut m = Map::new();
            for (name, v) in [
                ("kinetic", k),
                ("gravity", g),
                ("elastic", e),
                ("total", k + g + e),
            ] {
                m.insert(name.into(), Dynamic::from_float(v));
            }
            Ok(m)
        }
    );
    register!(engine, "stats", ["sim: Simulation", "Map"],
        "Statistics of the last step: #{step, time, kinetic, gravity, elastic, total, cg_iterations,\nresidual, converged, assemble_ms, solve_ms, step_ms}; empty before the first step.",
        |h: &mut SimHandle| -> RResult<Dynamic> {
            Ok(h.get()?.stats.last().map(to_map).unwrap_or_else(|| Dynamic::from_map(Map::new())))
        });
    register!(engine, "save_obj", ["sim: Simulation", "path: String"],
        "Writes the current shape as OBJ, +Y up in metres (as Blender and Maya read OBJ), with the\nrest (pattern) coordinates as texture coordinates.",
        |h: &mut SimHandle, path: &str| -> RResult<()> {
            save_obj(&*h.get()?, path, ExportFrame::Y_UP_METRES)
        });
    register!(engine, "save_obj", ["sim: Simulation", "path: String", "options: Map", "()"],
        "Writes the current shape as OBJ with #{up: \"y\" (default) | \"z\", units: \"m\" (default) |\n\"cm\" | \"mm\"}.",
        |h: &mut SimHandle, path: &str, m: Map| -> RResult<()> {
            save_obj(&*h.get()?, path, export_frame(&m)?)
        });
    register!(
        engine,
        "save_glb",
        ["sim: Simulation", "path: String"],
        "Writes the current shape as binary glTF (.glb): +Y up (glTF's frame), metres.",
        |h: &mut SimHandle, path: &str| -> RResult<()> {
            save_glb(&*h.get()?, path, ExportFrame::Y_UP_METRES)
        }
    );
    register!(engine, "save_glb", ["sim: Simulation", "path: String", "options: Map", "()"],
        "Writes the current shape as binary glTF (.glb) with #{units: \"m\" | \"cm\" | \"mm\"} (glTF is\nalways +Y up; `up` other than \"y\" is an error).",
        |h: &mut SimHandle, path: &str, m: Map| -> RResult<()> {
            save_glb(&*h.get()?, path, export_frame(&m)?)
        });
    register!(engine, "record", ["sim: Simulation", "path: String", "options: Map", "()"],
        "Starts recording the simulation as an animation cache (beside any other recording; the same\npath again starts that one over): the current state is frame 0 and frame k the state after k frames of `run_frames`; the file is (re)written at the end of each `run_frames`.\nThe cloth and every mesh body (a mannequin) are recorded. Options: #{format: \"usd\" (a .usda\nstage, +Z up unless `up` says otherwise) | \"pc2\" (one point cache and rest OBJ per mesh) |\n\"glb\" (morph-target animation), by default from the extension; fps: frames per second\n(24, use run_frames' rate); up: \"y\" | \"z\"; units: \"m\" | \"cm\" | \"mm\"}.",
        |h: &mut SimHandle, path: &str, m: Map| -> RResult<()> { record(h, path, &m) });
    register!(
        engine,
        "record",
        ["sim: Simulation", "path: String", "()"],
        "Starts recording the simulation into `path` (.usda, .pc2 or .glb), 24 frames per second.",
        |h: &mut SimHandle, path: &str| -> RResult<()> { record(h, path, &Map::new()) }
    );
    register!(
        engine,
        "save_recording",
        ["sim: Simulation", "Array"],
        "Writes every recording now (nothing without one); returns the paths of the files written.",
        |h: &mut SimHandle| -> RResult<Array> {
            Ok(h.write_recording()?
                .iter()
                .map(|p| Dynamic::from(p.display().to_string()))
                .collect())
        }
    );
    register!(
        engine,
        "save_stats_csv",
        ["sim: Simulation", "path: String"],
        "Writes the statistics of every step as CSV (one line per step).",
        |h: &mut SimHandle, path: &str| -> RResult<()> {
            Ok(stats::write_csv(&write_path(path)?, &h.get()?.stats)?)
        }
    );
    register!(
        engine,
        "save_stats_json",
        ["sim: Simulation", "path: String"],
        "Writes the statistics of every step as a JSON array.",
        |h: &mut SimHandle, path: &str| -> RResult<()> {
            Ok(stats::write_json(&write_path(path)?, &h.get()?.stats)?)
        }
    );
    register!(
        engine,
        "render",
        ["sim: Simulation", "path: String"],
        "Renders the cloth to an 800×600 PNG with a camera that frames it.",
        |h: &mut SimHandle, path: &str| -> RResult<()> {
            let s = h.get()?;
            render(&s, path, &auto_camera(&s, 800, 600))
        }
    );
    register!(engine, "render", ["sim: Simulation", "path: String", "camera: Map", "()"],
        "Renders the cloth to a PNG with a camera #{eye: [..], target: [..], up: [..], fov: degrees,\nwidth, height}; missing entries come from the auto-framing 800×600 camera. Width and height are ≥ 1\nand their product at most the `max_pixels` limit (an error otherwise, never a smaller picture).",
        |h: &mut SimHandle, path: &str, m: Map| -> RResult<()> {
            let s = h.get()?;
            render(&s, path, &camera(&s, &m)?)
        });
    register!(
        engine,
        "to_string",
        ["sim: Simulation", "String"],
        "One-line summary of a simulation.",
        |h: &mut SimHandle| h.to_string()
    );
    register!(
        engine,
        "to_debug",
        ["sim: Simulation", "String"],
        "One-line summary of a simulation.",
        |h: &mut SimHandle| h.to_string()
    );
}
