//! The CANDIDE-3 parameterised face (J. Ahlberg, report LiTH-ISY-R-2326, 2001): reader of its
//! `.wfm` files and the model `g = ḡ + S σ + A α` (report eq. 4, without the global motion).
//!
//! `.wfm` layout (report Appendix D): `#` comment lines, some meaningful: section headers
//! (`# VERTEX LIST:`, `# FACE LIST:`, `# ANIMATION UNITS LIST:`, `# SHAPE UNITS LIST:`,
//! `# ANIMATION PARAMETERS:`, `# SHAPE PARAMETERS:`, `# TEXTURE:`, `# GLOBAL MOTION:`,
//! `# END OF FILE`), and before each unit a name comment (`# AUV0   Upper lip raiser (AU10)`,
//! `# FAP 3 open_jaw`, `# FAP23 yaw_l_eyeball`) optionally followed by its FAP unit (`# MNS`,
//! `# MW`, `# ENS`, `# ES`, `# IRISD`). Each list section starts with a count; vertices are
//! `x y z`, faces three 0-based indices, units `n` then `n` lines `vertex dx dy dz`, parameters
//! `index value`. The texture section is skipped, the global motion (rotation, scale,
//! translation rows) kept as read. Coordinates are the model's own unitless ones (y up, +x the
//! subject's left).
//!
//! Units of the animation parameters in [`Candide::apply`]: action-unit vectors (AUV) take
//! CANDIDE's raw weights (about −1 … 1); a FAP with a FAPU moves its vertices by
//! `value / 1024 × FAPU`, FAPUs measured on the neutral mask ([`Candide::fapus`], report
//! Table 2: MW = x(31) − x(64), MNS = y(6) − y(87), ENS = pupil.y − y(6), ES = distance of the
//! pupils, IRISD = y(73) − y(74); pupils = means of the iris box vertices 67, 68, 71, 72 and
//! 69, 70, 73, 74); the eyeball FAPs 23–30 (no FAPU line) take MPEG-4 angle units, 1e-5 rad,
//! their unit vectors read as the displacement per radian (a small-angle approximation).

use std::path::{Path, PathBuf};

use super::fap::{FapUnit, Fapus};
use super::FaceError;
use crate::geometry::Vec3;

/// MPEG-4 angle unit (rad).
pub const ANGLE_UNIT: f64 = 1e-5;

/// One animation or shape unit of a CANDIDE model.
#[derive(Clone, Debug, PartialEq)]
pub struct CandideUnit {
    /// The name comment as written, e.g. `AUV0   Upper lip raiser (AU10)` or `FAP 3 open_jaw`
    /// (empty when the file has none).
    pub label: String,
    /// The name: `Upper lip raiser (AU10)`, `open_jaw`, `Head height`.
    pub name: String,
    /// The MPEG-4 FAP number, for FAP units.
    pub fap: Option<u8>,
    /// The FAP unit named under a FAP's name comment.
    pub fapu: Option<FapUnit>,
    /// `(vertex, displacement)` per unit value, model coordinates.
    pub displacements: Vec<(usize, Vec3)>,
}

/// A CANDIDE model read from a `.wfm` file.
#[derive(Clone, Debug, PartialEq)]
pub struct Candide {
    /// The file it was read from.
    pub path: PathBuf,
    /// Neutral vertices ḡ (model units).
    pub vertices: Vec<Vec3>,
    /// Triangles, 0-based.
    pub faces: Vec<[u32; 3]>,
    /// Animation units (the columns of A), in file order.
    pub animation_units: Vec<CandideUnit>,
    /// Shape units (the columns of S), in file order.
    pub shape_units: Vec<CandideUnit>,
    /// `(unit index, value)` pairs of the file's animation parameter section.
    pub animation_parameters: Vec<(usize, f64)>,
    /// `(unit index, value)` pairs of the file's shape parameter section.
    pub shape_parameters: Vec<(usize, f64)>,
    /// Global motion rows as read (rotation, scale, translation), when present.
    pub global_motion: Vec<[f64; 3]>,
}

/// A line of the file: comment text (after `#`, trimmed) or data tokens.
enum Line<'a> {
    Comment(&'a str),
    Data(Vec<&'a str>),
}

/// A section as split from the text: header, its line, its lines.
type RawSection<'a> = (&'static str, usize, Vec<(usize, Line<'a>)>);

/// Section headers, in the file's order of appearance (any order is accepted).
const HEADERS: [&str; 9] = [
    "VERTEX LIST:",
    "FACE LIST:",
    "ANIMATION UNITS LIST:",
    "SHAPE UNITS LIST:",
    "ANIMATION PARAMETERS:",
    "SHAPE PARAMETERS:",
    "TEXTURE:",
    "GLOBAL MOTION:",
    "END OF FILE",
];

/// Reader state: the file, its lines in one section, a cursor.
struct Section<'a> {
    path: &'a Path,
    header_line: usize,
    lines: Vec<(usize, Line<'a>)>,
    pos: usize,
}

impl<'a> Section<'a> {
    fn err(&self, line: usize, message: impl Into<String>) -> FaceError {
        FaceError::Parse {
            path: self.path.to_path_buf(),
            line,
            message: message.into(),
        }
    }

    /// Next data line, collecting the comments met on the way.
    fn next_data(&mut self, comments: &mut Vec<&'a str>) -> Option<(usize, Vec<&'a str>)> {
        while let Some((n, l)) = self.lines.get(self.pos) {
            self.pos += 1;
            match l {
                Line::Comment(c) => comments.push(c),
                Line::Data(t) => return Some((*n, t.clone())),
            }
        }
        None
    }

    /// Next data line, or an error naming what was expected.
    fn expect(&mut self, what: &str) -> Result<(usize, Vec<&'a str>), FaceError> {
        let mut ignored = Vec::new();
        let last = self.lines.last().map_or(self.header_line, |l| l.0);
        self.next_data(&mut ignored)
            .ok_or_else(|| self.err(last, format!("end of section: expected {what}")))
    }

    /// A count line (one non-negative integer).
    fn count(&mut self, what: &str) -> Result<usize, FaceError> {
        let (n, t) = self.expect(&format!("the number of {what}"))?;
        match t.as_slice() {
            [c] => c
                .parse::<usize>()
                .map_err(|_| self.err(n, format!("number of {what}: `{c}` is not a count"))),
            _ => Err(self.err(
                n,
                format!("expected the number of {what}, found {} values", t.len()),
            )),
        }
    }

    fn number<T: std::str::FromStr>(
        &self,
        n: usize,
        tok: &str,
        what: &str,
    ) -> Result<T, FaceError> {
        tok.parse::<T>()
            .map_err(|_| self.err(n, format!("{what}: `{tok}` is not a number")))
    }

    fn finite(&self, n: usize, tok: &str, what: &str) -> Result<f64, FaceError> {
        let v: f64 = self.number(n, tok, what)?;
        if v.is_finite() {
            Ok(v)
        } else {
            Err(self.err(n, format!("{what}: `{tok}` is not finite")))
        }
    }

    fn vec3(&self, n: usize, t: &[&str], what: &str) -> Result<Vec3, FaceError> {
        Ok(Vec3::new(
            self.finite(n, t[0], what)?,
            self.finite(n, t[1], what)?,
            self.finite(n, t[2], what)?,
        ))
    }

    /// `count` units (comments before each name it).
    fn units(&mut self, what: &str, vertices: usize) -> Result<Vec<CandideUnit>, FaceError> {
        let count = self.count(what)?;
        let mut units = Vec::with_capacity(count.min(1024));
        for u in 0..count {
            let mut comments = Vec::new();
            let (n, t) = self.next_data(&mut comments).ok_or_else(|| {
                self.err(self.last_line(), format!("{what}: {u} of {count} found"))
            })?;
            let k = match t.as_slice() {
                [c] => self.number::<usize>(n, c, "number of unit vertices")?,
                _ => return Err(self.err(n, format!("{what} {u}: expected its vertex count"))),
            };
            let mut displacements = Vec::with_capacity(k.min(4096));
            for _ in 0..k {
                let (n, t) = self.expect(&format!("{what} {u}: `vertex dx dy dz`"))?;
                if t.len() != 4 {
                    return Err(self.err(n, format!("{what} {u}: expected `vertex dx dy dz`")));
                }
                let v: usize = self.number(n, t[0], "vertex index")?;
                if v >= vertices {
                    return Err(self.err(n, format!("vertex {v} out of range (0..{vertices})")));
                }
                displacements.push((v, self.vec3(n, &t[1..], "displacement")?));
            }
            units.push(unit_from_comments(&comments, displacements));
        }
        Ok(units)
    }

    fn last_line(&self) -> usize {
        self.lines.last().map_or(self.header_line, |l| l.0)
    }

    /// `count` then `index value` lines.
    fn parameters(&mut self, units: usize) -> Result<Vec<(usize, f64)>, FaceError> {
        let count = self.count("parameters")?;
        let mut out = Vec::with_capacity(count.min(1024));
        for _ in 0..count {
            let (n, t) = self.expect("`unit value`")?;
            if t.len() != 2 {
                return Err(self.err(n, "expected `unit value`"));
            }
            let i: usize = self.number(n, t[0], "unit index")?;
            if i >= units {
                return Err(self.err(n, format!("unit {i} out of range (0..{units})")));
            }
            out.push((i, self.finite(n, t[1], "parameter value")?));
        }
        Ok(out)
    }
}

/// Name, FAP number and FAP unit from the comments before a unit.
fn unit_from_comments(comments: &[&str], displacements: Vec<(usize, Vec3)>) -> CandideUnit {
    let fapu_of = |c: &str| match c.trim() {
        "MW" => Some(FapUnit::Mw),
        "MNS" => Some(FapUnit::Mns),
        "ENS" => Some(FapUnit::Ens),
        "ES" => Some(FapUnit::Es),
        "IRISD" => Some(FapUnit::Irisd),
        _ => None,
    };
    let fapu = comments.iter().find_map(|c| fapu_of(c));
    let label = comments
        .iter()
        .rev()
        .find(|c| fapu_of(c).is_none() && !c.trim().is_empty())
        .map_or("", |c| c.trim())
        .to_string();
    let (mut fap, mut name) = (None, label.clone());
    if let Some(rest) = label.strip_prefix("FAP") {
        let rest = rest.trim_start();
        let digits: String = rest.chars().take_while(char::is_ascii_digit).collect();
        if let Ok(f) = digits.parse::<u8>() {
            fap = Some(f);
            name = rest[digits.len()..].trim().to_string();
        }
    } else if let Some(rest) = label.strip_prefix("AUV") {
        let rest = rest.trim_start_matches(|c: char| c.is_ascii_digit());
        name = rest.trim().to_string();
    }
    CandideUnit {
        label,
        name,
        fap,
        fapu,
        displacements,
    }
}

impl Candide {
    /// Reads a `.wfm` file. Errors name the file and the line.
    pub fn load(path: &Path) -> Result<Candide, FaceError> {
        let bytes = crate::limits::read(path).map_err(|e| FaceError::io(path, e))?;
        // The upstream file has a stray non-UTF-8 byte in a comment: read lossily.
        Candide::parse(&String::from_utf8_lossy(&bytes), path)
    }

    /// Parses `.wfm` text; `path` names it in errors.
    pub fn parse(text: &str, path: &Path) -> Result<Candide, FaceError> {
        let mut sections: Vec<RawSection> = Vec::new();
        for (i, raw) in text.lines().enumerate() {
            let n = i + 1;
            let s = raw.trim();
            if s.is_empty() {
                continue;
            }
            if let Some(c) = s.strip_prefix('#') {
                let c = c.trim();
                if let Some(h) = HEADERS.iter().find(|h| c.eq_ignore_ascii_case(h)) {
                    sections.push((h, n, Vec::new()));
                    continue;
                }
                if let Some(last) = sections.last_mut() {
                    last.2.push((n, Line::Comment(c)));
                }
            } else {
                let Some(last) = sections.last_mut() else {
                    return Err(FaceError::Parse {
                        path: path.to_path_buf(),
                        line: n,
                        message: "data before the first section header (`# VERTEX LIST:`)".into(),
                    });
                };
                last.2.push((n, Line::Data(s.split_whitespace().collect())));
            }
        }
        let mut model = Candide {
            path: path.to_path_buf(),
            vertices: Vec::new(),
            faces: Vec::new(),
            animation_units: Vec::new(),
            shape_units: Vec::new(),
            animation_parameters: Vec::new(),
            shape_parameters: Vec::new(),
            global_motion: Vec::new(),
        };
        let mut seen = Vec::new();
        for (header, header_line, lines) in sections {
            let mut s = Section {
                path,
                header_line,
                lines,
                pos: 0,
            };
            if seen.contains(&header) && header != "END OF FILE" {
                return Err(s.err(header_line, format!("second `# {header}` section")));
            }
            seen.push(header);
            let nv = model.vertices.len();
            match header {
                "VERTEX LIST:" => {
                    let count = s.count("vertices")?;
                    for _ in 0..count {
                        let (n, t) = s.expect("a vertex `x y z`")?;
                        if t.len() != 3 {
                            return Err(
                                s.err(n, format!("expected `x y z`, found {} values", t.len()))
                            );
                        }
                        model.vertices.push(s.vec3(n, &t, "vertex coordinate")?);
                    }
                }
                "FACE LIST:" => {
                    if nv == 0 {
                        return Err(s.err(header_line, "faces before the vertex list"));
                    }
                    let count = s.count("faces")?;
                    for _ in 0..count {
                        let (n, t) = s.expect("a face `a b c`")?;
                        if t.len() != 3 {
                            return Err(
                                s.err(n, format!("expected `a b c`, found {} values", t.len()))
                            );
                        }
                        let mut f = [0u32; 3];
                        for (k, tok) in t.iter().enumerate() {
                            let v: usize = s.number(n, tok, "face index")?;
                            if v >= nv {
                                return Err(s.err(n, format!("vertex {v} out of range (0..{nv})")));
                            }
                            f[k] = v as u32;
                        }
                        model.faces.push(f);
                    }
                }
                "ANIMATION UNITS LIST:" => model.animation_units = s.units("animation unit", nv)?,
                "SHAPE UNITS LIST:" => model.shape_units = s.units("shape unit", nv)?,
                "ANIMATION PARAMETERS:" => {
                    model.animation_parameters = s.parameters(model.animation_units.len())?
                }
                "SHAPE PARAMETERS:" => {
                    model.shape_parameters = s.parameters(model.shape_units.len())?
                }
                "GLOBAL MOTION:" => {
                    let mut ignored = Vec::new();
                    while let Some((n, t)) = s.next_data(&mut ignored) {
                        if t.len() != 3 {
                            return Err(s.err(n, "global motion: expected three values per row"));
                        }
                        let v = s.vec3(n, &t, "global motion")?;
                        model.global_motion.push([v.x, v.y, v.z]);
                    }
                }
                _ => {} // texture and end of file: tolerated, not used
            }
        }
        if model.vertices.is_empty() {
            return Err(FaceError::Parse {
                path: path.to_path_buf(),
                line: 0,
                message: "no `# VERTEX LIST:` section with vertices".into(),
            });
        }
        Ok(model)
    }

    /// The default CANDIDE-3 file under the shared data folder.
    pub fn default_path() -> PathBuf {
        crate::geometry::files::data_dir()
            .join("faces")
            .join("candide3")
            .join("candide3.wfm")
    }

    /// Index of the animation unit of FAP `number`.
    pub fn fap_index(&self, number: u8) -> Option<usize> {
        self.animation_units
            .iter()
            .position(|u| u.fap == Some(number))
    }

    /// Index of the first unit (animation units, then shape units) whose name contains
    /// `text`, case-insensitively: `(is_shape_unit, index)`.
    pub fn find_unit(&self, text: &str) -> Option<(bool, usize)> {
        let t = text.to_lowercase();
        let hit = |u: &CandideUnit| u.name.to_lowercase().contains(&t);
        self.animation_units
            .iter()
            .position(hit)
            .map(|i| (false, i))
            .or_else(|| self.shape_units.iter().position(hit).map(|i| (true, i)))
    }

    /// FAP units of the neutral mask (model units; report Table 2). Fails when a vertex the
    /// definitions use is missing or a unit is not a positive length.
    pub fn fapus(&self) -> Result<Fapus, FaceError> {
        let v = &self.vertices;
        if v.len() < 113 {
            return Err(FaceError::Failed(format!(
                "{}: FAPUs need the CANDIDE-3 vertex numbering (113 vertices), found {}",
                self.path.display(),
                v.len()
            )));
        }
        let mean = |ids: [usize; 4]| ids.iter().map(|&i| v[i]).sum::<Vec3>() / 4.0;
        let (lp, rp) = (mean([67, 68, 71, 72]), mean([69, 70, 73, 74]));
        let f = Fapus {
            mw: v[31].x - v[64].x,
            mns: v[6].y - v[87].y,
            ens: 0.5 * (lp.y + rp.y) - v[6].y,
            es: (lp - rp).norm(),
            irisd: v[73].y - v[74].y,
        };
        if [f.mw, f.mns, f.ens, f.es, f.irisd]
            .iter()
            .all(|x| x.is_finite() && *x > 0.0)
        {
            Ok(f)
        } else {
            Err(FaceError::Failed(format!(
                "{}: FAPUs not all positive: {f:?}",
                self.path.display()
            )))
        }
    }

    /// Scale of animation unit `k`: FAPU / 1024 for FAPs with a unit, [`ANGLE_UNIT`] for the
    /// other FAPs, 1 for action-unit vectors.
    pub fn animation_scale(&self, k: usize, fapus: &Fapus) -> f64 {
        match self.animation_units.get(k) {
            Some(CandideUnit {
                fap: Some(_),
                fapu: Some(u),
                ..
            }) => fapus.get(*u) / 1024.0,
            Some(CandideUnit { fap: Some(_), .. }) => ANGLE_UNIT,
            _ => 1.0,
        }
    }

    /// `g = ḡ + S σ + A α` (model units, no global motion). `shape[i]` weighs shape unit `i`,
    /// `animation[k]` animation unit `k` in its own unit (see the module docs). Missing values
    /// count as 0, extra ones are ignored. Falls back to raw scales if the FAPUs cannot be
    /// measured (a model that is not CANDIDE-3).
    pub fn apply(&self, shape: &[f64], animation: &[f64]) -> Vec<Vec3> {
        let fapus = self.fapus().ok();
        let mut g = self.vertices.clone();
        let n = g.len();
        for (u, &s) in self.shape_units.iter().zip(shape) {
            for &(i, d) in &u.displacements {
                if i < n {
                    g[i] += d * s;
                }
            }
        }
        for (k, (u, &a)) in self.animation_units.iter().zip(animation).enumerate() {
            let scale = fapus.as_ref().map_or(1.0, |f| self.animation_scale(k, f));
            for &(i, d) in &u.displacements {
                if i < n {
                    g[i] += d * (a * scale);
                }
            }
        }
        g
    }

    /// For each vertex, the vertex nearest its mirror image in `x = 0`. Coincident vertices
    /// (CANDIDE's closed lips: 81/83, 82/84) pair by rank: the k-th (by index) of a group of
    /// coincident vertices maps to the k-th of the group at the mirror position.
    pub fn mirror_map(&self) -> Vec<usize> {
        let v = &self.vertices;
        let group = |p: Vec3| -> Vec<usize> {
            let best = v
                .iter()
                .map(|q| (q - p).norm_squared())
                .fold(f64::INFINITY, f64::min);
            (0..v.len())
                .filter(|&j| (v[j] - p).norm_squared() <= best + 1e-18)
                .collect()
        };
        (0..v.len())
            .map(|i| {
                let own = group(v[i]);
                let rank = own.iter().position(|&j| j == i).unwrap_or(0);
                let p = v[i];
                let other = group(Vec3::new(-p.x, p.y, p.z));
                other.get(rank).or(other.first()).copied().unwrap_or(i)
            })
            .collect()
    }
}
