//! One piece of a DXF-AAMA file: its entities sorted by layer ([`collect`]), the block
//! transform ([`Xf`]) and the assembly into a [`Piece`] ([`build`]): closed outline, corners
//! and fitted segments, fold, grain line, notches and seam allowance.

use ::dxf::entities::{Entity, EntityType};

use super::annotation;
use super::geom::{self, add, closest_on_loop, dist, mul, signed_area, Path as GPath};
use super::{layer_of, locate, role, texts, value_of};
use crate::garment::pattern::{Copies, Corner, Outline, Piece, Segment, P2};

/// Tolerance for chaining boundary pieces end to end (m).
const CHAIN_TOL: f64 = 1e-5;
/// How far a turn or curve point may lie from the outline (m).
const MARK_TOL: f64 = 1e-4;
/// How far a fitted cubic may pass from a polyline vertex (m).
const FIT_TOL: f64 = 5e-5;
/// How far the ends of a fold edge may lie from the mirror line (m).
const FOLD_TOL: f64 = 5e-4;

/// A block-to-pattern transform, `p ↦ a p + t`, the units included (m).
#[derive(Clone, Copy)]
pub(super) struct Xf {
    a: [[f64; 2]; 2],
    t: P2,
}

impl Xf {
    pub(super) const ID: Xf = Xf {
        a: [[1.0, 0.0], [0.0, 1.0]],
        t: [0.0, 0.0],
    };
    /// `p ↦ units · (loc + R(rot) · diag(sx, sy) · (p − base))`; `f` = [sx, sy, rot°].
    pub(super) fn insert(units: f64, loc: P2, base: P2, f: [f64; 3]) -> Option<Xf> {
        let (s, c) = f[2].to_radians().sin_cos();
        let a = [
            [units * c * f[0], -units * s * f[1]],
            [units * s * f[0], units * c * f[1]],
        ];
        let mut xf = Xf { a, t: [0.0; 2] };
        let ab = xf.linear(base);
        xf.t = [units * loc[0] - ab[0], units * loc[1] - ab[1]];
        let ok = xf.a.iter().flatten().chain(&xf.t).all(|v| v.is_finite());
        (ok && xf.det().abs() > 0.0).then_some(xf)
    }
    /// This transform followed by `x ↦ −x`.
    pub(super) fn mirrored_x(mut self) -> Xf {
        self.a[0] = [-self.a[0][0], -self.a[0][1]];
        self.t[0] = -self.t[0];
        self
    }
    fn linear(&self, p: P2) -> P2 {
        [
            self.a[0][0] * p[0] + self.a[0][1] * p[1],
            self.a[1][0] * p[0] + self.a[1][1] * p[1],
        ]
    }
    fn apply(&self, p: P2) -> P2 {
        add(self.linear(p), self.t)
    }
    fn det(&self) -> f64 {
        self.a[0][0] * self.a[1][1] - self.a[0][1] * self.a[1][0]
    }
    /// Metres per block unit.
    fn metres(&self) -> f64 {
        self.det().abs().sqrt()
    }
    /// The chaining tolerance in block units.
    pub(super) fn tol(&self) -> f64 {
        CHAIN_TOL / self.metres()
    }
}

/// What one piece's entities say, in block coordinates.
#[derive(Default)]
pub(super) struct Raw {
    boundary: Vec<GPath>,
    sew: Vec<GPath>,
    turn: Vec<P2>,
    curve: Vec<P2>,
    notches: Vec<Vec<P2>>,
    mirror: Vec<(Vec<P2>, String)>,
    grain: Vec<(Vec<P2>, String)>,
    quantity: Option<u32>,
    /// Corner labels (`Corner: NAME` texts) where they stand, in file order.
    labels: Vec<(P2, String)>,
}

/// Sorts the entities of one piece by layer. `tol` (block units) bounds arc flattening.
pub(super) fn collect(
    ents: &[Entity],
    lines: Option<&[usize]>,
    block: Option<&str>,
    tol: f64,
) -> Result<Raw, String> {
    let mut raw = Raw {
        quantity: value_of(&texts(ents), "quantity").and_then(|q| {
            q.split(|c: char| !c.is_ascii_digit())
                .find_map(|d| d.parse().ok())
        }),
        ..Raw::default()
    };
    for (k, e) in ents.iter().enumerate() {
        if let EntityType::Text(t) = &e.specific {
            if let Some(name) = value_of(std::slice::from_ref(&t.value), annotation::CORNER) {
                raw.labels.push(([t.location.x, t.location.y], name));
            }
        }
        let Some(layer) = layer_of(e) else { continue };
        let at = locate(ents, k, lines, block);
        let xy = |p: &::dxf::Point| [p.x, p.y];
        let (pts, closed): (Vec<P2>, bool) = match &e.specific {
            EntityType::Line(l) => (vec![xy(&l.p1), xy(&l.p2)], false),
            EntityType::Polyline(p) => {
                let v: Vec<(P2, f64)> = p.vertices().map(|v| (xy(&v.location), v.bulge)).collect();
                (with_bulges(&v, p.is_closed(), tol), p.is_closed())
            }
            EntityType::LwPolyline(p) => {
                let v: Vec<(P2, f64)> = p.vertices.iter().map(|v| ([v.x, v.y], v.bulge)).collect();
                (with_bulges(&v, p.is_closed(), tol), p.is_closed())
            }
            EntityType::Arc(a) => {
                let sweep = (a.end_angle - a.start_angle).rem_euclid(360.0);
                let sweep = if sweep == 0.0 { 360.0 } else { sweep }.to_radians();
                let (c, a0) = (xy(&a.center), a.start_angle.to_radians());
                let mut pts = geom::arc_points(c, a.radius, a0, sweep, tol);
                let a1 = a0 + sweep;
                pts.push([c[0] + a.radius * a1.cos(), c[1] + a.radius * a1.sin()]);
                (pts, false)
            }
            EntityType::Circle(c) => {
                let tau = std::f64::consts::TAU;
                (
                    geom::arc_points(xy(&c.center), c.radius, 0.0, tau, tol),
                    true,
                )
            }
            EntityType::ModelPoint(p) => (vec![xy(&p.location)], false),
            EntityType::Insert(i) if block.is_some() => {
                return Err(format!(
                    "{at}: nested INSERT of block {} is not supported",
                    i.name
                ));
            }
            EntityType::Text(_)
            | EntityType::MText(_)
            | EntityType::Attribute(_)
            | EntityType::AttributeDefinition(_)
            | EntityType::Insert(_)
            | EntityType::Vertex(_)
            | EntityType::Seqend(_) => continue,
            other => {
                let kind = format!("{other:?}");
                let kind = kind.split(['(', ' ']).next().unwrap_or("entity");
                return Err(format!(
                    "{at}: {kind} on layer {layer} ({}) is not an AAMA entity",
                    role(layer)
                ));
            }
        };
        if pts.iter().flatten().any(|v| !v.is_finite()) {
            return Err(format!("{at}: coordinates are not finite numbers"));
        }
        let is_point = matches!(e.specific, EntityType::ModelPoint(_));
        match layer {
            1 | 14 if !is_point => {
                let path = GPath { pts, closed, at };
                if layer == 1 {
                    raw.boundary.push(path);
                } else {
                    raw.sew.push(path);
                }
            }
            2 if is_point => raw.turn.push(pts[0]),
            3 if is_point => raw.curve.push(pts[0]),
            4 | 80..=83 => raw.notches.push(pts),
            6 if pts.len() >= 2 => raw.mirror.push((pts, at)),
            7 if pts.len() >= 2 => raw.grain.push((pts, at)),
            _ => {}
        }
    }
    Ok(raw)
}

/// Polyline vertices with bulges turned into arcs.
fn with_bulges(v: &[(P2, f64)], closed: bool, tol: f64) -> Vec<P2> {
    let mut out = Vec::new();
    for (i, &(p, b)) in v.iter().enumerate() {
        let next = v.get(i + 1).or(if closed { v.first() } else { None });
        match next {
            Some(&(q, _)) => out.extend(geom::bulge_points(p, q, b, tol)),
            None => out.push(p),
        }
    }
    out
}

/// The single closed loop of one layer, in pattern coordinates (m), counter-clockwise.
fn one_loop(paths: Vec<GPath>, what: &str, xf: &Xf) -> Result<Option<Vec<P2>>, String> {
    if paths.is_empty() {
        return Ok(None);
    }
    let loops = geom::chain(paths, xf.tol()).map_err(|o| {
        let mm = o.gap * xf.metres() * 1000.0;
        format!(
            "{}: the {what} does not close: gap of {mm:.3} mm between ({}, {}) and ({}, {}) \
             (file units, block coordinates)",
            o.at, o.end[0], o.end[1], o.nearest[0], o.nearest[1]
        )
    })?;
    match loops.len() {
        0 => Err(format!("the {what} is empty")),
        1 => {
            let mut pts: Vec<P2> = loops[0].iter().map(|&p| xf.apply(p)).collect();
            let area = signed_area(&pts);
            if pts.len() < 3 || !area.is_finite() || area.abs() < 1e-12 {
                return Err(format!("the {what} encloses no area"));
            }
            if area < 0.0 {
                pts.reverse();
            }
            Ok(Some(pts))
        }
        n => Err(format!(
            "{n} closed loops in the {what}; a piece has one (internal cut-outs go on layer 11)"
        )),
    }
}

/// Assembles one piece from its sorted entities.
pub(super) fn build(raw: Raw, name: String, xf: &Xf) -> Result<Piece, String> {
    let boundary = one_loop(raw.boundary, "boundary (layer 1)", xf)?
        .ok_or("no boundary (layer 1): the piece has no cut line")?;
    let sew = one_loop(raw.sew, "sew line (layer 14)", xf)?;
    if let Some(s) = &sew {
        if signed_area(s) >= signed_area(&boundary) {
            return Err("the sew line (layer 14) is not inside the boundary (layer 1)".into());
        }
    }
    let mut pts = sew.clone().unwrap_or_else(|| boundary.clone());

    // Turn and curve points on the outline become flagged vertices (inserted on edges).
    let turn: Vec<P2> = raw.turn.iter().map(|&p| xf.apply(p)).collect();
    let curve: Vec<P2> = raw.curve.iter().map(|&p| xf.apply(p)).collect();
    let mut flags = vec![(false, false); pts.len()];
    let mut marked = false;
    for (marks, is_turn) in [(&turn, true), (&curve, false)] {
        for &m in marks.iter() {
            let (q, d, edge, t) = closest_on_loop(&pts, m);
            if d > MARK_TOL {
                continue;
            }
            marked = true;
            let next = (edge + 1) % pts.len();
            let k = if dist(q, pts[edge]) <= MARK_TOL && t < 0.5 {
                edge
            } else if dist(q, pts[next]) <= MARK_TOL {
                next
            } else {
                pts.insert(edge + 1, q);
                flags.insert(edge + 1, (false, false));
                edge + 1
            };
            if is_turn {
                // The corner is the turn point: the vertex it snapped to moves onto it (a
                // writer's samples crowd at a curve's end; chaining may have dropped the
                // corner's own vertex as a duplicate of its neighbour).
                if !flags[k].0 {
                    pts[k] = m;
                }
                flags[k].0 = true;
            } else {
                flags[k].1 = true;
            }
        }
    }
    let corner: Vec<bool> = flags.iter().map(|f| f.0 || !marked).collect();
    let prefer: Vec<bool> = flags.iter().map(|f| f.1).collect();
    let fitted = geom::fit_loop(&pts, &corner, &prefer, FIT_TOL);
    let mut corners: Vec<(P2, Segment)> = fitted.iter().map(|&(i, s)| (pts[i], s)).collect();

    // The fold: the straight edges on the mirror line, merged into one.
    let mut fold = None;
    if let Some((m, at)) = raw.mirror.first() {
        let (a, b) = (xf.apply(m[0]), xf.apply(m[m.len() - 1]));
        let n = corners.len();
        let on = |i: usize| {
            matches!(corners[i].1, Segment::Line)
                && geom::dist_to_line(a, b, corners[i].0) <= FOLD_TOL
                && geom::dist_to_line(a, b, corners[(i + 1) % n].0) <= FOLD_TOL
        };
        let flags: Vec<bool> = (0..n).map(on).collect();
        let len = |i: usize| dist(corners[i].0, corners[(i + 1) % n].0);
        let mut best: Option<(usize, usize, f64)> = None;
        for i in (0..n).filter(|&i| flags[i] && !flags[(i + n - 1) % n]) {
            let k = (0..n).take_while(|&j| flags[(i + j) % n]).count();
            let total: f64 = (0..k).map(|j| len((i + j) % n)).sum();
            if best.is_none_or(|b| total > b.2) {
                best = Some((i, k, total));
            }
        }
        let (i, k, _) = best.ok_or_else(|| {
            format!("{at}: the mirror line (layer 6) lies on no straight edge of the outline")
        })?;
        let drop: Vec<usize> = (1..k).map(|j| (i + j) % n).collect();
        let mut kept = Vec::new();
        let mut fold_at = 0;
        for (j, c) in corners.iter().enumerate() {
            if j == i {
                fold_at = kept.len();
            }
            if !drop.contains(&j) {
                kept.push(*c);
            }
        }
        corners = kept;
        fold = Some(fold_at);
    }

    // Corner names from the labels at the corners, the first label's corner first; else
    // `c0`, `c1`, … from the lowest-leftmost corner, counter-clockwise.
    let at: Vec<P2> = corners.iter().map(|c| c.0).collect();
    let labels: Vec<(P2, &str)> = raw
        .labels
        .iter()
        .map(|(p, n)| (xf.apply(*p), n.as_str()))
        .collect();
    let label_of = |p: P2| {
        labels
            .iter()
            .find(|(q, _)| dist(*q, p) <= MARK_TOL)
            .map(|(_, n)| *n)
    };
    let first = labels
        .first()
        .and_then(|(q, _)| at.iter().position(|&p| dist(*q, p) <= MARK_TOL))
        .unwrap_or_else(|| geom::lowest_leftmost(&at));
    corners.rotate_left(first);
    let n = corners.len();
    let mut names: Vec<String> = Vec::with_capacity(n);
    for (i, c) in corners.iter().enumerate() {
        let mut name = label_of(c.0).map_or_else(|| format!("c{i}"), str::to_string);
        while names.contains(&name)
            || (label_of(c.0).is_none() && labels.iter().any(|l| l.1 == name))
        {
            name.push('+');
        }
        names.push(name);
    }
    let fold = fold.map(|f| names[(f + n - first) % n].clone());
    let outline = Outline {
        corners: corners
            .iter()
            .zip(names)
            .map(|(&(at, segment), name)| Corner { name, at, segment })
            .collect(),
    };

    let grain = match raw.grain.first() {
        Some((g, at)) => {
            let g: Vec<P2> = g.iter().map(|&p| xf.apply(p)).collect();
            let (a, b) = g
                .windows(2)
                .map(|w| (w[0], w[1]))
                .max_by(|x, y| dist(x.0, x.1).total_cmp(&dist(y.0, y.1)))
                .unwrap_or((g[0], g[0]));
            if dist(a, b) <= 0.0 {
                return Err(format!("{at}: the grain line (layer 7) has no length"));
            }
            [a, b]
        }
        None => {
            let (lo, hi) = at.iter().fold(([f64::MAX; 2], [f64::MIN; 2]), |(l, h), p| {
                (
                    [l[0].min(p[0]), l[1].min(p[1])],
                    [h[0].max(p[0]), h[1].max(p[1])],
                )
            });
            let c = mul(add(lo, hi), 0.5);
            let h = (hi[1] - lo[1]) / 4.0;
            [[c[0], c[1] - h], [c[0], c[1] + h]]
        }
    };

    let notches = raw
        .notches
        .iter()
        .filter(|s| !s.is_empty())
        .map(|s| {
            let s: Vec<P2> = s.iter().map(|&p| xf.apply(p)).collect();
            let mut cands = s.clone();
            for w in s.windows(2) {
                for e in 0..pts.len() {
                    let (a, b) = (pts[e], pts[(e + 1) % pts.len()]);
                    cands.extend(geom::segment_intersection(w[0], w[1], a, b));
                }
            }
            let best = cands
                .iter()
                .map(|&c| closest_on_loop(&pts, c))
                .min_by(|x, y| x.1.total_cmp(&y.1));
            best.map_or(s[0], |b| b.0)
        })
        .collect();

    let seam_allowance = match &sew {
        Some(s) => geom::mean_offset(s, &boundary, 400, FIT_TOL).unwrap_or(0.0),
        None => 0.0,
    };
    let copies = match raw.quantity {
        Some(q) if q >= 2 && q % 2 == 0 => Copies::Pair,
        _ => Copies::One,
    };
    Ok(Piece {
        name,
        outline,
        grain,
        seam_allowance,
        notches,
        fold,
        copies,
        placement: None,
    })
}
