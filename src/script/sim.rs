//! Script bindings for simulations: the `Simulation` handle (a shared [`Simulation`]),
//! its constraints (pins, moving attachments, floor) and its runs, including runs that call a
//! script closure once per step or per frame.

use rhai::{Array, Dynamic, Locked, Map, Shared, INT};
use std::cell::{Ref, RefMut};
use std::fmt;

use super::convert::{
    count, finite, get_field, indices, rt_err, to_map, update_field, update_from_map, vec3, RResult,
};
use super::{function, getter, modules::ApiBuilder, register, ClothHandle};
use crate::cloth::{Simulation, SimulationParameters, Trajectory};
use crate::contact::recording::Recording;
use crate::contact::{Floor, SimulationContact};

/// A simulation as a script handle: every copy refers to the same simulation (and to the same
/// animation recordings, when some were started).
#[derive(Debug, Clone)]
pub struct SimHandle(
    pub Shared<Locked<Simulation>>,
    pub Shared<Locked<Vec<Recording>>>,
);

impl SimHandle {
    /// Wraps a simulation.
    pub fn new(sim: Simulation) -> Self {
        SimHandle(
            Shared::new(Locked::new(sim)),
            Shared::new(Locked::new(Vec::new())),
        )
    }

    /// Adds the simulation's current state to every recording started.
    pub fn capture_frame(&self) -> RResult<()> {
        let mut recs = self
            .1
            .try_borrow_mut()
            .map_err(|_| rt_err("the recording is busy"))?;
        for r in recs.iter_mut() {
            r.capture(&*self.get()?)?;
        }
        Ok(())
    }

    /// Writes every recording started; returns the files written.
    pub fn write_recording(&self) -> RResult<Vec<std::path::PathBuf>> {
        let recs = self
            .1
            .try_borrow()
            .map_err(|_| rt_err("the recording is busy"))?;
        let mut written = Vec::new();
        for r in recs.iter() {
            written.extend(r.write()?);
        }
        Ok(written)
    }
    /// Reads the simulation.
    pub fn get(&self) -> RResult<Ref<'_, Simulation>> {
        self.0
            .try_borrow()
            .map_err(|_| rt_err("the simulation is busy (it is being stepped)"))
    }
    /// Changes the simulation.
    pub fn get_mut(&self) -> RResult<RefMut<'_, Simulation>> {
        self.0
            .try_borrow_mut()
            .map_err(|_| rt_err("the simulation is busy (it is being read or stepped)"))
    }
}

impl fmt::Display for SimHandle {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.0.try_borrow() {
            Ok(s) => write!(
                f,
                "Simulation({} particles, t = {:.4} s, {} steps, dt = {} s, {:?}, {} attachments, {} step stages)",
                s.particle_count(), s.state.time, s.state.step, s.params.dt, s.params.integrator,
                s.attachments.len(), s.stages().len()
            ),
            Err(_) => f.write_str("Simulation(busy)"),
        }
    }
}

/// Grid particle indices of a named edge or corner set of a grid cloth.
fn grid_set(sim: &Simulation, which: &str, corners: bool) -> RResult<Vec<usize>> {
    let (nx, ny) = sim
        .model
        .grid
        .ok_or_else(|| rt_err("this cloth is not a grid"))?;
    let id = |i: usize, j: usize| i * nx + j;
    let (row, col): (Vec<usize>, Vec<usize>) = match which {
        "top" => (vec![ny - 1], (0..nx).collect()),
        "bottom" => (vec![0], (0..nx).collect()),
        "left" => ((0..ny).collect(), vec![0]),
        "right" => ((0..ny).collect(), vec![nx - 1]),
        "all" if corners => (vec![0, ny - 1], vec![0, nx - 1]),
        _ => {
            return Err(rt_err(format!(
                "unknown grid side `{which}` (top, bottom, left, right{})",
                if corners { ", all" } else { "" }
            )))
        }
    };
    let mut out: Vec<usize> = row
        .iter()
        .flat_map(|&i| col.iter().map(move |&j| id(i, j)))
        .collect();
    if corners && which != "all" {
        out = vec![out[0], out[out.len() - 1]];
    }
    Ok(out)
}

/// A trajectory from `#{velocity}`, `#{keyframes}` or `#{amplitude, frequency}` (`#{}`: fixed).
fn trajectory(m: &Map) -> RResult<Trajectory> {
    if let Some(k) = m
        .keys()
        .find(|k| !["velocity", "keyframes", "amplitude", "frequency"].contains(&k.as_str()))
    {
        return Err(rt_err(format!(
            "unknown attachment key `{k}` (velocity, keyframes, amplitude + frequency)"
        )));
    }
    if let Some(v) = m.get("velocity") {
        return Ok(Trajectory::Linear {
            velocity: vec3(v, "velocity")?,
        });
    }
    if let Some(k) = m.get("keyframes") {
        let arr = k
            .read_lock::<Array>()
            .ok_or_else(|| rt_err("`keyframes` must be an array of [t, x, y, z]"))?;
        let mut keys = Vec::with_capacity(arr.len());
        for key in arr.iter() {
            let a = key
                .read_lock::<Array>()
                .filter(|a| a.len() == 4)
                .ok_or_else(|| rt_err("each keyframe must be [t, x, y, z]"))?;
            let t = finite(&a[0], "keyframe time")?;
            let p = [
                finite(&a[1], "keyframe x")?,
                finite(&a[2], "keyframe y")?,
                finite(&a[3], "keyframe z")?,
            ];
            keys.push((t, p));
        }
        return Ok(Trajectory::Keyframes(keys));
    }
    match (m.get("amplitude"), m.get("frequency")) {
        (Some(a), Some(f)) => Ok(Trajectory::Oscillation {
            amplitude: vec3(a, "amplitude")?,
            frequency: finite(f, "frequency")?,
        }),
        (None, None) => Ok(Trajectory::Fixed),
        _ => Err(rt_err(
            "an oscillation needs both `amplitude` and `frequency`",
        )),
    }
}

/// Registers `cloth::simulation` and the `Simulation` methods for constraints and stepping.
pub fn register(engine: &mut ApiBuilder) {
    engine.register_type_with_name::<SimHandle>("Simulation");
    let new_sim = |c: &ClothHandle, m: &Map| -> RResult<SimHandle> {
        let params = update_from_map(&SimulationParameters::default(), m, "simulation")?;
        let mut sim = Simulation::new((*c.0).clone(), params)?;
        sim.add_contact();
        Ok(SimHandle::new(sim))
    };
    function!(engine, "cloth::simulation", alias = "simulation", ["cloth: Cloth", "Simulation"],
        "A simulation of `cloth` at rest, with default settings (dt 1/120 s, implicit, gravity −9.81 z).",
        move |c: ClothHandle| new_sim(&c, &Map::new()));
    function!(engine, "cloth::simulation", alias = "simulation", ["cloth: Cloth", "params: Map", "Simulation"],
        "A simulation of `cloth` with settings from a map: dt, integrator (\"implicit\" | \"explicit\"),\ngravity [x, y, z], cg_tolerance, cg_max_iterations, warm_start, explicit_substeps, max_speed.",
        move |c: ClothHandle, m: Map| new_sim(&c, &m));

    register!(
        engine,
        "pin",
        ["sim: Simulation", "particles: Array", "int"],
        "Pins particles where they are now; returns the attachment index.",
        |h: &mut SimHandle, p: Array| -> RResult<INT> {
            Ok(h.get_mut()?.pin(&indices(&p, "particle")?)? as INT)
        }
    );
    register!(engine, "pin_corners", ["sim: Simulation", "side: String", "int"],
        "Pins the two corners of a grid side (\"top\" = y max, \"bottom\", \"left\", \"right\") or \"all\" four.",
        |h: &mut SimHandle, side: &str| -> RResult<INT> {
            let mut s = h.get_mut()?;
            let p = grid_set(&s, side, true)?;
            Ok(s.pin(&p)? as INT)
        });
    register!(
        engine,
        "grid_edge",
        ["sim: Simulation", "side: String", "Array"],
        "Particle indices along a side of a grid cloth (\"top\", \"bottom\", \"left\", \"right\").",
        |h: &mut SimHandle, side: &str| -> RResult<Array> {
            Ok(grid_set(&*h.get()?, side, false)?
                .into_iter()
                .map(|i| Dynamic::from_int(i as INT))
                .collect())
        }
    );
    register!(
        engine,
        "grid_index",
        ["sim: Simulation", "row: int", "col: int", "int"],
        "Index of grid particle (row along y, column along x): `row * nx + col`.",
        |h: &mut SimHandle, i: INT, j: INT| -> RResult<INT> {
            let s = h.get()?;
            let (nx, ny) = s
                .model
                .grid
                .ok_or_else(|| rt_err("this cloth is not a grid"))?;
            let (i, j) = (
                count(&Dynamic::from_int(i), "row")?,
                count(&Dynamic::from_int(j), "col")?,
            );
            if i >= ny || j >= nx {
                return Err(rt_err(format!("grid cell ({i}, {j}) outside {nx}×{ny}")));
            }
            Ok((i * nx + j) as INT)
        }
    );
    register!(engine, "attach", ["sim: Simulation", "particles: Array", "motion: Map", "int"],
        "Attaches particles to a moving target starting now: `#{velocity: [vx, vy, vz]}`,\n`#{keyframes: [[t, dx, dy, dz], ...]}` (displacement at simulation time t, counted from\nits value now, so nothing jumps) or\n`#{amplitude: [ax, ay, az], frequency: f}`; `#{}` pins. Returns the attachment index.",
        |h: &mut SimHandle, p: Array, m: Map| -> RResult<INT> {
            let traj = trajectory(&m)?;
            Ok(h.get_mut()?.attach(&indices(&p, "particle")?, traj)? as INT)
        });
    register!(
        engine,
        "release",
        ["sim: Simulation", "particles: Array"],
        "Frees particles from every pin and attachment; an index past the cloth's particles is an error.",
        |h: &mut SimHandle, p: Array| -> RResult<()> {
            Ok(h.get_mut()?.release(&indices(&p, "particle")?)?)
        }
    );
    register!(
        engine,
        "add_floor",
        ["sim: Simulation", "height: float", "thickness: float"],
        "Adds an infinite floor at z = `height`, keeping the cloth `thickness` m above it.",
        |h: &mut SimHandle, z: Dynamic, t: Dynamic| -> RResult<()> {
            let floor = Floor {
                height: finite(&z, "height")?,
                thickness: finite(&t, "thickness")?,
            };
            h.get_mut()?.add_stage(Box::new(floor));
            Ok(())
        }
    );
    register!(
        engine,
        "compression_release",
        ["sim: Simulation", "options: Map"],
        "Turns on the seed report's compression-release buckling model (grids and triangle meshes): each step the
most compressed springs' particles are sent to where their springs regain their rest length
(three spheres' intersection) and held there. `#{strain: 0.01, hold_steps: 3, seed: 1}`: the
compression that triggers a release, how long a particle is held, the seed of the random
up/down choice on a flat cloth (one side of the cloth per step for all its ties).",
        |h: &mut SimHandle, m: Map| -> RResult<()> {
            use crate::cloth::buckling::compression_release::{CompressionRelease, ReleaseOptions};
            const KEYS: [&str; 3] = ["strain", "hold_steps", "seed"];
            if let Some(k) = m.keys().find(|k| !KEYS.contains(&k.as_str())) {
                return Err(rt_err(format!(
                    "compression_release: unknown option `{k}` (known: {})",
                    KEYS.join(", ")
                )));
            }
            let mut o = ReleaseOptions::default();
            if let Some(v) = m.get("strain") {
                o.strain = super::convert::non_negative(v, "strain")?;
            }
            if let Some(v) = m.get("hold_steps") {
                o.hold_steps = count(v, "hold_steps")?.max(1) as u32;
            }
            if let Some(v) = m.get("seed") {
                o.seed = v.as_int().map_err(|_| rt_err("`seed` must be an int"))? as u64;
            }
            let mut sim = h.get_mut()?;
            let cr = CompressionRelease::new(&sim.model, o);
            sim.add_stage(Box::new(cr));
            Ok(())
        }
    );

    getter!(
        engine,
        "time",
        ["sim: Simulation", "float"],
        "Simulated time (s).",
        |h: &mut SimHandle| -> RResult<f64> { Ok(h.get()?.state.time) }
    );
    getter!(
        engine,
        "steps",
        ["sim: Simulation", "int"],
        "Steps taken so far.",
        |h: &mut SimHandle| -> RResult<INT> { Ok(h.get()?.state.step as INT) }
    );
    getter!(
        engine,
        "vertex_count",
        ["sim: Simulation", "int"],
        "Number of particles.",
        |h: &mut SimHandle| -> RResult<INT> { Ok(h.get()?.particle_count() as INT) }
    );
    register!(engine, "set_param", ["sim: Simulation", "name: String", "value: ?"],
        "Changes one simulation setting (dt, integrator, gravity, cg_tolerance, cg_max_iterations,\nwarm_start, explicit_substeps, max_speed); the value is checked.",
        |h: &mut SimHandle, name: &str, v: Dynamic| -> RResult<()> {
            let mut s = h.get_mut()?;
            let p: SimulationParameters = update_field(&s.params, name, &v, "simulation")?;
            p.validate()?;
            s.params = p;
            Ok(())
        });
    register!(
        engine,
        "param",
        ["sim: Simulation", "name: String", "?"],
        "One simulation setting by name.",
        |h: &mut SimHandle, name: &str| -> RResult<Dynamic> {
            get_field(&h.get()?.params, name, "simulation")
        }
    );
    register!(
        engine,
        "params",
        ["sim: Simulation", "Map"],
        "All simulation settings as a map.",
        |h: &mut SimHandle| -> RResult<Dynamic> { Ok(to_map(&h.get()?.params)) }
    );
}
