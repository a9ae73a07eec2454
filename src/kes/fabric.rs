//! The fabric file (`emilion-fabric-1`, JSON; documented in `kawabata/FORMAT.md`): a fabric's
//! KES-F parameters per direction and/or its measured curves, every number with the unit KES
//! writes it in. Reading converts to SI through [`super::units`] and validates every field;
//! errors name the file and the field path.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde_json::{json, Map, Value};

use super::error::KesError;
use super::kes_param::KesParam;
use super::ranges;
use super::units::{self, Quantity};

/// Format tag of fabric files.
pub const FORMAT: &str = "emilion-fabric-1";

/// KES parameters of one direction, SI values.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct KesValues {
    /// Parameter → SI value.
    pub values: BTreeMap<KesParam, f64>,
}

impl KesValues {
    /// The SI value of `p`, if given.
    pub fn get(&self, p: KesParam) -> Option<f64> {
        self.values.get(&p).copied()
    }
    /// Sets the SI value of `p`.
    pub fn set(&mut self, p: KesParam, v: f64) {
        self.values.insert(p, v);
    }
}

/// A measured curve, SI: tensile (strain, N/m), shear (rad, N/m), bending (1/m, N).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Curve {
    /// Loading branch, x increasing.
    pub loading: Vec<[f64; 2]>,
    /// Unloading (recovery) branch, may be empty.
    pub unloading: Vec<[f64; 2]>,
}

/// The measured curves of a fabric.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct FabricCurves {
    /// Tensile along the warp.
    pub tensile_warp: Option<Curve>,
    /// Tensile along the weft.
    pub tensile_weft: Option<Curve>,
    /// Tensile along the bias (45°).
    pub tensile_bias: Option<Curve>,
    /// Shear.
    pub shear: Option<Curve>,
    /// Bending, curvature along the warp.
    pub bending_warp: Option<Curve>,
    /// Bending, curvature along the weft.
    pub bending_weft: Option<Curve>,
    /// Bending, curvature along the bias.
    pub bending_bias: Option<Curve>,
}

/// Curve slots: (file key, quantity of x, quantity of y).
const CURVES: [(&str, Quantity, Quantity); 7] = [
    ("tensile_warp", Quantity::Fraction, Quantity::ForcePerWidth),
    ("tensile_weft", Quantity::Fraction, Quantity::ForcePerWidth),
    ("tensile_bias", Quantity::Fraction, Quantity::ForcePerWidth),
    ("shear", Quantity::Angle, Quantity::ForcePerWidth),
    (
        "bending_warp",
        Quantity::Curvature,
        Quantity::MomentPerWidth,
    ),
    (
        "bending_weft",
        Quantity::Curvature,
        Quantity::MomentPerWidth,
    ),
    (
        "bending_bias",
        Quantity::Curvature,
        Quantity::MomentPerWidth,
    ),
];

impl FabricCurves {
    fn slot(&self, k: usize) -> &Option<Curve> {
        [
            &self.tensile_warp,
            &self.tensile_weft,
            &self.tensile_bias,
            &self.shear,
            &self.bending_warp,
            &self.bending_weft,
            &self.bending_bias,
        ][k]
    }
    fn slot_mut(&mut self, k: usize) -> &mut Option<Curve> {
        match k {
            0 => &mut self.tensile_warp,
            1 => &mut self.tensile_weft,
            2 => &mut self.tensile_bias,
            3 => &mut self.shear,
            4 => &mut self.bending_warp,
            5 => &mut self.bending_weft,
            _ => &mut self.bending_bias,
        }
    }
}

/// A fabric, SI units.
#[derive(Debug, Clone, PartialEq)]
pub struct FabricSpec {
    /// Name.
    pub name: String,
    /// What it is.
    pub description: String,
    /// Where every number came from.
    pub provenance: String,
    /// File it was read from ("" when built in code).
    pub path: String,
    /// Areal density (kg/m²).
    pub density: f64,
    /// Thickness (m).
    pub thickness: Option<f64>,
    /// KES parameters along the warp.
    pub warp: KesValues,
    /// KES parameters along the weft.
    pub weft: KesValues,
    /// Measured curves.
    pub curves: FabricCurves,
    /// Maximum load of the tensile protocol (N/m); 500 gf/cm by default.
    pub tensile_fm: f64,
}

/// The standard KES-FB1 maximum tensile load, 500 gf/cm (N/m).
pub const STANDARD_FM: f64 = 500.0 * units::GF_PER_CM;

struct Reader<'a> {
    file: &'a str,
}

impl Reader<'_> {
    fn err(&self, field: &str, msg: impl Into<String>) -> KesError {
        KesError::Field {
            file: self.file.to_string(),
            field: field.to_string(),
            message: msg.into(),
        }
    }

    /// `{"value": x, "unit": "u"}` → SI, finite.
    fn quantity(&self, v: &Value, field: &str, q: Quantity) -> Result<f64, KesError> {
        let obj = v
            .as_object()
            .ok_or_else(|| self.err(field, "expected {\"value\": number, \"unit\": string}"))?;
        for k in obj.keys() {
            if k != "value" && k != "unit" {
                return Err(self.err(field, format!("unknown key `{k}`")));
            }
        }
        let value = obj
            .get("value")
            .ok_or_else(|| self.err(field, "missing `value`"))?
            .as_f64()
            .ok_or_else(|| self.err(&format!("{field}.value"), "must be a number"))?;
        let unit = obj
            .get("unit")
            .ok_or_else(|| self.err(field, "missing `unit`"))?
            .as_str()
            .ok_or_else(|| self.err(&format!("{field}.unit"), "must be a string"))?;
        if !value.is_finite() {
            return Err(self.err(field, format!("value {value} is not finite")));
        }
        units::to_si(value, unit, q).map_err(|e| self.err(&format!("{field}.unit"), e.to_string()))
    }

    /// `si` (of quantity `q`) if its value in KES units lies in `range`.
    fn in_range(
        &self,
        si: f64,
        field: &str,
        q: Quantity,
        range: ranges::Range,
    ) -> Result<f64, KesError> {
        range
            .check(q.kes_unit().from_si(si))
            .map(|_| si)
            .map_err(|m| self.err(field, m))
    }

    fn non_negative(&self, v: f64, field: &str) -> Result<f64, KesError> {
        if v < 0.0 {
            Err(self.err(field, format!("must be ≥ 0, got {v}")))
        } else {
            Ok(v)
        }
    }

    fn points(&self, v: &Value, field: &str, fx: f64, fy: f64) -> Result<Vec<[f64; 2]>, KesError> {
        let arr = v
            .as_array()
            .ok_or_else(|| self.err(field, "expected an array of [x, y] pairs"))?;
        let mut out = Vec::with_capacity(arr.len());
        for (i, p) in arr.iter().enumerate() {
            let f = format!("{field}[{i}]");
            let pair = p
                .as_array()
                .filter(|a| a.len() == 2)
                .ok_or_else(|| self.err(&f, "expected [x, y]"))?;
            let x = pair[0]
                .as_f64()
                .ok_or_else(|| self.err(&f, "x must be a number"))?;
            let y = pair[1]
                .as_f64()
                .ok_or_else(|| self.err(&f, "y must be a number"))?;
            if !(x.is_finite() && y.is_finite()) {
                return Err(self.err(&f, "not finite"));
            }
            out.push([x * fx, y * fy]);
        }
        Ok(out)
    }

    fn curve(&self, v: &Value, key: &str, qx: Quantity, qy: Quantity) -> Result<Curve, KesError> {
        let field = format!("curves.{key}");
        let obj = v
            .as_object()
            .ok_or_else(|| self.err(&field, "expected an object"))?;
        for k in obj.keys() {
            if !["x_unit", "y_unit", "loading", "unloading"].contains(&k.as_str()) {
                return Err(self.err(&field, format!("unknown key `{k}`")));
            }
        }
        let unit = |k: &str, q: Quantity| -> Result<f64, KesError> {
            let f = format!("{field}.{k}");
            let u = obj
                .get(k)
                .ok_or_else(|| self.err(&f, "missing"))?
                .as_str()
                .ok_or_else(|| self.err(&f, "must be a string"))?;
            units::unit_for(u, q)
                .map(|u| u.factor())
                .map_err(|e| self.err(&f, e.to_string()))
        };
        let (fx, fy) = (unit("x_unit", qx)?, unit("y_unit", qy)?);
        let loading = self.points(
            obj.get("loading")
                .ok_or_else(|| self.err(&format!("{field}.loading"), "missing"))?,
            &format!("{field}.loading"),
            fx,
            fy,
        )?;
        if loading.len() < 2 {
            return Err(self.err(&format!("{field}.loading"), "needs at least 2 points"));
        }
        for i in 1..loading.len() {
            if loading[i][0] <= loading[i - 1][0] {
                return Err(self.err(
                    &format!("{field}.loading[{i}]"),
                    "x must increase along the loading branch",
                ));
            }
        }
        let unloading = match obj.get("unloading") {
            Some(u) => self.points(u, &format!("{field}.unloading"), fx, fy)?,
            None => Vec::new(),
        };
        if unloading.len() == 1 {
            return Err(self.err(
                &format!("{field}.unloading"),
                "needs at least 2 points (or leave it out)",
            ));
        }
        Ok(Curve { loading, unloading })
    }
}

/// Parses a fabric from JSON text; `file` names it in errors.
pub fn parse_fabric(text: &str, file: &str) -> Result<FabricSpec, KesError> {
    let root: Value = serde_json::from_str(text).map_err(|e| KesError::Syntax {
        file: file.to_string(),
        line: e.line(),
        column: e.column(),
        message: e.to_string(),
    })?;
    let r = Reader { file };
    let obj = root
        .as_object()
        .ok_or_else(|| r.err("(root)", "expected a JSON object"))?;
    const KEYS: [&str; 9] = [
        "format",
        "name",
        "description",
        "provenance",
        "weight",
        "thickness",
        "kes",
        "curves",
        "protocol",
    ];
    for k in obj.keys() {
        if !KEYS.contains(&k.as_str()) {
            return Err(r.err(k, "unknown field"));
        }
    }
    let text_field = |k: &str, required: bool| -> Result<String, KesError> {
        match obj.get(k) {
            Some(Value::String(s)) => Ok(s.clone()),
            Some(_) => Err(r.err(k, "must be a string")),
            None if required => Err(r.err(k, "missing")),
            None => Ok(String::new()),
        }
    };
    let format = text_field("format", true)?;
    if format != FORMAT {
        return Err(r.err("format", format!("expected \"{FORMAT}\", got \"{format}\"")));
    }
    let name = text_field("name", true)?;
    let weight = obj
        .get("weight")
        .ok_or_else(|| r.err("weight", "missing"))?;
    let density = r.quantity(weight, "weight", Quantity::ArealWeight)?;
    if density <= 0.0 {
        return Err(r.err("weight", format!("must be > 0, got {density}")));
    }
    r.in_range(density, "weight", Quantity::ArealWeight, ranges::WEIGHT)?;
    let thickness = match obj.get("thickness") {
        Some(v) => {
            let t = r.non_negative(
                r.quantity(v, "thickness", Quantity::Thickness)?,
                "thickness",
            )?;
            Some(r.in_range(t, "thickness", Quantity::Thickness, ranges::THICKNESS)?)
        }
        None => None,
    };
    let mut dirs = [KesValues::default(), KesValues::default()];
    if let Some(kes) = obj.get("kes") {
        let kes = kes
            .as_object()
            .ok_or_else(|| r.err("kes", "expected an object"))?;
        for (dname, dv) in kes {
            let d = match dname.as_str() {
                "warp" => 0,
                "weft" => 1,
                _ => return Err(r.err(&format!("kes.{dname}"), "expected `warp` or `weft`")),
            };
            let dv = dv
                .as_object()
                .ok_or_else(|| r.err(&format!("kes.{dname}"), "expected an object"))?;
            for (pname, pv) in dv {
                let field = format!("kes.{dname}.{pname}");
                let p = KesParam::from_name(pname)
                    .ok_or_else(|| r.err(&field, "unknown KES parameter"))?;
                let q = units::quantity_of(p);
                let v = r.non_negative(r.quantity(pv, &field, q)?, &field)?;
                dirs[d].set(p, r.in_range(v, &field, q, ranges::param_range(p))?);
            }
        }
    }
    let mut curves = FabricCurves::default();
    if let Some(cv) = obj.get("curves") {
        let cv = cv
            .as_object()
            .ok_or_else(|| r.err("curves", "expected an object"))?;
        for (key, v) in cv {
            let k = CURVES
                .iter()
                .position(|(n, _, _)| n == key)
                .ok_or_else(|| r.err(&format!("curves.{key}"), "unknown curve"))?;
            let (_, qx, qy) = CURVES[k];
            *curves.slot_mut(k) = Some(r.curve(v, key, qx, qy)?);
        }
    }
    let mut tensile_fm = STANDARD_FM;
    if let Some(p) = obj.get("protocol") {
        let p = p
            .as_object()
            .ok_or_else(|| r.err("protocol", "expected an object"))?;
        for (k, v) in p {
            match k.as_str() {
                "tensile_fm" => {
                    tensile_fm = r.quantity(v, "protocol.tensile_fm", Quantity::ForcePerWidth)?;
                    if tensile_fm <= 0.0 {
                        return Err(r.err("protocol.tensile_fm", "must be > 0"));
                    }
                    r.in_range(
                        tensile_fm,
                        "protocol.tensile_fm",
                        Quantity::ForcePerWidth,
                        ranges::TENSILE_FM,
                    )?;
                }
                _ => return Err(r.err(&format!("protocol.{k}"), "unknown field")),
            }
        }
    }
    let [warp, weft] = dirs;
    Ok(FabricSpec {
        name,
        description: text_field("description", false)?,
        provenance: text_field("provenance", false)?,
        path: file.to_string(),
        density,
        thickness,
        warp,
        weft,
        curves,
        tensile_fm,
    })
}

/// Checks every value of a fabric (built in code or read) against the ranges of real fabrics;
/// the error gives the field path as the file format names it (`kes.warp.B`, `weight`) and
/// the message.
pub fn check_ranges(spec: &FabricSpec) -> Result<(), (String, String)> {
    let kes = |q: Quantity, si: f64| q.kes_unit().from_si(si);
    let field =
        |f: &str, r: ranges::Range, v: f64| r.check(v).map(|_| ()).map_err(|m| (f.to_string(), m));
    field(
        "weight",
        ranges::WEIGHT,
        kes(Quantity::ArealWeight, spec.density),
    )?;
    if let Some(t) = spec.thickness {
        field("thickness", ranges::THICKNESS, kes(Quantity::Thickness, t))?;
    }
    for (name, d) in [("warp", &spec.warp), ("weft", &spec.weft)] {
        for (p, v) in &d.values {
            let f = format!("kes.{name}.{}", p.name());
            field(&f, ranges::param_range(*p), units::to_kes(*p, *v).1)?;
        }
    }
    field(
        "protocol.tensile_fm",
        ranges::TENSILE_FM,
        kes(Quantity::ForcePerWidth, spec.tensile_fm),
    )
}

/// Reads a fabric file.
pub fn read_fabric(path: &Path) -> Result<FabricSpec, KesError> {
    let file = path.display().to_string();
    let text = crate::limits::read_to_string(path).map_err(|e| KesError::Io {
        file: file.clone(),
        message: e.to_string(),
    })?;
    parse_fabric(&text, &file)
}

/// The `*.json` files of `dir`, sorted by name.
pub fn json_files(dir: &Path) -> Result<Vec<PathBuf>, KesError> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(dir)
        .map_err(|e| KesError::Io {
            file: dir.display().to_string(),
            message: e.to_string(),
        })?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.is_file() && p.extension().is_some_and(|x| x == "json"))
        .collect();
    files.sort();
    Ok(files)
}

/// Reads every `*.json` fabric of `dir`, sorted by file name.
pub fn read_fabric_dir(dir: &Path) -> Result<Vec<FabricSpec>, KesError> {
    json_files(dir)?.iter().map(|p| read_fabric(p)).collect()
}

fn quantity_json(si: f64, q: Quantity) -> Value {
    let u = q.kes_unit();
    json!({"value": u.from_si(si), "unit": u.symbol()})
}

/// The fabric as JSON in KES units (a non-finite number becomes `null`, which
/// [`parse_fabric`] refuses).
pub fn fabric_to_json(spec: &FabricSpec) -> Value {
    let mut root = Map::new();
    root.insert("format".into(), json!(FORMAT));
    root.insert("name".into(), json!(spec.name));
    root.insert("description".into(), json!(spec.description));
    root.insert("provenance".into(), json!(spec.provenance));
    root.insert(
        "weight".into(),
        quantity_json(spec.density, Quantity::ArealWeight),
    );
    if let Some(t) = spec.thickness {
        root.insert("thickness".into(), quantity_json(t, Quantity::Thickness));
    }
    let mut kes = Map::new();
    for (name, d) in [("warp", &spec.warp), ("weft", &spec.weft)] {
        if d.values.is_empty() {
            continue;
        }
        let mut m = Map::new();
        for (p, v) in &d.values {
            m.insert(p.name().into(), quantity_json(*v, units::quantity_of(*p)));
        }
        kes.insert(name.into(), Value::Object(m));
    }
    if !kes.is_empty() {
        root.insert("kes".into(), Value::Object(kes));
    }
    let mut curves = Map::new();
    for (k, (key, qx, qy)) in CURVES.iter().enumerate() {
        if let Some(c) = spec.curves.slot(k) {
            let (ux, uy) = (qx.kes_unit(), qy.kes_unit());
            let pts = |v: &[[f64; 2]]| -> Value {
                Value::Array(
                    v.iter()
                        .map(|p| json!([ux.from_si(p[0]), uy.from_si(p[1])]))
                        .collect(),
                )
            };
            let mut m = Map::new();
            m.insert("x_unit".into(), json!(ux.symbol()));
            m.insert("y_unit".into(), json!(uy.symbol()));
            m.insert("loading".into(), pts(&c.loading));
            if !c.unloading.is_empty() {
                m.insert("unloading".into(), pts(&c.unloading));
            }
            curves.insert((*key).into(), Value::Object(m));
        }
    }
    if !curves.is_empty() {
        root.insert("curves".into(), Value::Object(curves));
    }
    root.insert(
        "protocol".into(),
        json!({"tensile_fm": quantity_json(spec.tensile_fm, Quantity::ForcePerWidth)}),
    );
    Value::Object(root)
}

/// Writes a fabric file in KES units (gf/cm, %, deg, 1/cm, gf.cm/cm, mg/cm2, …), atomically
/// (a temporary file renamed into place). The text is checked with [`parse_fabric`] before
/// anything is written, so a spec that could not be read back (a negative stiffness, a NaN,
/// a loading branch going back) is an error naming `path` and the field, and reading the
/// written file gives the same spec (values equal to rounding, `path` the new file).
pub fn write_fabric(path: &Path, spec: &FabricSpec) -> Result<(), KesError> {
    let file = path.display().to_string();
    let io = |e: std::io::Error| KesError::Io {
        file: file.clone(),
        message: e.to_string(),
    };
    let text = serde_json::to_string_pretty(&fabric_to_json(spec)).map_err(|e| KesError::Io {
        file: file.clone(),
        message: e.to_string(),
    })?;
    parse_fabric(&text, &file)?;
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir).map_err(io)?;
    }
    let tmp = path.with_extension("json.tmp");
    std::fs::write(&tmp, text + "\n").map_err(io)?;
    std::fs::rename(&tmp, path).map_err(io)
}
