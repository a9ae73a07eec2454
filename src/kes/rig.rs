//! Virtual Kawabata rigs: the KES-FB1 tensile and shear tests, the KES-FB2 pure-bending test
//! and the Peirce cantilever, run on a simulated grid sample with the cloth engine's elements
//! and material law.
//!
//! **Quasi-static.** The instruments are slow (0.2 mm/s), so inertia plays no part: each rig
//! moves its clamps by small increments and, after each, brings the sample to static
//! equilibrium by Newton iterations — backward-Euler solves of the engine's own implicit
//! system (same assembly, filter S/z and modified PCG) with the velocity reset to zero and a
//! step of 1 s, so the mass term only regularises. Damping and air drag are switched off and
//! gravity too, except in the cantilever. Internal-friction states advance with every
//! evaluation, so hysteresis loops come out of the simulation. Forces and moments are read
//! from the reactions at the clamps (the internal force on the clamped particles), exactly as
//! the instrument's load cell reads them.

use std::sync::Arc;

use super::quasi_static::QuasiStatic;
use crate::cloth::constraints::ParticleFilter;
use crate::cloth::{ClothError, ClothModel, Direction, FabricParameters, MaterialLaw};
use crate::geometry::Vec3;

/// Sample resolution: grid cells per centimetre along the rig's main direction.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RigMesh {
    /// Cells per centimetre (e.g. 2 for a coarse and 8 for a fine mesh).
    pub cells_per_cm: f64,
}

impl RigMesh {
    /// A coarse sample mesh.
    pub const COARSE: RigMesh = RigMesh { cells_per_cm: 1.0 };
    /// A fine sample mesh (2× finer).
    pub const FINE: RigMesh = RigMesh { cells_per_cm: 2.0 };
}

/// A recorded experiment: the path (x, y) in SI units in the order the rig ran it.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct RigCurve {
    /// (strain, N/m) for tensile; (rad, N/m) for shear; (1/m, N) for bending.
    pub path: Vec<[f64; 2]>,
    /// Increments whose Newton iterations stopped at the cap before reaching the tolerance
    /// (a relative force residual of 1e-6); their readings are less exact.
    pub unconverged: usize,
}

/// A sample model: `along` × `across` metres, the rig's main direction along the fabric
/// direction `dir`. Returns the model and a map (index along, index across) → particle.
fn sample(
    law: &Arc<dyn MaterialLaw>,
    density: f64,
    dir: Direction,
    along: f64,
    across: f64,
    mesh: RigMesh,
    across_cells: Option<usize>,
) -> Result<(ClothModel, usize, usize), ClothError> {
    let na = ((along * 100.0 * mesh.cells_per_cm).round() as usize).max(4) + 1;
    let nc =
        across_cells.unwrap_or(((across * 100.0 * mesh.cells_per_cm).round() as usize).max(2)) + 1;
    let fabric = FabricParameters {
        density,
        stretch_damping: 0.0,
        bend_damping: 0.0,
        air_drag: 0.0,
        ..FabricParameters::default()
    };
    let mut model = match dir {
        Direction::Warp => ClothModel::grid(along, across, na, nc, fabric)?,
        Direction::Weft => ClothModel::grid(across, along, nc, na, fabric)?,
    };
    model.set_law(law.clone());
    Ok((model, na, nc))
}

/// The KES cycle 0 → +a → −a → +a in `steps` increments per amplitude.
fn cycle(a: f64, steps: usize) -> Vec<f64> {
    let d = a / steps as f64;
    let mut path: Vec<f64> = (0..=steps).map(|k| k as f64 * d).collect();
    path.extend((1..=2 * steps).map(|k| a - k as f64 * d));
    path.extend((1..=2 * steps).map(|k| -a + k as f64 * d));
    path
}

/// Particle index of (a along, c across) for a sample of `na` × `nc` along `dir`.
fn pid(dir: Direction, na: usize, nc: usize, a: usize, c: usize) -> usize {
    match dir {
        Direction::Warp => c * na + a,
        Direction::Weft => a * nc + c,
    }
}

/// Unit vectors (along, across) of a sample along `dir`.
fn axes(dir: Direction) -> (Vec3, Vec3) {
    match dir {
        Direction::Warp => (Vec3::x(), Vec3::y()),
        Direction::Weft => (Vec3::y(), Vec3::x()),
    }
}

/// KES-FB1 tensile test along `dir`: a 5 cm (gauge) × 20 cm strip between clamps that hold its
/// width, stretched until the force per width reaches `fm` (N/m) and returned until it drops
/// to zero. `strain_hint` sizes the increments (about 60 per branch).
pub fn tensile(
    law: Arc<dyn MaterialLaw>,
    density: f64,
    dir: Direction,
    fm: f64,
    mesh: RigMesh,
) -> Result<RigCurve, ClothError> {
    if !(fm.is_finite() && fm > 0.0) {
        return Err(ClothError::Parameter(format!(
            "tensile test: maximum load must be positive, got {fm} N/m"
        )));
    }
    let (gauge, width) = (0.05, 0.20);
    let (model, na, nc) = sample(&law, density, dir, gauge, width, mesh, None)?;
    let (ax, _) = axes(dir);
    let mut qs = QuasiStatic::new(model, Vec3::zeros());
    let x0 = qs.x.clone();
    let ends: Vec<usize> = (0..nc).map(|c| pid(dir, na, nc, na - 1, c)).collect();
    for c in 0..nc {
        qs.filter.kind[pid(dir, na, nc, 0, c)] = ParticleFilter::Fixed {
            target: x0[pid(dir, na, nc, 0, c)],
        };
    }
    qs.filter.any = true;
    // increment size from the law's own elastic curve (only to size steps)
    let mut em = 1e-4;
    while law.tension(dir, em).0 < fm && em < 10.0 {
        em *= 1.25;
    }
    let de = em / 60.0;
    let mut curve = RigCurve::default();
    let mut eps: f64 = 0.0;
    let mut loading = true;
    curve.path.push([0.0, 0.0]);
    for _ in 0..2000 {
        let step = if loading { de } else { -de };
        eps += step;
        if eps < 0.0 {
            break;
        }
        for &i in &ends {
            qs.filter.kind[i] = ParticleFilter::Fixed {
                target: x0[i] + ax * (eps * gauge),
            };
        }
        if !qs.solve("tensile test")? {
            curve.unconverged += 1;
        }
        let f = qs.forces();
        let force: f64 = -ends.iter().map(|&i| f[i].dot(&ax)).sum::<f64>() / width;
        curve.path.push([eps, force]);
        if loading && force >= fm {
            loading = false;
        } else if !loading && force <= 0.0 {
            break;
        }
    }
    Ok(curve)
}

/// KES-FB1 shear test: a 20 cm × 5 cm (gauge) sample under a constant tension `tension` (N/m,
/// 10 gf/cm in the standard) along the gauge, sheared by moving one clamp sideways through
/// 0 → +`amplitude` → −`amplitude` → +`amplitude` (rad). The force per clamp length includes
/// the sideways component of the tension, as the instrument's does.
pub fn shear(
    law: Arc<dyn MaterialLaw>,
    density: f64,
    tension: f64,
    amplitude: f64,
    mesh: RigMesh,
) -> Result<RigCurve, ClothError> {
    let (gauge, width) = (0.05, 0.20);
    // gauge along the warp (the tension is applied along it)
    let dir = Direction::Warp;
    let (model, na, nc) = sample(&law, density, dir, gauge, width, mesh, None)?;
    let (ax, ac) = axes(dir);
    let mut qs = QuasiStatic::new(model, Vec3::zeros());
    let x0 = qs.x.clone();
    let top: Vec<usize> = (0..nc).map(|c| pid(dir, na, nc, na - 1, c)).collect();
    for c in 0..nc {
        let i = pid(dir, na, nc, 0, c);
        qs.filter.kind[i] = ParticleFilter::Fixed { target: x0[i] };
        // each clamp particle carries the tension of its share of the clamp length
        let share = if c == 0 || c == nc - 1 { 0.5 } else { 1.0 } * width / (nc - 1) as f64;
        qs.ext[top[c]] = ax * (tension * share);
    }
    qs.filter.any = true;
    let path = cycle(amplitude, 24);
    let mut curve = RigCurve::default();
    // the shear angle is measured on the gauge length under the test's tension (a stretchy
    // knit lengthens noticeably under 10 gf/cm)
    for &i in &top {
        qs.filter.kind[i] = ParticleFilter::Axis {
            free: ax,
            target: x0[i],
        };
    }
    qs.solve("shear test (tension)")?;
    let stretched =
        gauge + top.iter().map(|&i| (qs.x[i] - x0[i]).dot(&ax)).sum::<f64>() / top.len() as f64;
    for phi in path {
        for &i in &top {
            // sideways position prescribed, free along the gauge (constant tension)
            let along = (qs.x[i] - x0[i]).dot(&ax);
            qs.filter.kind[i] = ParticleFilter::Axis {
                free: ax,
                target: x0[i] + ac * (stretched * phi.tan()) + ax * along,
            };
        }
        if !qs.solve("shear test")? {
            curve.unconverged += 1;
        }
        let f = qs.forces();
        let force: f64 = -top.iter().map(|&i| f[i].dot(&ac)).sum::<f64>() / width;
        curve.path.push([phi, force]);
    }
    Ok(curve)
}

/// Positions of a strip's cross-section columns on an arc of curvature `k` with equal chords
/// `d`: (distance along the flat direction, height) of column `j` of `n`, centred.
fn arc_point(k: f64, d: f64, j: usize, n: usize) -> (f64, f64) {
    let s = j as f64 - 0.5 * (n - 1) as f64;
    if k.abs() < 1e-9 {
        return (s * d, 0.0);
    }
    let alpha = 2.0 * (0.5 * k * d).clamp(-1.0, 1.0).asin();
    let phi = s * alpha;
    (phi.sin() / k, (1.0 - phi.cos()) / k)
}

/// KES-FB2 pure-bending test for curvature along `dir`: a 1 cm long, 1 cm wide strip whose two
/// end pairs of cross-sections are held on a circular arc of curvature K, cycled
/// 0 → +`amplitude` → −`amplitude` → +`amplitude` (1/m). Reports the moment per width read
/// from the couple at one clamp.
pub fn bending(
    law: Arc<dyn MaterialLaw>,
    density: f64,
    dir: Direction,
    amplitude: f64,
    mesh: RigMesh,
) -> Result<RigCurve, ClothError> {
    let (length, width) = (0.01, 0.01);
    // bending needs several cells along the strip even on a coarse mesh
    let fine = RigMesh {
        cells_per_cm: (mesh.cells_per_cm * 5.0).max(8.0),
    };
    let (model, na, nc) = sample(&law, density, dir, length, width, fine, Some(2))?;
    let (ax, ac) = axes(dir);
    let up = Vec3::z();
    let mut qs = QuasiStatic::new(model, Vec3::zeros());
    let x0 = qs.x.clone();
    let d = length / (na - 1) as f64;
    let centre = x0[pid(dir, na, nc, 0, 0)] + ax * (0.5 * length);
    let clamped: Vec<usize> = (0..na).filter(|&a| a < 2 || a + 2 >= na).collect();
    let right: Vec<usize> = (0..nc)
        .flat_map(|c| [pid(dir, na, nc, na - 2, c), pid(dir, na, nc, na - 1, c)])
        .collect();
    let path = cycle(amplitude, 50);
    let mut curve = RigCurve::default();
    qs.filter.any = true;
    // the moving clamp's tangent at the end of the arc: it may slide along it, so the strip
    // carries no axial force (pure bending)
    let mut arc = x0.clone();
    for kappa in path {
        let (s1, h1) = arc_point(kappa, d, na - 2, na);
        let (s2, h2) = arc_point(kappa, d, na - 1, na);
        let tangent = (ax * (s2 - s1) + up * (h2 - h1)).normalize();
        for &a in &clamped {
            let (s, h) = arc_point(kappa, d, a, na);
            for c in 0..nc {
                let i = pid(dir, na, nc, a, c);
                let across = (x0[i] - centre).dot(&ac);
                let on_arc = centre + ax * s + ac * across + up * h;
                qs.filter.kind[i] = if a < 2 {
                    ParticleFilter::Fixed { target: on_arc }
                } else {
                    // keep the slide found so far, move onto the rotated clamp line
                    let slide = match qs.filter.kind[i] {
                        ParticleFilter::Axis { free, .. } => (qs.x[i] - arc[i]).dot(&free),
                        _ => 0.0,
                    };
                    arc[i] = on_arc;
                    ParticleFilter::Axis {
                        free: tangent,
                        target: on_arc + tangent * slide,
                    }
                };
            }
        }
        if !qs.solve("bending test")? {
            curve.unconverged += 1;
        }
        qs.forces();
        let f = &qs.asm.b;
        // couple of the clamp's reactions about the clamp's centre, per width
        let pivot = right.iter().map(|&i| qs.x[i]).sum::<Vec3>() / right.len() as f64;
        let mut m = 0.0;
        for &i in &right {
            let r = qs.x[i] - pivot;
            let reaction = -f[i];
            m += r.cross(&reaction).dot(&ac);
        }
        // sign: a positive curvature (ends up) needs a clamp couple that turns the right end up
        let sign = match dir {
            Direction::Warp => -1.0,
            Direction::Weft => 1.0,
        };
        curve.path.push([kappa, sign * m / width]);
    }
    Ok(curve)
}

/// Peirce cantilever: a strip of overhang `overhang` (m) along `dir`, 1 cm wide, clamped flat
/// at one end, bends under its own weight (gravity ramped in ten steps). Returns the chord
/// angle of its tip (rad) below the horizontal.
pub fn cantilever_angle(
    law: Arc<dyn MaterialLaw>,
    density: f64,
    dir: Direction,
    overhang: f64,
    cells: usize,
) -> Result<f64, ClothError> {
    let width = 0.01;
    let mesh = RigMesh {
        cells_per_cm: cells as f64 / (overhang * 100.0),
    };
    let (model, na, nc) = sample(&law, density, dir, overhang, width, mesh, Some(2))?;
    let (ax, _) = axes(dir);
    let mut qs = QuasiStatic::new(model, Vec3::zeros());
    let x0 = qs.x.clone();
    for a in 0..2 {
        for c in 0..nc {
            let i = pid(dir, na, nc, a, c);
            qs.filter.kind[i] = ParticleFilter::Fixed { target: x0[i] };
        }
    }
    qs.filter.any = true;
    // the clamp edge is the second cross-section; the overhang starts there
    let root = x0[pid(dir, na, nc, 1, 0)];
    for k in 1..=10 {
        qs.gravity = Vec3::new(0.0, 0.0, -9.81 * k as f64 / 10.0);
        qs.solve("cantilever")?;
    }
    let (mut dx, mut dz) = (0.0, 0.0);
    for c in 0..nc {
        let t = qs.x[pid(dir, na, nc, na - 1, c)] - root;
        dx += t.dot(&ax);
        dz += t.z;
    }
    Ok((-dz).atan2(dx))
}

/// Bending length c (m) of a fabric by the Shirley/Peirce procedure: the overhang at which
/// the tip's chord reaches 41.5° equals 2c. Found by secant iteration on the overhang.
pub fn bending_length(
    law: Arc<dyn MaterialLaw>,
    density: f64,
    dir: Direction,
    guess: f64,
) -> Result<f64, ClothError> {
    let target = 41.5f64.to_radians();
    let cells = 30;
    let f = |l: f64| -> Result<f64, ClothError> {
        Ok(cantilever_angle(law.clone(), density, dir, l, cells)? - target)
    };
    // the angle grows like l³ at first: start from the elastica estimate 2c
    let (mut l0, mut l1) = (2.0 * guess, 2.2 * guess);
    let (mut f0, mut f1) = (f(l0)?, f(l1)?);
    for _ in 0..20 {
        if (f1).abs() < 1e-5 {
            break;
        }
        let l2 = l1 - f1 * (l1 - l0) / (f1 - f0);
        let l2 = l2.clamp(0.5 * l1, 2.0 * l1);
        (l0, f0) = (l1, f1);
        l1 = l2;
        f1 = f(l1)?;
    }
    // the overhang is measured from the clamp edge (one cell inside the sample)
    Ok(0.5 * l1 * (cells as f64 - 1.0) / cells as f64)
}
