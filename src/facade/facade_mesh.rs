//! 3D facades from a derived grammar: the leaves of [`Grammar::derive`] (a guillotine
//! partition of the facade rectangle) become a closed, watertight slab — a wall of some
//! thickness whose windows and doors are recessed boxes — with texture coordinates into the
//! rectified photo (`facade-reconstruction.md` §4.2 D, §5.4 "Geometry"). This module owns the
//! mesh and its checks; the files are written by [`super::facade_export`].
//!
//! Axes: x right, y **up** (the facade's y-down units are flipped), z out of the facade; the
//! front is at z = 0 (recesses at z = −depth), the back at z = −thickness, the origin at the
//! facade's bottom-left front corner, in metres.
//!
//! The front is **conforming**: all leaf boundaries form one global grid, every grid cell
//! lies inside exactly one leaf and is emitted at that leaf's depth, with vertical reveals
//! between neighbouring cells of different depths and side quads round the outer boundary;
//! reveals are cut at every depth level, so vertices are shared (indexed by grid node and
//! depth) and the result is a closed, consistently oriented 2-manifold: no T-junctions.
//!
//! [`Grammar::derive`]: super::grammar::Grammar::derive

use std::collections::HashMap;
use std::ops::Range;

use super::grammar::{Leaf, Scope};
use super::labels::Class;
use crate::geometry::Vec3;

/// How leaves become geometry. Lengths in metres, except `texture_size` (facade units).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MeshParams {
    /// Metres per facade unit (e.g. floor height 3 m / floor height in pixels).
    pub scale: f64,
    /// Thickness of the wall slab (m), e.g. 0.3.
    pub wall_thickness: f64,
    /// Recess of windows behind the front (m), e.g. 0.12; `0 ≤ depth < wall_thickness`.
    pub window_depth: f64,
    /// Recess of doors behind the front (m); `0 ≤ depth < wall_thickness`.
    pub door_depth: f64,
    /// Size of the photo that [`Leaf::source`] rectangles refer to (facade units): texture
    /// coordinates are source positions divided by it.
    pub texture_size: (f64, f64),
}

impl MeshParams {
    /// Typical depths (0.3 m wall, windows 0.12 m and doors 0.15 m deep) at `scale` metres per
    /// facade unit, for a photo of `texture_size` facade units.
    pub fn new(scale: f64, texture_size: (f64, f64)) -> Self {
        MeshParams {
            scale,
            wall_thickness: 0.3,
            window_depth: 0.12,
            door_depth: 0.15,
            texture_size,
        }
    }

    /// Recess of a class behind the front (m): windows and doors are recessed, the rest is
    /// flush with the front.
    pub fn depth(&self, class: Class) -> f64 {
        match class {
            Class::Window => self.window_depth,
            Class::Door => self.door_depth,
            _ => 0.0,
        }
    }

    /// Every length finite and positive, every recess in `[0, wall_thickness)`.
    pub fn check(&self) -> Result<(), String> {
        let pos = |v: f64| v.is_finite() && v > 0.0;
        let (t, (tw, th)) = (self.wall_thickness, self.texture_size);
        let fail = if !pos(self.scale) {
            format!("scale {} m/unit must be finite and > 0", self.scale)
        } else if !pos(t) {
            format!("wall thickness {t} m must be finite and > 0")
        } else if !(pos(tw) && pos(th)) {
            format!("texture size {tw} × {th} must be finite and > 0")
        } else {
            for (what, d) in [("window", self.window_depth), ("door", self.door_depth)] {
                if !(d.is_finite() && d >= 0.0 && d < t) {
                    return Err(format!(
                        "facade mesh: {what} depth {d} m must be ≥ 0 and less than the wall thickness {t} m"
                    ));
                }
            }
            return Ok(());
        };
        Err(format!("facade mesh: {fail}"))
    }
}

/// What a triangle is part of, hence its material.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Surface {
    /// The visible front of a leaf of this class (recessed for windows and doors).
    Front(Class),
    /// The vertical sides of a recess (jambs, lintels, sills), inside the facade.
    Reveal,
    /// The slab's outer sides and back.
    Shell,
    /// Inserted elements (window frames, mullions, door panels): closed solids of their own
    /// ([`super::element_library::insert_elements`]).
    Element,
}

impl Surface {
    /// Every surface, in the order groups are stored.
    pub const ALL: [Surface; 9] = [
        Surface::Front(Class::Wall),
        Surface::Front(Class::Window),
        Surface::Front(Class::Door),
        Surface::Front(Class::Balcony),
        Surface::Front(Class::Background),
        Surface::Front(Class::Ignore),
        Surface::Reveal,
        Surface::Shell,
        Surface::Element,
    ];

    /// Material name: the class name for fronts, `reveal`, `shell`, `element`.
    pub fn name(self) -> &'static str {
        match self {
            Surface::Front(c) => c.name(),
            Surface::Reveal => "reveal",
            Surface::Shell => "shell",
            Surface::Element => "element",
        }
    }

    /// Whether it shows the photo (fronts and reveals); the shell and elements are plain.
    pub fn textured(self) -> bool {
        !matches!(self, Surface::Shell | Surface::Element)
    }

    fn order(self) -> usize {
        Surface::ALL.iter().position(|s| *s == self).unwrap_or(0)
    }
}

/// A run of triangles sharing one surface (material).
#[derive(Debug, Clone, PartialEq)]
pub struct Group {
    /// The surface.
    pub surface: Surface,
    /// Its triangles: a range of [`FacadeMesh::triangles`].
    pub triangles: Range<usize>,
}

/// A closed facade slab. Positions and texture coordinates are indexed separately (as in
/// OBJ): a grid node is one position whatever leaves meet there, but each leaf maps it to its
/// own place in the photo.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct FacadeMesh {
    /// Vertex positions (m): x right, y up, z out of the facade.
    pub positions: Vec<Vec3>,
    /// Triangles (indices into `positions`), counter-clockwise seen from outside.
    pub triangles: Vec<[usize; 3]>,
    /// Texture coordinates in **image convention**: `u = x / width`, `v = y / height` from the
    /// photo's top-left corner (glTF's convention; OBJ writers store `1 − v`).
    pub uvs: Vec<[f64; 2]>,
    /// Per triangle, the indices into `uvs` of its corners.
    pub uv_triangles: Vec<[usize; 3]>,
    /// Triangles by surface: consecutive, non-empty ranges covering all triangles.
    pub groups: Vec<Group>,
}

impl FacadeMesh {
    /// Signed volume enclosed (m³): positive for a closed mesh wound outwards.
    pub fn signed_volume(&self) -> f64 {
        self.triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| self.positions[i]);
                a.dot(&b.cross(&c)) / 6.0
            })
            .sum()
    }

    /// Every index in range, both triangle lists of the same length, finite positions and
    /// texture coordinates, and groups that cover the triangles in order: what any consumer
    /// (writers included) needs before indexing the mesh.
    pub fn check_indices(&self) -> Result<(), String> {
        let finite = |p: &[f64]| p.iter().all(|c| c.is_finite());
        let out = |ts: &[[usize; 3]], n: usize| ts.iter().position(|t| t.iter().any(|&i| i >= n));
        let (n, nt, ntri) = (self.positions.len(), self.uvs.len(), self.triangles.len());
        let fail = if let Some(i) = self.positions.iter().position(|p| !finite(p.as_slice())) {
            format!("vertex {i} has a non-finite position")
        } else if let Some(i) = self.uvs.iter().position(|p| !finite(p)) {
            format!("texture coordinate {i} is not finite")
        } else if self.uv_triangles.len() != ntri {
            format!(
                "{ntri} triangles but {} texture triangles",
                self.uv_triangles.len()
            )
        } else if let Some(t) = out(&self.triangles, n) {
            format!("triangle {t} indexes a vertex out of range ({n} vertices)")
        } else if let Some(t) = out(&self.uv_triangles, nt) {
            format!("triangle {t} indexes a texture coordinate out of range ({nt})")
        } else {
            let mut end = 0;
            for g in &self.groups {
                let r = &g.triangles;
                if r.start != end || r.end <= r.start {
                    return Err(format!(
                        "group {} has range {r:?} after {end}",
                        g.surface.name()
                    ));
                }
                end = r.end;
            }
            if end == ntri {
                return Ok(());
            }
            format!("groups cover {end} of {ntri} triangles")
        };
        Err(fail)
    }
}

/// Builds the facade slab of `leaves` (a partition of the facade rectangle, as
/// [`Grammar::derive`](super::grammar::Grammar::derive) returns). Errors: invalid parameters,
/// no leaves, non-finite or inverted rectangles, a source outside the texture, leaves that
/// overlap or leave a gap, two recesses meeting only at a corner where the solid would
/// pinch to a line (not a manifold), or a front grid of more cells than `max_elements`.
pub fn build(leaves: &[Leaf], params: &MeshParams) -> Result<FacadeMesh, String> {
    params.check()?;
    if leaves.is_empty() {
        return Err("facade mesh: no leaves".into());
    }
    let (tw, th) = params.texture_size;
    let ttol = 1e-6 * tw.max(th);
    for (k, l) in leaves.iter().enumerate() {
        let ok = |s: &Scope| {
            [s.x0, s.y0, s.x1, s.y1].iter().all(|v| v.is_finite()) && s.x1 >= s.x0 && s.y1 >= s.y0
        };
        if !ok(&l.scope) || !ok(&l.source) {
            return Err(format!(
                "facade mesh: leaf {k} ({}) has an invalid rectangle: {l:?}",
                l.class.name()
            ));
        }
        let s = &l.source;
        if s.x0 < -ttol || s.y0 < -ttol || s.x1 > tw + ttol || s.y1 > th + ttol {
            return Err(format!(
                "facade mesh: leaf {k} ({}) source {s:?} lies outside the texture {tw} × {th}",
                l.class.name()
            ));
        }
    }
    let fold = |f: fn(f64, f64) -> f64, init: f64, get: fn(&Scope) -> f64| {
        leaves.iter().map(|l| get(&l.scope)).fold(init, f)
    };
    let xmin = fold(f64::min, f64::INFINITY, |s| s.x0);
    let xmax = fold(f64::max, f64::NEG_INFINITY, |s| s.x1);
    let ymin = fold(f64::min, f64::INFINITY, |s| s.y0);
    let ymax = fold(f64::max, f64::NEG_INFINITY, |s| s.y1);
    let extent = (xmax - xmin).max(ymax - ymin);
    if !(xmax > xmin && ymax > ymin) {
        return Err(format!(
            "facade mesh: the leaves span {} × {}: nothing to build",
            xmax - xmin,
            ymax - ymin
        ));
    }
    let tol = 1e-9 * extent;
    let xs = merged(leaves.iter().flat_map(|l| [l.scope.x0, l.scope.x1]), tol);
    let ys = merged(leaves.iter().flat_map(|l| [l.scope.y0, l.scope.y1]), tol);
    let (nx, ny) = (xs.len() - 1, ys.len() - 1);
    // the grid's cells are counted against max_elements before they are allocated
    let max = crate::limits::get().max_elements;
    crate::limits::check_count(
        &format!("facade mesh: the front's grid of {nx} × {ny} cells"),
        (nx as u64).saturating_mul(ny as u64),
        "max_elements",
        max,
    )
    .map_err(|e| e.to_string())?;

    // Which leaf owns each grid cell.
    let mut owner = vec![usize::MAX; nx * ny];
    for (k, l) in leaves.iter().enumerate() {
        let (i0, i1) = (nearest(&xs, l.scope.x0), nearest(&xs, l.scope.x1));
        let (j0, j1) = (nearest(&ys, l.scope.y0), nearest(&ys, l.scope.y1));
        for j in j0..j1 {
            for i in i0..i1 {
                let o = &mut owner[j * nx + i];
                if *o != usize::MAX {
                    return Err(format!(
                        "facade mesh: leaves {} and {k} overlap at ({}, {}) (not a partition)",
                        *o, xs[i], ys[j]
                    ));
                }
                *o = k;
            }
        }
    }
    if let Some(c) = owner.iter().position(|&o| o == usize::MAX) {
        let (i, j) = (c % nx, c / nx);
        return Err(format!(
            "facade mesh: no leaf covers [{}, {}] × [{}, {}] (not a partition)",
            xs[i],
            xs[i + 1],
            ys[j],
            ys[j + 1]
        ));
    }

    // Depth levels, front to back; the outside counts as the back level.
    let mut depths: Vec<f64> = [0.0, params.wall_thickness]
        .into_iter()
        .chain(leaves.iter().map(|l| params.depth(l.class)))
        .collect();
    depths.sort_by(f64::total_cmp);
    depths.dedup();
    let level_of = |d: f64| depths.iter().position(|&x| x == d).unwrap_or(0);
    let back = depths.len() - 1;
    let cell_leaf = |i: isize, j: isize| -> Option<usize> {
        (i >= 0 && j >= 0 && (i as usize) < nx && (j as usize) < ny)
            .then(|| owner[j as usize * nx + i as usize])
    };
    let level = |i: isize, j: isize| {
        cell_leaf(i, j).map_or(back, |k| level_of(params.depth(leaves[k].class)))
    };

    // Recesses meeting only diagonally would pinch the solid along a line.
    for j in 1..ny as isize {
        for i in 1..nx as isize {
            let [a, b, c, d] = [
                level(i - 1, j - 1),
                level(i, j - 1),
                level(i, j),
                level(i - 1, j),
            ];
            if a.max(c) < b.min(d) || b.max(d) < a.min(c) {
                return Err(format!(
                    "facade mesh: at ({}, {}) leaves of different depths meet only at a corner; the solid \
                     would pinch there (not a manifold)",
                    xs[i as usize], ys[j as usize]
                ));
            }
        }
    }

    let mut b = Builder {
        positions: Vec::new(),
        vertex: HashMap::new(),
        uvs: Vec::new(),
        uv_index: HashMap::new(),
        buckets: vec![Vec::new(); Surface::ALL.len()],
    };
    let s = params.scale;
    let pos = |i: usize, j: usize, l: usize| {
        Vec3::new((xs[i] - xmin) * s, (ymax - ys[j]) * s, -depths[l])
    };
    let uv_at =
        |k: usize, i: usize, j: usize| leaf_uv(&leaves[k], xs[i], ys[j], params.texture_size);

    // Fronts and back, cell by cell.
    for j in 0..ny {
        for i in 0..nx {
            let k = owner[j * nx + i];
            let l = level(i as isize, j as isize);
            let nodes = [(i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1)];
            let front = nodes.map(|(a, c)| (b.vertex(a, c, l, &pos), b.uv(k, a, c, &uv_at)));
            b.quad(Surface::Front(leaves[k].class), front, Vec3::z());
            let rear = nodes.map(|(a, c)| (b.vertex(a, c, back, &pos), b.uv(k, a, c, &uv_at)));
            b.quad(Surface::Shell, rear, -Vec3::z());
        }
    }
    // Reveals and sides along every grid edge whose two cells differ in depth: vertical grid
    // lines (x = xs[i]) then horizontal ones (y = ys[j]); `before` is left / above.
    let vertical = (0..ny).flat_map(|j| (0..=nx).map(move |i| (i as isize, j as isize, true)));
    let horizontal = (0..=ny).flat_map(|j| (0..nx).map(move |i| (i as isize, j as isize, false)));
    let edges = vertical.chain(horizontal).map(|(i, j, v)| match v {
        true => ((i - 1, j), (i, j), [(i, j), (i, j + 1)], Vec3::x()),
        false => ((i, j - 1), (i, j), [(i, j), (i + 1, j)], -Vec3::y()),
    });
    for (before, after, ends, towards_after) in edges {
        let (lb, la) = (level(before.0, before.1), level(after.0, after.1));
        if lb == la {
            continue;
        }
        // the reveal faces from the shallow cell's solid into the deep cell's hollow
        let (shallow, deep, normal) = if lb < la {
            (before, after, towards_after)
        } else {
            (after, before, -towards_after)
        };
        let Some(ks) = cell_leaf(shallow.0, shallow.1) else {
            continue; // unreachable: the outside is the deepest level
        };
        let kd = cell_leaf(deep.0, deep.1);
        let surface = if kd.is_some() {
            Surface::Reveal
        } else {
            Surface::Shell
        };
        let (lo, hi) = (lb.min(la), lb.max(la));
        let [(i0, j0), (i1, j1)] = ends.map(|(a, c)| (a as usize, c as usize));
        for l in lo..hi {
            let corner = |b: &mut Builder, i: usize, j: usize, l: usize| {
                let k = if l == lo { ks } else { kd.unwrap_or(ks) };
                (b.vertex(i, j, l, &pos), b.uv(k, i, j, &uv_at))
            };
            let q = [
                corner(&mut b, i0, j0, l),
                corner(&mut b, i1, j1, l),
                corner(&mut b, i1, j1, l + 1),
                corner(&mut b, i0, j0, l + 1),
            ];
            b.quad(surface, q, normal);
        }
    }
    Ok(b.finish())
}

/// Checks that `mesh` is a closed, consistently outward-wound 2-manifold: indices in range,
/// no degenerate (zero-area or collinear) triangle, every edge used by exactly two triangles
/// in opposite directions, and a positive enclosed volume.
pub fn check_closed(mesh: &FacadeMesh) -> Result<(), String> {
    mesh.check_indices()?;
    if mesh.triangles.is_empty() {
        return Err("no triangles".into());
    }
    for (t, tri) in mesh.triangles.iter().enumerate() {
        let [a, b, c] = tri.map(|i| mesh.positions[i]);
        let (e1, e2) = (b - a, c - a);
        let cross = e1.cross(&e2).norm();
        if cross.is_nan() || cross <= 1e-12 * e1.norm() * e2.norm() {
            return Err(format!(
                "triangle {t} {tri:?} is degenerate (area {})",
                cross / 2.0
            ));
        }
    }
    let mut directed: HashMap<(usize, usize), usize> = HashMap::new();
    for t in &mesh.triangles {
        for k in 0..3 {
            *directed.entry((t[k], t[(k + 1) % 3])).or_insert(0) += 1;
        }
    }
    for (&(a, b), &n) in &directed {
        let back = directed.get(&(b, a)).copied().unwrap_or(0);
        if n != 1 || back != 1 {
            return Err(format!(
                "edge {a}–{b} ({:?} – {:?}) is used {n} time(s) one way and {back} the other \
                 (needs exactly once each: closed and consistently wound)",
                mesh.positions[a].as_slice(),
                mesh.positions[b].as_slice()
            ));
        }
    }
    let v = mesh.signed_volume();
    if v.is_nan() || v <= 0.0 {
        return Err(format!(
            "signed volume {v} is not positive: the mesh is wound inwards"
        ));
    }
    Ok(())
}

/// Sorted distinct values, those closer than `tol` to the previous kept one merged into it.
fn merged(values: impl Iterator<Item = f64>, tol: f64) -> Vec<f64> {
    let mut v: Vec<f64> = values.collect();
    v.sort_by(f64::total_cmp);
    let mut out: Vec<f64> = Vec::with_capacity(v.len());
    for x in v {
        if out.last().is_none_or(|&l| x - l > tol) {
            out.push(x);
        }
    }
    out
}

/// Index of the grid coordinate nearest to `v` (`grid` sorted, non-empty).
fn nearest(grid: &[f64], v: f64) -> usize {
    let i = grid.partition_point(|&g| g < v).min(grid.len() - 1);
    if i > 0 && (v - grid[i - 1]).abs() <= (grid[i] - v).abs() {
        i - 1
    } else {
        i
    }
}

/// Texture coordinate (image convention) of the facade point (x, y) inside `leaf`: its
/// relative place in the leaf's scope, carried to the same relative place of its source.
fn leaf_uv(leaf: &Leaf, x: f64, y: f64, (tw, th): (f64, f64)) -> [f64; 2] {
    let rel = |v: f64, a: f64, b: f64| {
        if b > a {
            ((v - a) / (b - a)).clamp(0.0, 1.0)
        } else {
            0.0
        }
    };
    let (sc, src) = (&leaf.scope, &leaf.source);
    let u = src.x0 + rel(x, sc.x0, sc.x1) * src.width();
    let v = src.y0 + rel(y, sc.y0, sc.y1) * src.height();
    [(u / tw).clamp(0.0, 1.0), (v / th).clamp(0.0, 1.0)]
}

/// Shared vertices and texture coordinates, and triangles by surface.
struct Builder {
    positions: Vec<Vec3>,
    vertex: HashMap<(usize, usize, usize), usize>,
    uvs: Vec<[f64; 2]>,
    uv_index: HashMap<(usize, usize, usize), usize>,
    buckets: Vec<Vec<([usize; 3], [usize; 3])>>,
}

impl Builder {
    /// The vertex of grid node (i, j) at depth level `l`.
    fn vertex(
        &mut self,
        i: usize,
        j: usize,
        l: usize,
        pos: &impl Fn(usize, usize, usize) -> Vec3,
    ) -> usize {
        let n = self.positions.len();
        let id = *self.vertex.entry((i, j, l)).or_insert(n);
        if id == n {
            self.positions.push(pos(i, j, l));
        }
        id
    }

    /// The texture coordinate of grid node (i, j) as seen by leaf `k`.
    fn uv(
        &mut self,
        k: usize,
        i: usize,
        j: usize,
        uv_at: &impl Fn(usize, usize, usize) -> [f64; 2],
    ) -> usize {
        let n = self.uvs.len();
        let id = *self.uv_index.entry((k, i, j)).or_insert(n);
        if id == n {
            self.uvs.push(uv_at(k, i, j));
        }
        id
    }

    /// Two triangles of the planar quad `q` (corners in cyclic order), wound so that their
    /// normal points along `normal`.
    fn quad(&mut self, surface: Surface, q: [(usize, usize); 4], normal: Vec3) {
        let p = q.map(|c| self.positions[c.0]);
        let q = if (p[1] - p[0]).cross(&(p[2] - p[0])).dot(&normal) < 0.0 {
            [q[0], q[3], q[2], q[1]]
        } else {
            q
        };
        let bucket = &mut self.buckets[surface.order()];
        for t in [[q[0], q[1], q[2]], [q[0], q[2], q[3]]] {
            bucket.push((t.map(|c| c.0), t.map(|c| c.1)));
        }
    }

    fn finish(self) -> FacadeMesh {
        let mut mesh = FacadeMesh {
            positions: self.positions,
            uvs: self.uvs,
            ..Default::default()
        };
        for (surface, bucket) in Surface::ALL.into_iter().zip(self.buckets) {
            if bucket.is_empty() {
                continue;
            }
            let start = mesh.triangles.len();
            for (t, uv) in bucket {
                mesh.triangles.push(t);
                mesh.uv_triangles.push(uv);
            }
            mesh.groups.push(Group {
                surface,
                triangles: start..mesh.triangles.len(),
            });
        }
        mesh
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grid_lines_merge_within_tolerance_and_snap_to_the_nearest() {
        let xs = merged([3.0, 0.0, 3.0 + 1e-12, 10.0, 7.0, 3.0].into_iter(), 1e-9);
        assert_eq!(xs, vec![0.0, 3.0, 7.0, 10.0]);
        assert_eq!(
            [-1.0, 3.0 - 1e-12, 4.9, 5.1, 11.0].map(|v| nearest(&xs, v)),
            [0, 1, 1, 2, 3]
        );
        let l = Leaf {
            scope: Scope {
                x0: 10.0,
                y0: 0.0,
                x1: 20.0,
                y1: 5.0,
            },
            source: Scope {
                x0: 0.0,
                y0: 5.0,
                x1: 5.0,
                y1: 10.0,
            },
            class: Class::Window,
            element: None,
        };
        // the middle of the scope is the middle of the source; clamped to the leaf
        assert_eq!(leaf_uv(&l, 15.0, 2.5, (10.0, 20.0)), [0.25, 0.375]);
        assert_eq!(leaf_uv(&l, 20.0 + 1e-12, 5.0, (10.0, 20.0)), [0.5, 0.5]);
    }
}
