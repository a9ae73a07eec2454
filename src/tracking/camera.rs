//! Pinhole cameras with two-term radial distortion, and their JSON file format.
//!
//! # Model
//!
//! A world point `p` is moved into the camera frame by `pc = R p + t` ([`Camera::rotation`] is
//! world→camera, [`Camera::translation`] is `t`); the camera looks down `+z`, `x` to the right
//! and `y` down in the image. The ideal normalised coordinates `(x, y) = (pc.x / pc.z, pc.y / pc.z)`
//! are distorted radially, `(x, y) · (1 + k1 r² + k2 r⁴)` with `r² = x² + y²`, then mapped to
//! pixels by `u = fx · xd + cx`, `v = fy · yd + cy` (no skew). Pixel `(0, 0)` is the centre of
//! the top-left pixel.
//!
//! # File format
//!
//! A camera file is one JSON object with two parts; every number is a finite JSON number:
//!
//! ```json
//! {
//!   "intrinsics": { "fx": 400.0, "fy": 400.0, "cx": 162.0, "cy": 118.0,
//!                   "k1": -0.08, "k2": 0.02, "width": 320, "height": 240 },
//!   "extrinsics": { "rotation": [[1, 0, 0], [0, 1, 0], [0, 0, 1]],
//!                   "translation": [0.0, 0.0, 3.0] }
//! }
//! ```
//!
//! `fx, fy, cx, cy` are in pixels, `k1, k2` are dimensionless, `width, height` are positive
//! integers (pixels). `rotation` is the world→camera matrix, row-major (three rows of three), and
//! must be a proper rotation (orthonormal within 1e-6, determinant +1). `translation` is `t` in
//! world units (metres in this crate). Unknown keys are ignored. [`Camera::load`] reports errors
//! naming the file and the field (for example `intrinsics.fx`).

use std::path::{Path, PathBuf};

use nalgebra::{Matrix3, Vector3};
use serde::{Deserialize, Serialize};
use serde_json::Value;

/// Largest deviation of `RᵀR` from the identity (and of `det R` from 1) accepted for a rotation.
pub const ORTHONORMAL_TOLERANCE: f64 = 1e-6;

/// What went wrong when validating, reading or writing a camera.
///
/// `origin` names where the camera came from: a file path, or a short description such as
/// `"camera"` when validating an in-memory value.
#[derive(Debug, thiserror::Error)]
pub enum CameraError {
    /// The file could not be read or written.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The underlying error.
        #[source]
        source: std::io::Error,
    },
    /// The text is not valid JSON.
    #[error("{origin}: invalid JSON: {message}")]
    Json {
        /// Where the camera came from.
        origin: String,
        /// The parser's message.
        message: String,
    },
    /// A required field is absent.
    #[error("{origin}: missing field `{field}`")]
    MissingField {
        /// Where the camera came from.
        origin: String,
        /// Dotted path of the field, e.g. `intrinsics.fx`.
        field: String,
    },
    /// A field has the wrong JSON type or shape.
    #[error("{origin}: field `{field}` must be {expected}")]
    WrongType {
        /// Where the camera came from.
        origin: String,
        /// Dotted path of the field.
        field: String,
        /// What was expected, in words.
        expected: String,
    },
    /// A value is NaN or infinite (or `null` in a file, which is how JSON writers spell NaN).
    #[error("{origin}: field `{field}` is not a finite number ({value})")]
    NotFinite {
        /// Where the camera came from.
        origin: String,
        /// Dotted path of the field.
        field: String,
        /// The offending value, as text.
        value: String,
    },
    /// A focal length is zero or negative.
    #[error("{origin}: field `{field}` must be a positive focal length, got {value}")]
    NonPositiveFocal {
        /// Where the camera came from.
        origin: String,
        /// `intrinsics.fx` or `intrinsics.fy`.
        field: String,
        /// The value found.
        value: f64,
    },
    /// The image width or height is zero.
    #[error("{origin}: field `{field}` must be a positive integer, got {value}")]
    BadSize {
        /// Where the camera came from.
        origin: String,
        /// `intrinsics.width` or `intrinsics.height`.
        field: String,
        /// The value found.
        value: String,
    },
    /// The rotation is not orthonormal within [`ORTHONORMAL_TOLERANCE`], or is a reflection.
    #[error(
        "{origin}: field `extrinsics.rotation` is not a rotation: |RᵀR − I| = {deviation:.3e}, \
         det R = {det} (tolerance {ORTHONORMAL_TOLERANCE:e})"
    )]
    NotOrthonormal {
        /// Where the camera came from.
        origin: String,
        /// Largest absolute entry of `RᵀR − I`.
        deviation: f64,
        /// Determinant of the matrix.
        det: f64,
    },
}

/// A calibrated pinhole camera with radial distortion; see the [module docs](self) for the model.
#[derive(Debug, Clone, PartialEq)]
pub struct Camera {
    /// Horizontal focal length, pixels.
    pub fx: f64,
    /// Vertical focal length, pixels.
    pub fy: f64,
    /// Principal point, x, pixels.
    pub cx: f64,
    /// Principal point, y, pixels.
    pub cy: f64,
    /// First radial distortion coefficient (of `r²`).
    pub k1: f64,
    /// Second radial distortion coefficient (of `r⁴`).
    pub k2: f64,
    /// World→camera rotation.
    pub rotation: Matrix3<f64>,
    /// World→camera translation: `pc = rotation · p + translation`.
    pub translation: Vector3<f64>,
    /// Image width, pixels.
    pub width: u32,
    /// Image height, pixels.
    pub height: u32,
}

/// Intrinsic part of the camera file (see the [module docs](self)).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct IntrinsicsFile {
    /// Horizontal focal length, pixels.
    pub fx: f64,
    /// Vertical focal length, pixels.
    pub fy: f64,
    /// Principal point x, pixels.
    pub cx: f64,
    /// Principal point y, pixels.
    pub cy: f64,
    /// Radial distortion, `r²` term.
    pub k1: f64,
    /// Radial distortion, `r⁴` term.
    pub k2: f64,
    /// Image width, pixels.
    pub width: u32,
    /// Image height, pixels.
    pub height: u32,
}

/// Extrinsic part of the camera file (see the [module docs](self)).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ExtrinsicsFile {
    /// World→camera rotation, row-major.
    pub rotation: [[f64; 3]; 3],
    /// World→camera translation.
    pub translation: [f64; 3],
}

/// The camera file as plain serde data (see the [module docs](self)). Deserialising this
/// directly skips validation; [`Camera::from_json`] validates and gives better messages.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CameraFile {
    /// Focal lengths, principal point, distortion and image size.
    pub intrinsics: IntrinsicsFile,
    /// Pose: world→camera rotation and translation.
    pub extrinsics: ExtrinsicsFile,
}

impl From<&Camera> for CameraFile {
    fn from(c: &Camera) -> Self {
        let r = &c.rotation;
        CameraFile {
            intrinsics: IntrinsicsFile {
                fx: c.fx,
                fy: c.fy,
                cx: c.cx,
                cy: c.cy,
                k1: c.k1,
                k2: c.k2,
                width: c.width,
                height: c.height,
            },
            extrinsics: ExtrinsicsFile {
                rotation: [
                    [r[(0, 0)], r[(0, 1)], r[(0, 2)]],
                    [r[(1, 0)], r[(1, 1)], r[(1, 2)]],
                    [r[(2, 0)], r[(2, 1)], r[(2, 2)]],
                ],
                translation: [c.translation.x, c.translation.y, c.translation.z],
            },
        }
    }
}

impl From<&CameraFile> for Camera {
    fn from(f: &CameraFile) -> Self {
        let r = &f.extrinsics.rotation;
        let t = &f.extrinsics.translation;
        Camera {
            fx: f.intrinsics.fx,
            fy: f.intrinsics.fy,
            cx: f.intrinsics.cx,
            cy: f.intrinsics.cy,
            k1: f.intrinsics.k1,
            k2: f.intrinsics.k2,
            rotation: Matrix3::new(
                r[0][0], r[0][1], r[0][2], r[1][0], r[1][1], r[1][2], r[2][0], r[2][1], r[2][2],
            ),
            translation: Vector3::new(t[0], t[1], t[2]),
            width: f.intrinsics.width,
            height: f.intrinsics.height,
        }
    }
}

impl Camera {
    /// A camera without distortion from focal lengths, principal point, pose and image size.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        fx: f64,
        fy: f64,
        cx: f64,
        cy: f64,
        rotation: Matrix3<f64>,
        translation: Vector3<f64>,
        width: u32,
        height: u32,
    ) -> Self {
        Camera {
            fx,
            fy,
            cx,
            cy,
            k1: 0.0,
            k2: 0.0,
            rotation,
            translation,
            width,
            height,
        }
    }

    /// A camera without distortion at `eye` looking at `target`, the world's +y up in the image
    /// (image x towards +x when looking along −z), square pixels of focal length `focal`,
    /// principal point at the image centre.
    pub fn looking_at(
        eye: Vector3<f64>,
        target: Vector3<f64>,
        focal: f64,
        width: u32,
        height: u32,
    ) -> Camera {
        Camera::looking_at_up(eye, target, Vector3::y(), focal, width, height)
    }

    /// [`Camera::looking_at`] with `up` (a world direction, not along the view) up in the
    /// image: the z-up worlds of the tracking sequences pass +z.
    pub fn looking_at_up(
        eye: Vector3<f64>,
        target: Vector3<f64>,
        up: Vector3<f64>,
        focal: f64,
        width: u32,
        height: u32,
    ) -> Camera {
        let f = (target - eye).normalize();
        let right = f.cross(&up).normalize();
        let down = f.cross(&right);
        let rotation = Matrix3::from_rows(&[right.transpose(), down.transpose(), f.transpose()]);
        Camera::new(
            focal,
            focal,
            (width as f64 - 1.0) / 2.0,
            (height as f64 - 1.0) / 2.0,
            rotation,
            -(rotation * eye),
            width,
            height,
        )
    }

    /// The intrinsic matrix `K = [[fx, 0, cx], [0, fy, cy], [0, 0, 1]]`.
    pub fn k_matrix(&self) -> Matrix3<f64> {
        Matrix3::new(self.fx, 0.0, self.cx, 0.0, self.fy, self.cy, 0.0, 0.0, 1.0)
    }

    /// Camera centre in world coordinates, `−Rᵀ t`.
    pub fn center(&self) -> Vector3<f64> {
        -(self.rotation.transpose() * self.translation)
    }

    /// A world point in the camera frame, `R p + t`.
    pub fn to_camera_frame(&self, p: &Vector3<f64>) -> Vector3<f64> {
        self.rotation * p + self.translation
    }

    /// Applies the radial distortion to ideal normalised coordinates `(x, y)` (`X/Z, Y/Z`).
    pub fn distort(&self, xy: [f64; 2]) -> [f64; 2] {
        let r2 = xy[0] * xy[0] + xy[1] * xy[1];
        let f = 1.0 + self.k1 * r2 + self.k2 * r2 * r2;
        [xy[0] * f, xy[1] * f]
    }

    /// Inverts [`distort`](Self::distort): ideal normalised coordinates from distorted ones, by
    /// Newton iteration on the radius. Exact to ~1e-14 inside the region where the distortion is
    /// monotonic; outside it returns the best iterate found.
    pub fn undistort(&self, xy: [f64; 2]) -> [f64; 2] {
        let rd = (xy[0] * xy[0] + xy[1] * xy[1]).sqrt();
        if rd == 0.0 || (self.k1 == 0.0 && self.k2 == 0.0) {
            return xy;
        }
        // solve g(r) = r (1 + k1 r² + k2 r⁴) − rd = 0
        let mut r = rd;
        for _ in 0..50 {
            let r2 = r * r;
            let g = r * (1.0 + self.k1 * r2 + self.k2 * r2 * r2) - rd;
            let dg = 1.0 + 3.0 * self.k1 * r2 + 5.0 * self.k2 * r2 * r2;
            if dg.abs() < 1e-12 {
                break;
            }
            let step = g / dg;
            r -= step;
            if step.abs() <= 1e-15 * rd.max(1e-300) {
                break;
            }
        }
        let s = r / rd;
        [xy[0] * s, xy[1] * s]
    }

    /// Pixel → ideal normalised coordinates (`X/Z, Y/Z` in the camera frame), removing distortion.
    pub fn undistort_pixel_to_normalized(&self, uv: [f64; 2]) -> [f64; 2] {
        self.undistort([(uv[0] - self.cx) / self.fx, (uv[1] - self.cy) / self.fy])
    }

    /// The pixel where the point would appear with the same `K` but no distortion.
    pub fn undistorted_pixel(&self, uv: [f64; 2]) -> [f64; 2] {
        let n = self.undistort_pixel_to_normalized(uv);
        [self.fx * n[0] + self.cx, self.fy * n[1] + self.cy]
    }

    /// Projects a camera-frame point without checking that it is in front (divides by `z`).
    pub(crate) fn project_camera_frame_unchecked(&self, pc: &Vector3<f64>) -> [f64; 2] {
        let d = self.distort([pc.x / pc.z, pc.y / pc.z]);
        [self.fx * d[0] + self.cx, self.fy * d[1] + self.cy]
    }

    /// Projects a world point to pixels (distortion included); `None` when the point is not in
    /// front of the camera (`z ≤ 0` in the camera frame). Points outside the image are still
    /// projected: compare with [`width`](Self::width)/[`height`](Self::height) if that matters.
    pub fn project(&self, p: &Vector3<f64>) -> Option<[f64; 2]> {
        let pc = self.to_camera_frame(p);
        if pc.z.is_nan() || pc.z <= 0.0 {
            return None;
        }
        Some(self.project_camera_frame_unchecked(&pc))
    }

    /// The same camera for an image pyramid level shrunk by `factor` (2 = half size): focal
    /// lengths divided by `factor`, principal point `c' = (c + 0.5) / factor − 0.5` (pixel
    /// centres stay consistent), width and height divided and rounded (at least 1); distortion
    /// and pose unchanged.
    pub fn scaled(&self, factor: f64) -> Camera {
        let size = |n: u32| ((n as f64 / factor).round().max(1.0)) as u32;
        Camera {
            fx: self.fx / factor,
            fy: self.fy / factor,
            cx: (self.cx + 0.5) / factor - 0.5,
            cy: (self.cy + 0.5) / factor - 0.5,
            width: size(self.width),
            height: size(self.height),
            ..self.clone()
        }
    }

    /// Checks the invariants of the file format (finite values, positive focal lengths and image
    /// size, proper rotation); `source` names the camera in the error.
    pub fn validate_named(&self, source: &str) -> Result<(), CameraError> {
        let src = || source.to_string();
        let scalars = [
            ("intrinsics.fx", self.fx),
            ("intrinsics.fy", self.fy),
            ("intrinsics.cx", self.cx),
            ("intrinsics.cy", self.cy),
            ("intrinsics.k1", self.k1),
            ("intrinsics.k2", self.k2),
        ];
        for (field, v) in scalars {
            if !v.is_finite() {
                return Err(CameraError::NotFinite {
                    origin: src(),
                    field: field.into(),
                    value: v.to_string(),
                });
            }
        }
        for (i, v) in self.rotation.transpose().iter().enumerate() {
            if !v.is_finite() {
                return Err(CameraError::NotFinite {
                    origin: src(),
                    field: format!("extrinsics.rotation[{}][{}]", i / 3, i % 3),
                    value: v.to_string(),
                });
            }
        }
        for (i, v) in self.translation.iter().enumerate() {
            if !v.is_finite() {
                return Err(CameraError::NotFinite {
                    origin: src(),
                    field: format!("extrinsics.translation[{i}]"),
                    value: v.to_string(),
                });
            }
        }
        for (field, v) in [("intrinsics.fx", self.fx), ("intrinsics.fy", self.fy)] {
            if v <= 0.0 {
                return Err(CameraError::NonPositiveFocal {
                    origin: src(),
                    field: field.into(),
                    value: v,
                });
            }
        }
        for (field, v) in [
            ("intrinsics.width", self.width),
            ("intrinsics.height", self.height),
        ] {
            if v == 0 {
                return Err(CameraError::BadSize {
                    origin: src(),
                    field: field.into(),
                    value: v.to_string(),
                });
            }
        }
        let r = &self.rotation;
        let deviation = (r.transpose() * r - Matrix3::identity()).abs().max();
        let det = r.determinant();
        if deviation > ORTHONORMAL_TOLERANCE || (det - 1.0).abs() > ORTHONORMAL_TOLERANCE {
            return Err(CameraError::NotOrthonormal {
                origin: src(),
                deviation,
                det,
            });
        }
        Ok(())
    }

    /// [`validate_named`](Self::validate_named) with the source called `"camera"`.
    pub fn validate(&self) -> Result<(), CameraError> {
        self.validate_named("camera")
    }

    /// The camera as pretty-printed JSON in the documented format, after validation.
    pub fn to_json(&self) -> Result<String, CameraError> {
        self.validate()?;
        serde_json::to_string_pretty(&CameraFile::from(self)).map_err(|e| CameraError::Json {
            origin: "camera".into(),
            message: e.to_string(),
        })
    }

    /// Parses and validates a camera from JSON text; errors name `source` and the field.
    pub fn from_json_named(text: &str, source: &str) -> Result<Camera, CameraError> {
        // serde_json reads floats correctly rounded (feature `float_roundtrip`), so save → load
        // is the identity
        let value: Value = serde_json::from_str(text).map_err(|e| CameraError::Json {
            origin: source.into(),
            message: e.to_string(),
        })?;
        let reader = FieldReader { source };
        let intr = reader.object(&value, "intrinsics")?;
        let extr = reader.object(&value, "extrinsics")?;
        let num = |field: &str| reader.number(intr, "intrinsics", field);
        let fx = num("fx")?;
        let fy = num("fy")?;
        let cx = num("cx")?;
        let cy = num("cy")?;
        let k1 = num("k1")?;
        let k2 = num("k2")?;
        let width = reader.size(intr, "intrinsics", "width")?;
        let height = reader.size(intr, "intrinsics", "height")?;
        let rot = reader.array(extr, "extrinsics", "rotation", 3)?;
        let mut rotation = Matrix3::zeros();
        for (i, row) in rot.iter().enumerate() {
            let name = format!("extrinsics.rotation[{i}]");
            let row = reader.array_value(row, &name, 3)?;
            for (j, v) in row.iter().enumerate() {
                rotation[(i, j)] = reader.number_value(v, &format!("{name}[{j}]"))?;
            }
        }
        let tr = reader.array(extr, "extrinsics", "translation", 3)?;
        let mut translation = Vector3::zeros();
        for (i, v) in tr.iter().enumerate() {
            translation[i] = reader.number_value(v, &format!("extrinsics.translation[{i}]"))?;
        }
        let camera = Camera {
            fx,
            fy,
            cx,
            cy,
            k1,
            k2,
            rotation,
            translation,
            width,
            height,
        };
        camera.validate_named(source)?;
        Ok(camera)
    }

    /// [`from_json_named`](Self::from_json_named) with the source called `"camera JSON"`.
    pub fn from_json(text: &str) -> Result<Camera, CameraError> {
        Self::from_json_named(text, "camera JSON")
    }

    /// Reads and validates a camera file; errors name the file and the field.
    pub fn load(path: impl AsRef<Path>) -> Result<Camera, CameraError> {
        let path = path.as_ref();
        let text = std::fs::read_to_string(path).map_err(|source| CameraError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        Self::from_json_named(&text, &path.display().to_string())
    }

    /// Validates the camera and writes it as a JSON camera file.
    pub fn save(&self, path: impl AsRef<Path>) -> Result<(), CameraError> {
        let path = path.as_ref();
        self.validate_named(&path.display().to_string())?;
        let text = self.to_json()?;
        std::fs::write(path, text + "\n").map_err(|source| CameraError::Io {
            path: path.to_path_buf(),
            source,
        })
    }
}

/// Reads fields out of a JSON value with errors naming the source and the dotted field path.
struct FieldReader<'a> {
    source: &'a str,
}

impl FieldReader<'_> {
    fn missing(&self, field: &str) -> CameraError {
        CameraError::MissingField {
            origin: self.source.into(),
            field: field.into(),
        }
    }

    fn wrong(&self, field: &str, expected: &str) -> CameraError {
        CameraError::WrongType {
            origin: self.source.into(),
            field: field.into(),
            expected: expected.into(),
        }
    }

    fn object<'v>(&self, v: &'v Value, key: &str) -> Result<&'v Value, CameraError> {
        match v.get(key) {
            None => Err(self.missing(key)),
            Some(o) if o.is_object() => Ok(o),
            Some(_) => Err(self.wrong(key, "an object")),
        }
    }

    fn number(&self, obj: &Value, parent: &str, key: &str) -> Result<f64, CameraError> {
        let name = format!("{parent}.{key}");
        match obj.get(key) {
            None => Err(self.missing(&name)),
            Some(v) => self.number_value(v, &name),
        }
    }

    fn number_value(&self, v: &Value, name: &str) -> Result<f64, CameraError> {
        match v {
            Value::Null => Err(CameraError::NotFinite {
                origin: self.source.into(),
                field: name.into(),
                value: "null".into(),
            }),
            Value::Number(n) => match n.as_f64() {
                Some(x) if x.is_finite() => Ok(x),
                _ => Err(CameraError::NotFinite {
                    origin: self.source.into(),
                    field: name.into(),
                    value: n.to_string(),
                }),
            },
            Value::String(s) if s.parse::<f64>().is_ok_and(|x| !x.is_finite()) => {
                Err(CameraError::NotFinite {
                    origin: self.source.into(),
                    field: name.into(),
                    value: s.clone(),
                })
            }
            _ => Err(self.wrong(name, "a number")),
        }
    }

    fn size(&self, obj: &Value, parent: &str, key: &str) -> Result<u32, CameraError> {
        let name = format!("{parent}.{key}");
        let v = obj.get(key).ok_or_else(|| self.missing(&name))?;
        match v.as_u64().and_then(|x| u32::try_from(x).ok()) {
            Some(x) => Ok(x),
            None => Err(CameraError::BadSize {
                origin: self.source.into(),
                field: name,
                value: v.to_string(),
            }),
        }
    }

    fn array<'v>(
        &self,
        obj: &'v Value,
        parent: &str,
        key: &str,
        len: usize,
    ) -> Result<&'v Vec<Value>, CameraError> {
        let name = format!("{parent}.{key}");
        let v = obj.get(key).ok_or_else(|| self.missing(&name))?;
        self.array_value(v, &name, len)
    }

    fn array_value<'v>(
        &self,
        v: &'v Value,
        name: &str,
        len: usize,
    ) -> Result<&'v Vec<Value>, CameraError> {
        match v.as_array() {
            Some(a) if a.len() == len => Ok(a),
            _ => Err(self.wrong(name, &format!("an array of {len} elements"))),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cam() -> Camera {
        Camera {
            k1: -0.08,
            k2: 0.02,
            ..Camera::new(
                400.0,
                401.0,
                162.0,
                118.0,
                Matrix3::identity(),
                Vector3::zeros(),
                320,
                240,
            )
        }
    }

    #[test]
    fn undistort_inverts_distort() {
        let c = cam();
        for &p in &[[0.0, 0.0], [0.3, -0.2], [-0.5, 0.4], [0.01, 0.0]] {
            let d = c.distort(p);
            let u = c.undistort(d);
            assert!(
                (u[0] - p[0]).abs() < 1e-13 && (u[1] - p[1]).abs() < 1e-13,
                "{p:?} {u:?}"
            );
        }
    }

    #[test]
    fn behind_camera_is_none_and_centre_projects_to_principal_point() {
        let c = cam();
        assert!(c.project(&Vector3::new(0.0, 0.0, -1.0)).is_none());
        assert!(c.project(&Vector3::new(0.0, 0.0, 0.0)).is_none());
        let uv = c.project(&Vector3::new(0.0, 0.0, 2.0)).expect("in front");
        assert_eq!(uv, [162.0, 118.0]);
        assert_eq!(c.center(), Vector3::zeros());
    }

    #[test]
    fn json_null_is_not_finite_and_names_field() {
        let mut c = cam();
        c.cx = f64::NAN;
        let text = serde_json::to_string(&CameraFile::from(&c)).expect("serialises");
        let err = Camera::from_json_named(&text, "x.json").expect_err("NaN must fail");
        let msg = err.to_string();
        assert!(
            msg.contains("x.json") && msg.contains("intrinsics.cx"),
            "{msg}"
        );
    }

    #[test]
    fn scaled_camera_maps_pixel_areas_consistently() {
        let c = cam();
        let h = c.scaled(2.0);
        assert_eq!((h.width, h.height), (160, 120));
        assert_eq!((h.fx, h.fy), (200.0, 200.5));
        assert_eq!((h.cx, h.cy), (80.75, 58.75));
        assert_eq!(
            (h.k1, h.k2, h.rotation, h.translation),
            (c.k1, c.k2, c.rotation, c.translation)
        );
        let p = Vector3::new(0.3, -0.2, 2.5);
        let (a, b) = (c.project(&p).expect("front"), h.project(&p).expect("front"));
        // a full-resolution pixel u covers [u − 0.5, u + 0.5]; at half size that is (u + 0.5) / 2 − 0.5
        for i in 0..2 {
            assert!(
                ((a[i] + 0.5) / 2.0 - 0.5 - b[i]).abs() < 1e-12,
                "{a:?} {b:?}"
            );
        }
        assert_eq!(c.scaled(1.0), c);
        assert_eq!(c.scaled(3.0).width, 107);
    }
}
