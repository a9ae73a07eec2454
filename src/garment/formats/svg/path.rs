//! SVG path data (`d`: M L H V C S Q T A Z, absolute and relative), parsed into straight
//! lines and cubic Béziers (quadratics are raised, arcs split into cubics of at most 90°) in
//! user units.

use crate::garment::pattern::P2;

/// One drawing step of a sub-path.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum PathSeg {
    /// A straight line to the point.
    Line(P2),
    /// A cubic Bézier: control points, end point.
    Cubic(P2, P2, P2),
}

impl PathSeg {
    /// The end point.
    pub fn end(&self) -> P2 {
        match *self {
            PathSeg::Line(p) | PathSeg::Cubic(_, _, p) => p,
        }
    }

    /// The segment with all its points mapped by `f`.
    pub fn mapped(&self, f: &impl Fn(P2) -> P2) -> PathSeg {
        match *self {
            PathSeg::Line(p) => PathSeg::Line(f(p)),
            PathSeg::Cubic(a, b, p) => PathSeg::Cubic(f(a), f(b), f(p)),
        }
    }
}

/// A sub-path: a start point and the segments that follow it.
#[derive(Debug, Clone, PartialEq, Default)]
pub(crate) struct SubPath {
    /// The `M` point.
    pub start: P2,
    /// The segments (a `Z` that does not end at the start adds a line back to it).
    pub segs: Vec<PathSeg>,
    /// Whether the sub-path ended with `Z`.
    pub closed: bool,
}

impl SubPath {
    /// The last point.
    pub fn end(&self) -> P2 {
        self.segs.last().map_or(self.start, PathSeg::end)
    }
}

/// Parses path data into sub-paths; the error names what could not be read.
pub(crate) fn parse_path(d: &str) -> Result<Vec<SubPath>, String> {
    let mut s = Scanner {
        b: d.as_bytes(),
        i: 0,
    };
    let mut paths: Vec<SubPath> = Vec::new();
    let mut cur: Option<SubPath> = None;
    let mut pos: P2 = [0.0, 0.0];
    let mut start: P2 = [0.0, 0.0];
    // Last control point of the previous cubic (for S) or quadratic (for T).
    let mut last_cubic: Option<P2> = None;
    let mut last_quad: Option<P2> = None;
    let mut cmd: Option<u8> = None;
    loop {
        s.skip_sep();
        if s.i >= s.b.len() {
            break;
        }
        let c = s.b[s.i];
        if c.is_ascii_alphabetic() {
            s.i += 1;
            cmd = Some(c);
        } else if cmd.is_none() {
            return Err(format!(
                "path data does not start with a command: '{}'",
                s.context()
            ));
        }
        let Some(c) = cmd else { break };
        let rel = c.is_ascii_lowercase();
        let abs = |p: P2, pos: P2| {
            if rel {
                [p[0] + pos[0], p[1] + pos[1]]
            } else {
                p
            }
        };
        let upper = c.to_ascii_uppercase();
        if upper != b'M' && upper != b'Z' && cur.is_none() {
            // A drawing command after Z (or first, illegally): start at the last start point.
            cur = Some(SubPath {
                start,
                ..SubPath::default()
            });
        }
        let (mut next_cubic, mut next_quad) = (None, None);
        match upper {
            b'M' => {
                let p = abs(s.point()?, pos);
                if let Some(done) = cur.take() {
                    paths.push(done);
                }
                cur = Some(SubPath {
                    start: p,
                    ..SubPath::default()
                });
                pos = p;
                start = p;
                cmd = Some(if rel { b'l' } else { b'L' });
            }
            b'Z' => {
                if let Some(mut done) = cur.take() {
                    if done.end() != done.start {
                        done.segs.push(PathSeg::Line(done.start));
                    }
                    done.closed = true;
                    paths.push(done);
                }
                pos = start;
                cmd = None;
            }
            b'L' => {
                let p = abs(s.point()?, pos);
                push(&mut cur, PathSeg::Line(p));
                pos = p;
            }
            b'H' => {
                let x = s.number()? + if rel { pos[0] } else { 0.0 };
                pos = [x, pos[1]];
                push(&mut cur, PathSeg::Line(pos));
            }
            b'V' => {
                let y = s.number()? + if rel { pos[1] } else { 0.0 };
                pos = [pos[0], y];
                push(&mut cur, PathSeg::Line(pos));
            }
            b'C' | b'S' => {
                let c1 = if upper == b'C' {
                    abs(s.point()?, pos)
                } else {
                    last_cubic.map_or(pos, |q| [2.0 * pos[0] - q[0], 2.0 * pos[1] - q[1]])
                };
                let c2 = abs(s.point()?, pos);
                let p = abs(s.point()?, pos);
                push(&mut cur, PathSeg::Cubic(c1, c2, p));
                next_cubic = Some(c2);
                pos = p;
            }
            b'Q' | b'T' => {
                let q = if upper == b'Q' {
                    abs(s.point()?, pos)
                } else {
                    last_quad.map_or(pos, |q| [2.0 * pos[0] - q[0], 2.0 * pos[1] - q[1]])
                };
                let p = abs(s.point()?, pos);
                let c1 = [
                    pos[0] + 2.0 / 3.0 * (q[0] - pos[0]),
                    pos[1] + 2.0 / 3.0 * (q[1] - pos[1]),
                ];
                let c2 = [
                    p[0] + 2.0 / 3.0 * (q[0] - p[0]),
                    p[1] + 2.0 / 3.0 * (q[1] - p[1]),
                ];
                push(&mut cur, PathSeg::Cubic(c1, c2, p));
                next_quad = Some(q);
                pos = p;
            }
            b'A' => {
                let (rx, ry, rot) = (s.number()?, s.number()?, s.number()?);
                let (large, sweep) = (s.flag()?, s.flag()?);
                let p = abs(s.point()?, pos);
                for seg in arc_to_cubics(pos, rx, ry, rot, large, sweep, p) {
                    push(&mut cur, seg);
                }
                pos = p;
            }
            other => return Err(format!("unknown path command '{}'", other as char)),
        }
        last_cubic = next_cubic;
        last_quad = next_quad;
    }
    if let Some(done) = cur.take() {
        paths.push(done);
    }
    Ok(paths)
}

/// The numbers of a list separated by white space and/or commas.
pub(crate) fn parse_numbers(text: &str) -> Result<Vec<f64>, String> {
    let mut s = Scanner {
        b: text.as_bytes(),
        i: 0,
    };
    let mut out = Vec::new();
    loop {
        s.skip_sep();
        if s.i >= s.b.len() {
            return Ok(out);
        }
        out.push(s.number()?);
    }
}

fn push(cur: &mut Option<SubPath>, seg: PathSeg) {
    if let Some(c) = cur {
        c.segs.push(seg);
    }
}

struct Scanner<'a> {
    b: &'a [u8],
    i: usize,
}

impl Scanner<'_> {
    fn skip_sep(&mut self) {
        while self.i < self.b.len()
            && (self.b[self.i].is_ascii_whitespace() || self.b[self.i] == b',')
        {
            self.i += 1;
        }
    }

    fn context(&self) -> String {
        let end = (self.i + 20).min(self.b.len());
        String::from_utf8_lossy(&self.b[self.i.min(end)..end]).into_owned()
    }

    fn number(&mut self) -> Result<f64, String> {
        self.skip_sep();
        let start = self.i;
        let b = self.b;
        let mut i = self.i;
        if i < b.len() && (b[i] == b'+' || b[i] == b'-') {
            i += 1;
        }
        let mut digits = false;
        while i < b.len() && b[i].is_ascii_digit() {
            i += 1;
            digits = true;
        }
        if i < b.len() && b[i] == b'.' {
            i += 1;
            while i < b.len() && b[i].is_ascii_digit() {
                i += 1;
                digits = true;
            }
        }
        if digits && i < b.len() && (b[i] == b'e' || b[i] == b'E') {
            let mut j = i + 1;
            if j < b.len() && (b[j] == b'+' || b[j] == b'-') {
                j += 1;
            }
            if j < b.len() && b[j].is_ascii_digit() {
                while j < b.len() && b[j].is_ascii_digit() {
                    j += 1;
                }
                i = j;
            }
        }
        let text = std::str::from_utf8(&b[start..i]).unwrap_or("");
        match text.parse::<f64>() {
            Ok(v) if digits && v.is_finite() => {
                self.i = i;
                Ok(v)
            }
            _ => Err(format!("expected a number at '{}'", self.context())),
        }
    }

    fn point(&mut self) -> Result<P2, String> {
        Ok([self.number()?, self.number()?])
    }

    fn flag(&mut self) -> Result<bool, String> {
        self.skip_sep();
        match self.b.get(self.i) {
            Some(b'0') => {
                self.i += 1;
                Ok(false)
            }
            Some(b'1') => {
                self.i += 1;
                Ok(true)
            }
            _ => Err(format!(
                "expected an arc flag (0 or 1) at '{}'",
                self.context()
            )),
        }
    }
}

/// An SVG elliptical arc as cubics (SVG 1.1 appendix F.6), each spanning at most 90°.
fn arc_to_cubics(
    p0: P2,
    rx: f64,
    ry: f64,
    rot_deg: f64,
    large: bool,
    sweep: bool,
    p1: P2,
) -> Vec<PathSeg> {
    let (mut rx, mut ry) = (rx.abs(), ry.abs());
    if p0 == p1 {
        return Vec::new();
    }
    if rx == 0.0 || ry == 0.0 {
        return vec![PathSeg::Line(p1)];
    }
    let (sin, cos) = rot_deg.to_radians().sin_cos();
    let (dx, dy) = ((p0[0] - p1[0]) / 2.0, (p0[1] - p1[1]) / 2.0);
    let (x1, y1) = (cos * dx + sin * dy, -sin * dx + cos * dy);
    let lambda = (x1 * x1) / (rx * rx) + (y1 * y1) / (ry * ry);
    if lambda > 1.0 {
        rx *= lambda.sqrt();
        ry *= lambda.sqrt();
    }
    let num = rx * rx * ry * ry - rx * rx * y1 * y1 - ry * ry * x1 * x1;
    let den = rx * rx * y1 * y1 + ry * ry * x1 * x1;
    let mut coef = if den > 0.0 {
        (num / den).max(0.0).sqrt()
    } else {
        0.0
    };
    if large == sweep {
        coef = -coef;
    }
    let (cx1, cy1) = (coef * rx * y1 / ry, -coef * ry * x1 / rx);
    let (cx, cy) = (
        cos * cx1 - sin * cy1 + (p0[0] + p1[0]) / 2.0,
        sin * cx1 + cos * cy1 + (p0[1] + p1[1]) / 2.0,
    );
    let angle = |ux: f64, uy: f64, vx: f64, vy: f64| (ux * vy - uy * vx).atan2(ux * vx + uy * vy);
    let theta1 = angle(1.0, 0.0, (x1 - cx1) / rx, (y1 - cy1) / ry);
    let mut dtheta = angle(
        (x1 - cx1) / rx,
        (y1 - cy1) / ry,
        (-x1 - cx1) / rx,
        (-y1 - cy1) / ry,
    );
    if !sweep && dtheta > 0.0 {
        dtheta -= std::f64::consts::TAU;
    } else if sweep && dtheta < 0.0 {
        dtheta += std::f64::consts::TAU;
    }
    let n = (dtheta.abs() / std::f64::consts::FRAC_PI_2).ceil().max(1.0) as usize;
    let step = dtheta / n as f64;
    let k = 4.0 / 3.0 * (step / 4.0).tan();
    let at = |t: f64| {
        let (s, c) = t.sin_cos();
        [
            cx + cos * rx * c - sin * ry * s,
            cy + sin * rx * c + cos * ry * s,
        ]
    };
    let deriv = |t: f64| {
        let (s, c) = t.sin_cos();
        [-cos * rx * s - sin * ry * c, -sin * rx * s + cos * ry * c]
    };
    (0..n)
        .map(|i| {
            let (ta, tb) = (theta1 + step * i as f64, theta1 + step * (i + 1) as f64);
            let (a, b) = (at(ta), if i + 1 == n { p1 } else { at(tb) });
            let (da, db) = (deriv(ta), deriv(tb));
            PathSeg::Cubic(
                [a[0] + k * da[0], a[1] + k * da[1]],
                [b[0] - k * db[0], b[1] - k * db[1]],
                b,
            )
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_relative_and_shorthand_commands() {
        let p = parse_path("m10,10 h5 v5 l-5-5z M0 0 C1 1 2 2 3 3 s1 1 2 2 q1 0 1 1 t1 1 L0 0")
            .unwrap();
        assert_eq!(p.len(), 2);
        assert!(p[0].closed);
        assert_eq!(p[0].segs[0], PathSeg::Line([15.0, 10.0]));
        assert_eq!(p[0].segs[1], PathSeg::Line([15.0, 15.0]));
        assert_eq!(p[0].end(), [10.0, 10.0]);
        assert_eq!(
            p[1].segs[1],
            PathSeg::Cubic([4.0, 4.0], [4.0, 4.0], [5.0, 5.0])
        );
        assert!(!p[1].closed);
        assert!(parse_path("M 0 0 L 1 x").is_err());
        assert!(parse_path("10 10").is_err());
        assert_eq!(
            parse_path("M0 0L1.5.5").unwrap()[0].segs[0],
            PathSeg::Line([1.5, 0.5])
        );
    }

    #[test]
    fn arcs_become_quarter_cubics_on_the_circle() {
        let p = parse_path("M 1 0 A 1 1 0 0 1 -1 0").unwrap();
        assert_eq!(p[0].segs.len(), 2);
        if let PathSeg::Cubic(_, _, mid) = p[0].segs[0] {
            assert!(
                (mid[0]).abs() < 1e-12 && (mid[1] - 1.0).abs() < 1e-12,
                "{mid:?}"
            );
        } else {
            panic!("not a cubic");
        }
    }
}
