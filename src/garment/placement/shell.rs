//! `Shell`: a closed convex curve around a body cross-section in the (left, front) plane at one
//! height, the surface a garment row is wrapped on during pre-positioning. Built as the convex
//! hull of the section's points grown by a clearance, it is walked by arc length: clockwise
//! seen from above, so that from the front centre the arc runs towards the body's left (+s).

/// A convex closed curve, clockwise in the (s, d) plane, with its arc-length table.
#[derive(Debug, Clone)]
pub struct Shell {
    pts: Vec<[f64; 2]>,
    /// Arc length at each point from `pts[0]`; `cum[n]` is the perimeter.
    cum: Vec<f64>,
}

/// Andrew's monotone chain: the convex hull of `p`, counter-clockwise, without repeats.
pub fn convex_hull(mut p: Vec<[f64; 2]>) -> Vec<[f64; 2]> {
    p.sort_by(|a, b| a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1])));
    p.dedup();
    if p.len() < 3 {
        return p;
    }
    let cross = |o: &[f64; 2], a: &[f64; 2], b: &[f64; 2]| {
        (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
    };
    let mut h: Vec<[f64; 2]> = Vec::with_capacity(2 * p.len());
    for pass in 0..2 {
        let start = h.len();
        let it: Box<dyn Iterator<Item = &[f64; 2]>> = if pass == 0 {
            Box::new(p.iter())
        } else {
            Box::new(p.iter().rev())
        };
        for q in it {
            while h.len() >= start + 2 && cross(&h[h.len() - 2], &h[h.len() - 1], q) <= 0.0 {
                h.pop();
            }
            h.push(*q);
        }
        h.pop();
    }
    h
}

impl Shell {
    /// The hull of `points` grown by `clearance` (a Minkowski sum with a 24-gon).
    pub fn around(points: &[[f64; 2]], clearance: f64) -> Option<Shell> {
        let k = 24;
        let mut grown = Vec::with_capacity(points.len() * k);
        for q in convex_hull(points.to_vec()) {
            for i in 0..k {
                let a = std::f64::consts::TAU * i as f64 / k as f64;
                // the polygon's inradius is r cos(π/k): scale so the clearance is a minimum
                let r = clearance / (std::f64::consts::PI / k as f64).cos();
                grown.push([q[0] + r * a.cos(), q[1] + r * a.sin()]);
            }
        }
        let mut hull = convex_hull(grown);
        if hull.len() < 3 {
            return None;
        }
        hull.reverse(); // clockwise
        Some(Shell::from_clockwise(hull))
    }

    fn from_clockwise(pts: Vec<[f64; 2]>) -> Shell {
        let n = pts.len();
        let mut cum = Vec::with_capacity(n + 1);
        cum.push(0.0);
        for i in 0..n {
            let (a, b) = (pts[i], pts[(i + 1) % n]);
            let l = (b[0] - a[0]).hypot(b[1] - a[1]);
            cum.push(cum[i] + l);
        }
        Shell { pts, cum }
    }

    /// The perimeter (m).
    pub fn perimeter(&self) -> f64 {
        self.cum[self.pts.len()]
    }

    /// The shell scaled by `k` about its vertex centroid.
    pub fn scaled(&self, k: f64) -> Shell {
        self.scaled_about(k, self.centroid())
    }

    /// The vertex centroid of the shell.
    pub fn centroid(&self) -> [f64; 2] {
        let n = self.pts.len() as f64;
        self.pts
            .iter()
            .fold([0.0, 0.0], |a, p| [a[0] + p[0] / n, a[1] + p[1] / n])
    }

    /// The smallest and largest left coordinate of the shell.
    pub fn s_range(&self) -> (f64, f64) {
        self.pts
            .iter()
            .fold((f64::MAX, f64::MIN), |(l, h), p| (l.min(p[0]), h.max(p[0])))
    }

    /// The shell scaled by `k` about the point `c`.
    pub fn scaled_about(&self, k: f64, c: [f64; 2]) -> Shell {
        let pts = self
            .pts
            .iter()
            .map(|p| [c[0] + k * (p[0] - c[0]), c[1] + k * (p[1] - c[1])])
            .collect();
        Shell::from_clockwise(pts)
    }

    /// The point at arc length `sigma` (taken modulo the perimeter).
    pub fn at(&self, sigma: f64) -> [f64; 2] {
        let per = self.perimeter();
        let s = sigma.rem_euclid(per);
        let i = match self.cum.binary_search_by(|c| c.total_cmp(&s)) {
            Ok(i) => i.min(self.pts.len() - 1),
            Err(i) => i - 1,
        };
        let (a, b) = (self.pts[i], self.pts[(i + 1) % self.pts.len()]);
        let l = self.cum[i + 1] - self.cum[i];
        let t = if l > 0.0 { (s - self.cum[i]) / l } else { 0.0 };
        [a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])]
    }

    /// Arc length of the point where the vertical line at `s` (clamped into the shell's span)
    /// crosses the shell on its front (`front` = larger d) or back side.
    pub fn arc_at(&self, s: f64, front: bool) -> f64 {
        let n = self.pts.len();
        let (lo, hi) = self
            .pts
            .iter()
            .fold((f64::MAX, f64::MIN), |(l, h), p| (l.min(p[0]), h.max(p[0])));
        let s = s.clamp(lo, hi);
        let mut best: Option<(f64, f64)> = None; // (d, arc)
        for i in 0..n {
            let (a, b) = (self.pts[i], self.pts[(i + 1) % n]);
            let (smin, smax) = (a[0].min(b[0]), a[0].max(b[0]));
            if s < smin || s > smax {
                continue;
            }
            let t = if b[0] != a[0] {
                (s - a[0]) / (b[0] - a[0])
            } else {
                0.0
            };
            let d = a[1] + t * (b[1] - a[1]);
            let arc = self.cum[i] + t * (self.cum[i + 1] - self.cum[i]);
            let better = match best {
                None => true,
                Some((bd, _)) => (front && d > bd) || (!front && d < bd),
            };
            if better {
                best = Some((d, arc));
            }
        }
        best.map_or(0.0, |b| b.1)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn circle_shell_has_the_grown_perimeter_and_runs_clockwise() {
        // a unit square grown by 0.5: perimeter 4 + 2π·0.5 (within the 24-gon's error)
        let sq = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
        let sh = Shell::around(&sq, 0.5).unwrap();
        let exact = 4.0 + std::f64::consts::PI;
        assert!((sh.perimeter() - exact).abs() < 0.02, "{}", sh.perimeter());
        // from the top (front) at s = 0.5, walking a little goes to +s
        let a = sh.arc_at(0.5, true);
        let p = sh.at(a);
        assert!(
            (p[0] - 0.5).abs() < 1e-9 && (p[1] - 1.5).abs() < 0.01,
            "{p:?}"
        );
        let q = sh.at(a + 0.1);
        assert!(q[0] > p[0] + 0.09, "{q:?}");
        let b = sh.arc_at(0.5, false);
        assert!((sh.at(b)[1] + 0.5).abs() < 0.01);
        // halfway round from the top is the bottom
        assert!(((b - a).rem_euclid(sh.perimeter()) - sh.perimeter() / 2.0).abs() < 0.02);
        // scaling scales the perimeter
        assert!((sh.scaled(2.0).perimeter() - 2.0 * sh.perimeter()).abs() < 1e-9);
    }
}
