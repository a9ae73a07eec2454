//! Conversions between Rhai values and the engine's types: error conversion, numbers and
//! vectors from script values, and `…Parameters` structs to and from object maps (through
//! their serde form, so every field is settable by name and unknown names are rejected).

use rhai::{Array, Dynamic, EvalAltResult, Map, Position, FLOAT, INT};
use serde::{de::DeserializeOwned, Serialize};
use serde_json::Value;

use crate::cloth::ClothError;
use crate::geometry::{ExportFrame, GeometryError, Units, UpAxis};

/// Result type of every registered function.
pub type RResult<T> = Result<T, Box<EvalAltResult>>;

/// A runtime error with `message`; rhai fills in the script position of the failing call.
pub fn rt_err(message: impl std::fmt::Display) -> Box<EvalAltResult> {
    EvalAltResult::ErrorRuntime(message.to_string().into(), Position::NONE).into()
}

impl From<ClothError> for Box<EvalAltResult> {
    fn from(e: ClothError) -> Self {
        rt_err(e)
    }
}

impl From<GeometryError> for Box<EvalAltResult> {
    fn from(e: GeometryError) -> Self {
        rt_err(e)
    }
}

/// A number (integer or float) named `what` in error messages.
pub fn num(d: &Dynamic, what: &str) -> RResult<f64> {
    if let Some(f) = d.clone().try_cast::<FLOAT>() {
        Ok(f)
    } else if let Some(i) = d.clone().try_cast::<INT>() {
        Ok(i as f64)
    } else {
        Err(rt_err(format!(
            "`{what}` must be a number, got {}",
            d.type_name()
        )))
    }
}

/// A finite number.
pub fn finite(d: &Dynamic, what: &str) -> RResult<f64> {
    let v = num(d, what)?;
    if v.is_finite() {
        Ok(v)
    } else {
        Err(rt_err(format!("`{what}` must be finite, got {v}")))
    }
}

/// A finite number ≥ 0 (else an error naming `what`).
pub fn non_negative(d: &Dynamic, what: &str) -> RResult<f64> {
    let v = finite(d, what)?;
    if v < 0.0 {
        return Err(rt_err(format!("`{what}` must be ≥ 0, got {v}")));
    }
    Ok(v)
}

/// A non-negative integer (counts, indices).
pub fn count(d: &Dynamic, what: &str) -> RResult<usize> {
    match d.clone().try_cast::<INT>() {
        Some(i) if i >= 0 => Ok(i as usize),
        Some(i) => Err(rt_err(format!("`{what}` must be ≥ 0, got {i}"))),
        None => Err(rt_err(format!(
            "`{what}` must be an integer, got {}",
            d.type_name()
        ))),
    }
}

/// A non-negative integer from an `INT` argument.
pub fn index(i: INT, what: &str) -> RResult<usize> {
    count(&Dynamic::from_int(i), what)
}

/// A 3-vector `[x, y, z]` of finite numbers.
pub fn vec3(d: &Dynamic, what: &str) -> RResult<[f64; 3]> {
    let arr = d.read_lock::<Array>().ok_or_else(|| {
        rt_err(format!(
            "`{what}` must be an array [x, y, z], got {}",
            d.type_name()
        ))
    })?;
    if arr.len() != 3 {
        return Err(rt_err(format!(
            "`{what}` must have 3 numbers, got {}",
            arr.len()
        )));
    }
    let mut out = [0.0; 3];
    for (k, v) in arr.iter().enumerate() {
        out[k] = finite(v, what)?;
    }
    Ok(out)
}

/// A 3-vector as a script array.
pub fn arr3(v: impl Into<[f64; 3]>) -> Dynamic {
    let v: [f64; 3] = v.into();
    Dynamic::from_array(v.iter().map(|&c| Dynamic::from_float(c)).collect())
}

/// Particle indices from an array of integers.
pub fn indices(arr: &Array, what: &str) -> RResult<Vec<usize>> {
    arr.iter().map(|d| count(d, what)).collect()
}

/// A JSON value as a script value (objects become maps, arrays arrays).
pub fn json_to_dynamic(v: &Value) -> Dynamic {
    match v {
        Value::Null => Dynamic::UNIT,
        Value::Bool(b) => Dynamic::from_bool(*b),
        Value::Number(n) => match (n.as_i64(), n.as_f64()) {
            (Some(i), _) if !n.is_f64() => Dynamic::from_int(i),
            (_, Some(f)) => Dynamic::from_float(f),
            _ => Dynamic::UNIT,
        },
        Value::String(s) => s.clone().into(),
        Value::Array(a) => Dynamic::from_array(a.iter().map(json_to_dynamic).collect()),
        Value::Object(o) => {
            let m: Map = o
                .iter()
                .map(|(k, v)| (k.as_str().into(), json_to_dynamic(v)))
                .collect();
            Dynamic::from_map(m)
        }
    }
}

/// A serializable struct as a script map.
pub fn to_map<T: Serialize>(value: &T) -> Dynamic {
    serde_json::to_value(value)
        .map(|v| json_to_dynamic(&v))
        .unwrap_or(Dynamic::UNIT)
}

/// Sets field `key` of a serialized struct from a script value, checked against the field's
/// current JSON type: finite numbers for floats, non-negative integers for counts, `[..]` of
/// the same length for vectors, strings and booleans as such.
fn set_json_field(
    obj: &mut serde_json::Map<String, Value>,
    key: &str,
    v: &Dynamic,
    what: &str,
) -> RResult<()> {
    let name = format!("{what} parameter `{key}`");
    let Some(cur) = obj.get(key) else {
        let known: Vec<&str> = obj.keys().map(String::as_str).collect();
        return Err(rt_err(format!(
            "unknown {what} parameter `{key}` (known: {})",
            known.join(", ")
        )));
    };
    let new = match cur {
        Value::Number(n) if n.is_f64() => {
            let x = num(v, &name)?;
            serde_json::Number::from_f64(x)
                .map(Value::Number)
                .ok_or_else(|| rt_err(format!("{name} must be a finite number, got {x}")))?
        }
        Value::Number(_) => Value::from(count(v, &name)? as u64),
        Value::Bool(_) => Value::Bool(
            v.as_bool()
                .map_err(|t| rt_err(format!("{name} must be a bool, got {t}")))?,
        ),
        Value::String(_) => Value::String(
            v.clone()
                .into_immutable_string()
                .map_err(|t| rt_err(format!("{name} must be a string, got {t}")))?
                .to_string(),
        ),
        Value::Array(a) => {
            let arr = v
                .read_lock::<Array>()
                .ok_or_else(|| rt_err(format!("{name} must be an array")))?;
            if arr.len() != a.len() {
                return Err(rt_err(format!(
                    "{name} must have {} numbers, got {}",
                    a.len(),
                    arr.len()
                )));
            }
            let mut out = Vec::with_capacity(arr.len());
            for d in arr.iter() {
                let x = finite(d, &name)?;
                out.push(Value::Number(serde_json::Number::from_f64(x).unwrap()));
            }
            Value::Array(out)
        }
        _ => return Err(rt_err(format!("{name} cannot be set from a script"))),
    };
    obj.insert(key.to_string(), new);
    Ok(())
}

/// `base` with the fields named in `map` replaced; `what` names the struct in errors
/// ("fabric", "simulation"). Unknown keys and ill-typed or non-finite values are errors.
pub fn update_from_map<T: Serialize + DeserializeOwned>(
    base: &T,
    map: &Map,
    what: &str,
) -> RResult<T> {
    let mut v = serde_json::to_value(base).map_err(rt_err)?;
    let obj = v
        .as_object_mut()
        .ok_or_else(|| rt_err(format!("{what} parameters are not a struct")))?;
    let mut keys: Vec<_> = map.keys().collect();
    keys.sort();
    for k in keys {
        set_json_field(obj, k, &map[k], what)?;
    }
    serde_json::from_value(v).map_err(|e| rt_err(format!("invalid {what} parameters: {e}")))
}

/// `base` with the single field `key` replaced by `value`.
pub fn update_field<T: Serialize + DeserializeOwned>(
    base: &T,
    key: &str,
    value: &Dynamic,
    what: &str,
) -> RResult<T> {
    let mut m = Map::new();
    m.insert(key.into(), value.clone());
    update_from_map(base, &m, what)
}

/// Field `key` of a serializable struct as a script value.
pub fn get_field<T: Serialize>(base: &T, key: &str, what: &str) -> RResult<Dynamic> {
    let v = serde_json::to_value(base).map_err(rt_err)?;
    match v.get(key) {
        Some(x) => Ok(json_to_dynamic(x)),
        None => Err(rt_err(format!("unknown {what} parameter `{key}`"))),
    }
}

/// The doc-comment block rhai metadata expects: every line of `text` prefixed with `/// `.
pub fn doc_comment(text: &str) -> String {
    text.lines()
        .map(|l| {
            if l.is_empty() {
                "///".to_string()
            } else {
                format!("/// {l}")
            }
        })
        .collect::<Vec<_>>()
        .join("\n")
}

/// An export frame from a script options map `#{up: "y" | "z", units: "m" | "cm" | "mm"}`
/// (each optional: +Y up in metres by default); other keys are errors.
pub fn export_frame(m: &Map) -> RResult<ExportFrame> {
    let mut frame = ExportFrame::Y_UP_METRES;
    for (k, v) in m {
        let text = || {
            v.clone()
                .into_string()
                .map_err(|_| rt_err(format!("`{k}` must be a string")))
        };
        match k.as_str() {
            "up" => frame.up = UpAxis::parse(&text()?).map_err(rt_err)?,
            "units" => frame.units = Units::parse(&text()?).map_err(rt_err)?,
            _ => {
                return Err(rt_err(format!(
                    "unknown export option `{k}` (known: up, units)"
                )))
            }
        }
    }
    Ok(frame)
}
