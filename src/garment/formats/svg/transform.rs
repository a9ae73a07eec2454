//! SVG `transform` lists (matrix, translate, scale, rotate, skewX, skewY) as 2D affine maps.

use super::path::parse_numbers;
use crate::garment::pattern::P2;

/// A 2D affine map `[a, b, c, d, e, f]`: (x, y) ↦ (a x + c y + e, b x + d y + f), as SVG's
/// `matrix(a b c d e f)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Affine(pub [f64; 6]);

impl Affine {
    /// The identity.
    pub const IDENTITY: Affine = Affine([1.0, 0.0, 0.0, 1.0, 0.0, 0.0]);

    /// Applies the map to a point.
    pub fn apply(&self, p: P2) -> P2 {
        let m = &self.0;
        [
            m[0] * p[0] + m[2] * p[1] + m[4],
            m[1] * p[0] + m[3] * p[1] + m[5],
        ]
    }

    /// `self ∘ other` (apply `other` first).
    pub fn then_inner(&self, other: &Affine) -> Affine {
        let (a, b) = (&self.0, &other.0);
        Affine([
            a[0] * b[0] + a[2] * b[1],
            a[1] * b[0] + a[3] * b[1],
            a[0] * b[2] + a[2] * b[3],
            a[1] * b[2] + a[3] * b[3],
            a[0] * b[4] + a[2] * b[5] + a[4],
            a[1] * b[4] + a[3] * b[5] + a[5],
        ])
    }
}

/// Parses an SVG `transform` list (matrix, translate, scale, rotate, skewX, skewY).
pub(crate) fn parse_transform(t: &str) -> Result<Affine, String> {
    let mut total = Affine::IDENTITY;
    let mut rest = t.trim();
    while !rest.is_empty() {
        let open = rest
            .find('(')
            .ok_or_else(|| format!("bad transform '{t}'"))?;
        let close = rest
            .find(')')
            .ok_or_else(|| format!("bad transform '{t}': missing ')'"))?;
        if close < open {
            return Err(format!("bad transform '{t}'"));
        }
        let name = rest[..open].trim().trim_start_matches(',').trim();
        let args = parse_numbers(&rest[open + 1..close])
            .map_err(|e| format!("bad transform '{t}': {e}"))?;
        let arg = |i: usize, default: f64| args.get(i).copied().unwrap_or(default);
        let m = match (name, args.len()) {
            ("matrix", 6) => Affine([args[0], args[1], args[2], args[3], args[4], args[5]]),
            ("translate", 1 | 2) => Affine([1.0, 0.0, 0.0, 1.0, args[0], arg(1, 0.0)]),
            ("scale", 1 | 2) => Affine([args[0], 0.0, 0.0, arg(1, args[0]), 0.0, 0.0]),
            ("rotate", 1 | 3) => {
                let (s, c) = args[0].to_radians().sin_cos();
                let (cx, cy) = (arg(1, 0.0), arg(2, 0.0));
                Affine([c, s, -s, c, cx - c * cx + s * cy, cy - s * cx - c * cy])
            }
            ("skewX", 1) => Affine([1.0, 0.0, args[0].to_radians().tan(), 1.0, 0.0, 0.0]),
            ("skewY", 1) => Affine([1.0, args[0].to_radians().tan(), 0.0, 1.0, 0.0, 0.0]),
            _ => {
                return Err(format!(
                    "bad transform '{t}': {name} with {} arguments",
                    args.len()
                ))
            }
        };
        total = total.then_inner(&m);
        rest = rest[close + 1..].trim_start();
    }
    Ok(total)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn transforms_compose_left_to_right() {
        let t = parse_transform("translate(10, 20) scale(2) rotate(90)").unwrap();
        let p = t.apply([1.0, 0.0]);
        assert!(
            (p[0] - 10.0).abs() < 1e-12 && (p[1] - 22.0).abs() < 1e-12,
            "{p:?}"
        );
        let u = parse_transform("translate(40.54, 165.41) scale(1) translate(-40.54, -165.41)")
            .unwrap();
        let q = u.apply([40.54, 165.41]);
        assert!((q[0] - 40.54).abs() < 1e-9 && (q[1] - 165.41).abs() < 1e-9);
        assert!(parse_transform("frobnicate(1)").is_err());
    }
}
