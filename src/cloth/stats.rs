//! Per-step statistics (energy, solver iterations, residual, timings) and their CSV/JSON output.

use std::io::Write;
use std::path::Path;

use serde::{Deserialize, Serialize};

use super::ClothError;

/// Statistics of one step. Energies are those of the state at the start of the step.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct StepStats {
    /// Step index.
    pub step: u64,
    /// Time at the start of the step (s).
    pub time: f64,
    /// Kinetic energy (J).
    pub kinetic: f64,
    /// Gravitational potential energy −Σ m g·x (J).
    pub gravity: f64,
    /// Elastic energy stored in the elements (J).
    pub elastic: f64,
    /// Total mechanical energy (J).
    pub total: f64,
    /// Conjugate-gradient iterations (0 for explicit steps).
    pub cg_iterations: u32,
    /// Final relative residual ‖S(b − AΔv)‖ / ‖S(b − Az)‖, recomputed from the matrix (the
    /// true residual, not the iteration's recurrence; the worst substep's for a split step).
    pub residual: f64,
    /// Whether the true residual met the tolerance (every substep's, for a split step).
    pub converged: bool,
    /// Time spent assembling forces and the matrix (ms).
    pub assemble_ms: f64,
    /// Time spent in the linear solve (ms).
    pub solve_ms: f64,
    /// Wall time of the whole step (ms).
    pub step_ms: f64,
    /// Time in collision detection and response (ms).
    pub collision_ms: f64,
    /// Vertices constrained against bodies.
    pub contacts: usize,
    /// Cloth–cloth pairs in contact (closer than the self thickness) at the start of the step.
    pub self_contacts: usize,
    /// Smallest signed distance of a vertex to a body at the end of the step (m; infinite, and
    /// written empty in CSV, without bodies near).
    pub min_distance: f64,
    /// Vertices inside a body at the end of the step.
    pub penetrating: usize,
    /// Intersecting (edge, triangle) pairs of the cloth at the end of the step.
    pub intersections: usize,
    /// Times the step failed its checks and was retried split in halves (0: taken whole; k:
    /// taken as 2^k substeps).
    pub retries: u32,
}

const HEADER: &str = "step,time,kinetic,gravity,elastic,total,cg_iterations,residual,converged,assemble_ms,solve_ms,step_ms,collision_ms,contacts,self_contacts,min_distance,penetrating,intersections,retries";

fn write_atomic(path: &Path, body: &[u8]) -> Result<(), ClothError> {
    let err = |e: std::io::Error| ClothError::Output {
        path: path.display().to_string(),
        message: e.to_string(),
    };
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(err)?;
    }
    let tmp = path.with_extension("tmp~");
    let mut f = std::fs::File::create(&tmp).map_err(err)?;
    f.write_all(body).map_err(err)?;
    drop(f);
    std::fs::rename(&tmp, path).map_err(err)
}

/// Writes statistics as CSV with a header line.
pub fn write_csv(path: &Path, stats: &[StepStats]) -> Result<(), ClothError> {
    let mut s = String::with_capacity(100 * (stats.len() + 1));
    s.push_str(HEADER);
    s.push('\n');
    for r in stats {
        s.push_str(&format!(
            "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}\n",
            r.step,
            r.time,
            r.kinetic,
            r.gravity,
            r.elastic,
            r.total,
            r.cg_iterations,
            r.residual,
            r.converged as u8,
            r.assemble_ms,
            r.solve_ms,
            r.step_ms,
            r.collision_ms,
            r.contacts,
            r.self_contacts,
            if r.min_distance.is_finite() {
                r.min_distance.to_string()
            } else {
                String::new()
            },
            r.penetrating,
            r.intersections,
            r.retries
        ));
    }
    write_atomic(path, s.as_bytes())
}

/// Writes statistics as a JSON array.
pub fn write_json(path: &Path, stats: &[StepStats]) -> Result<(), ClothError> {
    let body = serde_json::to_vec_pretty(stats).map_err(|e| ClothError::Output {
        path: path.display().to_string(),
        message: e.to_string(),
    })?;
    write_atomic(path, &body)
}
