//! Random scripts for the `script` target: a small cloth and simulation, then 1 to 6 calls of
//! script functions (cloth builders, fabric and simulation option maps, constraints, stepping,
//! render options, cloth transforms) with random numbers, strings, arrays and maps. Values are
//! mostly ordinary (a run of a few steps) and sometimes extreme (0, negative, NaN, 1e300,
//! i64::MAX, unknown keys, wrong types); sizes, counts and durations are extreme only one time
//! in 32, since their blow-ups are the known cases of issue 48. Each call sits in its own
//! `try`, so an error (the expected answer to a bad value) does not end the script. Files are
//! written under `out`.

use emilion::geometry::random::SplitMix64;

const FABRIC_KEYS: &[&str] = &[
    "density",
    "stretch_warp",
    "stretch_weft",
    "shear",
    "bend_warp",
    "bend_weft",
    "stretch_damping",
    "bend_damping",
    "air_drag",
];
const SIM_KEYS: &[&str] = &[
    "dt",
    "integrator",
    "gravity",
    "cg_tolerance",
    "cg_max_iterations",
    "warm_start",
    "explicit_substeps",
    "max_speed",
    "preconditioner",
];
const RENDER_KEYS: &[&str] = &["width", "height", "fov", "eye", "target", "up"];
const ATTACH_KEYS: &[&str] = &["keyframes", "amplitude", "frequency", "velocity"];
const RELEASE_KEYS: &[&str] = &["strain", "hold_steps", "seed"];
const STRINGS: &[&str] = &[
    "",
    "top",
    "bottom",
    "left",
    "right",
    "implicit",
    "explicit",
    "jacobi",
    "none",
    "dt",
    "integrator",
    "gravity",
    "x",
    "\\u{0}",
    "ünïcode",
    "../../x",
];

/// A random script for case `index` of `seed`.
pub fn program(seed: u64, index: u64) -> Vec<u8> {
    let mut rng = SplitMix64::new(seed ^ index.wrapping_mul(0xD1B5_4A32_D192_ED03));
    rng.next_u64();
    let mut s = String::from(
        "let c = cloth_grid(0.2, 0.2, 4, 4, fabric());\nlet s = simulation(c, #{ dt: 0.01 });\n",
    );
    let calls = 1 + rng.below(6);
    for _ in 0..calls {
        let call = call(&mut rng);
        s.push_str(&format!("try {{ {call}; }} catch (e) {{ }}\n"));
    }
    s.into_bytes()
}

/// A float literal: mostly ordinary, sometimes extreme.
fn num(rng: &mut SplitMix64) -> String {
    if rng.below(8) == 0 {
        const X: &[&str] = &[
            "0.0",
            "-0.0",
            "-1.0",
            "1e-300",
            "-1e-300",
            "1e300",
            "-1e300",
            "1e9",
            "1e6",
            "(0.0/0.0)",
            "(1.0/0.0)",
            "(-1.0/0.0)",
            "1e-9",
            "1e5",
            "0",
            "-1",
            "\"1\"",
            "()",
        ];
        return X[rng.below(X.len())].to_string();
    }
    format!("{:.3}", rng.range(-0.5, 2.0))
}

/// An int literal: mostly small, sometimes extreme.
fn int(rng: &mut SplitMix64) -> String {
    if rng.below(8) == 0 {
        const X: &[&str] = &[
            "0",
            "-1",
            "1",
            "1000",
            "100000",
            "1000000000",
            "9223372036854775807",
            "-9223372036854775808",
            "2.5",
            "\"3\"",
        ];
        return X[rng.below(X.len())].to_string();
    }
    format!("{}", rng.below(12))
}

fn string(rng: &mut SplitMix64) -> String {
    format!("\"{}\"", STRINGS[rng.below(STRINGS.len())])
}

fn array(rng: &mut SplitMix64) -> String {
    let n = match rng.below(6) {
        0 => 0,
        1 => 3,
        _ => 1 + rng.below(5),
    };
    let items: Vec<String> = (0..n)
        .map(|_| match rng.below(5) {
            0 => num(rng),
            1 if rng.below(4) == 0 => array(rng),
            _ => int(rng),
        })
        .collect();
    format!("[{}]", items.join(", "))
}

fn vec3(rng: &mut SplitMix64) -> String {
    if rng.below(8) == 0 {
        return array(rng);
    }
    format!("[{}, {}, {}]", num(rng), num(rng), num(rng))
}

/// Any value: number, int, string, bool, array.
fn value(rng: &mut SplitMix64) -> String {
    match rng.below(6) {
        0 => int(rng),
        1 => string(rng),
        2 => if rng.bit() { "true" } else { "false" }.into(),
        3 => array(rng),
        _ => num(rng),
    }
}

/// A map with some of `keys` (and, sometimes, an unknown key), values of the likely type.
fn map(rng: &mut SplitMix64, keys: &[&str]) -> String {
    let n = rng.below(4);
    let mut fields = Vec::new();
    for _ in 0..n {
        let k = if rng.below(12) == 0 {
            "bogus"
        } else {
            keys[rng.below(keys.len())]
        };
        let v = match k {
            "integrator" => ["\"implicit\"", "\"explicit\"", "\"x\""][rng.below(3)].into(),
            "preconditioner" => ["\"jacobi\"", "\"none\"", "\"x\""][rng.below(3)].into(),
            "gravity" | "eye" | "target" | "up" | "velocity" | "amplitude" => vec3(rng),
            "width" | "height" | "cg_max_iterations" | "explicit_substeps" | "hold_steps"
            | "seed" => int(rng),
            "keyframes" => format!(
                "[[0.0, 0.0, 0.0, 0.0], [{}, {}, 0.0, 0.0]]",
                num(rng),
                num(rng)
            ),
            "warm_start" => "true".into(),
            _ if rng.below(6) == 0 => value(rng),
            _ => num(rng),
        };
        fields.push(format!("{k}: {v}"));
    }
    format!("#{{ {} }}", fields.join(", "))
}

/// A size (cloth dimensions, particle counts): ordinary, or extreme one time in 32 (the known
/// size blow-ups of issue 48 would otherwise take most of the run).
fn size(rng: &mut SplitMix64) -> String {
    if rng.below(32) == 0 {
        return num(rng);
    }
    format!("{:.3}", rng.range(0.05, 1.5))
}

fn count(rng: &mut SplitMix64) -> String {
    if rng.below(32) == 0 {
        return int(rng);
    }
    format!("{}", rng.below(10))
}

fn call(rng: &mut SplitMix64) -> String {
    match rng.below(22) {
        0 => format!("fabric({})", map(rng, FABRIC_KEYS)),
        1 => format!(
            "cloth_grid({}, {}, {}, {}, fabric())",
            size(rng),
            size(rng),
            count(rng),
            count(rng)
        ),
        2 => format!(
            "cloth_cone({}, {}, {}, {}, {}, fabric(), {}, {})",
            size(rng),
            size(rng),
            size(rng),
            count(rng),
            count(rng),
            vec3(rng),
            num(rng)
        ),
        3 => {
            // a patch with about 10 to 400 triangles, or an extreme one
            let edge = if rng.below(32) == 0 {
                num(rng)
            } else {
                format!("{:.3}", rng.range(0.05, 0.3))
            };
            format!(
                "cloth_patch({}, {}, {edge}, fabric())",
                size(rng),
                size(rng)
            )
        }
        4 => format!(
            "simulation(cloth_grid(0.2, 0.2, 4, 4, fabric()), {})",
            map(rng, SIM_KEYS)
        ),
        5 => {
            let k = SIM_KEYS[rng.below(SIM_KEYS.len())];
            format!("s.set_param(\"{k}\", {})", value(rng))
        }
        6 => format!("s.run_steps({})", small_int(rng)),
        7 => format!("s.run({})", small_num(rng)),
        8 => format!("s.pin({})", array(rng)),
        9 => format!("s.release({}); s.run_steps(2)", array(rng)),
        10 => format!("s.grid_index({}, {})", int(rng), int(rng)),
        11 => format!("s.grid_edge({})", string(rng)),
        12 => format!("s.pin_corners({})", string(rng)),
        13 => format!(
            "s.attach({}, {}); s.run_steps(2)",
            array(rng),
            map(rng, ATTACH_KEYS)
        ),
        14 => format!("s.add_floor({}, {}); s.run_steps(2)", num(rng), num(rng)),
        15 => format!("s.render(out + \"/r.png\", {})", render_map(rng)),
        16 => format!("c.rotated({}, {})", vec3(rng), num(rng)),
        17 => format!(
            "simulation(c.perturbed({}, {})).run_steps(2)",
            num(rng),
            int(rng)
        ),
        18 => format!(
            "simulation(c.prestrained({}, {})).run_steps(2)",
            num(rng),
            num(rng)
        ),
        19 => format!("c.translated({})", vec3(rng)),
        20 => format!(
            "s.compression_release({}); s.run_steps(2)",
            map(rng, RELEASE_KEYS)
        ),
        _ => format!(
            "s.run_frames({}, {}, |t| t.frame)",
            small_int(rng),
            num(rng)
        ),
    }
}

/// A duration that keeps a run short, or (rarely) an extreme one.
fn small_num(rng: &mut SplitMix64) -> String {
    if rng.below(32) == 0 {
        return num(rng);
    }
    format!("{:.3}", rng.range(0.0, 0.1))
}

fn small_int(rng: &mut SplitMix64) -> String {
    if rng.below(32) == 0 {
        return int(rng);
    }
    format!("{}", rng.below(4))
}

/// Render options: a small picture, or extreme sizes and camera vectors.
fn render_map(rng: &mut SplitMix64) -> String {
    if rng.below(3) == 0 {
        return map(rng, RENDER_KEYS);
    }
    let (w, h) = (1 + rng.below(64), 1 + rng.below(64));
    format!("#{{ width: {w}, height: {h}, fov: {} }}", num(rng))
}
