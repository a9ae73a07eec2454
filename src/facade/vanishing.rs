//! Automatic rectification of a facade photo by its two dominant vanishing points. This
//! module owns the vanishing-point estimation and the rectifying homography built from them;
//! segments come from [`super::segments`], warping from [`super::homography`].
//!
//! 1. Segments are split into near-vertical (within 30° of vertical) and near-horizontal
//!    (within 50° of horizontal: perspective slants the horizontals strongly) families.
//! 2. In each family a deterministic exhaustive RANSAC tries the intersections of all pairs of
//!    its longest segments (homogeneous, so parallel pairs give a point at infinity) and keeps
//!    the one that the most segment length agrees with: a segment agrees when the direction
//!    from its midpoint to the point is within an angle of its own direction (the angle its
//!    endpoints' localisation error of about a pixel allows, 1°–4°), MSAC-weighted.
//! 3. Each point is refined on its inliers by iteratively reweighted least squares: it
//!    minimises Σ length · sin²(angle between segment and direction to the point), in
//!    homogeneous coordinates (a point at infinity is an ordinary unit vector).
//! 4. The homography sends the horizon (the line through both points) to infinity and the
//!    vertical and horizontal points to the y and x directions; its remaining affine freedom
//!    keeps the output upright, unmirrored, with unit scale along both directions at the image
//!    centre, and translated so the warped image starts at the origin. Two vanishing points fix
//!    the facade only up to the aspect ratio: that ratio is the one of the image centre.

use std::f64::consts::PI;

use nalgebra::{Matrix3, SymmetricEigen, Vector3};

use super::error::FacadeError;
use super::homography::{warp_gray, Homography};
use super::segments::{detect, Segment};
use crate::geometry::image::Gray;

/// Largest deviation from vertical of a near-vertical segment.
pub const VERTICAL_TOLERANCE_DEG: f64 = 30.0;
/// Largest deviation from horizontal of a near-horizontal segment.
pub const HORIZONTAL_TOLERANCE_DEG: f64 = 50.0;
/// Fewest segments a family needs.
pub const MIN_FAMILY: usize = 8;
/// Fewest inliers a vanishing point needs.
pub const MIN_INLIERS: usize = 6;
/// Longest segments of a family whose pairwise intersections are tried.
const HYPOTHESIS_SEGMENTS: usize = 80;
/// Smallest ratio between the homogeneous scales of the warped image corners: under it the
/// horizon is too close to (or through) the image and the far side would blow up (a ratio r
/// stretches the far side about r^-1.5 times more than the near one).
const MIN_CORNER_SCALE_RATIO: f64 = 0.2;
/// Largest output, in multiples of the input pixel count.
const MAX_AREA_FACTOR: f64 = 2.0;

/// The outcome of automatic rectification.
#[derive(Debug, Clone, PartialEq)]
pub struct Rectification {
    /// Maps photo pixels to rectified pixels (use with [`warp_gray`] or
    /// [`super::homography::warp_labels`] and `width` × `height`).
    pub h: Homography,
    /// Columns of the rectified image.
    pub width: u32,
    /// Rows of the rectified image.
    pub height: u32,
    /// Vertical vanishing point, homogeneous pixel coordinates, unit norm.
    pub vertical_vp: [f64; 3],
    /// Horizontal vanishing point, homogeneous pixel coordinates, unit norm.
    pub horizontal_vp: [f64; 3],
    /// Inlier segments of the vertical and the horizontal point.
    pub inliers: (usize, usize),
}

impl Rectification {
    /// The photo warped to the rectified frame.
    pub fn warp(&self, img: &Gray) -> Option<Gray> {
        warp_gray(img, &self.h, self.width, self.height)
    }
}

/// A vanishing point with its support.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VanishingPoint {
    /// Homogeneous pixel coordinates, unit norm.
    pub point: [f64; 3],
    /// Segments that agree with it.
    pub inliers: usize,
    /// Segments of its family.
    pub family: usize,
}

/// Which family of segments.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Direction {
    /// Near-vertical segments.
    Vertical,
    /// Near-horizontal segments.
    Horizontal,
}

impl Direction {
    fn name(self) -> &'static str {
        match self {
            Direction::Vertical => "vertical",
            Direction::Horizontal => "horizontal",
        }
    }

    /// Whether a segment of direction angle `a` (in [0, π)) belongs to the family.
    fn contains(self, a: f64) -> bool {
        match self {
            Direction::Vertical => (a - PI / 2.0).abs() <= VERTICAL_TOLERANCE_DEG.to_radians(),
            Direction::Horizontal => a.min(PI - a) <= HORIZONTAL_TOLERANCE_DEG.to_radians(),
        }
    }
}

/// Rectifies a photo: segments, vanishing points, homography. Errors say which step failed.
pub fn rectify(img: &Gray) -> Result<Rectification, FacadeError> {
    let segs = detect(img);
    rectify_segments(&segs, img.width, img.height)
}

/// [`rectify`] from given segments of a `width` × `height` image.
pub fn rectify_segments(
    segs: &[Segment],
    width: u32,
    height: u32,
) -> Result<Rectification, FacadeError> {
    let v = vanishing_point(segs, width, height, Direction::Vertical)?;
    let hz = vanishing_point(segs, width, height, Direction::Horizontal)?;
    let (h, w_out, h_out) = rectifying_homography(v.point, hz.point, width, height)?;
    Ok(Rectification {
        h,
        width: w_out,
        height: h_out,
        vertical_vp: v.point,
        horizontal_vp: hz.point,
        inliers: (v.inliers, hz.inliers),
    })
}

fn fail(message: String) -> FacadeError {
    FacadeError::Rectification { message }
}

/// A segment in normalised coordinates (image centre at 0, half the larger side 1).
struct Line {
    /// Homogeneous line (unit normal, offset).
    l: Vector3<f64>,
    mid: [f64; 2],
    dir: [f64; 2],
    /// Length in pixels.
    len: f64,
    /// Inlier angle (radians).
    tol: f64,
}

/// The dominant vanishing point of one family of `segs` in a `width` × `height` image.
pub fn vanishing_point(
    segs: &[Segment],
    width: u32,
    height: u32,
    family: Direction,
) -> Result<VanishingPoint, FacadeError> {
    let (cx, cy) = (width as f64 / 2.0, height as f64 / 2.0);
    let s = cx.max(cy).max(0.5);
    let mut lines: Vec<Line> = segs
        .iter()
        .filter(|g| g.length() > 1.0 && g.length().is_finite() && family.contains(g.angle()))
        .map(|g| {
            let a = [(g.a[0] - cx) / s, (g.a[1] - cy) / s];
            let b = [(g.b[0] - cx) / s, (g.b[1] - cy) / s];
            let len = g.length();
            let dir = [(b[0] - a[0]) * s / len, (b[1] - a[1]) * s / len];
            let n = [-dir[1], dir[0]];
            let mid = [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])];
            Line {
                l: Vector3::new(n[0], n[1], -(n[0] * mid[0] + n[1] * mid[1])),
                mid,
                dir,
                len,
                tol: (1.5 / len)
                    .atan()
                    .clamp(1f64.to_radians(), 4f64.to_radians()),
            }
        })
        .collect();
    let name = family.name();
    if lines.len() < MIN_FAMILY {
        return Err(fail(format!(
            "no dominant {name} direction: {} near-{name} segments, need ≥ {MIN_FAMILY}",
            lines.len()
        )));
    }
    // longest first, ties by position: a deterministic order
    lines.sort_by(|p, q| {
        q.len
            .total_cmp(&p.len)
            .then(p.mid[0].total_cmp(&q.mid[0]))
            .then(p.mid[1].total_cmp(&q.mid[1]))
    });
    let n = lines.len().min(HYPOTHESIS_SEGMENTS);
    let half = [cx / s, cy / s];
    let mut best: Option<(f64, Vector3<f64>)> = None;
    for i in 0..n {
        for j in i + 1..n {
            let Some(v) = unit(lines[i].l.cross(&lines[j].l)) else {
                continue;
            };
            // a vanishing point inside the image cannot rectify it
            if v.z.abs() > 1e-9 && (v.x / v.z).abs() < half[0] && (v.y / v.z).abs() < half[1] {
                continue;
            }
            let score = support(&lines, &v);
            if best.is_none_or(|(b, _)| score > b) {
                best = Some((score, v));
            }
        }
    }
    let Some((_, mut v)) = best else {
        return Err(fail(format!(
            "no consistent {name} vanishing point among {} near-{name} segments",
            lines.len()
        )));
    };
    for _ in 0..2 {
        let inl: Vec<usize> = (0..lines.len())
            .filter(|&k| residual(&lines[k], &v).is_some_and(|r| r <= lines[k].tol))
            .collect();
        if inl.len() < 2 {
            break;
        }
        v = refine(&lines, &inl, v);
    }
    let inliers = (0..lines.len())
        .filter(|&k| residual(&lines[k], &v).is_some_and(|r| r <= lines[k].tol))
        .count();
    if inliers < MIN_INLIERS {
        return Err(fail(format!(
            "no consistent {name} vanishing point: the best explains {inliers} of {} \
             near-{name} segments, need ≥ {MIN_INLIERS}",
            lines.len()
        )));
    }
    // back to pixel coordinates
    let p = Vector3::new(s * v.x + cx * v.z, s * v.y + cy * v.z, v.z);
    let p = unit(p).unwrap_or(p);
    let p = if p.z < 0.0 { -p } else { p };
    Ok(VanishingPoint {
        point: [p.x, p.y, p.z],
        inliers,
        family: lines.len(),
    })
}

/// `v / |v|`, `None` for a (nearly) zero or non-finite vector.
fn unit(v: Vector3<f64>) -> Option<Vector3<f64>> {
    let n = v.norm();
    (n > 1e-12 && n.is_finite()).then(|| v / n)
}

/// Angle between a segment and the direction from its midpoint to `v`, `None` when `v` is
/// (nearly) at the midpoint.
fn residual(l: &Line, v: &Vector3<f64>) -> Option<f64> {
    let d = [v.x - v.z * l.mid[0], v.y - v.z * l.mid[1]];
    let dn = d[0].hypot(d[1]);
    if dn < 1e-12 {
        return None;
    }
    let sin = (l.dir[0] * d[1] - l.dir[1] * d[0]).abs() / dn;
    Some(sin.min(1.0).asin())
}

/// MSAC support of `v`: Σ length · (1 − (angle/tolerance)²) over the agreeing segments.
fn support(lines: &[Line], v: &Vector3<f64>) -> f64 {
    lines
        .iter()
        .filter_map(|l| {
            let r = residual(l, v)?;
            (r <= l.tol).then(|| l.len * (1.0 - (r / l.tol).powi(2)))
        })
        .sum()
}

/// Least squares on the inliers: the unit `v` minimising Σ len · sin²(angle), by reweighting
/// the algebraic residual l·v (= |d| sin(angle)) with 1/|d|², a few rounds.
fn refine(lines: &[Line], inl: &[usize], mut v: Vector3<f64>) -> Vector3<f64> {
    for _ in 0..5 {
        let mut m = Matrix3::<f64>::zeros();
        for &k in inl {
            let l = &lines[k];
            let d2 = (v.x - v.z * l.mid[0]).powi(2) + (v.y - v.z * l.mid[1]).powi(2);
            if d2 < 1e-18 {
                continue;
            }
            m += l.l * l.l.transpose() * (l.len / d2);
        }
        if !m.iter().all(|x| x.is_finite()) {
            break;
        }
        let e = SymmetricEigen::new(m);
        let k = e.eigenvalues.imin();
        let Some(nv) = unit(e.eigenvectors.column(k).into_owned()) else {
            break;
        };
        let nv = if nv.dot(&v) < 0.0 { -nv } else { nv };
        let done = (nv - v).norm() < 1e-12;
        v = nv;
        if done {
            break;
        }
    }
    v
}

/// The rectifying homography of a `width` × `height` photo with vertical vanishing point `vv`
/// and horizontal `vh` (homogeneous pixel coordinates), and the rectified size. Errors when
/// the points coincide, their directions are under 20° apart at the image centre, or the
/// horizon passes through or near the image.
pub fn rectifying_homography(
    vv: [f64; 3],
    vh: [f64; 3],
    width: u32,
    height: u32,
) -> Result<(Homography, u32, u32), FacadeError> {
    let (w, h) = (width.max(1) as f64, height.max(1) as f64);
    let c = Vector3::new(w / 2.0, h / 2.0, 1.0);
    let (v1, v2) = (Vector3::from(vv), Vector3::from(vh));
    let horizon = v1.cross(&v2);
    let lc = horizon.dot(&c);
    let hn = horizon.norm();
    if hn.is_nan() || hn <= 1e-12 * v1.norm() * v2.norm() || !lc.is_finite() {
        return Err(fail(
            "the vertical and horizontal vanishing points coincide".into(),
        ));
    }
    if lc.abs() < 1e-12 * horizon.norm() {
        return Err(fail("the horizon passes through the image centre".into()));
    }
    let l = horizon / lc; // l·c = 1
    let corners = [[0.0, 0.0], [w, 0.0], [w, h], [0.0, h]];
    let ws = corners.map(|[x, y]| l.x * x + l.y * y + l.z);
    let (wmin, wmax) = ws
        .iter()
        .fold((f64::MAX, f64::MIN), |(a, b), &x| (a.min(x), b.max(x)));
    if !(wmin > 0.0 && wmin >= MIN_CORNER_SCALE_RATIO * wmax) {
        return Err(fail(format!(
            "the horizon passes through or near the image (corner scale ratio {:.3}, need ≥ \
             {MIN_CORNER_SCALE_RATIO})",
            wmin / wmax
        )));
    }
    // send the horizon to infinity
    let p = Matrix3::new(1.0, 0.0, 0.0, 0.0, 1.0, 0.0, l.x, l.y, l.z);
    // image directions of the two families at the centre: down and right
    let toward = |v: &Vector3<f64>| {
        let d = [v.x - v.z * c.x, v.y - v.z * c.y];
        let n = d[0].hypot(d[1]);
        [d[0] / n, d[1] / n]
    };
    let mut t1 = toward(&v1);
    let mut t2 = toward(&v2);
    if t1[1] < 0.0 {
        t1 = [-t1[0], -t1[1]];
    }
    if t2[0] < 0.0 {
        t2 = [-t2[0], -t2[1]];
    }
    let cross = t2[0] * t1[1] - t2[1] * t1[0];
    if cross.is_nan() || cross < 20f64.to_radians().sin() {
        return Err(fail(format!(
            "the vertical and horizontal directions are {:.1}° apart at the image centre, need \
             ≥ 20° and an unmirrored pair",
            cross.clamp(-1.0, 1.0).asin().to_degrees()
        )));
    }
    // the vanishing points at infinity: directions (x, y) after P; map them to the axes
    let (u1, u2) = ((p * v1).xy(), (p * v2).xy());
    let m = nalgebra::Matrix2::new(u2.x, u1.x, u2.y, u1.y);
    let a = m
        .try_inverse()
        .ok_or_else(|| fail("degenerate vanishing points".into()))?;
    let a3 = Matrix3::new(
        a[(0, 0)],
        a[(0, 1)],
        0.0,
        a[(1, 0)],
        a[(1, 1)],
        0.0,
        0.0,
        0.0,
        1.0,
    );
    let h0 = a3 * p;
    // Jacobian of h0 at the centre: (H₂ₓ₂ − q h₃ᵀ)/w with q the mapped centre
    let hc = h0 * c;
    let q = [hc.x / hc.z, hc.y / hc.z];
    let jac = |t: [f64; 2]| {
        let r3 = h0[(2, 0)] * t[0] + h0[(2, 1)] * t[1];
        [
            (h0[(0, 0)] * t[0] + h0[(0, 1)] * t[1] - q[0] * r3) / hc.z,
            (h0[(1, 0)] * t[0] + h0[(1, 1)] * t[1] - q[1] * r3) / hc.z,
        ]
    };
    let (j1, j2) = (jac(t1), jac(t2));
    // unit steps along the image's vertical (horizontal) at the centre become unit steps
    // down (right): signed scales fix the orientation
    let (sx, sy) = (1.0 / j2[0], 1.0 / j1[1]);
    if !(sx.is_finite() && sy.is_finite() && sx != 0.0 && sy != 0.0) {
        return Err(fail("degenerate vanishing points".into()));
    }
    let h1 = Matrix3::new(sx, 0.0, 0.0, 0.0, sy, 0.0, 0.0, 0.0, 1.0) * h0;
    let hh = Homography(h1);
    let mapped: Vec<[f64; 2]> = corners.iter().filter_map(|&q| hh.apply(q)).collect();
    if mapped.len() < 4
        || mapped
            .iter()
            .any(|q| !(q[0].is_finite() && q[1].is_finite()))
    {
        return Err(fail("a warped image corner goes to infinity".into()));
    }
    let (x0, x1) = mapped
        .iter()
        .fold((f64::MAX, f64::MIN), |(a, b), q| (a.min(q[0]), b.max(q[0])));
    let (y0, y1) = mapped
        .iter()
        .fold((f64::MAX, f64::MIN), |(a, b), q| (a.min(q[1]), b.max(q[1])));
    let (bw, bh) = (x1 - x0, y1 - y0);
    let k = (MAX_AREA_FACTOR * w * h / (bw * bh)).sqrt().min(1.0);
    if !(k.is_finite() && k > 0.0) {
        return Err(fail("degenerate warped image".into()));
    }
    let t = Matrix3::new(k, 0.0, -k * x0, 0.0, k, -k * y0, 0.0, 0.0, 1.0);
    let hf = t * h1;
    let hf = hf / hf[(2, 2)];
    let (ow, oh) = ((k * bw).ceil().max(1.0), (k * bh).ceil().max(1.0));
    Ok((Homography(hf), ow as u32, oh as u32))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Segments of length 40 on lines through `vp` (homogeneous pixels), spread over the image.
    fn pencil(vp: [f64; 3], n: usize, horizontal: bool) -> Vec<Segment> {
        (0..n)
            .map(|k| {
                let t = 40.0 + 400.0 * k as f64 / n as f64;
                let m = if horizontal {
                    [250.0 + 60.0 * ((k % 5) as f64 - 2.0), t]
                } else {
                    [t, 200.0 + 50.0 * ((k % 5) as f64 - 2.0)]
                };
                let d = [vp[0] - vp[2] * m[0], vp[1] - vp[2] * m[1]];
                let n = d[0].hypot(d[1]);
                let d = [20.0 * d[0] / n, 20.0 * d[1] / n];
                Segment {
                    a: [m[0] - d[0], m[1] - d[1]],
                    b: [m[0] + d[0], m[1] + d[1]],
                    strength: 50.0,
                }
            })
            .collect()
    }

    #[test]
    fn exact_pencils_give_their_vanishing_points_and_send_them_to_infinity() {
        let (vv, vh) = ([300.0, -2500.0, 1.0], [-1800.0, 150.0, 1.0]);
        let mut segs = pencil(vv, 20, false);
        segs.extend(pencil(vh, 20, true));
        let r = rectify_segments(&segs, 500, 400).unwrap();
        for (got, want) in [(r.vertical_vp, vv), (r.horizontal_vp, vh)] {
            let (g, w) = (Vector3::from(got), Vector3::from(want).normalize());
            assert!(g.cross(&w).norm() < 1e-9, "{g} {w}");
        }
        assert_eq!(r.inliers, (20, 20));
        let (a, b) = (r.h.0 * Vector3::from(vv), r.h.0 * Vector3::from(vh));
        assert!(
            a.z.abs() < 1e-9 * a.norm() && a.x.abs() < 1e-9 * a.norm(),
            "{a}"
        );
        assert!(
            b.z.abs() < 1e-9 * b.norm() && b.y.abs() < 1e-9 * b.norm(),
            "{b}"
        );
    }

    #[test]
    fn points_at_infinity_along_the_axes_give_a_translation() {
        let (h, w, hh) =
            rectifying_homography([0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], 300, 200).unwrap();
        assert!((h.0 - Matrix3::identity()).norm() < 1e-12, "{}", h.0);
        assert_eq!((w, hh), (300, 200));
    }

    #[test]
    fn a_horizon_through_the_image_is_refused() {
        // a vertical point above the image and a horizontal one right of it, both near: the
        // line through them crosses the image at (500, 157)
        let e = rectifying_homography([0.0, -200.0, 1.0], [700.0, 300.0, 1.0], 500, 400);
        let msg = e.map(|_| ()).unwrap_err().to_string();
        assert!(msg.contains("horizon"), "{msg}");
    }
}
