//! Issue 48, cloth, garment, body, simulation and bench: the inputs that crashed (stack overflow,
//! "capacity overflow", aborted allocations), hung or passed silently are each a clear error
//! naming the parameter or file and the limit. The case scripts are `tests/hostile_cloth/*.rhai`,
//! run here through the script engine; `tests/hostile_cloth/run_cases.sh` runs the same scripts
//! with the release binary under a 4 GB address-space limit (see docs/limits.md).
#![cfg(feature = "scripting")]

use std::path::{Path, PathBuf};

use emilion::body::Motion;
use emilion::cloth::{ClothModel, FabricParameters, Simulation, SimulationParameters};
use emilion::garment::{mesh_pattern, read_garment, MeshParameters, SvgOptions};
use emilion::script::build_engine;
use rhai::Dynamic;

/// A path as a script string.
fn text(p: &Path) -> Dynamic {
    Dynamic::from(p.display().to_string())
}

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn bad_pattern(name: &str) -> PathBuf {
    root().join("tests/data/patterns_bad").join(name)
}

fn data() -> Option<PathBuf> {
    let d = emilion::geometry::files::data_dir();
    if d.join("bodies/makehuman").is_dir() && d.join("motion/cmu_bvh").is_dir() {
        Some(d)
    } else {
        eprintln!("skipped: the shared data folder {} is absent", d.display());
        None
    }
}

fn temp_dir(name: &str) -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("hostile_cloth")
        .join(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Runs `tests/hostile_cloth/CASE.rhai` with the variables `vars`; returns its error, failing
/// the test if it succeeds or takes more than 5 s to fail.
fn case_error(case: &str, vars: &[(&str, Dynamic)]) -> String {
    let path = root()
        .join("tests/hostile_cloth")
        .join(format!("{case}.rhai"));
    let source = std::fs::read_to_string(&path).unwrap();
    let mut scope = rhai::Scope::new();
    for (k, v) in vars {
        scope.push_constant_dynamic(k.to_string(), v.clone());
    }
    let t0 = std::time::Instant::now();
    match build_engine().run_with_scope(&mut scope, &source) {
        Ok(()) => panic!("{case}.rhai succeeded; it must fail"),
        Err(e) => {
            let took = t0.elapsed().as_secs_f64();
            assert!(took < 5.0, "{case}.rhai took {took:.1} s to fail");
            e.to_string()
        }
    }
}

fn assert_has(message: &str, words: &[&str]) {
    for w in words {
        assert!(message.contains(w), "`{w}` missing from: {message}");
    }
}

fn small_sim(params: SimulationParameters) -> Result<Simulation, emilion::cloth::ClothError> {
    let model = ClothModel::grid(1.0, 1.0, 4, 4, FabricParameters::default())?;
    Simulation::new(model, params)
}

// ---- simulation runs: step counts, dt, substeps --------------------------------------------

#[test]
fn sim_run_of_1e9_seconds_is_refused_before_reserving_16_tb() {
    // 1e9 s at dt = 1/120 s: 1.2e11 steps
    let e = case_error("sim_run_1e9", &[]);
    assert_has(&e, &["max_steps", "1.2e11", "100000000"]);
}

#[test]
fn sim_run_of_1e300_seconds_is_not_a_capacity_overflow() {
    let e = case_error("sim_run_1e300", &[]);
    assert_has(&e, &["max_steps", "1e300 s"]);
}

#[test]
fn run_steps_of_i64_max_is_not_a_capacity_overflow() {
    let e = case_error("run_steps_int_max", &[]);
    assert_has(&e, &["max_steps", "9223372036854775807"]);
    // the same through Rust, with nothing stepped
    let mut sim = small_sim(SimulationParameters::default()).unwrap();
    let e = sim.run_steps(u64::MAX, |_, _| Ok(())).unwrap_err();
    assert_has(&e.to_string(), &["max_steps", "18446744073709551615"]);
    assert_eq!(sim.state.step, 0);
    assert!(sim.stats.capacity() < 1 << 20);
}

#[test]
fn dt_of_1e_300_is_refused_by_name() {
    let e = case_error("dt_tiny", &[]);
    assert_has(&e, &["`dt`", "1e-300", "[1e-7, 1]"]);
}

#[test]
fn dt_of_1e308_is_refused_instead_of_running_zero_steps() {
    let e = case_error("dt_huge", &[]);
    assert_has(&e, &["`dt`", "1e308", "[1e-7, 1]"]);
}

#[test]
fn dt_range_ends_are_accepted() {
    for dt in [emilion::cloth::MIN_DT, 1.0 / 120.0, emilion::cloth::MAX_DT] {
        let params = SimulationParameters {
            dt,
            ..Default::default()
        };
        small_sim(params).unwrap_or_else(|e| panic!("dt {dt}: {e}"));
    }
    for dt in [0.99e-7, 1.01, f64::NAN, -1.0] {
        let params = SimulationParameters {
            dt,
            ..Default::default()
        };
        assert!(small_sim(params).is_err(), "dt {dt} accepted");
    }
}

#[test]
fn run_with_a_callback_for_1e9_seconds_does_not_hang() {
    let e = case_error("run_callback_1e9", &[]);
    assert_has(&e, &["max_steps", "1.2e11"]);
}

#[test]
fn explicit_substeps_of_1e9_do_not_hang() {
    let e = case_error("explicit_substeps_1e9", &[]);
    assert_has(&e, &["explicit_substeps", "1000000000", "1..=10000"]);
    let params = SimulationParameters {
        integrator: emilion::cloth::Integrator::Explicit,
        explicit_substeps: emilion::cloth::MAX_EXPLICIT_SUBSTEPS,
        ..Default::default()
    };
    small_sim(params).unwrap();
}

#[test]
fn run_frames_at_an_fps_of_1e_300_is_refused_before_the_first_frame() {
    let e = case_error("run_frames_fps_tiny", &[]);
    assert_has(&e, &["max_steps", "2e300 s"]);
}

#[test]
fn release_of_an_index_past_the_cloth_is_an_error() {
    let e = case_error("release_out_of_range", &[]);
    assert_has(&e, &["particle index 1000", "cloth has 16"]);
}

// ---- sizes: particle counts checked before allocating ---------------------------------------

#[test]
fn cloth_grid_of_1e6_by_1e6_is_refused_before_allocating() {
    let e = case_error("cloth_grid_1e6", &[]);
    assert_has(&e, &["nx × ny", "is 1e12,", "max_particles"]);
}

#[test]
fn cloth_cone_of_1e5_by_1e5_is_refused_before_allocating() {
    let e = case_error("cloth_cone_1e5", &[]);
    assert_has(&e, &["n_around × n_down", "is 1e10,", "max_particles"]);
}

#[test]
fn cloth_patch_of_1000_m_at_1_mm_does_not_hang() {
    // 10⁶ m² / (10⁻⁶ m² · √3/2) ≈ 1.15e12 vertices; the piece's size is refused first
    let e = case_error("cloth_patch_1000m", &[]);
    assert_has(
        &e,
        &[
            "spans 1000.000 m × 1000.000 m",
            "largest accepted piece size of 10 m",
        ],
    );
}

#[test]
fn cloth_patch_strip_of_100_km_within_the_particle_limit_is_refused_before_meshing() {
    let e = case_error("cloth_patch_100km_strip", &[]);
    assert_has(
        &e,
        &[
            "rectangle 1.284 m × 100000 m",
            "not a finite number within ±1000 m",
        ],
    );
}

#[test]
fn mesh_at_edge_length_1e_5_is_refused_before_meshing() {
    let pattern = read_garment(root().join("scripts/patterns/aaron.garment.json")).unwrap();
    let params = MeshParameters {
        edge_length: 1e-5,
        ..Default::default()
    };
    let e = mesh_pattern(&pattern.expanded().unwrap(), &params).unwrap_err();
    assert_has(
        &e.to_string(),
        &["aaron", "estimated vertex count", "max_particles"],
    );
    // the estimate at the default edge length is close to the count meshed (within 20 %)
    let expanded = pattern.expanded().unwrap();
    let mesh = mesh_pattern(&expanded, &MeshParameters::default()).unwrap();
    let h = MeshParameters::default().edge_length;
    let estimate: f64 = expanded
        .pieces
        .iter()
        .map(|p| {
            let perimeter: f64 = (0..p.outline.corners.len())
                .map(|i| p.outline.segment_length(i))
                .sum();
            p.outline.area() / (h * h * 3f64.sqrt() / 2.0) + perimeter / h
        })
        .sum();
    let n = mesh.mesh.positions.len() as f64;
    assert!(
        (estimate / n - 1.0).abs() < 0.2,
        "estimate {estimate:.0} vs {n} vertices"
    );
}

#[test]
fn dress_at_edge_length_1e_5_is_refused_before_meshing() {
    if data().is_none() {
        return;
    }
    let input = root().join("scripts/patterns/aaron.garment.json");
    let e = case_error("edge_length_1e5", &[("input", text(&input))]);
    assert_has(&e, &["aaron", "estimated vertex count", "max_particles"]);
}

#[test]
fn bench_of_100000_by_100000_is_refused_before_building() {
    let e = emilion::bench::bench_scene("hang", 100_000, 1, 1).unwrap_err();
    assert_has(&e.to_string(), &["bench size", "is 1e10,", "max_particles"]);
    let e = emilion::bench::bench_scene("hang", 8, u32::MAX, 1).unwrap_err();
    assert_has(&e.to_string(), &["bench frames", "max_frames"]);
}

// ---- patterns: ranges of coordinates and sizes, SVG nesting and viewBox ----------------------

#[test]
fn pattern_piece_of_100_m_is_refused_by_validation() {
    let input = bad_pattern("piece_100m.json");
    let e = case_error("pattern_piece", &[("input", text(&input))]);
    assert_has(&e, &["piece_100m.json", "'sail'", "100.000 m", "10 m"]);
}

#[test]
fn pattern_coordinates_of_1e308_are_refused_by_validation() {
    let input = bad_pattern("coordinates_1e308.json");
    let e = case_error("pattern_piece", &[("input", text(&input))]);
    assert_has(&e, &["coordinates_1e308.json", "corner 'b'", "1000 m"]);
}

/// An SVG of `depth` nested `<g>` around one 300 × 600 mm piece.
fn nested_svg(depth: usize) -> String {
    format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"300mm\" height=\"600mm\" viewBox=\"0 0 300 600\">\n{}<g id=\"front\"><path d=\"M 0 0 L 300 0 L 300 600 L 0 600 z\"/></g>{}\n</svg>\n",
        "<g>".repeat(depth),
        "</g>".repeat(depth)
    )
}

#[test]
fn nested_svg_groups_do_not_overflow_the_stack() {
    let dir = temp_dir("nested_svg");
    let path = dir.join("nested_10000.svg");
    std::fs::write(&path, nested_svg(10_000)).unwrap();
    let e = case_error("svg_pattern", &[("input", text(&path))]);
    assert_has(&e, &["nested_10000.svg:2:", "max_nesting = 256"]);
    // within the limit, the piece is found through its 200 groups
    let text = nested_svg(200);
    let p = emilion::garment::formats::svg::parse_pattern_svg(
        &text,
        Path::new("nested_200.svg"),
        &SvgOptions::default(),
    )
    .unwrap();
    assert_eq!(p.pieces.len(), 1);
    assert!((p.pieces[0].outline.area() - 0.3 * 0.6).abs() < 1e-9);
}

#[test]
fn svg_viewbox_of_zero_size_is_an_error() {
    let input = bad_pattern("viewbox_zero.svg");
    let e = case_error("svg_pattern", &[("input", text(&input))]);
    assert_has(&e, &["viewbox_zero.svg:1:", "viewBox=\"0 0 0 0\""]);
}

// ---- motion: frame times and frame counts ----------------------------------------------------

#[test]
fn make_sequence_at_1e9_fps_is_refused() {
    let out = temp_dir("sequence_fps");
    let e = case_error(
        "make_sequence_fps",
        &[
            ("input", Dynamic::from("no_such.bvh".to_string())),
            ("out", text(&out)),
            ("fps", Dynamic::from_float(1e9)),
        ],
    );
    assert_has(&e, &["fps", "[0.1, 10000]", "1000000000"]);
}

#[test]
fn bvh_frame_time_of_1e9_is_refused() {
    let bvh = "HIERARCHY ROOT a { OFFSET 0 0 0 CHANNELS 1 Xrotation } MOTION\nFrames: 2\nFrame Time: 1e9\n0\n0\n";
    let e = Motion::parse_bvh(bvh, "slow.bvh").unwrap_err();
    assert_has(
        &e.to_string(),
        &["slow.bvh:3", "1000000000 s", "[0.0001, 10]"],
    );
    let ok = bvh.replace("1e9", "10");
    assert_eq!(Motion::parse_bvh(&ok, "ok.bvh").unwrap().frame_time(), 10.0);
    // frames without channels are not counted one by one up to 10^18
    let many = "HIERARCHY ROOT a { } MOTION Frames: 1000000000000000000 Frame Time: 0.1";
    let e = Motion::parse_bvh(many, "many.bvh").unwrap_err();
    assert_has(&e.to_string(), &["many.bvh:1", "max_frames"]);
    // and through make_sequence, with a real clip whose frame time was edited
    let Some(d) = data() else { return };
    let clip = std::fs::read_to_string(d.join("motion/cmu_bvh/002_01.bvh")).unwrap();
    let edited: String = clip
        .lines()
        .map(|l| {
            if l.starts_with("Frame Time:") {
                "Frame Time: 1e9".to_string()
            } else {
                l.to_string()
            }
        })
        .collect::<Vec<_>>()
        .join("\n");
    let dir = temp_dir("bvh_frame_time");
    let path = dir.join("frame_time_1e9.bvh");
    std::fs::write(&path, edited).unwrap();
    let out = dir.join("seq");
    let e = case_error(
        "make_sequence_fps",
        &[("input", text(&path)), ("out", text(&out))],
    );
    assert_has(&e, &["frame_time_1e9.bvh:673", "frame time"]);
}
