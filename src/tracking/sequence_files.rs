//! Reading any multi-camera sequence folder (synthetic ones from
//! [`make_sequence`](super::sequence::make_sequence), or real footage laid out the same way),
//! the joint CSV format, the photo and PNG helpers of sequences, and the errors of the sequence code ([`SequenceError`]).
//!
//! # Folder layout
//!
//! ```text
//! DIR/sequence.json          fps, frames, width, height, cameras ["cam0", …], motion file
//!                            name, joint names, noise / lighting / occluder settings, seed
//! DIR/cameras/cam0.json …    one camera file per camera (see `camera` module docs)
//! DIR/images/cam0/0000.png … one image per camera and frame (4-digit frame numbers from 0;
//!                            PNG, or any other photo format of the same stem)
//! DIR/backgrounds/cam0.png … optional: each camera's empty scene (clean plate, any photo
//!                            format); without
//!                            them the tracker takes the median of frames
//! DIR/ground_truth.csv       optional: frame,time,pelvis_x,pelvis_y,pelvis_z,spine_x,…
//!                            (metres, world frame, z up, TRACKING_JOINTS order), one row
//!                            per frame
//! DIR/init_joints.csv        optional: same columns, one row: an approximate first pose
//!                            (frame 0's joints with 2 cm noise), for pre-positioning
//! ```
//!
//! Only `fps`, `frames` and `cameras` of `sequence.json` are required by [`Sequence::open`];
//! `width` and `height` default to the first camera's. Joint columns may come in any order,
//! but all sixteen joints must be there, each as `name_x, name_y, name_z`.

use std::path::{Path, PathBuf};

use image::codecs::png::{CompressionType, FilterType, PngEncoder};
use image::{ImageEncoder, RgbImage};
use serde_json::Value;

use super::joints::{joint_index, JOINT_COUNT, TRACKING_JOINTS};
use crate::body::BodyError;
use crate::geometry::camera::{Camera, CameraError};
use crate::geometry::{GeometryError, SplitMix64, Vec3};

/// Joint positions of one frame, in [`TRACKING_JOINTS`] order.
pub type JointFrame = [Vec3; JOINT_COUNT];

/// What went wrong making or reading a sequence; every variant names the file concerned.
#[derive(Debug, thiserror::Error)]
pub enum SequenceError {
    /// A file or folder could not be read or written.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The underlying error.
        #[source]
        source: std::io::Error,
    },
    /// A file the layout requires is absent.
    #[error("{path}: missing {what}")]
    Missing {
        /// The file expected.
        path: PathBuf,
        /// What it should hold.
        what: String,
    },
    /// `sequence.json` is not valid JSON or lacks a field.
    #[error("{path}: {message}")]
    Json {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// A CSV file is malformed.
    #[error("{path}:{line}: {message}")]
    Csv {
        /// The file.
        path: PathBuf,
        /// 1-based line number.
        line: usize,
        /// What is wrong.
        message: String,
    },
    /// A CSV header names a column that is not `frame`, `time` or a tracking joint coordinate.
    #[error("{path}:1: unknown column `{column}` (joints: {known})")]
    UnknownColumn {
        /// The file.
        path: PathBuf,
        /// The column name.
        column: String,
        /// The known joint names, comma separated.
        known: String,
    },
    /// A camera file is invalid (the error names the file and field).
    #[error(transparent)]
    Camera(#[from] CameraError),
    /// An image could not be decoded or encoded.
    #[error("{path}: {message}")]
    Image {
        /// The file.
        path: PathBuf,
        /// The codec's message.
        message: String,
    },
    /// An image's size differs from its camera's.
    #[error("{path}: image is {width}×{height} pixels but camera {camera} is {camera_width}×{camera_height}")]
    ImageSize {
        /// The image file.
        path: PathBuf,
        /// Its width.
        width: u32,
        /// Its height.
        height: u32,
        /// The camera's name.
        camera: String,
        /// The camera's width.
        camera_width: u32,
        /// The camera's height.
        camera_height: u32,
    },
    /// A frame index past the end of the sequence.
    #[error("{path}: frame {frame} out of range (the sequence has {frames} frames)")]
    FrameOutOfRange {
        /// The sequence folder.
        path: PathBuf,
        /// The frame asked for.
        frame: usize,
        /// The number of frames.
        frames: usize,
    },
    /// The motion clip or the mannequin could not be loaded or retargeted.
    #[error(transparent)]
    Body(#[from] BodyError),
    /// The motion source (a capture file) could not be fitted or used.
    #[error("{path}: {message}")]
    Motion {
        /// The motion file.
        path: PathBuf,
        /// What went wrong.
        message: String,
    },
    /// Invalid sequence options.
    #[error("invalid sequence options: {0}")]
    Options(String),
}

/// Writes `DIR/sequence.json` (pretty JSON and a newline).
pub(crate) fn write_sequence_json(out: &Path, meta: &Value) -> Result<(), SequenceError> {
    let path = out.join("sequence.json");
    let text = serde_json::to_string_pretty(meta).map_err(|e| SequenceError::Json {
        path: path.clone(),
        message: e.to_string(),
    })?;
    std::fs::write(&path, text + "\n").map_err(io_err(&path))
}

/// Writes `DIR/ground_truth.csv` (`rows`: frame, time, joints) and `DIR/init_joints.csv`
/// (the first row's joints with 2 cm of Gaussian noise per coordinate drawn from `rng`).
pub(crate) fn write_truth_files(
    out: &Path,
    rows: &[(usize, f64, JointFrame)],
    rng: &mut SplitMix64,
) -> Result<(), SequenceError> {
    write_joints_csv(&out.join("ground_truth.csv"), rows)?;
    if let Some((_, _, first)) = rows.first() {
        let init = first.map(|p| p + Vec3::new(rng.normal(), rng.normal(), rng.normal()) * 0.02);
        write_joints_csv(&out.join("init_joints.csv"), &[(0, 0.0, init)])?;
    }
    Ok(())
}

/// An `Io` error for `path`.
pub(crate) fn io_err(path: &Path) -> impl FnOnce(std::io::Error) -> SequenceError + '_ {
    move |source| SequenceError::Io {
        path: path.to_path_buf(),
        source,
    }
}

/// A sequence folder, opened: its settings, cameras, and ground truth where present.
#[derive(Clone, Debug)]
pub struct Sequence {
    /// The folder.
    pub dir: PathBuf,
    /// Frames per second.
    pub fps: f64,
    /// Number of frames.
    pub frames: usize,
    /// Nominal image width, pixels (each camera has its own in [`Camera::width`]).
    pub width: u32,
    /// Nominal image height, pixels.
    pub height: u32,
    /// The cameras, in [`camera_names`](Self::camera_names) order.
    pub cameras: Vec<Camera>,
    /// Camera names: file stems of `cameras/NAME.json` and folders `images/NAME/`.
    pub camera_names: Vec<String>,
    /// Joint positions per frame from `ground_truth.csv`, when present.
    pub ground_truth: Option<Vec<JointFrame>>,
    /// The approximate first pose from `init_joints.csv`, when present.
    pub init_joints: Option<JointFrame>,
}

impl Sequence {
    /// Opens a sequence folder (see the [module docs](self) for the layout): reads
    /// `sequence.json`, every camera file, and the joint CSV files that are present. Images
    /// are read on demand by [`frame_images`](Self::frame_images).
    pub fn open(dir: impl AsRef<Path>) -> Result<Sequence, SequenceError> {
        let dir = dir.as_ref().to_path_buf();
        let meta_path = dir.join("sequence.json");
        if !meta_path.is_file() {
            return Err(SequenceError::Missing {
                path: meta_path,
                what: "sequence description (sequence.json)".into(),
            });
        }
        let text = crate::limits::read_to_string(&meta_path).map_err(io_err(&meta_path))?;
        let json_err = |message: String| SequenceError::Json {
            path: meta_path.clone(),
            message,
        };
        let meta: Value =
            serde_json::from_str(&text).map_err(|e| json_err(format!("invalid JSON: {e}")))?;
        let fps = meta
            .get("fps")
            .and_then(Value::as_f64)
            .filter(|f| f.is_finite() && *f > 0.0)
            .ok_or_else(|| json_err("field `fps` must be a positive number".into()))?;
        let frames = meta
            .get("frames")
            .and_then(Value::as_u64)
            .ok_or_else(|| json_err("field `frames` must be a non-negative integer".into()))?
            as usize;
        let names = meta
            .get("cameras")
            .and_then(Value::as_array)
            .filter(|a| !a.is_empty())
            .ok_or_else(|| json_err("field `cameras` must be a non-empty array of names".into()))?;
        let mut camera_names = Vec::with_capacity(names.len());
        for n in names {
            let n = n
                .as_str()
                .filter(|s| !s.is_empty() && !s.contains(['/', '\\']) && *s != "..")
                .ok_or_else(|| json_err(format!("camera name {n} must be a plain file stem")))?;
            camera_names.push(n.to_string());
        }
        let mut cameras = Vec::with_capacity(camera_names.len());
        for n in &camera_names {
            let path = dir.join("cameras").join(format!("{n}.json"));
            if !path.is_file() {
                return Err(SequenceError::Missing {
                    path,
                    what: format!("camera file of camera {n}"),
                });
            }
            cameras.push(Camera::load(&path)?);
        }
        let size = |key: &str, default: u32| -> Result<u32, SequenceError> {
            match meta.get(key) {
                None => Ok(default),
                Some(v) => v
                    .as_u64()
                    .and_then(|x| u32::try_from(x).ok())
                    .filter(|&x| x > 0)
                    .ok_or_else(|| json_err(format!("field `{key}` must be a positive integer"))),
            }
        };
        let width = size("width", cameras[0].width)?;
        let height = size("height", cameras[0].height)?;
        let gt_path = dir.join("ground_truth.csv");
        let ground_truth = if gt_path.is_file() {
            let rows = read_joints_csv(&gt_path)?;
            if rows.len() != frames {
                return Err(SequenceError::Csv {
                    path: gt_path,
                    line: rows.len() + 1,
                    message: format!(
                        "{} data rows but the sequence has {frames} frames",
                        rows.len()
                    ),
                });
            }
            Some(rows.into_iter().map(|r| r.2).collect())
        } else {
            None
        };
        let init_path = dir.join("init_joints.csv");
        let init_joints = if init_path.is_file() {
            let rows = read_joints_csv(&init_path)?;
            let first = rows.first().ok_or_else(|| SequenceError::Csv {
                path: init_path.clone(),
                line: 2,
                message: "no data row".into(),
            })?;
            Some(first.2)
        } else {
            None
        };
        Ok(Sequence {
            dir,
            fps,
            frames,
            width,
            height,
            cameras,
            camera_names,
            ground_truth,
            init_joints,
        })
    }

    /// Path of the image of camera `camera` (index) at frame `frame`: `images/NAME/kkkk.png`,
    /// or the same stem in another photo format
    /// ([`photo_with_stem`](crate::geometry::image::photo_with_stem)).
    pub fn image_path(&self, camera: usize, frame: usize) -> PathBuf {
        let dir = self.dir.join("images").join(&self.camera_names[camera]);
        crate::geometry::image::photo_with_stem_or(&dir, &format!("{frame:04}"), "png")
    }

    /// Time of frame `frame`, seconds (`frame / fps`).
    pub fn time(&self, frame: usize) -> f64 {
        frame as f64 / self.fps
    }

    /// The images of all cameras at frame `k`, in camera order; each must have its camera's
    /// size.
    pub fn frame_images(&self, k: usize) -> Result<Vec<RgbImage>, SequenceError> {
        let mut out = Vec::with_capacity(self.cameras.len());
        self.frame_images_into(k, &mut out)?;
        Ok(out)
    }

    /// [`frame_images`](Self::frame_images) into `out` (cleared first).
    pub fn frame_images_into(
        &self,
        k: usize,
        out: &mut Vec<RgbImage>,
    ) -> Result<(), SequenceError> {
        out.clear();
        if k >= self.frames {
            return Err(SequenceError::FrameOutOfRange {
                path: self.dir.clone(),
                frame: k,
                frames: self.frames,
            });
        }
        for c in 0..self.cameras.len() {
            let what = format!("image of camera {} at frame {k}", self.camera_names[c]);
            out.push(self.read_image(c, &self.image_path(c, k), &what)?);
        }
        Ok(())
    }
}

impl Sequence {
    /// Reads the image `path` of camera `c`, checking its size against the camera.
    fn read_image(&self, c: usize, path: &Path, what: &str) -> Result<RgbImage, SequenceError> {
        let cam = &self.cameras[c];
        if !path.is_file() {
            return Err(SequenceError::Missing {
                path: path.to_path_buf(),
                what: what.to_string(),
            });
        }
        let img = read_rgb(path)?;
        if img.dimensions() != (cam.width, cam.height) {
            return Err(SequenceError::ImageSize {
                path: path.to_path_buf(),
                width: img.width(),
                height: img.height(),
                camera: self.camera_names[c].clone(),
                camera_width: cam.width,
                camera_height: cam.height,
            });
        }
        Ok(img)
    }

    /// The clean plates `backgrounds/NAME.png` (one per camera, any photo format), or `None` when the folder
    /// is absent; an error when it is there but a plate is missing or of the wrong size.
    pub fn background_plates(&self) -> Result<Option<Vec<RgbImage>>, SequenceError> {
        let dir = self.dir.join("backgrounds");
        if !dir.is_dir() {
            return Ok(None);
        }
        (0..self.cameras.len())
            .map(|c| {
                let name = &self.camera_names[c];
                let what = format!("clean plate of camera {name}");
                let path = crate::geometry::image::photo_with_stem_or(&dir, name, "png");
                self.read_image(c, &path, &what)
            })
            .collect::<Result<Vec<_>, _>>()
            .map(Some)
    }
}

/// `dir/images/NAME/kkkk.png`.
pub fn image_path(dir: &Path, camera: &str, frame: usize) -> PathBuf {
    dir.join("images")
        .join(camera)
        .join(format!("{frame:04}.png"))
}

/// The joint CSV header: `frame,time,pelvis_x,pelvis_y,pelvis_z,…`.
pub fn joints_csv_header() -> String {
    let mut h = String::from("frame,time");
    for j in &TRACKING_JOINTS {
        for a in ["x", "y", "z"] {
            h.push_str(&format!(",{}_{a}", j.name));
        }
    }
    h
}

/// Writes a joint CSV file: the header, then one row `frame,time,coords…` per entry of `rows`
/// (numbers in shortest round-trip form, so reading gives back the same values).
pub fn write_joints_csv(
    path: &Path,
    rows: &[(usize, f64, JointFrame)],
) -> Result<(), SequenceError> {
    let mut text = joints_csv_header();
    text.push('\n');
    for (frame, time, joints) in rows {
        text.push_str(&format!("{frame},{time}"));
        for p in joints {
            text.push_str(&format!(",{},{},{}", p.x, p.y, p.z));
        }
        text.push('\n');
    }
    std::fs::write(path, text).map_err(io_err(path))
}

/// Reads a joint CSV file: `(frame, time, joints)` per data row. The header must hold
/// `frame`, `time` and the three coordinates of every tracking joint, in any order; frames
/// must count up from 0 by one.
pub fn read_joints_csv(path: &Path) -> Result<Vec<(usize, f64, JointFrame)>, SequenceError> {
    let text = crate::limits::read_to_string(path).map_err(io_err(path))?;
    let csv_err = |line: usize, message: String| SequenceError::Csv {
        path: path.to_path_buf(),
        line,
        message,
    };
    let mut lines = text.lines();
    let header = lines
        .next()
        .ok_or_else(|| csv_err(1, "empty file: expected a header line".into()))?;
    // column → (joint, axis) or frame/time
    #[derive(Clone, Copy)]
    enum Col {
        Frame,
        Time,
        Coord(usize, usize),
    }
    let mut cols = Vec::new();
    let mut seen = [[false; 3]; JOINT_COUNT];
    let (mut has_frame, mut has_time) = (false, false);
    for name in header.split(',').map(str::trim) {
        let col = match name {
            "frame" => {
                has_frame = true;
                Col::Frame
            }
            "time" => {
                has_time = true;
                Col::Time
            }
            _ => {
                let parsed = name.rsplit_once('_').and_then(|(j, a)| {
                    let axis = ["x", "y", "z"].iter().position(|&x| x == a)?;
                    Some((joint_index(j)?, axis))
                });
                let (j, a) = parsed.ok_or_else(|| SequenceError::UnknownColumn {
                    path: path.to_path_buf(),
                    column: name.to_string(),
                    known: TRACKING_JOINTS.map(|t| t.name).join(", "),
                })?;
                if seen[j][a] {
                    return Err(csv_err(1, format!("column `{name}` appears twice")));
                }
                seen[j][a] = true;
                Col::Coord(j, a)
            }
        };
        cols.push(col);
    }
    if !has_frame || !has_time {
        return Err(csv_err(
            1,
            "the header needs columns `frame` and `time`".into(),
        ));
    }
    for (j, s) in seen.iter().enumerate() {
        if let Some(a) = s.iter().position(|&b| !b) {
            return Err(csv_err(
                1,
                format!(
                    "missing column `{}_{}`",
                    TRACKING_JOINTS[j].name,
                    ["x", "y", "z"][a]
                ),
            ));
        }
    }
    let mut rows = Vec::new();
    for (i, line) in lines.enumerate() {
        let ln = i + 2;
        if line.trim().is_empty() {
            continue;
        }
        let fields: Vec<&str> = line.split(',').map(str::trim).collect();
        if fields.len() != cols.len() {
            return Err(csv_err(
                ln,
                format!("{} fields, the header has {}", fields.len(), cols.len()),
            ));
        }
        let (mut frame, mut time) = (0usize, 0.0);
        let mut joints = [Vec3::zeros(); JOINT_COUNT];
        for (f, col) in fields.iter().zip(&cols) {
            match *col {
                Col::Frame => {
                    frame = f
                        .parse()
                        .map_err(|_| csv_err(ln, format!("frame `{f}` is not a frame number")))?
                }
                Col::Time | Col::Coord(..) => {
                    let x: f64 = f
                        .parse()
                        .ok()
                        .filter(|x: &f64| x.is_finite())
                        .ok_or_else(|| csv_err(ln, format!("`{f}` is not a finite number")))?;
                    match *col {
                        Col::Coord(j, a) => joints[j][a] = x,
                        _ => time = x,
                    }
                }
            }
        }
        if frame != rows.len() {
            return Err(csv_err(
                ln,
                format!("frame {frame} where frame {} was expected", rows.len()),
            ));
        }
        rows.push((frame, time, joints));
    }
    Ok(rows)
}

/// Photos of `dir` (any of the [`PHOTO_EXTENSIONS`](crate::geometry::image::PHOTO_EXTENSIONS)),
/// sorted by name.
pub(crate) fn list_photos(dir: &Path) -> Result<Vec<PathBuf>, SequenceError> {
    let photos = crate::geometry::photo_files(dir).map_err(io_err(dir))?;
    if photos.is_empty() {
        return Err(SequenceError::Missing {
            path: dir.to_path_buf(),
            what: format!(
                "background photos ({})",
                crate::geometry::image::photo_formats::photo_extensions_list()
            ),
        });
    }
    Ok(photos)
}

/// An image file as 8-bit RGB ([`geometry::image::read_rgb`](crate::geometry::image::read_rgb));
/// the error names the file.
fn read_rgb(path: &Path) -> Result<RgbImage, SequenceError> {
    crate::geometry::image::read_rgb(path).map_err(|e| match e {
        GeometryError::Image { path, message } => SequenceError::Image { path, message },
        other => SequenceError::Image {
            path: path.to_path_buf(),
            message: other.to_string(),
        },
    })
}

/// `photo` scaled to cover `w × h` and cropped at a seeded place.
pub(crate) fn cover(
    path: &Path,
    w: u32,
    h: u32,
    rng: &mut SplitMix64,
) -> Result<RgbImage, SequenceError> {
    let img = read_rgb(path)?;
    let (iw, ih) = (img.width().max(1) as f64, img.height().max(1) as f64);
    let s = (w as f64 / iw).max(h as f64 / ih);
    let (nw, nh) = (
        ((iw * s).ceil() as u32).max(w),
        ((ih * s).ceil() as u32).max(h),
    );
    let big = image::imageops::resize(&img, nw, nh, image::imageops::FilterType::Triangle);
    let ox = rng.below((nw - w + 1) as usize) as u32;
    let oy = rng.below((nh - h + 1) as usize) as u32;
    Ok(image::imageops::crop_imm(&big, ox, oy, w, h).to_image())
}

/// Writes `img` as a PNG (fast compression; deterministic).
pub(crate) fn write_png(path: &Path, img: &RgbImage) -> Result<(), SequenceError> {
    let file = std::fs::File::create(path).map_err(io_err(path))?;
    let enc = PngEncoder::new_with_quality(
        std::io::BufWriter::new(file),
        CompressionType::Fast,
        FilterType::Sub,
    );
    enc.write_image(
        img.as_raw(),
        img.width(),
        img.height(),
        image::ExtendedColorType::Rgb8,
    )
    .map_err(|e| SequenceError::Image {
        path: path.to_path_buf(),
        message: e.to_string(),
    })
}
