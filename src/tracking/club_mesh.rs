//! The golf club as coloured triangles for rendering: a thin shaft (grip end dark) from a
//! little past the hands to the head, and the head as a small sphere. The topology is fixed,
//! so [`ClubMesh::place`] only rewrites positions.

use crate::geometry::Vec3;

/// Sides of the shaft's prism.
const SIDES: usize = 6;
/// Shaft radius, metres.
const SHAFT_RADIUS: f64 = 0.009;
/// How far the butt end stands past the grip point (the hands), metres.
const BUTT: f64 = 0.12;
/// Length of the dark grip from the butt, metres.
const GRIP_LENGTH: f64 = 0.27;
/// Radius of the head's sphere, metres (a driver head is about 0.12 m long).
pub const HEAD_RADIUS: f64 = 0.05;
/// Rings and segments of the head's sphere.
const RINGS: usize = 5;
const SEGMENTS: usize = 8;
/// Colours (linear 0..255): grip, shaft, head.
const GRIP_COLOUR: [f32; 3] = [28.0, 28.0, 30.0];
const SHAFT_COLOUR: [f32; 3] = [175.0, 175.0, 182.0];
const HEAD_COLOUR: [f32; 3] = [45.0, 45.0, 52.0];

/// A club's triangles, colours and (after [`ClubMesh::place`]) positions.
#[derive(Clone, Debug)]
pub struct ClubMesh {
    /// Vertex positions (world frame).
    pub positions: Vec<Vec3>,
    /// Unshaded vertex colours.
    pub colours: Vec<[f32; 3]>,
    /// Triangles.
    pub triangles: Vec<[u32; 3]>,
}

impl Default for ClubMesh {
    fn default() -> Self {
        Self::new()
    }
}

impl ClubMesh {
    /// No club: no vertex, no triangle (a golfer filmed without one).
    pub fn empty() -> ClubMesh {
        ClubMesh {
            positions: Vec::new(),
            colours: Vec::new(),
            triangles: Vec::new(),
        }
    }

    /// The club's topology and colours (positions at the origin until placed).
    pub fn new() -> ClubMesh {
        let mut colours = Vec::new();
        let mut triangles = Vec::new();
        // shaft: three rings (butt, end of grip, neck) of SIDES vertices
        for c in [GRIP_COLOUR, SHAFT_COLOUR, SHAFT_COLOUR] {
            colours.extend(std::iter::repeat_n(c, SIDES));
        }
        // the grip ring is doubled so the grip's colour does not bleed into the shaft
        colours.extend(std::iter::repeat_n(GRIP_COLOUR, SIDES));
        let ring = |r: usize, s: usize| (r * SIDES + s % SIDES) as u32;
        for (a, b) in [(0, 3), (1, 2)] {
            for s in 0..SIDES {
                triangles.push([ring(a, s), ring(a, s + 1), ring(b, s + 1)]);
                triangles.push([ring(a, s), ring(b, s + 1), ring(b, s)]);
            }
        }
        for s in 1..SIDES - 1 {
            triangles.push([ring(0, 0), ring(0, s + 1), ring(0, s)]);
        }
        // head: poles and RINGS − 1 rings of SEGMENTS
        let base = colours.len() as u32;
        let rings = RINGS - 1;
        colours.extend(std::iter::repeat_n(HEAD_COLOUR, 2 + rings * SEGMENTS));
        let v = |r: usize, s: usize| base + 2 + (r * SEGMENTS + s % SEGMENTS) as u32;
        for s in 0..SEGMENTS {
            triangles.push([base, v(0, s + 1), v(0, s)]);
            triangles.push([base + 1, v(rings - 1, s), v(rings - 1, s + 1)]);
            for r in 0..rings - 1 {
                triangles.push([v(r, s), v(r, s + 1), v(r + 1, s + 1)]);
                triangles.push([v(r, s), v(r + 1, s + 1), v(r + 1, s)]);
            }
        }
        ClubMesh {
            positions: vec![Vec3::zeros(); colours.len()],
            colours,
            triangles,
        }
    }

    /// Places the club with its grip point (the hands) at `grip` and the head's centre at
    /// `head`. A degenerate club (grip on the head) collapses to a point.
    pub fn place(&mut self, grip: Vec3, head: Vec3) {
        let d = (head - grip).try_normalize(1e-9).unwrap_or_else(Vec3::z);
        let helper = if d.x.abs() < 0.9 {
            Vec3::x()
        } else {
            Vec3::y()
        };
        let u = d.cross(&helper).normalize();
        let w = d.cross(&u);
        let butt = grip - d * BUTT;
        let centres = [
            butt,
            butt + d * GRIP_LENGTH,
            head - d * HEAD_RADIUS,
            butt + d * GRIP_LENGTH,
        ];
        let mut k = 0;
        for c in centres {
            for s in 0..SIDES {
                let a = std::f64::consts::TAU * s as f64 / SIDES as f64;
                self.positions[k] = c + (u * a.cos() + w * a.sin()) * SHAFT_RADIUS;
                k += 1;
            }
        }
        self.positions[k] = head + d * HEAD_RADIUS;
        self.positions[k + 1] = head - d * HEAD_RADIUS;
        k += 2;
        for r in 0..RINGS - 1 {
            let polar = std::f64::consts::PI * (r + 1) as f64 / RINGS as f64;
            for s in 0..SEGMENTS {
                let a = std::f64::consts::TAU * s as f64 / SEGMENTS as f64;
                let radial = (u * a.cos() + w * a.sin()) * polar.sin();
                self.positions[k] = head + (d * polar.cos() + radial) * HEAD_RADIUS;
                k += 1;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_club_spans_butt_to_head_and_every_triangle_is_valid() {
        let mut c = ClubMesh::new();
        let (grip, head) = (Vec3::new(0.0, 0.0, 1.0), Vec3::new(0.0, 1.0, 0.0));
        c.place(grip, head);
        let n = c.positions.len() as u32;
        assert!(c.triangles.iter().flatten().all(|&i| i < n));
        assert_eq!(c.colours.len(), c.positions.len());
        let d = (head - grip).normalize();
        let along: Vec<f64> = c.positions.iter().map(|p| (p - grip).dot(&d)).collect();
        let (lo, hi) = along
            .iter()
            .fold((f64::MAX, f64::MIN), |(a, b), &x| (a.min(x), b.max(x)));
        assert!((lo + BUTT).abs() < 1e-12, "{lo}");
        assert!(
            (hi - ((head - grip).norm() + HEAD_RADIUS)).abs() < 1e-12,
            "{hi}"
        );
        // every head vertex on the sphere
        for p in &c.positions[4 * SIDES..] {
            assert!(((p - head).norm() - HEAD_RADIUS).abs() < 1e-12);
        }
    }
}
