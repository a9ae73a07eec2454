//! Meshing of an expanded pattern ([`mesh_pattern`]): every piece becomes a disc of triangles
//! at a target edge length, all pieces in one [`TriMesh`] as disconnected components, with the
//! vertex pairs of each seam.
//!
//! This module owns the triangulation of a piece's interior and the assembly of the
//! [`GarmentMesh`]; the boundary sampling (seam edges at common arc-length fractions) lives in
//! `boundary`. How a piece is meshed: its sampled outline, rotated so the grain line is
//! +u, is the constraint loop of a constrained Delaunay triangulation (spade); the interior is
//! seeded with a hexagonal lattice aligned with the warp (rows along the grain), kept at least
//! 0.6 edge length from the boundary; the lattice vertices near the boundary are smoothed
//! (Laplacian, over the neighbours of a first triangulation) and the result triangulated
//! again, then refined (spade's Delaunay refinement) for the minimum angle and the area with
//! the constraint edges kept whole, so that the boundary vertices are exactly the sampled ones
//! and seam pairs stay one to one.

pub(crate) mod boundary;
pub(crate) mod graph;
pub mod patch;

use std::ops::Range;

use serde::{Deserialize, Serialize};
use spade::handles::FixedVertexHandle;
use spade::{
    AngleLimit, ConstrainedDelaunayTriangulation, Point2, RefinementParameters, Triangulation,
};

use self::boundary::{plan, source_name, Curve};
use super::error::PatternError;
use super::pattern::{Copies, Pattern, Piece, P2};
use crate::geometry::{TriMesh, Vec3};

/// How pieces are meshed.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct MeshParameters {
    /// Target edge length (m).
    pub edge_length: f64,
    /// Smallest angle the refinement aims for (degrees, at most 30); sharp pattern corners
    /// can keep smaller ones.
    pub min_angle_deg: f64,
}

impl Default for MeshParameters {
    fn default() -> Self {
        MeshParameters {
            edge_length: 0.01,
            min_angle_deg: 25.0,
        }
    }
}

impl MeshParameters {
    /// Checks the fields: a positive finite edge length, an angle in (0°, 30°].
    pub fn validate(&self) -> Result<(), PatternError> {
        if !(self.edge_length.is_finite() && self.edge_length > 0.0) {
            return Err(PatternError::Parameter(format!(
                "edge_length must be a positive length in metres, got {}",
                self.edge_length
            )));
        }
        if !(self.min_angle_deg.is_finite() && self.min_angle_deg > 0.0)
            || self.min_angle_deg > 30.0
        {
            return Err(PatternError::Parameter(format!(
                "min_angle_deg must be in (0, 30] degrees, got {}",
                self.min_angle_deg
            )));
        }
        Ok(())
    }
}

/// Where one piece lies in a [`GarmentMesh`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PieceMesh {
    /// The piece's name.
    pub name: String,
    /// Its vertices (global ids); the boundary vertices come first.
    pub vertices: Range<usize>,
    /// Its triangles (indices into `mesh.triangles`).
    pub triangles: Range<usize>,
    /// The boundary loop, counter-clockwise, starting at the first corner (global ids).
    pub boundary: Vec<usize>,
    /// Each corner's name and vertex (global id), in outline order.
    pub corners: Vec<(String, usize)>,
}

/// The vertex pairs of one seam.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SeamMesh {
    /// The seam's name.
    pub name: String,
    /// (vertex on edge a, the vertex of edge b it meets), from `a.from` to `a.to`, ends
    /// included.
    pub pairs: Vec<(usize, usize)>,
}

/// A meshed pattern: all pieces in one mesh, each a disconnected disc.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct GarmentMesh {
    /// The mesh: `positions` are the drawing coordinates at z = 0, `rest` the same rotated so
    /// each piece's grain line is +u (warp) and v is the weft.
    pub mesh: TriMesh,
    /// Per vertex, the piece's drawing coordinates (pattern frame, m).
    pub flat: Vec<[f64; 2]>,
    /// The pieces, in pattern order.
    pub pieces: Vec<PieceMesh>,
    /// The seams, in pattern order.
    pub seams: Vec<SeamMesh>,
}

/// Meshes every piece of an expanded pattern (no fold, no pairs: see `Pattern::expanded`)
/// at `params.edge_length`.
pub fn mesh_pattern(
    pattern: &Pattern,
    params: &MeshParameters,
) -> Result<GarmentMesh, PatternError> {
    params.validate()?;
    let src = source_name(pattern);
    let piece_err = |piece: &Piece, message: String| PatternError::Piece {
        source_name: src.clone(),
        piece: piece.name.clone(),
        message,
    };
    let h = params.edge_length;
    let mut curves = Vec::with_capacity(pattern.pieces.len());
    let mut frames = Vec::with_capacity(pattern.pieces.len());
    for piece in &pattern.pieces {
        if piece.fold.is_some() || piece.copies != Copies::One {
            return Err(piece_err(
                piece,
                "cut on the fold or as a pair: expand the pattern before meshing".into(),
            ));
        }
        let corners = &piece.outline.corners;
        if corners.is_empty() {
            return Err(piece_err(piece, "outline has no corners".into()));
        }
        let mut segs = Vec::with_capacity(corners.len());
        for (j, c) in corners.iter().enumerate() {
            let curve = Curve::new(c.at, &c.segment, corners[(j + 1) % corners.len()].at);
            if !(curve.length > 0.0 && curve.length.is_finite()) {
                return Err(piece_err(
                    piece,
                    format!("the segment after corner '{}' has no length", c.name),
                ));
            }
            segs.push(curve);
        }
        curves.push(segs);
        let [g0, g1] = piece.grain;
        let (dx, dy) = (g1[0] - g0[0], g1[1] - g0[1]);
        let len = dx.hypot(dy);
        if !(len > 0.0 && len.is_finite()) {
            return Err(piece_err(piece, "grain line has no direction".into()));
        }
        frames.push([dx / len, dy / len]);
    }
    check_particle_estimate(pattern, &curves, h, &src)?;
    let plan = plan(pattern, &curves, h)?;

    let mut out = GarmentMesh {
        mesh: TriMesh::default(),
        flat: Vec::new(),
        pieces: Vec::with_capacity(pattern.pieces.len()),
        seams: Vec::with_capacity(pattern.seams.len()),
    };
    for ((piece, boundary), u) in pattern.pieces.iter().zip(&plan.boundaries).zip(frames) {
        // rest = rotation taking the grain direction u to +x
        let to_rest = |p: P2| [p[0] * u[0] + p[1] * u[1], p[1] * u[0] - p[0] * u[1]];
        let to_flat = |q: P2| [q[0] * u[0] - q[1] * u[1], q[0] * u[1] + q[1] * u[0]];
        let rest: Vec<P2> = boundary.points.iter().map(|&p| to_rest(p)).collect();
        let (interior, triangles) =
            triangulate(&rest, h, params.min_angle_deg).map_err(|m| piece_err(piece, m))?;
        let v0 = out.flat.len();
        let t0 = out.mesh.triangles.len();
        let flat = boundary
            .points
            .iter()
            .copied()
            .chain(interior.iter().map(|&q| to_flat(q)));
        for p in flat {
            out.flat.push(p);
            out.mesh.positions.push(Vec3::new(p[0], p[1], 0.0));
        }
        out.mesh.rest.extend(rest.iter().chain(&interior));
        out.mesh
            .triangles
            .extend(triangles.iter().map(|t| t.map(|i| i + v0)));
        out.pieces.push(PieceMesh {
            name: piece.name.clone(),
            vertices: v0..out.flat.len(),
            triangles: t0..out.mesh.triangles.len(),
            boundary: (v0..v0 + rest.len()).collect(),
            corners: piece
                .outline
                .corners
                .iter()
                .zip(&boundary.corners)
                .map(|(c, &i)| (c.name.clone(), v0 + i))
                .collect(),
        });
    }
    for (seam, sp) in pattern.seams.iter().zip(plan.seams) {
        let (pa, pb) = sp.pieces;
        let (a0, b0) = (out.pieces[pa].vertices.start, out.pieces[pb].vertices.start);
        out.seams.push(SeamMesh {
            name: seam.name.clone(),
            pairs: sp.pairs.iter().map(|&(i, j)| (a0 + i, b0 + j)).collect(),
        });
    }
    Ok(out)
}

/// Refuses, before anything is meshed, a pattern whose estimated vertex count at edge length
/// `h` is over the limit `max_particles`. The estimate per piece is the interior lattice
/// (area / (h² · √3/2): one vertex per rhombus of two equilateral triangles of side `h`) plus
/// the boundary samples (perimeter / `h`).
fn check_particle_estimate(
    pattern: &Pattern,
    curves: &[Vec<Curve>],
    h: f64,
    src: &str,
) -> Result<(), PatternError> {
    let per_vertex = h * h * 3f64.sqrt() / 2.0;
    let estimate: f64 = pattern
        .pieces
        .iter()
        .zip(curves)
        .map(|(piece, segs)| {
            let perimeter: f64 = segs.iter().map(|c| c.length).sum();
            piece.outline.area().abs() / per_vertex + perimeter / h
        })
        .sum();
    let what = format!("{src}: the estimated vertex count at edge_length {h} m");
    crate::limits::check(
        &what,
        estimate.ceil(),
        "max_particles",
        crate::limits::get().max_particles,
    )
    .map(|_| ())
    .map_err(|e| PatternError::Parameter(e.to_string()))
}

/// Interior lattice points closer than this (× edge length) to the boundary are dropped.
const LATTICE_CLEARANCE: f64 = 0.6;
/// Smoothing keeps interior vertices at least this far (× edge length) from the boundary.
const SMOOTH_CLEARANCE: f64 = 0.3;
/// Laplacian smoothing passes over the vertices near the boundary.
const SMOOTH_PASSES: usize = 3;

type Cdt = ConstrainedDelaunayTriangulation<Point2<f64>>;

/// Triangulates the polygon `boundary` (CCW, rest coordinates): returns the interior vertices
/// it added and the triangles (CCW), indexing the boundary points first, then the interior.
fn triangulate(
    boundary: &[P2],
    h: f64,
    min_angle_deg: f64,
) -> Result<(Vec<P2>, Vec<[usize; 3]>), String> {
    let nb = boundary.len();
    let grid = BoundaryGrid::new(boundary, h);
    let mut interior = lattice(boundary, h, &grid);
    let cdt = build(boundary, &interior)?;
    smooth(&cdt, nb, &mut interior, &grid, h);
    let mut cdt = build(boundary, &interior)?;
    let ideal = 3f64.sqrt() / 4.0 * h * h;
    cdt.refine(
        RefinementParameters::<f64>::new()
            .exclude_outer_faces(true)
            .keep_constraint_edges()
            .with_angle_limit(AngleLimit::from_deg(min_angle_deg))
            .with_max_allowed_area(1.5 * ideal)
            .with_min_required_area(ideal / 16.0)
            .with_max_additional_vertices(cdt.num_vertices() / 2 + 64),
    );
    let inside = inside_faces(&cdt);
    // boundary vertices keep their ids (bulk loading keeps the order; refinement appends)
    let mut id = vec![usize::MAX; cdt.num_vertices()];
    id[..nb].iter_mut().enumerate().for_each(|(i, x)| *x = i);
    let mut points = Vec::new();
    let mut triangles = Vec::new();
    for face in cdt.inner_faces() {
        if !inside[face.fix().index()] {
            continue;
        }
        let tri = face.vertices().map(|v| {
            let k = v.fix().index();
            if id[k] == usize::MAX {
                id[k] = nb + points.len();
                let p = v.position();
                points.push([p.x, p.y]);
            }
            id[k]
        });
        triangles.push(tri);
    }
    Ok((points, triangles))
}

/// The constrained Delaunay triangulation of the boundary loop and the interior points.
fn build(boundary: &[P2], interior: &[P2]) -> Result<Cdt, String> {
    let nb = boundary.len();
    let vertices: Vec<Point2<f64>> = boundary
        .iter()
        .chain(interior)
        .map(|p| Point2::new(p[0], p[1]))
        .collect();
    let n = vertices.len();
    let edges = (0..nb).map(|i| [i, (i + 1) % nb]).collect();
    let mut conflict = false;
    let cdt = Cdt::try_bulk_load_cdt(vertices, edges, |_| conflict = true)
        .map_err(|e| format!("triangulation failed: {e:?}"))?;
    if conflict || cdt.num_vertices() != n {
        return Err("outline touches itself: boundary points coincide or sides cross".into());
    }
    Ok(cdt)
}

/// Per face index: whether the face lies inside the constraint loop (flood fill from the
/// convex hull, stopping at constraint edges).
fn inside_faces(cdt: &Cdt) -> Vec<bool> {
    let mut inside = vec![true; cdt.num_all_faces()];
    inside[0] = false; // the outer face
    let mut stack = Vec::new();
    for e in cdt.convex_hull() {
        if !e.is_constraint_edge() {
            if let Some(f) = e.rev().face().as_inner() {
                stack.push(f.fix());
            }
        }
    }
    while let Some(f) = stack.pop() {
        if !inside[f.index()] {
            continue;
        }
        inside[f.index()] = false;
        for e in cdt.face(f).adjacent_edges() {
            if !e.is_constraint_edge() {
                if let Some(g) = e.rev().face().as_inner() {
                    if inside[g.fix().index()] {
                        stack.push(g.fix());
                    }
                }
            }
        }
    }
    inside
}

/// Laplacian smoothing of the interior vertices near the boundary (closer than `h`), over the
/// neighbours they have in `cdt` (Jacobi passes). Each move stays inside the disc
/// free of boundary around the vertex and ends away from the boundary.
fn smooth(cdt: &Cdt, nb: usize, interior: &mut [P2], grid: &BoundaryGrid, h: f64) {
    let band: Vec<(usize, Vec<usize>)> = (0..interior.len())
        .filter(|&k| grid.distance(interior[k]) < h)
        .map(|k| {
            let v = cdt.vertex(FixedVertexHandle::from_index(nb + k));
            (k, v.out_edges().map(|e| e.to().fix().index()).collect())
        })
        .collect();
    let position = |interior: &[P2], i: usize| {
        if i < nb {
            let p = cdt.vertex(FixedVertexHandle::from_index(i)).position();
            [p.x, p.y]
        } else {
            interior[i - nb]
        }
    };
    let mut moved = Vec::with_capacity(band.len());
    for _ in 0..SMOOTH_PASSES {
        moved.clear();
        for (k, ring) in &band {
            let mut q = [0.0, 0.0];
            for &i in ring {
                let p = position(interior, i);
                q = [q[0] + p[0], q[1] + p[1]];
            }
            let q = q.map(|c| c / ring.len() as f64);
            let old = interior[*k];
            let step = (q[0] - old[0]).hypot(q[1] - old[1]);
            if step < grid.distance(old) && grid.distance(q) >= SMOOTH_CLEARANCE * h {
                moved.push((*k, q));
            }
        }
        for &(k, q) in &moved {
            interior[k] = q;
        }
    }
}

/// A hexagonal lattice of spacing `h`, rows along u, covering the inside of the polygon at
/// least `LATTICE_CLEARANCE · h` from its sides.
fn lattice(boundary: &[P2], h: f64, grid: &BoundaryGrid) -> Vec<P2> {
    let (lo, hi) = bbox(boundary);
    let dv = h * 3f64.sqrt() / 2.0;
    let rows = ((hi[1] - lo[1]) / dv).floor();
    let v_start = lo[1] + 0.5 * (hi[1] - lo[1] - rows * dv);
    let cols = ((hi[0] - lo[0]) / h).floor();
    let u_start = lo[0] + 0.5 * (hi[0] - lo[0] - cols * h);
    let n = boundary.len();
    let mut points = Vec::new();
    let mut cross = Vec::new();
    for r in 0..=rows as usize {
        let v = v_start + r as f64 * dv;
        cross.clear();
        for i in 0..n {
            let (a, b) = (boundary[i], boundary[(i + 1) % n]);
            if (a[1] > v) != (b[1] > v) {
                cross.push(a[0] + (v - a[1]) * (b[0] - a[0]) / (b[1] - a[1]));
            }
        }
        cross.sort_by(f64::total_cmp);
        let u0 = u_start + if r % 2 == 1 { 0.5 * h } else { 0.0 };
        for span in cross.chunks_exact(2) {
            let first = ((span[0] - u0) / h).ceil() as i64;
            let last = ((span[1] - u0) / h).floor() as i64;
            for i in first..=last {
                let p = [u0 + i as f64 * h, v];
                if p[0] > span[0] && p[0] < span[1] && grid.distance(p) >= LATTICE_CLEARANCE * h {
                    points.push(p);
                }
            }
        }
    }
    points
}

fn bbox(points: &[P2]) -> (P2, P2) {
    let mut lo = [f64::INFINITY; 2];
    let mut hi = [f64::NEG_INFINITY; 2];
    for p in points {
        for d in 0..2 {
            lo[d] = lo[d].min(p[d]);
            hi[d] = hi[d].max(p[d]);
        }
    }
    (lo, hi)
}

/// Distance to the sides of a closed polygon, capped at `reach`: each cell of a uniform grid
/// (cell size `reach`) lists the sides that come within `reach` of it.
struct BoundaryGrid {
    points: Vec<P2>,
    origin: P2,
    reach: f64,
    nx: usize,
    ny: usize,
    cells: Vec<Vec<u32>>,
}

impl BoundaryGrid {
    fn new(points: &[P2], reach: f64) -> Self {
        let (lo, hi) = bbox(points);
        let origin = [lo[0] - reach, lo[1] - reach];
        let nx = ((hi[0] - origin[0] + reach) / reach).ceil() as usize + 1;
        let ny = ((hi[1] - origin[1] + reach) / reach).ceil() as usize + 1;
        let mut grid = BoundaryGrid {
            points: points.to_vec(),
            origin,
            reach,
            nx,
            ny,
            cells: vec![Vec::new(); nx * ny],
        };
        let n = points.len();
        for i in 0..n {
            let (a, b) = (points[i], points[(i + 1) % n]);
            let c0 = grid.cell([a[0].min(b[0]) - reach, a[1].min(b[1]) - reach]);
            let c1 = grid.cell([a[0].max(b[0]) + reach, a[1].max(b[1]) + reach]);
            for y in c0.1..=c1.1 {
                for x in c0.0..=c1.0 {
                    grid.cells[y * nx + x].push(i as u32);
                }
            }
        }
        grid
    }

    fn cell(&self, p: P2) -> (usize, usize) {
        let x = ((p[0] - self.origin[0]) / self.reach).floor().max(0.0) as usize;
        let y = ((p[1] - self.origin[1]) / self.reach).floor().max(0.0) as usize;
        (x.min(self.nx - 1), y.min(self.ny - 1))
    }

    /// Distance from `p` to the nearest side, or `reach` if none is nearer.
    fn distance(&self, p: P2) -> f64 {
        let (x, y) = self.cell(p);
        let n = self.points.len();
        let mut best = self.reach;
        for &i in &self.cells[y * self.nx + x] {
            let (a, b) = (self.points[i as usize], self.points[(i as usize + 1) % n]);
            best = best.min(point_segment(p, a, b));
        }
        best
    }
}

fn point_segment(p: P2, a: P2, b: P2) -> f64 {
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    let l2 = dx * dx + dy * dy;
    let t = if l2 > 0.0 {
        (((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (p[0] - a[0] - t * dx).hypot(p[1] - a[1] - t * dy)
}
