//! Script bindings of the meshless Kirchhoff–Love shell: its benchmark cases (the work lives in
//! `crate::shell::benchmarks`), the KES rigs on it (`crate::kes::shell_rigs`) and the
//! sampling-independence study against the mass-spring cloth (`crate::scenes::sampling`) and
//! the vibrating strip (`crate::scenes::vibration`).

use rhai::{Array, Dynamic, Map, INT};

use super::convert::{rt_err, update_from_map, RResult};
use super::{function, modules::ApiBuilder};
use crate::kes::shell_rigs::{run_shell_rigs, ShellRigOptions};
use crate::shell::benchmarks::{
    heavy_cantilever, pinched_cylinder, pinched_hemisphere, scordelis_lo, square_plate,
    BenchmarkResult,
};
use crate::shell::ShellParameters;

/// Shell rig options from a script map (`points_along`, `tensile_steps`, `bending_steps`).
fn rig_options(options: &Map) -> RResult<ShellRigOptions> {
    let mut o = ShellRigOptions::default();
    for (k, v) in options {
        let n = v
            .as_int()
            .map_err(|_| rt_err(format!("shell::kes_rigs: option `{k}` must be an int")))?;
        let n = usize::try_from(n).map_err(|_| {
            rt_err(format!(
                "shell::kes_rigs: option `{k}` must be ≥ 0, got {n}"
            ))
        })?;
        match k.as_str() {
            "points_along" => o.points_along = n,
            "tensile_steps" => o.tensile_steps = n,
            "bending_steps" => o.bending_steps = n,
            other => {
                return Err(rt_err(format!(
                    "shell::kes_rigs: unknown option `{other}` (points_along, tensile_steps, bending_steps)"
                )))
            }
        }
    }
    o.validate().map_err(rt_err)?;
    Ok(o)
}

fn result_map(r: &BenchmarkResult) -> Map {
    let mut m = Map::new();
    m.insert("name".into(), Dynamic::from(r.name.clone()));
    m.insert("points".into(), Dynamic::from_int(r.points as INT));
    m.insert("value".into(), Dynamic::from_float(r.value));
    m.insert("reference".into(), Dynamic::from_float(r.reference));
    m.insert("error".into(), Dynamic::from_float(r.error));
    m.insert("seconds".into(), Dynamic::from_float(r.seconds));
    m
}

/// One run of the sampling study (`shell::sampling_run`).
fn sampling_run(f: &super::kes::KesFabric, scene: &str, model: &str, n: INT) -> RResult<Map> {
    use crate::scenes::sampling::{
        linear_fabric, mass_spring_run, shell_run, study_shell_parameters, Scene,
    };
    let scene = match scene {
        "drape" => Scene::Drape,
        "hang" => Scene::Hang,
        "hang_clips" => Scene::HangClips,
        other => {
            return Err(rt_err(format!(
                "shell::sampling_run: scene must be \"drape\", \"hang\" or \"hang_clips\", got {other:?}"
            )))
        }
    };
    let n = usize::try_from(n).map_err(|_| {
        rt_err(format!(
            "shell::sampling_run: `n` (points per side) must be odd and lie in [5, 201], got {n}"
        ))
    })?;
    let (params, law) = crate::kes::lab::measured_fabric(&f.0).map_err(rt_err)?;
    let fabric = linear_fabric(std::sync::Arc::new(law), params.density).map_err(rt_err)?;
    let row = match model {
        "shell" => shell_run(
            scene,
            n,
            &fabric,
            study_shell_parameters(),
            &Default::default(),
        ),
        "mass-spring" => mass_spring_run(scene, n, &fabric, 60.0),
        other => Err(format!(
            "shell::sampling_run: model must be \"shell\" or \"mass-spring\", got {other:?}"
        )),
    }
    .map_err(rt_err)?;
    let mut m = Map::new();
    m.insert("model".into(), Dynamic::from(row.model.to_string()));
    m.insert("scene".into(), Dynamic::from(row.scene.name().to_string()));
    m.insert("per_side".into(), Dynamic::from_int(row.per_side as INT));
    m.insert("spacing".into(), Dynamic::from_float(row.spacing));
    m.insert("value".into(), Dynamic::from_float(row.value));
    m.insert("steps".into(), Dynamic::from_int(row.steps as INT));
    m.insert("seconds".into(), Dynamic::from_float(row.seconds));
    m.insert("settled".into(), Dynamic::from_bool(row.settled));
    Ok(m)
}

/// One run of the vibrating strip (`shell::vibration`).
fn vibration(f: &super::kes::KesFabric, model: &str, along: INT, options: &Map) -> RResult<Map> {
    use crate::scenes::sampling::linear_fabric;
    use crate::scenes::vibration::{mass_spring_vibration, shell_vibration};
    let (mut length, mut steps) = (0.2, 100usize);
    for (k, v) in options {
        match k.as_str() {
            "length" => {
                length = v
                    .as_float()
                    .map_err(|_| rt_err("shell::vibration: option `length` must be a float (m)"))?
            }
            "steps_per_period" => {
                steps = v
                    .as_int()
                    .ok()
                    .and_then(|n| usize::try_from(n).ok())
                    .ok_or_else(|| {
                        rt_err("shell::vibration: option `steps_per_period` must be an int ≥ 0")
                    })?
            }
            other => {
                return Err(rt_err(format!(
                    "shell::vibration: unknown option `{other}` (length, steps_per_period)"
                )))
            }
        }
    }
    let along = usize::try_from(along).map_err(|_| {
        rt_err(format!(
            "shell::vibration: `along` must lie in [5, 201], got {along}"
        ))
    })?;
    let (params, law) = crate::kes::lab::measured_fabric(&f.0).map_err(rt_err)?;
    let fabric = linear_fabric(std::sync::Arc::new(law), params.density).map_err(rt_err)?;
    let row = match model {
        "shell" => shell_vibration(&fabric, length, along, steps),
        "mass-spring" => mass_spring_vibration(&fabric, length, along, steps),
        other => Err(format!(
            "shell::vibration: model must be \"shell\" or \"mass-spring\", got {other:?}"
        )),
    }
    .map_err(rt_err)?;
    let mut m = Map::new();
    m.insert("model".into(), Dynamic::from(row.model.to_string()));
    m.insert("along".into(), Dynamic::from_int(row.along as INT));
    m.insert("period".into(), Dynamic::from_float(row.period));
    m.insert("reference".into(), Dynamic::from_float(row.reference));
    m.insert("error_pct".into(), Dynamic::from_float(row.error_pct));
    m.insert(
        "amplitude_kept".into(),
        Dynamic::from_float(row.amplitude_kept),
    );
    m.insert("steps".into(), Dynamic::from_int(row.steps as INT));
    m.insert(
        "iterations".into(),
        Dynamic::from_int(row.iterations as INT),
    );
    m.insert("seconds".into(), Dynamic::from_float(row.seconds));
    Ok(m)
}

/// Registers the shell functions.
pub fn register(engine: &mut ApiBuilder) {
    function!(engine, "shell::vibration", ["fabric: KesFabric", "model: String", "along: int", "options: Map", "Map"],
        "The vibrating strip (docs/shell.md): a strip of the fabric's linear law (length 0.2 m,\nwidth a quarter of it, warp along it), clamped at one end, no gravity, released from its\nfirst mode shape (tip amplitude 1 % of the length) and run for three analytic periods;\n`model` \"shell\" (meshless shell, Newmark, consistent mass) or \"mass-spring\" (the cloth's\nimplicit solver), `along` points (5 to 201) along the strip. Options: `length` (m, 0.2),\n`steps_per_period` (100). Returns #{model, along, period (s, from the tip's zero\ncrossings), reference (2π/ω₁ of Euler–Bernoulli), error_pct, amplitude_kept (last period's\nlargest tip excursion over the first), steps, iterations (Newton or CG, in all), seconds}.",
        |f: super::kes::KesFabric, model: &str, along: INT, options: Map| -> RResult<Map> {
            vibration(&f, model, along, &options)
        });
    function!(engine, "shell::sampling_run", ["fabric: KesFabric", "scene: String", "model: String", "n: int", "Map"],
        "One run of the sampling-independence study (docs/shell.md): a 1 m square of the fabric's\nlinear law (initial slopes of its measured law) on `n` × `n` points (odd, 5 to 201), `scene`\n\"drape\" (over a 0.3 m sphere, centre held: the drape coefficient), \"hang\" (from the\ntop corners: the sag of the top edge's middle, m) or \"hang_clips\" (held by 5 cm square\nclips at the top corners), `model` \"shell\" (relaxed to\nequilibrium) or \"mass-spring\" (run until still). Returns #{model, scene, per_side,\nspacing (m), value, steps (Newton iterations or time steps), seconds, settled (false: the\nmass-spring cloth still moved after 60 s; its last value)}.",
        |f: super::kes::KesFabric, scene: &str, model: &str, n: INT| -> RResult<Map> {
            sampling_run(&f, scene, model, n)
        });
    function!(engine, "shell::kes_rigs", ["fabric: KesFabric", "options: Map", "Map"],
        "Runs the KES-FB1 tensile and KES-FB2 pure-bending rigs on the meshless shell with the\nfabric's measured law (elastic backbone), for every measured tensile and bending curve the\nfabric has, and compares each loading path with the measured loading branch. Options:\n`points_along` (11), `tensile_steps` (20), `bending_steps` (15). Returns #{name,\nworst_rms_pct, rows: [#{test, rms_pct (% of the measured range), max_x (strain or 1/m)}]}.",
        |f: super::kes::KesFabric, options: Map| -> RResult<Map> {
            let r = run_shell_rigs(&f.0, &rig_options(&options)?).map_err(rt_err)?;
            let rows: Array = r
                .rows
                .iter()
                .map(|row| {
                    let mut m = Map::new();
                    m.insert("test".into(), Dynamic::from(row.test.clone()));
                    m.insert("rms_pct".into(), Dynamic::from_float(row.rms_pct));
                    m.insert("max_x".into(), Dynamic::from_float(row.max_x));
                    Dynamic::from_map(m)
                })
                .collect();
            let mut m = Map::new();
            m.insert("name".into(), Dynamic::from(r.name.clone()));
            m.insert("worst_rms_pct".into(), Dynamic::from_float(r.worst()));
            m.insert("rows".into(), Dynamic::from_array(rows));
            Ok(m)
        });
    function!(engine, "shell::benchmark", ["case: String", "points: int", "options: Map", "Map"],
        "Runs one shell benchmark with `points` sample points along its longer side and the\nshell parameters `options` (fields of ShellParameters: basis, support_factor,\ncell_factor, gauss, penalty, ...; #{} for the defaults). `case`:\n\"plate_simply_supported\", \"plate_clamped\" (centre deflection / (q a⁴/D)), \"cantilever\"\n(tip angle, degrees, worst of q L³/B = 1 … 20), \"scordelis_lo\", \"pinched_cylinder\",\n\"pinched_hemisphere\". Returns #{name, points, value, reference, error (percent; degrees\nfor the cantilever), seconds, rows (cantilever: [q L³/B, angle, reference] per row)}.",
        |case: &str, points: INT, options: Map| -> RResult<Map> {
            if !(3..=200).contains(&points) {
                return Err(rt_err(format!("shell::benchmark: `points` must lie in [3, 200], got {points}")));
            }
            let n = points as usize;
            let params: ShellParameters = update_from_map(&ShellParameters::default(), &options, "shell")?;
            let mut rows = Array::new();
            let r = match case {
                "plate_simply_supported" => square_plate(n, false, params),
                "plate_clamped" => square_plate(n, true, params),
                "scordelis_lo" => scordelis_lo(n, params),
                "pinched_cylinder" => pinched_cylinder(n, params),
                "pinched_hemisphere" => pinched_hemisphere(n, params),
                "cantilever" => heavy_cantilever(n, params).map(|(table, r)| {
                    rows = table
                        .iter()
                        .map(|row| Dynamic::from_array(row.iter().map(|v| Dynamic::from_float(*v)).collect()))
                        .collect();
                    r
                }),
                other => return Err(rt_err(format!(
                    "shell::benchmark: unknown case `{other}` (plate_simply_supported, plate_clamped, cantilever, scordelis_lo, pinched_cylinder, pinched_hemisphere)"
                ))),
            }
            .map_err(rt_err)?;
            let mut m = result_map(&r);
            m.insert("rows".into(), Dynamic::from_array(rows));
            Ok(m)
        });
}
