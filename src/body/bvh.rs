//! BVH motion capture clips: a small, non-panicking parser of the Biovision hierarchy format
//! and forward kinematics.
//!
//! A clip is a joint tree (each joint: name, parent, offset from its parent, channels) and a
//! table of frames (one value per channel). Rotation channels are in degrees and compose
//! intrinsically in the order they are listed (`Zrotation Yrotation Xrotation` gives
//! `R = Rz·Ry·Rx`); position channels add to the offset. `End Site` blocks become joints
//! without channels, named `<parent>_End`. Joints are looked up by name, never by position,
//! since different exports order children differently.
//!
//! Offsets and channels are kept in the file's units and axes (CMU/iClone: centimetres, y up);
//! [`Motion::joint_positions`] converts to the engine's world, metres with z up, by
//! `(x, y, z) ↦ (x, −z, y)·0.01` (see [`bvh_to_world`]).

use std::collections::HashMap;
use std::path::Path;

use nalgebra::{Matrix3, Vector3};

use super::error::{read_text, BodyError};
use crate::geometry::Vec3;

/// Converts a BVH point (centimetres, y up) to the engine's world (metres, z up):
/// `(x, y, z) ↦ (x, −z, y)·0.01`.
pub fn bvh_to_world(p: Vec3) -> Vec3 {
    Vec3::new(p.x, -p.z, p.y) * 0.01
}

/// One channel of a BVH joint.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Channel {
    /// Translation along x (file units).
    Xposition,
    /// Translation along y (file units).
    Yposition,
    /// Translation along z (file units).
    Zposition,
    /// Rotation about x (degrees).
    Xrotation,
    /// Rotation about y (degrees).
    Yrotation,
    /// Rotation about z (degrees).
    Zrotation,
}

impl Channel {
    fn parse(token: &str) -> Option<Channel> {
        Some(match token.to_ascii_lowercase().as_str() {
            "xposition" => Channel::Xposition,
            "yposition" => Channel::Yposition,
            "zposition" => Channel::Zposition,
            "xrotation" => Channel::Xrotation,
            "yrotation" => Channel::Yrotation,
            "zrotation" => Channel::Zrotation,
            _ => return None,
        })
    }
}

/// Shortest accepted frame time (s): 0.1 ms, a 10 kHz capture, faster than any motion-capture
/// system records.
pub const MIN_FRAME_TIME: f64 = 1e-4;
/// Longest accepted frame time (s): 10 s between frames, slower than any clip is keyed.
pub const MAX_FRAME_TIME: f64 = 10.0;

/// One joint of a BVH hierarchy (an `End Site` is a joint without channels).
#[derive(Clone, Debug)]
pub struct BvhJoint {
    /// Joint name (`<parent>_End` for an end site).
    pub name: String,
    /// Index of the parent joint; `None` for the root.
    pub parent: Option<usize>,
    /// Offset from the parent joint, in the parent's frame, in file units and axes.
    pub offset: Vec3,
    /// The joint's channels, in file order.
    pub channels: Vec<Channel>,
    /// Index of the joint's first channel within a frame.
    pub first_channel: usize,
    /// Whether this joint comes from an `End Site` block.
    pub end_site: bool,
}

/// A parsed BVH clip: the joint tree (parents before children) and its frames.
#[derive(Clone, Debug)]
pub struct Motion {
    name: String,
    joints: Vec<BvhJoint>,
    by_name: HashMap<String, usize>,
    channel_count: usize,
    frame_time: f64,
    frame_count: usize,
    /// Frame-major channel values, `frame_count × channel_count`.
    values: Vec<f64>,
}

/// Whitespace tokenizer that remembers line numbers.
struct Lexer<'a> {
    lines: std::str::Lines<'a>,
    words: std::str::SplitWhitespace<'a>,
    line: usize,
    file: &'a str,
}

impl<'a> Lexer<'a> {
    fn new(text: &'a str, file: &'a str) -> Self {
        Lexer {
            lines: text.lines(),
            words: "".split_whitespace(),
            line: 0,
            file,
        }
    }

    fn next(&mut self) -> Option<(usize, &'a str)> {
        loop {
            if let Some(w) = self.words.next() {
                return Some((self.line, w));
            }
            let l = self.lines.next()?;
            self.line += 1;
            self.words = l.split_whitespace();
        }
    }

    /// The next token, or an "unexpected end of file" error naming what was expected.
    fn expect_any(&mut self, what: &str) -> Result<(usize, &'a str), BodyError> {
        self.next().ok_or_else(|| {
            BodyError::parse(
                self.file,
                self.line,
                format!("unexpected end of file, expected {what}"),
            )
        })
    }

    /// The next token, which must be `keyword` (case-insensitive).
    fn expect(&mut self, keyword: &str) -> Result<usize, BodyError> {
        let (line, t) = self.expect_any(&format!("'{keyword}'"))?;
        if t.eq_ignore_ascii_case(keyword) {
            Ok(line)
        } else {
            Err(BodyError::parse(
                self.file,
                line,
                format!("expected '{keyword}', found '{t}'"),
            ))
        }
    }

    fn number(&mut self, what: &str) -> Result<f64, BodyError> {
        let (line, t) = self.expect_any(what)?;
        match t.parse::<f64>() {
            Ok(v) if v.is_finite() => Ok(v),
            _ => Err(BodyError::parse(
                self.file,
                line,
                format!("expected {what} (a finite number), found '{t}'"),
            )),
        }
    }

    fn count(&mut self, what: &str) -> Result<(usize, usize), BodyError> {
        let (line, t) = self.expect_any(what)?;
        t.parse::<usize>().map(|n| (line, n)).map_err(|_| {
            BodyError::parse(
                self.file,
                line,
                format!("expected {what} (a count), found '{t}'"),
            )
        })
    }
}

impl Motion {
    /// Reads and parses a BVH file; errors name the file and, for syntax errors, the line.
    pub fn load_bvh(path: &Path) -> Result<Motion, BodyError> {
        let text = read_text(path)?;
        Motion::parse_bvh(&text, &path.display().to_string())
    }

    /// Parses BVH text; `name_for_errors` names the text in errors (usually its path).
    ///
    /// Fails (never panics) on a truncated text, a malformed number, an unknown channel, a
    /// duplicate joint name, an end site with channels or children, joints nested deeper than
    /// the limit `max_nesting`, no frames or more than the limit `max_frames`, or a frame time
    /// outside [[`MIN_FRAME_TIME`], [`MAX_FRAME_TIME`]].
    pub fn parse_bvh(text: &str, name_for_errors: &str) -> Result<Motion, BodyError> {
        let file = name_for_errors;
        let mut lx = Lexer::new(text, file);
        lx.expect("HIERARCHY")?;
        lx.expect("ROOT")?;
        let mut joints: Vec<BvhJoint> = Vec::new();
        let mut by_name = HashMap::new();
        let mut channel_count = 0usize;
        let (line, name) = lx.expect_any("the root joint's name")?;
        let mut add = |joints: &mut Vec<BvhJoint>,
                       name: String,
                       parent: Option<usize>,
                       end_site: bool,
                       line: usize|
         -> Result<usize, BodyError> {
            let idx = joints.len();
            if by_name.insert(name.clone(), idx).is_some() {
                return Err(BodyError::parse(
                    file,
                    line,
                    format!("duplicate joint name '{name}'"),
                ));
            }
            joints.push(BvhJoint {
                name,
                parent,
                offset: Vec3::zeros(),
                channels: Vec::new(),
                first_channel: 0,
                end_site,
            });
            Ok(idx)
        };
        let root = add(&mut joints, name.to_string(), None, false, line)?;
        lx.expect("{")?;
        let mut stack = vec![root];
        while let Some(&top) = stack.last() {
            let (line, t) = lx.expect_any("a joint entry or '}'")?;
            match t.to_ascii_uppercase().as_str() {
                "OFFSET" => {
                    let x = lx.number("an offset coordinate")?;
                    let y = lx.number("an offset coordinate")?;
                    let z = lx.number("an offset coordinate")?;
                    joints[top].offset = Vec3::new(x, y, z);
                }
                "CHANNELS" => {
                    let (cl, n) = lx.count("the number of channels")?;
                    if joints[top].end_site {
                        return Err(BodyError::parse(file, cl, "an End Site has no channels"));
                    }
                    if n > 6 || !joints[top].channels.is_empty() {
                        return Err(BodyError::parse(
                            file,
                            cl,
                            format!("joint '{}': bad channel list", joints[top].name),
                        ));
                    }
                    joints[top].first_channel = channel_count;
                    for _ in 0..n {
                        let (l, c) = lx.expect_any("a channel name")?;
                        let ch = Channel::parse(c).ok_or_else(|| {
                            BodyError::parse(file, l, format!("unknown channel '{c}'"))
                        })?;
                        joints[top].channels.push(ch);
                    }
                    channel_count += n;
                }
                "JOINT" | "END" => {
                    if joints[top].end_site {
                        return Err(BodyError::parse(file, line, "an End Site has no children"));
                    }
                    let end_site = t.eq_ignore_ascii_case("END");
                    let name = if end_site {
                        lx.expect("Site")?;
                        format!("{}_End", joints[top].name)
                    } else {
                        lx.expect_any("a joint name")?.1.to_string()
                    };
                    let max_depth = crate::limits::get().max_nesting;
                    if stack.len() as u64 >= max_depth {
                        return Err(BodyError::parse(
                            file,
                            line,
                            format!(
                                "joint nested {} deep, over the limit max_nesting = {max_depth} (raise it with `emilion run --limit max_nesting=N`)",
                                stack.len() + 1
                            ),
                        ));
                    }
                    let j = add(&mut joints, name, Some(top), end_site, line)?;
                    lx.expect("{")?;
                    stack.push(j);
                }
                "}" => {
                    stack.pop();
                }
                _ => {
                    return Err(BodyError::parse(
                        file,
                        line,
                        format!("unexpected '{t}' in the hierarchy"),
                    ))
                }
            }
        }
        lx.expect("MOTION")?;
        lx.expect("Frames:")?;
        let (fl, frame_count) = lx.count("the number of frames")?;
        if frame_count == 0 {
            return Err(BodyError::parse(file, fl, "the clip has no frames"));
        }
        let max_frames = crate::limits::get().max_frames;
        crate::limits::check_count(
            "the number of frames",
            frame_count as u64,
            "max_frames",
            max_frames,
        )
        .map_err(|e| BodyError::parse(file, fl, e.to_string()))?;
        lx.expect("Frame")?;
        let tl = lx.expect("Time:")?;
        let frame_time = lx.number("the frame time")?;
        if !(MIN_FRAME_TIME..=MAX_FRAME_TIME).contains(&frame_time) {
            return Err(BodyError::parse(
                file,
                tl,
                format!(
                    "the frame time {frame_time} s is outside the accepted range [{MIN_FRAME_TIME}, {MAX_FRAME_TIME}] s"
                ),
            ));
        }
        let total = frame_count
            .checked_mul(channel_count)
            .ok_or_else(|| BodyError::parse(file, fl, "the frame count is too large"))?;
        // never trust the header for the allocation: each value takes at least 2 bytes
        let mut values = Vec::with_capacity(total.min(text.len() / 2 + 1));
        for f in 0..frame_count {
            for c in 0..channel_count {
                let (line, t) = lx.next().ok_or_else(|| {
                    BodyError::parse(
                        file,
                        lx.line,
                        format!(
                            "unexpected end of file in frame {} of {frame_count} \
                             (value {} of {channel_count})",
                            f + 1,
                            c + 1
                        ),
                    )
                })?;
                match t.parse::<f64>() {
                    Ok(v) if v.is_finite() => values.push(v),
                    _ => {
                        return Err(BodyError::parse(
                            file,
                            line,
                            format!("frame {}: '{t}' is not a finite number", f + 1),
                        ))
                    }
                }
            }
        }
        if let Some((line, t)) = lx.next() {
            return Err(BodyError::parse(
                file,
                line,
                format!("unexpected '{t}' after the {frame_count} declared frames"),
            ));
        }
        Ok(Motion {
            name: file.to_string(),
            joints,
            by_name,
            channel_count,
            frame_time,
            frame_count,
            values,
        })
    }

    /// The clip's name (the path or name it was parsed under).
    pub fn name(&self) -> &str {
        &self.name
    }

    /// All joints, parents before children (end sites included).
    pub fn joints(&self) -> &[BvhJoint] {
        &self.joints
    }

    /// Index of the joint called `name`.
    pub fn joint_index(&self, name: &str) -> Option<usize> {
        self.by_name.get(name).copied()
    }

    /// Number of frames.
    pub fn frame_count(&self) -> usize {
        self.frame_count
    }

    /// Seconds between frames.
    pub fn frame_time(&self) -> f64 {
        self.frame_time
    }

    /// Length of the clip, `frame_count × frame_time` (seconds), as motion databases list it;
    /// the last frame is held over its own frame time.
    pub fn duration(&self) -> f64 {
        self.frame_count as f64 * self.frame_time
    }

    /// Number of channels per frame.
    pub fn channel_count(&self) -> usize {
        self.channel_count
    }

    /// The channel values of `frame` (clamped to the last frame).
    pub fn frame(&self, frame: usize) -> &[f64] {
        let k = frame.min(self.frame_count - 1);
        &self.values[k * self.channel_count..(k + 1) * self.channel_count]
    }

    /// World joint positions at `frame` (clamped to the last frame), in metres with z up,
    /// indexed like [`Motion::joints`] (forward kinematics).
    pub fn joint_positions(&self, frame: usize) -> Vec<Vec3> {
        let mut out = Vec::new();
        self.joint_positions_into(frame, &mut out);
        out
    }

    /// [`Motion::joint_positions`] into a reused buffer.
    pub fn joint_positions_into(&self, frame: usize, out: &mut Vec<Vec3>) {
        let values = self.frame(frame);
        let mut rot: Vec<Matrix3<f64>> = Vec::with_capacity(self.joints.len());
        out.clear();
        for j in &self.joints {
            let mut local = Matrix3::identity();
            let mut shift = j.offset;
            for (i, ch) in j.channels.iter().enumerate() {
                let v = values[j.first_channel + i];
                match ch {
                    Channel::Xposition => shift.x += v,
                    Channel::Yposition => shift.y += v,
                    Channel::Zposition => shift.z += v,
                    Channel::Xrotation => local *= axis_rotation(Vector3::x_axis(), v),
                    Channel::Yrotation => local *= axis_rotation(Vector3::y_axis(), v),
                    Channel::Zrotation => local *= axis_rotation(Vector3::z_axis(), v),
                }
            }
            let (r, p) = match j.parent {
                Some(p) => (rot[p] * local, out[p] + rot[p] * shift),
                None => (local, shift),
            };
            rot.push(r);
            out.push(p);
        }
        for p in out.iter_mut() {
            *p = bvh_to_world(*p);
        }
    }
}

/// Rotation by `degrees` about a unit axis.
fn axis_rotation(axis: nalgebra::Unit<Vector3<f64>>, degrees: f64) -> Matrix3<f64> {
    *nalgebra::Rotation3::from_axis_angle(&axis, degrees.to_radians()).matrix()
}
