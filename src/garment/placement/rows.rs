//! Rows of the pre-positioning: each silhouette row's piece intervals on the figurines,
//! grouped with the body sections they cover, each group wrapped on a convex shell around its
//! sections (widened where the garment row is longer), and the placement of a figurine point
//! on its row's shell.

use super::figurine::{s_of, Figurine};
use super::shell::Shell;
use super::silhouette::{Landmarks, Silhouettes};
use crate::garment::mesh::GarmentMesh;
use crate::garment::{Side, P2};

/// One piece's horizontal interval in one row: (piece, X0, X1, group).
#[derive(Clone, Copy)]
pub(super) struct Interval {
    pub(super) piece: usize,
    pub(super) x0: f64,
    pub(super) x1: f64,
    pub(super) group: usize,
}

/// A group's shell and the arc positions of its front and back centres.
pub(super) struct Group {
    pub(super) shell: Shell,
    /// Widening factor of the shell (≥ 1).
    pub(super) k: f64,
    /// Left coordinates of the front and back centres.
    centre_s: [f64; 2],
    pub(super) front_arc: f64,
    front_c: f64,
    pub(super) back_arc: f64,
    back_c: f64,
}

impl Group {
    /// Widens the shell by `k` and finds the arc positions of the centres on it.
    fn finish(&mut self, k: f64) {
        self.k = k;
        if k > 1.0 {
            let c = self.shell.centroid();
            let (lo, hi) = self.shell.s_range();
            // a group dressing one leg widens away from the other leg: scaled about its
            // innermost point, so that the two legs' shells never overlap
            let inner = match self.centre_s[0] {
                s if s > LEG_OFFSET => Some(lo),
                s if s < -LEG_OFFSET => Some(hi),
                _ => None,
            };
            match inner {
                Some(s) => {
                    let about = [s, c[1]];
                    self.shell = self.shell.scaled_about(k, about);
                    // the row's centres move with the shell (the same similarity)
                    for c in self.centre_s.iter_mut() {
                        *c = about[0] + k * (*c - about[0]);
                    }
                }
                None => self.shell = self.shell.scaled(k),
            }
        }
        self.front_arc = self.shell.arc_at(self.centre_s[0], true);
        self.back_arc = self.shell.arc_at(self.centre_s[1], false);
    }
}

/// A group whose body centre lies further than this (m) from the centre line dresses one leg.
const LEG_OFFSET: f64 = 0.03;

/// Largest change of a shell's widening factor per metre of height: the shell narrows or
/// widens gradually, so that vertical edges are not sheared where the garment's width changes
/// fast (an armhole).
const WIDENING_RATE: f64 = 0.4;

/// A silhouette row: the pieces' intervals and their groups.
pub(super) struct Row {
    pub(super) intervals: Vec<Interval>,
    pub(super) groups: Vec<Group>,
}

/// The rows covering the figurine positions `fig_pos` (with a row of margin each side), from
/// row `r0` up to `r1`, their shells widened and finished.
pub(super) struct Rows {
    pub(super) r0: usize,
    pub(super) r1: usize,
    pub(super) rows: Vec<Row>,
}

impl Rows {
    /// Builds the rows of the garment laid out by `figs` at `fig_pos`.
    pub(super) fn new(
        garment: &GarmentMesh,
        figs: &[Figurine],
        fig_pos: &[P2],
        sil: &Silhouettes,
        marks: &Landmarks,
        dz: f64,
    ) -> Rows {
        let (ymin, ymax) = fig_pos
            .iter()
            .fold((f64::MAX, f64::MIN), |(l, h), p| (l.min(p[1]), h.max(p[1])));
        let (r0, r1) = (
            sil.row(ymin).saturating_sub(1),
            (sil.row(ymax) + 1).min(sil.nh - 1),
        );
        let mut rows: Vec<Row> = (r0..=r1)
            .map(|i| build_row(i, garment, figs, fig_pos, sil, marks, dz))
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
        Rows { r0, r1, rows }
    }

    /// The (s, d) of a vertex of piece `k` at figurine X in row `r` (an index into `rows`),
    /// if the piece crosses the row.
    pub(super) fn place(&self, r: usize, k: usize, x: f64, fig: &Figurine) -> Option<[f64; 2]> {
        place(&self.rows, r, k, x, fig)
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
