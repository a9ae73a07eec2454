//! Tracked motion written as files other tools read: BVH (the sixteen tracking joints as a
//! joint tree with rotations) and a plain CSV of joint positions; and
//! [`TrackingOutputError`], the error of every tracking output (BVH, CSV, overlays, metrics).
//!
//! # BVH
//!
//! The hierarchy is [`TRACKING_JOINTS`] (the pelvis is the root), plus an `End Site` on the
//! head, the wrists and the ankles. Offsets are the bone vectors of a rest frame (given by the
//! caller, or the first frame) in BVH units and axes: centimetres with y up, the inverse of
//! [`bvh_to_world`](crate::body::bvh::bvh_to_world), so the rest pose has every rotation at
//! zero. The root has `Xposition Yposition Zposition Zrotation Xrotation Yrotation`, every
//! other joint `Zrotation Xrotation Yrotation` (`R = Rz·Rx·Ry`, degrees), which
//! [`Motion::parse_bvh`](crate::body::bvh::Motion::parse_bvh) reads back.
//!
//! Each frame's global joint rotations are solved from the positions, parents first:
//! - a joint with one child gets the smallest rotation that takes its rest bone direction,
//!   carried by the parent's rotation, onto the frame's bone direction (so twist is inherited
//!   from the parent);
//! - a joint with several children (pelvis: spine and hips; spine: neck and shoulders) gets
//!   the rotation that best takes the rest child directions onto the frame's (least squares,
//!   Kabsch), falling back to the single-child rule when they are collinear;
//! - a leaf joint keeps its parent's rotation.
//!
//! With constant bone lengths (a rigid skeleton) forward kinematics of the file reproduces
//! every joint to rounding (~1e-7 m); when lengths vary, bone directions are kept and lengths
//! are those of the rest frame.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use nalgebra::{Matrix3, Vector3};

use super::joints::{JOINT_COUNT, TRACKING_JOINTS};
use crate::geometry::Vec3;
use crate::render::plot::PlotError;

/// Error of the tracking outputs (BVH, CSV, overlay pictures, swing metrics).
#[derive(Debug, thiserror::Error)]
pub enum TrackingOutputError {
    /// A file could not be written.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file being written.
        path: PathBuf,
        /// The underlying error.
        #[source]
        source: std::io::Error,
    },
    /// A picture could not be encoded or written.
    #[error("{}: {message}", path.display())]
    Image {
        /// The file being written.
        path: PathBuf,
        /// What failed.
        message: String,
    },
    /// A plot could not be drawn or written (the error names the file).
    #[error(transparent)]
    Plot(#[from] PlotError),
    /// The input is unusable: no frames, a non-finite joint (naming frame and joint), a
    /// frame rate that is not positive, a degenerate rest pose.
    #[error("invalid input: {0}")]
    InvalidInput(String),
}

/// An [`TrackingOutputError::Io`] naming `path`.
pub(crate) fn io_error(path: &Path, source: std::io::Error) -> TrackingOutputError {
    TrackingOutputError::Io {
        path: path.to_path_buf(),
        source,
    }
}

/// Checks that `frames` is not empty, every joint is finite, and `fps` is positive and
/// finite; the error names the first bad frame (counted from 0) and joint.
pub fn validate_frames(
    frames: &[[Vec3; JOINT_COUNT]],
    fps: f64,
) -> Result<(), TrackingOutputError> {
    if !(fps.is_finite() && fps > 0.0) {
        return Err(TrackingOutputError::InvalidInput(format!(
            "the frame rate must be positive and finite, got fps = {fps}"
        )));
    }
    if frames.is_empty() {
        return Err(TrackingOutputError::InvalidInput(
            "no frames (empty motion)".to_string(),
        ));
    }
    for (f, frame) in frames.iter().enumerate() {
        check_pose(frame, &format!("frame {f}"))?;
    }
    Ok(())
}

/// Checks that every joint of `pose` is finite; `what` names the pose in the error.
fn check_pose(pose: &[Vec3; JOINT_COUNT], what: &str) -> Result<(), TrackingOutputError> {
    for (k, p) in pose.iter().enumerate() {
        if !p.iter().all(|c| c.is_finite()) {
            return Err(TrackingOutputError::InvalidInput(format!(
                "{what}, joint {}: non-finite position ({}, {}, {})",
                TRACKING_JOINTS[k].name, p.x, p.y, p.z
            )));
        }
    }
    Ok(())
}

/// Converts a world point (metres, z up) to BVH units and axes (centimetres, y up): the
/// inverse of [`bvh_to_world`](crate::body::bvh::bvh_to_world).
pub fn world_to_bvh(p: Vec3) -> Vec3 {
    Vec3::new(p.x, p.z, -p.y) * 100.0
}

/// Children of every tracking joint, in [`TRACKING_JOINTS`] order.
fn children() -> [Vec<usize>; JOINT_COUNT] {
    let mut c: [Vec<usize>; JOINT_COUNT] = std::array::from_fn(|_| Vec::new());
    for (k, t) in TRACKING_JOINTS.iter().enumerate() {
        if let Some(p) = t.parent {
            c[p].push(k);
        }
    }
    c
}

/// Joints in depth-first order (the order of the hierarchy and of the channels).
fn dfs_order(children: &[Vec<usize>; JOINT_COUNT]) -> Vec<usize> {
    let mut order = Vec::with_capacity(JOINT_COUNT);
    let mut stack = vec![0usize];
    while let Some(j) = stack.pop() {
        order.push(j);
        stack.extend(children[j].iter().rev());
    }
    order
}

/// The smallest rotation taking unit vector `a` onto unit vector `b`.
fn rotation_between(a: &Vector3<f64>, b: &Vector3<f64>) -> Matrix3<f64> {
    let c = a.dot(b);
    let axis = a.cross(b);
    let s = axis.norm();
    if s < 1e-12 {
        if c > 0.0 {
            return Matrix3::identity();
        }
        // opposite: half turn about any axis perpendicular to a
        let helper = if a.x.abs() < 0.9 {
            Vector3::x()
        } else {
            Vector3::y()
        };
        let n = a.cross(&helper).normalize();
        return 2.0 * n * n.transpose() - Matrix3::identity();
    }
    let angle = s.atan2(c);
    *nalgebra::Rotation3::from_axis_angle(&nalgebra::Unit::new_normalize(axis), angle).matrix()
}

/// The rotation that best takes unit vectors `from[i]` onto `to[i]` (Kabsch); `None` when the
/// `from`/`to` pairs do not fix a rotation (collinear directions).
fn kabsch(from: &[Vector3<f64>], to: &[Vector3<f64>]) -> Option<Matrix3<f64>> {
    let mut m = Matrix3::zeros();
    for (a, b) in from.iter().zip(to) {
        m += b * a.transpose();
    }
    let svd = m.svd(true, true);
    let (u, v_t) = (svd.u?, svd.v_t?);
    let s = svd.singular_values;
    let mut idx = [0usize, 1, 2];
    idx.sort_by(|&i, &j| s[j].total_cmp(&s[i]));
    let rank_two = s[idx[1]] > 1e-9 * s[idx[0]].max(1e-300);
    if !rank_two {
        return None;
    }
    let d = (u * v_t).determinant().signum();
    let mut diag = Matrix3::identity();
    diag[(idx[2], idx[2])] = d;
    let r = u * diag * v_t;
    r.iter().all(|c| c.is_finite()).then_some(r)
}

/// Global rotations (BVH axes) of every joint for one frame, given rest bone vectors.
fn global_rotations(
    rest_bones: &[Vector3<f64>; JOINT_COUNT],
    frame: &[Vec3; JOINT_COUNT],
    children: &[Vec<usize>; JOINT_COUNT],
) -> [Matrix3<f64>; JOINT_COUNT] {
    let mut g = [Matrix3::identity(); JOINT_COUNT];
    for j in 0..JOINT_COUNT {
        let parent_rot = TRACKING_JOINTS[j]
            .parent
            .map_or(Matrix3::identity(), |p| g[p]);
        let kids = &children[j];
        // rest and current unit directions of the children with usable (non-zero) bones
        let mut from = Vec::with_capacity(kids.len());
        let mut to = Vec::with_capacity(kids.len());
        for &c in kids {
            let cur = frame[c] - frame[j];
            let (ln, lc) = (rest_bones[c].norm(), cur.norm());
            if ln > 1e-12 && lc > 1e-12 {
                from.push(rest_bones[c] / ln);
                to.push(cur / lc);
            }
        }
        g[j] = if from.is_empty() {
            parent_rot
        } else if from.len() >= 2 {
            kabsch(&from, &to)
                .unwrap_or_else(|| rotation_between(&(parent_rot * from[0]), &to[0]) * parent_rot)
        } else {
            rotation_between(&(parent_rot * from[0]), &to[0]) * parent_rot
        };
    }
    g
}

/// Euler angles `(z, x, y)` in degrees with `r = Rz(z)·Rx(x)·Ry(y)`.
fn euler_zxy(r: &Matrix3<f64>) -> [f64; 3] {
    let cb = (r[(0, 1)] * r[(0, 1)] + r[(1, 1)] * r[(1, 1)]).sqrt();
    let x = r[(2, 1)].atan2(cb);
    let (z, y) = if cb > 1e-9 {
        ((-r[(0, 1)]).atan2(r[(1, 1)]), (-r[(2, 0)]).atan2(r[(2, 2)]))
    } else {
        // gimbal lock: put the whole turn about the vertical on z
        (r[(1, 0)].atan2(r[(0, 0)]), 0.0)
    };
    [z.to_degrees(), x.to_degrees(), y.to_degrees()]
}

/// Short offset (BVH units) of the end site of a leaf joint, in the rest frame: along the
/// parent bone for the head and wrists (5 cm and 8 cm), forward for the ankles (10 cm).
fn end_site_offset(j: usize, rest: &[Vec3; JOINT_COUNT]) -> Vec3 {
    let name = TRACKING_JOINTS[j].name;
    if name.ends_with("ankle") {
        // forward is world −y, BVH +z
        return Vec3::new(0.0, 0.0, 10.0);
    }
    let len = if name == "head" { 5.0 } else { 8.0 };
    let dir = TRACKING_JOINTS[j]
        .parent
        .map(|p| rest[j] - rest[p])
        .and_then(|d| d.try_normalize(1e-12))
        .unwrap_or_else(|| Vec3::new(0.0, 1.0, 0.0));
    dir * len
}

/// The BVH text of `frames` at `fps`, with the rest skeleton taken from `rest` (or the first
/// frame when `None`); see the [module docs](self).
///
/// # Errors
///
/// [`TrackingOutputError::InvalidInput`] for no frames, a non-finite joint (naming frame and
/// joint), `fps` not positive, or a rest pose with a zero-length bone (naming it).
pub fn to_bvh_string(
    frames: &[[Vec3; JOINT_COUNT]],
    fps: f64,
    rest: Option<&[Vec3; JOINT_COUNT]>,
) -> Result<String, TrackingOutputError> {
    validate_frames(frames, fps)?;
    let rest_world = match rest {
        Some(r) => {
            check_pose(r, "rest pose")?;
            r
        }
        None => &frames[0],
    };
    let rest_bvh: [Vec3; JOINT_COUNT] = std::array::from_fn(|k| world_to_bvh(rest_world[k]));
    let mut rest_bones = [Vector3::zeros(); JOINT_COUNT];
    for (k, t) in TRACKING_JOINTS.iter().enumerate() {
        if let Some(p) = t.parent {
            rest_bones[k] = rest_bvh[k] - rest_bvh[p];
            if rest_bones[k].norm() < 1e-6 {
                return Err(TrackingOutputError::InvalidInput(format!(
                    "rest pose: the bone {} -> {} has zero length",
                    TRACKING_JOINTS[p].name, t.name
                )));
            }
        }
    }
    let kids = children();
    let order = dfs_order(&kids);

    let mut s = String::new();
    s.push_str("HIERARCHY\n");
    write_joint(&mut s, 0, 0, &kids, &rest_bones, &rest_bvh);
    let _ = writeln!(
        s,
        "MOTION\nFrames: {}\nFrame Time: {:.9}",
        frames.len(),
        1.0 / fps
    );
    for frame in frames {
        let cur: [Vec3; JOINT_COUNT] = std::array::from_fn(|k| world_to_bvh(frame[k]));
        let g = global_rotations(&rest_bones, &cur, &kids);
        let mut line = String::new();
        let root = cur[0];
        let _ = write!(line, "{:.6} {:.6} {:.6}", root.x, root.y, root.z);
        for &j in &order {
            let local = match TRACKING_JOINTS[j].parent {
                Some(p) => g[p].transpose() * g[j],
                None => g[j],
            };
            let [z, x, y] = euler_zxy(&local);
            let _ = write!(line, " {z:.6} {x:.6} {y:.6}");
        }
        s.push_str(&line.replace("-0.000000", "0.000000"));
        s.push('\n');
    }
    Ok(s)
}

/// Writes the hierarchy block of joint `j` and its subtree at indentation `depth`.
fn write_joint(
    s: &mut String,
    j: usize,
    depth: usize,
    kids: &[Vec<usize>; JOINT_COUNT],
    rest_bones: &[Vector3<f64>; JOINT_COUNT],
    rest_bvh: &[Vec3; JOINT_COUNT],
) {
    let ind = "  ".repeat(depth);
    let t = &TRACKING_JOINTS[j];
    let off = if t.parent.is_some() {
        rest_bones[j]
    } else {
        Vec3::zeros()
    };
    if t.parent.is_none() {
        let _ = writeln!(s, "{ind}ROOT {}", t.name);
    } else {
        let _ = writeln!(s, "{ind}JOINT {}", t.name);
    }
    let _ = writeln!(s, "{ind}{{");
    let _ = writeln!(s, "{ind}  OFFSET {:.6} {:.6} {:.6}", off.x, off.y, off.z);
    if t.parent.is_none() {
        let _ = writeln!(
            s,
            "{ind}  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation"
        );
    } else {
        let _ = writeln!(s, "{ind}  CHANNELS 3 Zrotation Xrotation Yrotation");
    }
    for &c in &kids[j] {
        write_joint(s, c, depth + 1, kids, rest_bones, rest_bvh);
    }
    if kids[j].is_empty() {
        let e = end_site_offset(j, rest_bvh);
        let _ = writeln!(s, "{ind}  End Site\n{ind}  {{");
        let _ = writeln!(s, "{ind}    OFFSET {:.6} {:.6} {:.6}", e.x, e.y, e.z);
        let _ = writeln!(s, "{ind}  }}");
    }
    let _ = writeln!(s, "{ind}}}");
}

/// Writes `frames` at `fps` as BVH to `path`, the rest skeleton being the first frame.
///
/// # Errors
///
/// As [`to_bvh_string`]; [`TrackingOutputError::Io`] naming `path` when it cannot be written.
pub fn write_bvh(
    path: &Path,
    frames: &[[Vec3; JOINT_COUNT]],
    fps: f64,
) -> Result<(), TrackingOutputError> {
    write_bvh_with_rest(path, frames, fps, None)
}

/// [`write_bvh`] with an explicit rest skeleton (`None`: the first frame).
///
/// # Errors
///
/// As [`write_bvh`].
pub fn write_bvh_with_rest(
    path: &Path,
    frames: &[[Vec3; JOINT_COUNT]],
    fps: f64,
    rest: Option<&[Vec3; JOINT_COUNT]>,
) -> Result<(), TrackingOutputError> {
    let text = to_bvh_string(frames, fps, rest)?;
    std::fs::write(path, text).map_err(|e| io_error(path, e))
}

/// The joint-position CSV text: header `frame,time,pelvis_x,pelvis_y,pelvis_z,…` (joints in
/// [`TRACKING_JOINTS`] order), one row per frame, time in seconds, positions in metres
/// (world, z up), full precision.
///
/// # Errors
///
/// As [`validate_frames`].
pub fn joints_csv_string(
    frames: &[[Vec3; JOINT_COUNT]],
    fps: f64,
) -> Result<String, TrackingOutputError> {
    validate_frames(frames, fps)?;
    let mut s = super::sequence_files::joints_csv_header();
    s.push('\n');
    for (f, frame) in frames.iter().enumerate() {
        let _ = write!(s, "{f},{}", f as f64 / fps);
        for p in frame {
            let _ = write!(s, ",{},{},{}", p.x, p.y, p.z);
        }
        s.push('\n');
    }
    Ok(s)
}

/// Writes [`joints_csv_string`] to `path`.
///
/// # Errors
///
/// As [`validate_frames`]; [`TrackingOutputError::Io`] naming `path` when it cannot be written.
pub fn write_joints_csv(
    path: &Path,
    frames: &[[Vec3; JOINT_COUNT]],
    fps: f64,
) -> Result<(), TrackingOutputError> {
    let text = joints_csv_string(frames, fps)?;
    std::fs::write(path, text).map_err(|e| io_error(path, e))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rot(axis: Vector3<f64>, deg: f64) -> Matrix3<f64> {
        *nalgebra::Rotation3::from_axis_angle(
            &nalgebra::Unit::new_normalize(axis),
            deg.to_radians(),
        )
        .matrix()
    }

    #[test]
    fn euler_round_trip() {
        for (ax, deg) in [
            (Vector3::new(1.0, 2.0, 3.0), 40.0),
            (Vector3::new(0.0, 0.0, 1.0), 170.0),
            (Vector3::new(1.0, 0.0, 0.0), 90.0),
            (Vector3::new(1.0, 0.0, 0.0), -90.0),
            (Vector3::new(-1.0, 0.3, 0.0), 120.0),
        ] {
            let r = rot(ax, deg);
            let [z, x, y] = euler_zxy(&r);
            let back = rot(Vector3::z(), z) * rot(Vector3::x(), x) * rot(Vector3::y(), y);
            assert!((back - r).norm() < 1e-9, "{ax:?} {deg}");
        }
    }

    #[test]
    fn kabsch_recovers_rotation() {
        let r = rot(Vector3::new(0.2, -1.0, 0.5), 75.0);
        let from = [
            Vector3::x(),
            Vector3::new(0.0, 1.0, 0.0),
            Vector3::new(-1.0, 0.0, 0.0),
        ];
        let to: Vec<_> = from.iter().map(|a| r * a).collect();
        let k = kabsch(&from, &to).unwrap();
        assert!((k - r).norm() < 1e-12);
        assert!(kabsch(&from[..1], &to[..1]).is_none());
    }

    #[test]
    fn opposite_directions() {
        let a = Vector3::new(0.0, 1.0, 0.0);
        let r = rotation_between(&a, &-a);
        assert!((r * a + a).norm() < 1e-12);
        assert!((r.determinant() - 1.0).abs() < 1e-12);
    }
}
