//! The fuzz corpus, replayed: every input under `tests/fuzz/<reader>/` (the seeds) and
//! `tests/fuzz/<reader>/crashes/` (what the harness found, since fixed) goes through its reader
//! (`examples/fuzz/targets.rs`) without a panic and within a time bound. An input whose fix is
//! still to come goes under `tests/fuzz/<reader>/known/`, replayed only with `--ignored` (none
//! today). See docs/fuzzing.md.

#[allow(dead_code)] // the harness's mutation settings are not used here
#[path = "../examples/fuzz/targets.rs"]
mod targets;

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// The most one input may take (the harness's hang limit).
const PER_INPUT: Duration = Duration::from_secs(10);
/// The most the whole replay may take.
const TOTAL: Duration = Duration::from_secs(60);

fn corpus() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fuzz")
}

/// The inputs in `dir` (not notes: `*.why`, `*.md`, dot files), sorted.
fn inputs(dir: &Path) -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(dir)
        .map(|d| d.flatten().map(|e| e.path()).collect())
        .unwrap_or_default();
    files.retain(|p| {
        let name = p.file_name().and_then(|n| n.to_str()).unwrap_or("");
        p.is_file() && !(name.starts_with('.') || name.ends_with(".why") || name.ends_with(".md"))
    });
    files.sort();
    files
}

/// Replays the inputs of `sub` ("" for the seeds) of every reader; returns how many.
fn replay(sub: &str) -> usize {
    let start = Instant::now();
    let mut failures = Vec::new();
    let mut count = 0;
    for t in targets::all() {
        let dir = corpus().join(t.name).join(sub);
        for file in inputs(&dir) {
            let data = std::fs::read(&file).expect("reading a corpus file");
            let t0 = Instant::now();
            let r = catch_unwind(AssertUnwindSafe(|| (t.run)(&data)));
            let took = t0.elapsed();
            count += 1;
            if r.is_err() {
                failures.push(format!("{}: panicked", file.display()));
            } else if took > PER_INPUT {
                failures.push(format!("{}: took {took:?}", file.display()));
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    assert!(
        start.elapsed() < TOTAL,
        "the replay took {:?}",
        start.elapsed()
    );
    count
}

#[test]
fn every_seed_and_fixed_crash_reads_without_a_panic() {
    let seeds = replay("");
    let crashes = replay("crashes");
    assert!(seeds >= 20, "only {seeds} seed inputs");
    eprintln!("replayed {seeds} seeds and {crashes} fixed crashes");
}

#[test]
fn every_reader_has_a_seed_corpus() {
    for t in targets::all() {
        assert!(
            !inputs(&corpus().join(t.name)).is_empty(),
            "tests/fuzz/{} has no seed input",
            t.name
        );
    }
}

#[test]
fn seeds_are_read_as_their_readers_expect() {
    // Hand-written valid files read without an error (ground truth: they are well formed).
    for (reader, file) in [
        ("obj", "square_uv.obj"),
        ("svg", "two_pieces.svg"),
        ("dxf", "one_piece.dxf"),
        ("pattern", "two_pieces_seam.json"),
        ("fabric", "params_only.json"),
        ("bvh", "two_joints.bvh"),
        ("c3d", "two_points.c3d"),
        ("pts", "sixty_eight.pts"),
        ("facade", "small_house.cga"),
        ("image", "rgb.png"),
        ("script", "grid_run.rhai"),
    ] {
        let t = targets::by_name(reader).expect("a target");
        let data = std::fs::read(corpus().join(reader).join(file)).expect("a seed");
        if let Err(e) = (t.run)(&data) {
            panic!("{reader}/{file}: {e}");
        }
    }
}

#[test]
#[ignore = "known crashes whose fixes are still to come: run with --ignored"]
fn known_crashes_read_without_a_panic() {
    replay("known");
}
