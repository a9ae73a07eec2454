//! Reading and writing face sequence folders (layout in [`sequence`](super::sequence)): the
//! description `sequence.json`, pose/FAP CSV files, and [`FaceSequence`] to open a folder.

use std::path::{Path, PathBuf};

use image::RgbImage;
use serde::{Deserialize, Serialize};

use super::head_pose::HeadPose;
use super::model::FaceMesh;
use super::sequence_options::FaceSequenceOptions;
use super::FaceError;
use crate::geometry::Camera;
use crate::geometry::Vec3;

/// The description of a sequence (`sequence.json`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SequenceInfo {
    /// Number of frames.
    pub frames: usize,
    /// Frame rate (Hz).
    pub fps: f64,
    /// Image width (pixels).
    pub width: u32,
    /// Image height (pixels).
    pub height: u32,
    /// Camera names (`cameras/NAME.json`, `images/NAME/`).
    pub cameras: Vec<String>,
    /// FAP numbers in the CSV columns.
    pub faps: Vec<u8>,
    /// Their names.
    pub fap_names: Vec<String>,
    /// Their ranges (FAP units).
    pub fap_ranges: Vec<(f64, f64)>,
    /// The settings that made the sequence, when synthetic.
    #[serde(default)]
    pub options: Option<FaceSequenceOptions>,
}

impl SequenceInfo {
    /// Writes `sequence.json`.
    pub fn save(&self, path: &Path) -> Result<(), FaceError> {
        let text = serde_json::to_string_pretty(self).map_err(|e| FaceError::io(path, e))?;
        std::fs::write(path, text).map_err(|e| FaceError::io(path, e))
    }

    /// Reads `sequence.json`; errors name the file.
    pub fn load(path: &Path) -> Result<SequenceInfo, FaceError> {
        let text = crate::limits::read_to_string(path).map_err(|e| FaceError::io(path, e))?;
        let info: SequenceInfo = serde_json::from_str(&text).map_err(|e| FaceError::Parse {
            path: path.to_path_buf(),
            line: e.line(),
            message: e.to_string(),
        })?;
        if info.faps.len() != info.fap_ranges.len() || info.faps.len() != info.fap_names.len() {
            return Err(FaceError::Parse {
                path: path.to_path_buf(),
                line: 0,
                message: "`faps`, `fap_names` and `fap_ranges` differ in length".into(),
            });
        }
        if info.cameras.is_empty() || info.frames == 0 {
            return Err(FaceError::Parse {
                path: path.to_path_buf(),
                line: 0,
                message: "no cameras or no frames".into(),
            });
        }
        Ok(info)
    }
}

/// Pose and FAP values of one frame.
#[derive(Clone, Debug, PartialEq)]
pub struct PoseRow {
    /// Frame number.
    pub frame: usize,
    /// Time (s).
    pub time: f64,
    /// Head pose.
    pub pose: HeadPose,
    /// FAP values in the file's FAP order (FAP units).
    pub faps: Vec<f64>,
}

/// The header of a pose CSV for FAPs `faps`.
pub fn pose_csv_header(faps: &[u8]) -> String {
    let mut s = String::from("frame,time,yaw_deg,pitch_deg,roll_deg,tx,ty,tz");
    for f in faps {
        s.push_str(&format!(",fap_{f}"));
    }
    s
}

/// Writes pose rows as CSV (see [`pose_csv_header`]).
pub fn write_pose_csv(path: &Path, faps: &[u8], rows: &[PoseRow]) -> Result<(), FaceError> {
    let mut s = pose_csv_header(faps);
    s.push('\n');
    for r in rows {
        let [y, p, ro] = r.pose.angles();
        let t = r.pose.translation;
        s.push_str(&format!(
            "{},{:.6},{:.9},{:.9},{:.9},{:.9},{:.9},{:.9}",
            r.frame,
            r.time,
            y.to_degrees(),
            p.to_degrees(),
            ro.to_degrees(),
            t.x,
            t.y,
            t.z
        ));
        for v in &r.faps {
            s.push_str(&format!(",{v:.6}"));
        }
        s.push('\n');
    }
    std::fs::write(path, s).map_err(|e| FaceError::io(path, e))
}

/// Reads a pose CSV; returns the FAP numbers of its columns and the rows. Errors name the
/// file and line.
pub fn read_pose_csv(path: &Path) -> Result<(Vec<u8>, Vec<PoseRow>), FaceError> {
    let text = crate::limits::read_to_string(path).map_err(|e| FaceError::io(path, e))?;
    let err = |line: usize, message: String| FaceError::Parse {
        path: path.to_path_buf(),
        line,
        message,
    };
    let mut lines = text.lines();
    let header = lines.next().ok_or_else(|| err(1, "empty file".into()))?;
    let cols: Vec<&str> = header.split(',').map(str::trim).collect();
    let fixed = [
        "frame",
        "time",
        "yaw_deg",
        "pitch_deg",
        "roll_deg",
        "tx",
        "ty",
        "tz",
    ];
    if cols.len() < fixed.len() || cols[..fixed.len()] != fixed {
        return Err(err(
            1,
            format!("header must start with `{}`", fixed.join(",")),
        ));
    }
    let mut faps = Vec::new();
    for c in &cols[fixed.len()..] {
        let n = c
            .strip_prefix("fap_")
            .and_then(|n| n.parse::<u8>().ok())
            .ok_or_else(|| err(1, format!("unknown column `{c}` (expected fap_N)")))?;
        faps.push(n);
    }
    let mut rows = Vec::new();
    for (k, line) in lines.enumerate() {
        let no = k + 2;
        if line.trim().is_empty() {
            continue;
        }
        let vals: Vec<&str> = line.split(',').map(str::trim).collect();
        if vals.len() != cols.len() {
            return Err(err(
                no,
                format!("{} fields, the header has {}", vals.len(), cols.len()),
            ));
        }
        let mut nums = Vec::with_capacity(vals.len());
        for v in &vals {
            let x: f64 = v
                .parse()
                .map_err(|_| err(no, format!("`{v}` is not a number")))?;
            if !x.is_finite() {
                return Err(err(no, format!("`{v}` is not finite")));
            }
            nums.push(x);
        }
        rows.push(PoseRow {
            frame: nums[0] as usize,
            time: nums[1],
            pose: HeadPose::from_angles(
                nums[2].to_radians(),
                nums[3].to_radians(),
                nums[4].to_radians(),
                Vec3::new(nums[5], nums[6], nums[7]),
            ),
            faps: nums[8..].to_vec(),
        });
    }
    Ok((faps, rows))
}

/// An opened sequence folder.
#[derive(Clone, Debug)]
pub struct FaceSequence {
    /// The folder.
    pub dir: PathBuf,
    /// Its description.
    pub info: SequenceInfo,
    /// Its cameras, in `info.cameras` order.
    pub cameras: Vec<Camera>,
    /// The neutral model (`model.obj`, metres).
    pub model: FaceMesh,
    /// Pose and FAPs of frame 0 (`init.csv`).
    pub init: PoseRow,
    /// Ground truth (`ground_truth.csv`), when present.
    pub truth: Option<Vec<PoseRow>>,
}

impl FaceSequence {
    /// Opens a folder written by [`make_face_sequence`](super::sequence::make_face_sequence) or
    /// laid out the same way. Errors name the missing or malformed file.
    pub fn open(dir: &Path) -> Result<FaceSequence, FaceError> {
        let info = SequenceInfo::load(&dir.join("sequence.json"))?;
        let cameras = info
            .cameras
            .iter()
            .map(|c| {
                let path = dir.join("cameras").join(format!("{c}.json"));
                let cam = Camera::load(&path).map_err(|e| FaceError::io(&path, e))?;
                if cam.width != info.width || cam.height != info.height {
                    return Err(FaceError::Failed(format!(
                        "{}: camera image {}×{}, the sequence's {}×{}",
                        path.display(),
                        cam.width,
                        cam.height,
                        info.width,
                        info.height
                    )));
                }
                Ok(cam)
            })
            .collect::<Result<Vec<_>, _>>()?;
        let model = FaceMesh::load_obj(&dir.join("model.obj"), 1.0)?;
        model.validate(&dir.join("model.obj").display().to_string())?;
        let init_path = dir.join("init.csv");
        let (init_faps, init_rows) = read_pose_csv(&init_path)?;
        if init_faps != info.faps {
            return Err(FaceError::Parse {
                path: init_path,
                line: 1,
                message: format!(
                    "FAP columns {init_faps:?}, sequence.json says {:?}",
                    info.faps
                ),
            });
        }
        let init = init_rows
            .into_iter()
            .next()
            .ok_or_else(|| FaceError::Parse {
                path: dir.join("init.csv"),
                line: 2,
                message: "no pose row".into(),
            })?;
        let gt = dir.join("ground_truth.csv");
        let truth = if gt.exists() {
            let (f, rows) = read_pose_csv(&gt)?;
            if f != info.faps {
                return Err(FaceError::Parse {
                    path: gt,
                    line: 1,
                    message: format!("FAP columns {f:?}, sequence.json says {:?}", info.faps),
                });
            }
            Some(rows)
        } else {
            None
        };
        Ok(FaceSequence {
            dir: dir.to_path_buf(),
            info,
            cameras,
            model,
            init,
            truth,
        })
    }

    /// The image file of camera `c`, frame `k`: `images/CAM/kkkk.png`, or the same stem in
    /// another photo format ([`photo_with_stem`](crate::geometry::image::photo_with_stem)).
    pub fn image_path(&self, c: usize, k: usize) -> PathBuf {
        let dir = self.dir.join("images").join(&self.info.cameras[c]);
        crate::geometry::image::photo_with_stem_or(&dir, &format!("{k:04}"), "png")
    }

    /// The images of frame `k`, one per camera; errors name a missing or wrong-size file.
    pub fn frame_images(&self, k: usize) -> Result<Vec<RgbImage>, FaceError> {
        (0..self.cameras.len())
            .map(|c| {
                let path = self.image_path(c, k);
                let img = crate::geometry::image::read_photo(&path)?;
                if img.width() != self.info.width || img.height() != self.info.height {
                    return Err(FaceError::Failed(format!(
                        "{}: image is {}×{}, the sequence's {}×{}",
                        path.display(),
                        img.width(),
                        img.height(),
                        self.info.width,
                        self.info.height
                    )));
                }
                Ok(img)
            })
            .collect()
    }
}
