//! The `emilion bench` benchmark: the peer scenes (hanging cloth, drape on a sphere, hanging
//! cloth with self-collision) at several resolutions, one JSON line per case with the median
//! time per substep over several runs after a warm-up.

use std::time::Instant;

use serde::Serialize;

use crate::cloth::ClothError;
use crate::contact::SimulationContact;
use crate::limits;
use crate::scenes;

fn limit_err(e: limits::LimitError) -> ClothError {
    ClothError::Parameter(e.to_string())
}

/// One benchmark case's result.
#[derive(Debug, Clone, Serialize)]
pub struct BenchResult {
    /// Scene name.
    pub scene: String,
    /// Particles per side.
    pub n: usize,
    /// Particle count.
    pub vertices: usize,
    /// Frames simulated per run.
    pub frames: u32,
    /// Substeps per frame.
    pub substeps: u32,
    /// Median wall time per substep over the runs (ms).
    pub substep_ms: f64,
    /// Every run's time per substep (ms).
    pub runs_ms: Vec<f64>,
    /// Mean CG iterations per substep (of the median run).
    pub cg_iters: f64,
    /// Largest CG iteration count of a substep.
    pub cg_iters_max: u32,
    /// Mean assembly time per substep (ms).
    pub assemble_ms: f64,
    /// Mean solve time per substep (ms).
    pub solve_ms: f64,
    /// CG relative tolerance used.
    pub cg_tolerance: f64,
    /// Substeps whose solve did not reach the tolerance.
    pub unconverged: u64,
    /// Worker threads.
    pub threads: usize,
    /// Multigrid levels (1 = block-Jacobi only).
    pub levels: usize,
    /// Mean V-cycles per substep.
    pub vcycles: f64,
    /// Mean multigrid setup time per substep (ms: coarse operators, smoother factors).
    pub setup_ms: f64,
    /// Mean time of one V-cycle (ms).
    pub vcycle_ms: f64,
    /// Mean collision detection + response time per substep (ms).
    pub collision_ms: f64,
    /// Collision time as a share of the substep time.
    pub collision_share: f64,
    /// Vertices inside bodies at the end.
    pub penetrating: usize,
    /// Intersecting cloth (edge, triangle) pairs at the end.
    pub intersections: usize,
    /// Smallest vertex–body distance over the run (m; null without bodies).
    pub min_distance: Option<f64>,
    /// Bytes of the implicit system's matrix (pattern, blocks, single-precision mirrors) per
    /// vertex.
    pub matrix_bytes_per_vertex: f64,
    /// The process's peak resident memory so far (MB, `VmHWM`; null where the system does not
    /// say): it covers every case run before this one in the same process.
    pub peak_rss_mb: Option<f64>,
}

/// The process's peak resident set size in MB, from `/proc/self/status` (Linux only).
pub fn peak_rss_mb() -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb / 1024.0)
}

/// Runs the hang scene at `n` × `n` for `frames` frames of 5 substeps, `runs` times after one
/// warm-up run, and returns the median.
pub fn bench_hang(n: usize, frames: u32, runs: usize) -> Result<BenchResult, ClothError> {
    bench_scene("hang", n, frames, runs)
}

/// Runs scene `scene` ("hang", "drape" or "hang_self") at `n` × `n` for `frames` frames of 5
/// substeps, `runs` times after one warm-up run, and returns the median run. A size over the
/// limit `max_particles` or a frame count over `max_frames` is refused before anything is built.
/// Scene "garment" is the A-shirt on the mannequin ([`scenes::garment`]) with `n` its edge length
/// in millimetres, run for `frames` × 5 of its own steps from the pattern (sewing, then drape).
pub fn bench_scene(
    scene: &str,
    n: usize,
    frames: u32,
    runs: usize,
) -> Result<BenchResult, ClothError> {
    let substeps = 5;
    let runs = runs.max(1);
    let lim = limits::get();
    let particles = if scene == "garment" {
        1.0
    } else {
        (n as f64) * (n as f64)
    };
    let what = format!("bench size {n} × {n} particles");
    limits::check(&what, particles, "max_particles", lim.max_particles).map_err(limit_err)?;
    limits::check_count("bench frames", frames as u64, "max_frames", lim.max_frames)
        .map_err(limit_err)?;
    let mut results = Vec::new();
    let mut contact = Vec::new();
    let (mut vertices, mut matrix_bytes) = (n * n, 0);
    for r in 0..=runs {
        let mut sim = match scene {
            "hang" => scenes::hang(n)?,
            "drape" => scenes::drape(n)?,
            "hang_self" => scenes::hang_self(n)?,
            "garment" => scenes::garment(n)?,
            other => {
                return Err(ClothError::Parameter(format!(
                    "unknown bench scene `{other}` (hang, drape, hang_self, garment)"
                )))
            }
        };
        // per-step intersection counting is a diagnostic, not part of the solver: the final
        // state is checked once after the timed loop
        sim.add_contact().settings.count_intersections = false;
        let steps = frames as u64 * substeps as u64;
        let t0 = Instant::now();
        sim.run_steps(steps, |_, _| Ok(()))?;
        let ms = t0.elapsed().as_secs_f64() * 1e3 / steps as f64;
        if r > 0 {
            vertices = sim.particle_count();
            matrix_bytes = sim.system_matrix_bytes();
            let x = sim.state.x.clone();
            let last = sim.contact_mut().report(&x);
            let s = &sim.stats;
            let k = s.len() as f64;
            let iters = s.iter().map(|x| x.cg_iterations as f64).sum::<f64>() / k;
            let imax = s.iter().map(|x| x.cg_iterations).max().unwrap_or(0);
            let am = s.iter().map(|x| x.assemble_ms).sum::<f64>() / k;
            let sm = s.iter().map(|x| x.solve_ms).sum::<f64>() / k;
            let (setup, apply, cycles) = sim.multigrid_timing().unwrap_or((0.0, 0.0, 0));
            let vc = cycles as f64 / k;
            let setup_ms = setup * 1e3 / k;
            let vcycle_ms = apply * 1e3 / (cycles.max(1) as f64);
            let cm = s.iter().map(|x| x.collision_ms).sum::<f64>() / k;
            let md = s
                .iter()
                .map(|x| x.min_distance)
                .fold(f64::INFINITY, f64::min);
            contact.push((
                ms,
                cm,
                last.penetrating,
                last.intersections,
                md.is_finite().then_some(md),
            ));
            results.push((
                ms,
                iters,
                imax,
                am,
                sm,
                sim.unconverged_steps,
                sim.params.cg_tolerance,
                vc,
                sim.multigrid_levels(),
                setup_ms,
                vcycle_ms,
            ));
        }
    }
    let mut runs_ms: Vec<f64> = results.iter().map(|r| r.0).collect();
    let mut sorted = results.clone();
    sorted.sort_by(|a, b| a.0.total_cmp(&b.0));
    let med = sorted[sorted.len() / 2];
    let c = contact
        .iter()
        .find(|c| c.0 == med.0)
        .copied()
        .unwrap_or((med.0, 0.0, 0, 0, None));
    runs_ms
        .iter_mut()
        .for_each(|x| *x = (*x * 1000.0).round() / 1000.0);
    Ok(BenchResult {
        scene: scene.into(),
        n,
        vertices,
        frames,
        substeps,
        substep_ms: med.0,
        runs_ms,
        cg_iters: med.1,
        cg_iters_max: med.2,
        assemble_ms: med.3,
        solve_ms: med.4,
        cg_tolerance: med.6,
        unconverged: med.5,
        threads: rayon::current_num_threads(),
        levels: med.8,
        vcycles: med.7,
        setup_ms: med.9,
        vcycle_ms: med.10,
        collision_ms: c.1,
        collision_share: c.1 / med.0,
        penetrating: c.2,
        intersections: c.3,
        min_distance: c.4,
        matrix_bytes_per_vertex: matrix_bytes as f64 / vertices.max(1) as f64,
        peak_rss_mb: peak_rss_mb(),
    })
}
