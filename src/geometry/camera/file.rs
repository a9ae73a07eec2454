//! The JSON camera file (see the [camera module](super) for the format): its serde layout,
//! validation of a [`Camera`]'s invariants, reading with errors that name the file and the
//! field, and writing.

use std::path::{Path, PathBuf};

use nalgebra::{Matrix3, Vector3};
use serde::{Deserialize, Serialize};
use serde_json::Value;

use super::Camera;

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

/// Intrinsic part of the camera file (see the [camera module](super)).
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

/// Extrinsic part of the camera file (see the [camera module](super)).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ExtrinsicsFile {
    /// World→camera rotation, row-major.
    pub rotation: [[f64; 3]; 3],
    /// World→camera translation.
    pub translation: [f64; 3],
}

/// The camera file as plain serde data (see the [camera module](super)). Deserialising this
/// directly skips validation; [`Camera::from_json`] validates and gives better messages.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct JsonCamera {
    /// Focal lengths, principal point, distortion and image size.
    pub intrinsics: IntrinsicsFile,
    /// Pose: world→camera rotation and translation.
    pub extrinsics: ExtrinsicsFile,
}

impl From<&Camera> for JsonCamera {
    fn from(c: &Camera) -> Self {
        let r = &c.rotation;
        JsonCamera {
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

impl From<&JsonCamera> for Camera {
    fn from(f: &JsonCamera) -> Self {
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
        serde_json::to_string_pretty(&JsonCamera::from(self)).map_err(|e| CameraError::Json {
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
        let text = crate::limits::read_to_string(path).map_err(|source| CameraError::Io {
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

    use crate::geometry::camera::model::tests::cam;

    #[test]
    fn json_null_is_not_finite_and_names_field() {
        let mut c = cam();
        c.cx = f64::NAN;
        let text = serde_json::to_string(&JsonCamera::from(&c)).expect("serialises");
        let err = Camera::from_json_named(&text, "x.json").expect_err("NaN must fail");
        let msg = err.to_string();
        assert!(
            msg.contains("x.json") && msg.contains("intrinsics.cx"),
            "{msg}"
        );
    }
}
