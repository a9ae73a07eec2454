//! Automatic pre-positioning of a meshed pattern around a mannequin, after Le Thanh &
//! Gagalowicz (seed report §5.4.1), without manual arrangement points.
//!
//! 1. Each piece is laid on the front or back "figurine" plane of the body (its placement:
//!    an anchor corner at a horizontal offset and at a landmark height), grain vertical.
//! 2. Both figurines are sampled row by row at the silhouettes' cell size. In each row the
//!    pieces' horizontal intervals are grouped with the body sections they cover (torso, or
//!    one leg, or both legs for a skirt); rows above the shoulders reuse the shoulder row,
//!    and above the armpits the arms are cut off the torso.
//! 3. Each group's section points (front and back depths of the silhouettes) give a convex
//!    shell grown by the clearance `d_z`; if the garment row is longer than the shell, the
//!    shell is widened (the elliptic interpolation between silhouette and figurine extremes
//!    of the seed, done so that arc lengths are kept).
//! 4. Every vertex is put on its row's shell at the arc length of its horizontal position
//!    from the front (or back) centre, and interpolated between the two nearest rows: rows are
//!    kept isometric, front and back meet at the side seams.
//! 5. A vertex that still ends closer to the skin than half the clearance is pushed out along
//!    the skin normal.

use std::time::Instant;

use super::centre_seams::{lay_centre_seams, CentreEdge};
use super::figurine::{figurines, Figurine};
use super::hierarchy::interpolate;
use super::layers::{layer_lifts, mean_edge_length};
use super::over_the_top::{column_tops, over_the_top, over_the_top_lifts};
use super::relax::{push_out, relax};
use super::rows::Rows;
use super::silhouette::{Landmarks, Silhouettes};
use crate::contact::MeshBody;
use crate::garment::mesh::GarmentMesh;
use crate::garment::mesh::{mesh_pattern, MeshParameters};
use crate::garment::{Pattern, PatternError, Side, P2};
use crate::geometry::Vec3;

/// Settings of the pre-positioning.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default)]
pub struct PrepositionParameters {
    /// Distance kept between the garment and the skin (m), the seed's d_z.
    pub clearance: f64,
    /// Relaxation sweeps after the mapping, on each level (0: none).
    pub relax_iterations: usize,
    /// Levels of the multi-resolution relaxation: 1 relaxes the garment's own mesh only; each
    /// further level first relaxes the pattern meshed with edges twice as long and carries its
    /// displacement over (coarse levels stop at 6 cm edges).
    pub levels: usize,
    /// Distance (m) by which a piece overlapping an earlier one on the same figurine is lifted
    /// off it (two layers, such as a skirt's vent extensions); 0 leaves overlaps as they are.
    pub layer_gap: f64,
}

impl Default for PrepositionParameters {
    fn default() -> Self {
        PrepositionParameters {
            clearance: 0.012,
            relax_iterations: 60,
            levels: 3,
            layer_gap: 0.01,
        }
    }
}

/// What pre-positioning did.
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize)]
pub struct PrepositionReport {
    /// Garment vertices.
    pub vertices: usize,
    /// Mean |L/L0 − 1| over the mesh edges after the mapping, before relaxation.
    pub initial_mean_strain: f64,
    /// Largest |L/L0 − 1| after the mapping, before relaxation.
    pub initial_max_strain: f64,
    /// Mean |L/L0 − 1| over the mesh edges at the end.
    pub mean_strain: f64,
    /// Largest |L/L0 − 1|.
    pub max_strain: f64,
    /// Vertices pushed out because they were closer than half the clearance to the skin.
    pub pushed_out: usize,
    /// Vertices inside the body at the end (should be 0).
    pub inside: usize,
    /// Smallest signed distance to the skin at the end (m).
    pub min_distance: f64,
    /// Wall time (s).
    pub seconds: f64,
}

/// Distance (m) along a piece over which the displacement that lays a centre seam on the
/// body's centre profile fades out.
const CENTRE_FALLOFF: f64 = 0.12;

/// Longest mesh edge (m) of a coarse level of the multi-resolution relaxation.
const COARSEST_EDGE: f64 = 0.06;

/// Distance (m) along a piece over which a layer's lift falls from the layer gap to 0.
const LAYER_RAMP: f64 = 0.03;

/// Pre-positions the meshed `garment` (from `pattern`, expanded, every piece placed) around the
/// body `skin` whose silhouettes and landmarks are given; returns the 3D vertex positions.
pub fn preposition(
    pattern: &Pattern,
    garment: &GarmentMesh,
    sil: &Silhouettes,
    marks: &Landmarks,
    skin: &MeshBody,
    params: &PrepositionParameters,
) -> Result<(Vec<Vec3>, PrepositionReport), PatternError> {
    let start = Instant::now();
    if !(1..=6).contains(&params.levels) {
        return Err(PatternError::Parameter(format!(
            "pre-positioning levels must be 1 to 6, got {}",
            params.levels
        )));
    }
    let (_, x, mut report) = solve(pattern, garment, sil, marks, skin, params)?;
    report.seconds = start.elapsed().as_secs_f64();
    Ok((x, report))
}

/// Maps `garment` onto the body and relaxes it (over `params.levels` levels); returns the
/// mapped positions (before any relaxation), the relaxed ones and the report.
fn solve(
    pattern: &Pattern,
    garment: &GarmentMesh,
    sil: &Silhouettes,
    marks: &Landmarks,
    skin: &MeshBody,
    params: &PrepositionParameters,
) -> Result<(Vec<Vec3>, Vec<Vec3>, PrepositionReport), PatternError> {
    let dz = params.clearance;
    if !(dz.is_finite() && dz > 0.0) {
        return Err(PatternError::Parameter(format!(
            "pre-positioning clearance must be > 0, got {dz}"
        )));
    }
    if !(params.layer_gap.is_finite() && params.layer_gap >= 0.0) {
        return Err(PatternError::Parameter(format!(
            "pre-positioning layer_gap must be ≥ 0, got {}",
            params.layer_gap
        )));
    }
    let mut figs = figurines(pattern, garment, marks)?;
    let n = garment.mesh.positions.len();
    let mut fig_pos = vec![[0.0; 2]; n];
    let mut piece_of = vec![0usize; n];
    let tops = column_tops(sil, marks);
    for pass in 0..2 {
        for (k, pm) in garment.pieces.iter().enumerate() {
            for v in pm.vertices.clone() {
                fig_pos[v] = figs[k].apply(&garment.flat[v]);
                piece_of[v] = k;
            }
        }
        if pass == 0 {
            let lifts =
                over_the_top_lifts(garment, &figs, &fig_pos, &piece_of, sil, marks, &tops, dz);
            for (f, l) in figs.iter_mut().zip(lifts) {
                f.at[1] += l;
            }
        }
    }
    let rows = Rows::new(garment, &figs, &fig_pos, sil, marks, dz);
    let (r0, r1) = (rows.r0, rows.r1);
    let mut x = vec![Vec3::zeros(); n];
    for v in 0..n {
        let [fx, fy] = fig_pos[v];
        let t = (fy - sil.h0) / sil.cell;
        let i0 = (t.floor() as usize).clamp(r0, r1);
        let i1 = (i0 + 1).min(r1);
        let w = (t - i0 as f64).clamp(0.0, 1.0);
        let k = piece_of[v];
        let a = rows.place(i0 - r0, k, fx, &figs[k]);
        let b = rows.place(i1 - r0, k, fx, &figs[k]);
        let (s, d) = match (a, b) {
            (Some(a), Some(b)) => (a[0] * (1.0 - w) + b[0] * w, a[1] * (1.0 - w) + b[1] * w),
            (Some(a), None) | (None, Some(a)) => (a[0], a[1]),
            (None, None) => {
                // no row of this piece here: search outwards
                let found = (1..rows.rows.len()).find_map(|o| {
                    rows.place((i0 - r0).saturating_sub(o), k, fx, &figs[k])
                        .or_else(|| {
                            rows.place((i0 - r0 + o).min(rows.rows.len() - 1), k, fx, &figs[k])
                        })
                });
                let p = found.ok_or_else(|| PatternError::Piece {
                    source_name: pattern.source.clone(),
                    piece: garment.pieces[k].name.clone(),
                    message: "no row of the piece could be placed on the body".into(),
                })?;
                (p[0], p[1])
            }
        };
        let (h, d) = over_the_top(sil, marks, &tops, figs[k].side, s, fy, d, dz);
        x[v] = sil.frame.to_world(s, h, d);
    }
    // overlapping pieces of one figurine become layers
    let sides: Vec<Side> = figs.iter().map(|f| f.side).collect();
    let edge = mean_edge_length(garment);
    let lifts = layer_lifts(
        garment,
        &fig_pos,
        &sides,
        params.layer_gap,
        LAYER_RAMP,
        0.5 * edge,
    );
    if lifts.iter().any(|&l| l > 0.0) {
        let normals = outward_normals(garment, &x, skin);
        for ((p, &l), n) in x.iter_mut().zip(&lifts).zip(&normals) {
            *p += n * l;
        }
    }
    // centre seams along the body's centre profile (a crotch seam passes under the body)
    let centre = centre_edges(garment, &figs, &fig_pos, &piece_of, sil.cell);
    if !centre.is_empty() {
        // the body's centre line from the garment's top down to the crotch (or its bottom)
        let col = sil.col(0.0);
        let profile_rows: Vec<(f64, f64, f64)> = (r0..=r1)
            .rev()
            .skip_while(|&i| sil.depths(i, col).is_none())
            .map_while(|i| sil.depths(i, col).map(|(f, b)| (sil.h_of(i), f, b)))
            .collect();
        let frame = &sil.frame;
        lay_centre_seams(
            garment,
            &centre,
            &profile_rows,
            dz,
            |p| frame.to_body(p)[1],
            |h, d| frame.to_world(0.0, h, d),
            CENTRE_FALLOFF,
            &mut x,
        );
    }
    // push out what the shells did not keep clear (between rows, sharp features)
    let mut report = PrepositionReport {
        vertices: n,
        ..Default::default()
    };
    let reach = 1.0;
    report.pushed_out = push_out(&mut x, skin, dz);
    (report.initial_mean_strain, report.initial_max_strain) = edge_strain(garment, &x);
    let mapped = x.clone();
    // coarse levels first: the displacement their relaxation made, carried over
    let coarse_edge = 2.0 * mean_edge_length(garment);
    if params.levels > 1 && coarse_edge <= COARSEST_EDGE {
        let coarse = mesh_pattern(
            pattern,
            &MeshParameters {
                edge_length: coarse_edge,
                ..Default::default()
            },
        )?;
        if coarse.pieces.len() == garment.pieces.len() {
            let sub = PrepositionParameters {
                levels: params.levels - 1,
                ..*params
            };
            let (cm, cx, _) = solve(pattern, &coarse, sil, marks, skin, &sub)?;
            let delta: Vec<Vec3> = cx.iter().zip(&cm).map(|(a, b)| a - b).collect();
            let mut fine = interpolate(garment, &coarse, &delta);
            // the two sides of a seam move together, keeping how the mapping matched them
            for seam in &garment.seams {
                for &(a, b) in &seam.pairs {
                    let m = 0.5 * (fine[a] + fine[b]);
                    fine[a] = m;
                    fine[b] = m;
                }
            }
            for (p, d) in x.iter_mut().zip(fine) {
                *p += d;
            }
            push_out(&mut x, skin, dz);
        }
    }
    relax(garment, &mut x, skin, dz, params.relax_iterations);
    report.min_distance = f64::MAX;
    for p in &x {
        if let Some(pr) = skin.proximity(p, reach) {
            report.min_distance = report.min_distance.min(pr.distance);
            if pr.distance < 0.0 {
                report.inside += 1;
            }
        }
    }
    let (mean, max) = edge_strain(garment, &x);
    report.mean_strain = mean;
    report.max_strain = max;
    Ok((mapped, x, report))
}

/// The edges of centre seams: seams joining two pieces of one figurine whose top end lies on
/// the centre line (within two cells), each edge's vertices from its top end down.
fn centre_edges(
    garment: &GarmentMesh,
    figs: &[Figurine],
    fig_pos: &[P2],
    piece_of: &[usize],
    cell: f64,
) -> Vec<CentreEdge> {
    let mut out = Vec::new();
    for seam in &garment.seams {
        let (Some(&first), Some(&last)) = (seam.pairs.first(), seam.pairs.last()) else {
            continue;
        };
        let (pa, pb) = (piece_of[first.0], piece_of[first.1]);
        let side = figs[pa].side;
        if pa == pb || figs[pb].side != side {
            continue;
        }
        let down = fig_pos[first.0][1] >= fig_pos[last.0][1];
        let top = if down { first } else { last };
        if fig_pos[top.0][0].abs() > 2.0 * cell || fig_pos[top.1][0].abs() > 2.0 * cell {
            continue;
        }
        let mut pairs = seam.pairs.clone();
        if !down {
            pairs.reverse();
        }
        for (piece, pick) in [(pa, 0), (pb, 1)] {
            out.push(CentreEdge {
                vertices: pairs
                    .iter()
                    .map(|p| if pick == 0 { p.0 } else { p.1 })
                    .collect(),
                side,
                piece,
            });
        }
    }
    out
}

/// Unit vertex normals of the garment at `x` (area-weighted), each piece's turned away from
/// the body by a majority of its vertices.
fn outward_normals(garment: &GarmentMesh, x: &[Vec3], skin: &MeshBody) -> Vec<Vec3> {
    let mut normals = vec![Vec3::zeros(); x.len()];
    for t in &garment.mesh.triangles {
        let n = (x[t[1]] - x[t[0]]).cross(&(x[t[2]] - x[t[0]]));
        for &v in t {
            normals[v] += n;
        }
    }
    for pm in &garment.pieces {
        let votes: i64 = pm
            .vertices
            .clone()
            .step_by(7)
            .filter_map(|v| {
                skin.proximity(&x[v], 1.0)
                    .map(|pr| pr.normal.dot(&normals[v]))
            })
            .map(|d| if d >= 0.0 { 1 } else { -1 })
            .sum();
        let sign = if votes >= 0 { 1.0 } else { -1.0 };
        for v in pm.vertices.clone() {
            let len = normals[v].norm().max(1e-300);
            normals[v] *= sign / len;
        }
    }
    normals
}

/// Mean and largest |L/L0 − 1| over the garment's edges at positions `x`.
pub fn edge_strain(garment: &GarmentMesh, x: &[Vec3]) -> (f64, f64) {
    let m = &garment.mesh;
    let (mut sum, mut max, mut count) = (0.0, 0.0f64, 0usize);
    for t in &m.triangles {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            if a > b {
                continue; // each interior edge once; boundary edges in one direction only
            }
            let r = (m.rest[a][0] - m.rest[b][0]).hypot(m.rest[a][1] - m.rest[b][1]);
            if r <= 0.0 {
                continue;
            }
            let e = ((x[a] - x[b]).norm() / r - 1.0).abs();
            sum += e;
            max = max.max(e);
            count += 1;
        }
    }
    (sum / count.max(1) as f64, max)
}
