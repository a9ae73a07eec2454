//! The 68-point iBUG landmark scheme (300-W, LFPW, HELEN `.pts` files) on the face mesh, and
//! the `.pts` file format.
//!
//! Point numbers are 0-based here (the iBUG figure counts from 1). `0..=16` are the jaw line
//! from the subject's right ear to the left ear through the chin (8); `17..=21` the right brow
//! and `22..=26` the left brow (outer to inner, inner to outer); `27..=30` the nose bridge
//! down to the tip; `31..=35` the nose base; `36..=41` the right eye (36 outer corner, 39
//! inner) and `42..=47` the left eye (42 inner, 45 outer corner); `48..=59` the outer lip (48
//! right corner, 51 top middle, 54 left corner, 57 bottom middle) and `60..=67` the inner lip.
//!
//! [`IBUG68_TO_MEDIAPIPE`] gives, per iBUG point, two MediaPipe vertices whose midpoint is the
//! point (the same vertex twice where one vertex fits). The table is left–right symmetric: the
//! mirror of point `i` ([`IBUG68_MIRROR`]) uses the mirrored vertices (checked by a test on the
//! mesh). The jaw points `0..=16` ([`is_contour`]) are *sliding*: on a real face they lie on the
//! occluding contour of the view, which moves over the surface when the head turns, so a fit
//! matches them to the nearest point of the projected silhouette rather than to fixed vertices.
//!
//! `.pts` files: a `version: 1` line, `n_points: 68`, `{`, one `x y` per line (pixels, origin
//! at the top-left corner of the image, as the 300-W files: the centre of the top-left pixel is
//! `(1, 1)` in those files' MATLAB convention; this module reads and writes the numbers as they
//! are and the fit subtracts [`PTS_PIXEL_ORIGIN`]), `}`.

use std::path::Path;

use super::model::FaceMesh;
use super::FaceError;
use crate::geometry::Vec3;

/// Number of points of the iBUG scheme.
pub const IBUG_POINTS: usize = 68;

/// Offset of `.pts` coordinates from this crate's pixel coordinates (where the centre of the
/// top-left pixel is `(0, 0)`): the 300-W files count pixels from 1.
pub const PTS_PIXEL_ORIGIN: f64 = 1.0;

/// MediaPipe vertex pair per iBUG point (midpoint; one vertex twice where it fits alone).
pub const IBUG68_TO_MEDIAPIPE: [[usize; 2]; IBUG_POINTS] = [
    // jaw line 0..=16, subject's right ear → chin → left ear
    [127, 127],
    [234, 234],
    [93, 93],
    [132, 132],
    [58, 58],
    [172, 136],
    [150, 150],
    [176, 149],
    [152, 152],
    [400, 378],
    [379, 379],
    [397, 365],
    [288, 288],
    [361, 361],
    [323, 323],
    [454, 454],
    [356, 356],
    // right brow 17..=21 (outer → inner), left brow 22..=26 (inner → outer)
    [70, 70],
    [63, 63],
    [105, 105],
    [66, 66],
    [107, 107],
    [336, 336],
    [296, 296],
    [334, 334],
    [293, 293],
    [300, 300],
    // nose bridge 27..=30, down to the tip
    [168, 168],
    [197, 197],
    [5, 5],
    [4, 4],
    // nose base 31..=35
    [75, 75],
    [97, 97],
    [2, 2],
    [326, 326],
    [305, 305],
    // right eye 36..=41: outer corner, upper lid ×2, inner corner, lower lid ×2
    [33, 33],
    [160, 160],
    [158, 158],
    [133, 133],
    [153, 153],
    [144, 144],
    // left eye 42..=47: inner corner, upper lid ×2, outer corner, lower lid ×2
    [362, 362],
    [385, 385],
    [387, 387],
    [263, 263],
    [373, 373],
    [380, 380],
    // outer lip 48..=59: right corner, upper lip, top middle, …, left corner, lower lip
    [61, 61],
    [39, 39],
    [37, 37],
    [0, 0],
    [267, 267],
    [269, 269],
    [291, 291],
    [405, 405],
    [314, 314],
    [17, 17],
    [84, 84],
    [181, 181],
    // inner lip 60..=67
    [78, 78],
    [82, 82],
    [13, 13],
    [312, 312],
    [308, 308],
    [317, 317],
    [14, 14],
    [87, 87],
];

/// The iBUG point that is the mirror image of each point (left ↔ right).
pub const IBUG68_MIRROR: [usize; IBUG_POINTS] = [
    16, 15, 14, 13, 12, 11, 10, 9, 8, 7, 6, 5, 4, 3, 2, 1, 0, // jaw
    26, 25, 24, 23, 22, 21, 20, 19, 18, 17, // brows
    27, 28, 29, 30, // bridge
    35, 34, 33, 32, 31, // nose base
    45, 44, 43, 42, 47, 46, // right eye ↔ left eye
    39, 38, 37, 36, 41, 40, // left eye ↔ right eye
    54, 53, 52, 51, 50, 49, 48, 59, 58, 57, 56, 55, // outer lip
    64, 63, 62, 61, 60, 67, 66, 65, // inner lip
];

/// iBUG outer corner of the subject's right eye.
pub const IBUG_RIGHT_EYE_OUTER: usize = 36;
/// iBUG outer corner of the subject's left eye.
pub const IBUG_LEFT_EYE_OUTER: usize = 45;

/// Whether iBUG point `i` is on the jaw line (a sliding contour point).
pub fn is_contour(i: usize) -> bool {
    i <= 16
}

/// Whether iBUG point `i` lies on the symmetry plane (the central points: chin, nose bridge and
/// base middle, lip middles).
pub fn is_central(i: usize) -> bool {
    IBUG68_MIRROR[i] == i
}

/// The 68 landmark positions on a mesh with MediaPipe vertex order.
pub fn landmark_positions(mesh: &FaceMesh) -> Vec<Vec3> {
    IBUG68_TO_MEDIAPIPE
        .iter()
        .map(|[a, b]| (mesh.positions[*a] + mesh.positions[*b]) * 0.5)
        .collect()
}

/// Inter-ocular distance of 2D landmarks: outer eye corners (points 36 and 45), the
/// normalisation of 300-W.
pub fn inter_ocular_distance(points: &[[f64; 2]]) -> f64 {
    let (a, b) = (points[IBUG_RIGHT_EYE_OUTER], points[IBUG_LEFT_EYE_OUTER]);
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)).sqrt()
}

/// Smallest inter-ocular distance (pixels) of a usable face: below it the face is a few pixels
/// across, or its points are piled up (a file of identical points), and no adaptation is
/// defined.
pub const MIN_IOD_PX: f64 = 4.0;

/// Smallest spread of the 68 points across their main direction, as a share of the
/// inter-ocular distance: a real face's points spread about as far down (eyes to chin) as
/// across (≈ 0.6 of the IOD as an RMS); points on one line (0) are no face.
pub const MIN_SPREAD_IOD: f64 = 0.1;

/// Checks that 68 landmarks can be a face: finite, the outer eye corners at least
/// [`MIN_IOD_PX`] apart, and not all on one line (their RMS spread across their main
/// direction at least [`MIN_SPREAD_IOD`] × the inter-ocular distance). Errors name `source`.
pub fn check_geometry(points: &[[f64; 2]], source: &str) -> Result<(), FaceError> {
    let err = |message: String| FaceError::Landmarks {
        source_name: source.to_string(),
        message,
    };
    if points.len() != IBUG_POINTS {
        return Err(err(format!(
            "expected {IBUG_POINTS} landmarks (iBUG scheme), got {}",
            points.len()
        )));
    }
    if let Some(i) = points
        .iter()
        .position(|p| !(p[0].is_finite() && p[1].is_finite()))
    {
        return Err(err(format!("landmark {i} is not finite")));
    }
    let iod = inter_ocular_distance(points);
    if iod.is_nan() || iod < MIN_IOD_PX {
        return Err(err(format!(
            "degenerate landmarks: the outer eye corners (points {IBUG_RIGHT_EYE_OUTER} and {IBUG_LEFT_EYE_OUTER}) are {iod:.3} px apart, less than {MIN_IOD_PX} px"
        )));
    }
    // the smaller principal spread of the points (the square root of the covariance's
    // smaller eigenvalue)
    let n = points.len() as f64;
    let (mx, my) = points
        .iter()
        .fold((0.0, 0.0), |(x, y), p| (x + p[0] / n, y + p[1] / n));
    let (mut sxx, mut syy, mut sxy) = (0.0, 0.0, 0.0);
    for p in points {
        let (dx, dy) = (p[0] - mx, p[1] - my);
        sxx += dx * dx / n;
        syy += dy * dy / n;
        sxy += dx * dy / n;
    }
    let half = 0.5 * (sxx + syy);
    let minor = (half - (0.25 * (sxx - syy).powi(2) + sxy * sxy).sqrt())
        .max(0.0)
        .sqrt();
    if minor.is_nan() || minor < MIN_SPREAD_IOD * iod {
        return Err(err(format!(
            "degenerate landmarks: the points lie on a line (spread {minor:.3} px across it, less than {MIN_SPREAD_IOD} × the inter-ocular distance {iod:.1} px)"
        )));
    }
    Ok(())
}

/// Reads a `.pts` file of exactly 68 points. Errors name the file and line: missing header or
/// braces, wrong count, malformed or non-finite numbers.
pub fn read_pts(path: &Path) -> Result<Vec<[f64; 2]>, FaceError> {
    let text = crate::limits::read_to_string(path).map_err(|e| FaceError::io(path, e))?;
    parse_pts(&text, path)
}

/// Parses the text of a `.pts` file; `path` names it in errors.
pub fn parse_pts(text: &str, path: &Path) -> Result<Vec<[f64; 2]>, FaceError> {
    let err = |line: usize, message: String| FaceError::Parse {
        path: path.to_path_buf(),
        line,
        message,
    };
    let mut declared: Option<usize> = None;
    let mut inside = false;
    let mut closed = false;
    let mut points = Vec::new();
    for (k, raw) in text.lines().enumerate() {
        let line = raw.trim();
        let no = k + 1;
        if line.is_empty() || line.starts_with("//") || line.starts_with('#') {
            continue;
        }
        if closed {
            return Err(err(no, format!("text after the closing brace: `{line}`")));
        }
        if !inside {
            if let Some(v) = line.strip_prefix("n_points:") {
                let n: usize = v
                    .trim()
                    .parse()
                    .map_err(|_| err(no, format!("bad point count `{}`", v.trim())))?;
                declared = Some(n);
            } else if line.starts_with("version:") {
            } else if line == "{" {
                inside = true;
            } else {
                return Err(err(
                    no,
                    format!("expected `n_points:` or `{{`, found `{line}`"),
                ));
            }
            continue;
        }
        if line == "}" {
            closed = true;
            continue;
        }
        let mut it = line.split_whitespace();
        let mut num = || -> Result<f64, FaceError> {
            let s = it
                .next()
                .ok_or_else(|| err(no, format!("expected `x y`, found `{line}`")))?;
            let v: f64 = s
                .parse()
                .map_err(|_| err(no, format!("`{s}` is not a number")))?;
            if !v.is_finite() {
                return Err(err(no, format!("coordinate `{s}` is not finite")));
            }
            Ok(v)
        };
        let (x, y) = (num()?, num()?);
        if it.next().is_some() {
            return Err(err(no, format!("expected two numbers, found `{line}`")));
        }
        points.push([x, y]);
    }
    if !inside || !closed {
        return Err(err(0, "missing `{` … `}` around the points".into()));
    }
    if let Some(n) = declared {
        if n != points.len() {
            return Err(err(
                0,
                format!(
                    "header says n_points: {n} but {} points follow",
                    points.len()
                ),
            ));
        }
    }
    if points.len() != IBUG_POINTS {
        return Err(err(
            0,
            format!(
                "the iBUG scheme has {IBUG_POINTS} points, this file has {}",
                points.len()
            ),
        ));
    }
    Ok(points)
}

/// Writes 68 (or any number of) points as a `.pts` file.
pub fn write_pts(path: &Path, points: &[[f64; 2]]) -> Result<(), FaceError> {
    let mut s = format!("version: 1\nn_points: {}\n{{\n", points.len());
    for p in points {
        s.push_str(&format!("{:.3} {:.3}\n", p[0], p[1]));
    }
    s.push_str("}\n");
    std::fs::write(path, s).map_err(|e| FaceError::io(path, e))
}

/// Checks that every point lies inside a `width × height` image (in `.pts` coordinates, with a
/// margin of one pixel); `source` names the file in the error.
pub fn check_inside(
    points: &[[f64; 2]],
    width: u32,
    height: u32,
    source: &str,
) -> Result<(), FaceError> {
    for (i, p) in points.iter().enumerate() {
        let (w, h) = (
            width as f64 + PTS_PIXEL_ORIGIN,
            height as f64 + PTS_PIXEL_ORIGIN,
        );
        if !(p[0] >= PTS_PIXEL_ORIGIN - 1.0
            && p[0] <= w
            && p[1] >= PTS_PIXEL_ORIGIN - 1.0
            && p[1] <= h)
        {
            return Err(FaceError::Landmarks {
                source_name: source.to_string(),
                message: format!(
                    "point {i} at ({:.1}, {:.1}) is outside the {width}×{height} image",
                    p[0], p[1]
                ),
            });
        }
    }
    Ok(())
}
