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

use super::layers::{layer_lifts, mean_edge_length};
use super::mesh::GarmentMesh;
use super::over_the_top::{column_tops, over_the_top, over_the_top_lifts};
use super::relax::{push_out, relax};
use super::shell::Shell;
use super::silhouette::{Landmarks, Silhouettes};
use super::{Pattern, PatternError, Side, P2};
use crate::contact::MeshBody;
use crate::geometry::Vec3;

/// Settings of the pre-positioning.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default)]
pub struct PrepositionParameters {
    /// Distance kept between the garment and the skin (m), the seed's d_z.
    pub clearance: f64,
    /// Relaxation sweeps after the mapping (0: none).
    pub relax_iterations: usize,
    /// Distance (m) by which a piece overlapping an earlier one on the same figurine is lifted
    /// off it (two layers, such as a skirt's vent extensions); 0 leaves overlaps as they are.
    pub layer_gap: f64,
}

impl Default for PrepositionParameters {
    fn default() -> Self {
        PrepositionParameters {
            clearance: 0.012,
            relax_iterations: 60,
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

/// The figurine (front or back view) transform of a piece: flat point ↦ (X, height).
pub(super) struct Figurine {
    pub(super) side: Side,
    rot: [f64; 4],
    anchor: P2,
    pub(super) at: P2,
}

impl Figurine {
    fn apply(&self, p: &P2) -> P2 {
        let (x, y) = (p[0] - self.anchor[0], p[1] - self.anchor[1]);
        let r = &self.rot;
        [
            self.at[0] + r[0] * x + r[1] * y,
            self.at[1] + r[2] * x + r[3] * y,
        ]
    }
}

/// One piece's horizontal interval in one row: (piece, X0, X1, group).
#[derive(Clone, Copy)]
struct Interval {
    piece: usize,
    x0: f64,
    x1: f64,
    group: usize,
}

/// A group's shell and the arc positions of its front and back centres.
struct Group {
    shell: Shell,
    /// Widening factor of the shell (≥ 1).
    k: f64,
    /// Left coordinates of the front and back centres.
    centre_s: [f64; 2],
    front_arc: f64,
    front_c: f64,
    back_arc: f64,
    back_c: f64,
}

impl Group {
    /// Widens the shell by `k` and finds the arc positions of the centres on it.
    fn finish(&mut self, k: f64) {
        self.k = k;
        if k > 1.0 {
            self.shell = self.shell.scaled(k);
        }
        self.front_arc = self.shell.arc_at(self.centre_s[0], true);
        self.back_arc = self.shell.arc_at(self.centre_s[1], false);
    }
}

/// Largest change of a shell's widening factor per metre of height: the shell narrows or
/// widens gradually, so that vertical edges are not sheared where the garment's width changes
/// fast (an armhole).
const WIDENING_RATE: f64 = 0.4;

/// Distance (m) along a piece over which a layer's lift falls from the layer gap to 0.
const LAYER_RAMP: f64 = 0.03;

struct Row {
    intervals: Vec<Interval>,
    groups: Vec<Group>,
}

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
    let (ymin, ymax) = fig_pos
        .iter()
        .fold((f64::MAX, f64::MIN), |(l, h), p| (l.min(p[1]), h.max(p[1])));
    let (r0, r1) = (
        sil.row(ymin).saturating_sub(1),
        (sil.row(ymax) + 1).min(sil.nh - 1),
    );
    let mut rows: Vec<Row> = (r0..=r1)
        .map(|i| build_row(i, garment, &figs, &fig_pos, sil, marks, dz))
        .collect();
    // above the lower chest (where armholes open the ring) the widening factor of one-group rows
    // may only fall gradually going up: the shell does not shrink where the garment's width
    // drops fast along an armhole, and the seams below, where the ring closes, still meet
    let step = WIDENING_RATE * sil.cell;
    let from = marks.waist + 0.25 * (marks.armpit - marks.waist);
    let mut k: Vec<Option<f64>> = rows
        .iter()
        .map(|r| (r.groups.len() == 1).then(|| r.groups[0].k))
        .collect();
    for i in 1..k.len() {
        if sil.h_of(r0 + i) < from {
            continue;
        }
        if let (Some(a), Some(b)) = (k[i - 1], k[i]) {
            k[i] = Some(b.max(a - step));
        }
    }
    for (row, ki) in rows.iter_mut().zip(&k) {
        for g in row.groups.iter_mut() {
            let f = ki.unwrap_or(g.k);
            g.finish(f);
        }
    }
    let mut x = vec![Vec3::zeros(); n];
    for v in 0..n {
        let [fx, fy] = fig_pos[v];
        let t = (fy - sil.h0) / sil.cell;
        let i0 = (t.floor() as usize).clamp(r0, r1);
        let i1 = (i0 + 1).min(r1);
        let w = (t - i0 as f64).clamp(0.0, 1.0);
        let k = piece_of[v];
        let a = place(&rows, i0 - r0, k, fx, &figs[k]);
        let b = place(&rows, i1 - r0, k, fx, &figs[k]);
        let (s, d) = match (a, b) {
            (Some(a), Some(b)) => (a[0] * (1.0 - w) + b[0] * w, a[1] * (1.0 - w) + b[1] * w),
            (Some(a), None) | (None, Some(a)) => (a[0], a[1]),
            (None, None) => {
                // no row of this piece here: search outwards
                let found = (1..rows.len()).find_map(|o| {
                    place(&rows, (i0 - r0).saturating_sub(o), k, fx, &figs[k]).or_else(|| {
                        place(&rows, (i0 - r0 + o).min(rows.len() - 1), k, fx, &figs[k])
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
    // push out what the shells did not keep clear (between rows, sharp features)
    let mut report = PrepositionReport {
        vertices: n,
        ..Default::default()
    };
    let reach = 1.0;
    report.pushed_out = push_out(&mut x, skin, dz);
    (report.initial_mean_strain, report.initial_max_strain) = edge_strain(garment, &x);
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
    report.seconds = start.elapsed().as_secs_f64();
    Ok((x, report))
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

/// Each piece's figurine transform from its placement.
fn figurines(
    pattern: &Pattern,
    garment: &GarmentMesh,
    marks: &Landmarks,
) -> Result<Vec<Figurine>, PatternError> {
    garment
        .pieces
        .iter()
        .map(|pm| {
            let err = |message: String| PatternError::Piece {
                source_name: pattern.source.clone(),
                piece: pm.name.clone(),
                message,
            };
            let piece = pattern
                .pieces
                .iter()
                .find(|p| p.name == pm.name)
                .ok_or_else(|| err("not in the pattern".into()))?;
            let pl = piece
                .placement
                .as_ref()
                .ok_or_else(|| err("has no placement: pre-positioning needs one".into()))?;
            let level = marks.get(&pl.level).ok_or_else(|| {
                err(format!(
                    "placement level '{}' is not a landmark (neck, shoulder, chest, armpit, waist, hip, crotch, knee, ankle)",
                    pl.level
                ))
            })?;
            let anchor = pm
                .corners
                .iter()
                .find(|(name, _)| *name == pl.anchor)
                .map(|&(_, v)| garment.flat[v])
                .ok_or_else(|| err(format!("placement anchor corner '{}' not found", pl.anchor)))?;
            let g = [
                piece.grain[1][0] - piece.grain[0][0],
                piece.grain[1][1] - piece.grain[0][1],
            ];
            // the smallest turn that makes the grain vertical
            let mut phi = std::f64::consts::FRAC_PI_2 - g[1].atan2(g[0]);
            while phi > std::f64::consts::FRAC_PI_2 {
                phi -= std::f64::consts::PI;
            }
            while phi <= -std::f64::consts::FRAC_PI_2 {
                phi += std::f64::consts::PI;
            }
            let (c, s) = (phi.cos(), phi.sin());
            Ok(Figurine {
                side: pl.side,
                rot: [c, -s, s, c],
                anchor,
                at: [pl.x, level + pl.dz],
            })
        })
        .collect()
}

/// Left coordinate of a figurine X on a side.
#[inline]
pub(super) fn s_of(side: Side, x: f64) -> f64 {
    match side {
        Side::Front => x,
        Side::Back => -x,
    }
}

/// The (s, d) of a vertex of piece `k` at figurine X in row `r`, if the piece crosses the row.
fn place(rows: &[Row], r: usize, k: usize, x: f64, fig: &Figurine) -> Option<[f64; 2]> {
    let row = &rows[r];
    let iv = row
        .intervals
        .iter()
        .filter(|iv| iv.piece == k)
        .min_by(|a, b| gap(a, x).total_cmp(&gap(b, x)))?;
    let g = &row.groups[iv.group];
    let sigma = match fig.side {
        Side::Front => g.front_arc + (x - g.front_c),
        Side::Back => g.back_arc + (x - g.back_c),
    };
    Some(g.shell.at(sigma))
}

fn gap(iv: &Interval, x: f64) -> f64 {
    (iv.x0 - x).max(x - iv.x1).max(0.0)
}

/// The intervals, groups and (unwidened) shells of one silhouette row; each group's widening
/// factor is the garment row's length over the shell's perimeter when above 1.
fn build_row(
    i: usize,
    garment: &GarmentMesh,
    figs: &[Figurine],
    fig_pos: &[P2],
    sil: &Silhouettes,
    marks: &Landmarks,
    dz: f64,
) -> Row {
    let h = sil.h_of(i);
    // intervals of each piece's boundary polygon on the line y = h
    let mut intervals = Vec::new();
    for (k, pm) in garment.pieces.iter().enumerate() {
        let b = &pm.boundary;
        let mut xs = Vec::new();
        for e in 0..b.len() {
            let (p, q) = (fig_pos[b[e]], fig_pos[b[(e + 1) % b.len()]]);
            if (p[1] <= h) != (q[1] <= h) {
                xs.push(p[0] + (h - p[1]) / (q[1] - p[1]) * (q[0] - p[0]));
            }
        }
        xs.sort_by(f64::total_cmp);
        for pair in xs.chunks_exact(2) {
            intervals.push(Interval {
                piece: k,
                x0: pair[0],
                x1: pair[1],
                group: usize::MAX,
            });
        }
    }
    // body sections: rows above the shoulders reuse the shoulder row; above the armpits the
    // torso is cut to its width below the armpits (the arms are not dressed)
    let body_row = i.min(sil.row(marks.shoulder));
    let centre = sil.col(0.0);
    let arm_cut = if sil.h_of(body_row) >= marks.armpit {
        let below = sil.row(marks.chest);
        sil.run_at(below, centre)
            .map(|r| (sil.s_of(r.0) - sil.cell, sil.s_of(r.1) + sil.cell))
    } else {
        None
    };
    let mut sections: Vec<(f64, f64, Vec<[f64; 2]>)> = Vec::new();
    for (j0, j1) in sil.runs(body_row) {
        let mut pts = Vec::new();
        for j in j0..=j1 {
            let s = sil.s_of(j);
            if let Some((lo, hi)) = arm_cut {
                if s < lo || s > hi {
                    continue;
                }
            }
            if let Some((f, b)) = sil.depths(body_row, j) {
                pts.push([s, f]);
                pts.push([s, b]);
            }
        }
        if !pts.is_empty() {
            let (lo, hi) = pts
                .iter()
                .fold((f64::MAX, f64::MIN), |(l, h), p| (l.min(p[0]), h.max(p[0])));
            sections.push((lo, hi, pts));
        }
    }
    // union–find over intervals (first) and sections (after)
    let ni = intervals.len();
    let mut parent: Vec<usize> = (0..ni + sections.len()).collect();
    fn find(p: &mut [usize], mut a: usize) -> usize {
        while p[a] != a {
            p[a] = p[p[a]];
            a = p[a];
        }
        a
    }
    let span = |iv: &Interval| {
        let side = figs[iv.piece].side;
        let (a, b) = (s_of(side, iv.x0), s_of(side, iv.x1));
        (a.min(b), a.max(b))
    };
    // intervals meet only through the body sections they cover: the crotch extensions of two
    // trouser fronts overlap on the centre line, yet each front dresses its own leg
    for a in 0..ni {
        let (a0, a1) = span(&intervals[a]);
        let mut joined = false;
        for (k, sec) in sections.iter().enumerate() {
            // a section joins when the interval covers its middle: an arm hanging beside a
            // shirt's side does not widen the shirt's shell
            let mid = 0.5 * (sec.0 + sec.1);
            if a0 <= mid && mid <= a1 {
                let (ra, rb) = (find(&mut parent, a), find(&mut parent, ni + k));
                parent[ra] = rb;
                joined = true;
            }
        }
        if !joined && !sections.is_empty() {
            // over no body section: join the nearest one
            let mid = 0.5 * (a0 + a1);
            let k = (0..sections.len())
                .min_by(|&p, &q| {
                    let dp = (sections[p].0 - mid).max(mid - sections[p].1);
                    let dq = (sections[q].0 - mid).max(mid - sections[q].1);
                    dp.total_cmp(&dq)
                })
                .unwrap_or(0);
            let (ra, rb) = (find(&mut parent, a), find(&mut parent, ni + k));
            parent[ra] = rb;
        }
    }
    // one group per root holding intervals
    let mut root_group: Vec<usize> = vec![usize::MAX; parent.len()];
    let mut groups = Vec::new();
    for a in 0..ni {
        let r = find(&mut parent, a);
        if root_group[r] == usize::MAX {
            root_group[r] = groups.len();
            groups.push(());
        }
        intervals[a].group = root_group[r];
    }
    let groups = (0..groups.len())
        .map(|g| {
            let members: Vec<&Interval> = intervals.iter().filter(|iv| iv.group == g).collect();
            let mut pts: Vec<[f64; 2]> = Vec::new();
            let (mut body_lo, mut body_hi) = (f64::MAX, f64::MIN);
            for (k, sec) in sections.iter().enumerate() {
                let r = find(&mut parent, ni + k);
                if root_group[r] == g {
                    pts.extend_from_slice(&sec.2);
                    body_lo = body_lo.min(sec.0);
                    body_hi = body_hi.max(sec.1);
                }
            }
            if pts.is_empty() {
                // no body at all (should not happen on a standing body): a flat slab
                for iv in &members {
                    let (a, b) = span(iv);
                    pts.extend([[a, 0.05], [b, 0.05], [a, -0.05], [b, -0.05]]);
                }
            }
            let Some(shell) = Shell::around(&pts, dz) else {
                unreachable_shell()
            };
            // the length the row takes on the shell: the extent of each side's intervals (a
            // dart's gap inside a piece is laid out too, to close when sewn)
            let extent = |side: Side| {
                let (lo, hi) = members
                    .iter()
                    .filter(|iv| figs[iv.piece].side == side)
                    .fold((f64::MAX, f64::MIN), |(l, h), iv| {
                        (l.min(iv.x0), h.max(iv.x1))
                    });
                (hi - lo).max(0.0)
            };
            let width = extent(Side::Front) + extent(Side::Back);
            let k = (width / shell.perimeter()).max(1.0);
            let centre = |side: Side| {
                let (lo, hi) = members
                    .iter()
                    .filter(|iv| figs[iv.piece].side == side)
                    .fold((f64::MAX, f64::MIN), |(l, h), iv| {
                        (l.min(iv.x0), h.max(iv.x1))
                    });
                (lo <= hi).then_some(0.5 * (lo + hi))
            };
            let fc = centre(Side::Front);
            let bc = centre(Side::Back);
            // the garment row is centred on the body it dresses (a trouser leg on its leg);
            // with no body under it, on its own pieces
            let (fc_s, bc_s) = if body_lo <= body_hi {
                let c = 0.5 * (body_lo + body_hi);
                (c, c)
            } else {
                let f = fc.or(bc.map(|b| -b)).unwrap_or(0.0);
                (f, bc.map(|b| -b).unwrap_or(f))
            };
            Group {
                shell,
                k,
                centre_s: [fc_s, bc_s],
                front_arc: 0.0,
                back_arc: 0.0,
                front_c: fc.unwrap_or(fc_s),
                back_c: bc.unwrap_or(-bc_s),
            }
        })
        .collect();
    Row { intervals, groups }
}

/// A shell grown from at least one point always exists (24 points round it).
fn unreachable_shell() -> ! {
    unreachable!("a grown shell of a non-empty section has 24 points or more")
}
