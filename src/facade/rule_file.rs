//! Rule files: the text of a facade grammar ([`Grammar::to_text`], [`Grammar::parse`]) and
//! its reading from a file as input, within stated bounds. Every number of a rule file (the
//! axiom's size, fixed sizes, floating weights, repeat sizes) is finite, ≥ 0 and at most
//! [`MAX_FACADE_UNITS`] (the axiom's size and repeat sizes > 0); a derivation makes at most
//! `max_elements` shapes ([`check_shapes`](super::grammar::check_shapes), counted before
//! they are made); a generated facade
//! is at most [`MAX_FACADE_METRES`] wide and high ([`check_extent`]). Errors name the file and
//! the line ([`read_rules`]).

use std::collections::BTreeMap;
use std::fmt::Write;
use std::path::Path;

use super::error::FacadeError;
use super::grammar::{Body, Dir, Grammar, Size};
use super::labels::Class;
use crate::limits;

/// Largest number a rule file may hold (facade units): a facade of 1 km at 1 mm per unit.
pub const MAX_FACADE_UNITS: f64 = 1e6;

/// Largest width or height (m) of a facade generated from a rule file: 1 km.
pub const MAX_FACADE_METRES: f64 = 1000.0;

/// `v` as a rule file's number: finite, ≥ 0 (> 0 when `positive`) and at most
/// [`MAX_FACADE_UNITS`]; the error says which and the range.
pub fn check_number(v: f64, what: &str, positive: bool) -> Result<f64, String> {
    let low_ok = if positive { v > 0.0 } else { v >= 0.0 };
    if v.is_finite() && low_ok && v <= MAX_FACADE_UNITS {
        Ok(v)
    } else {
        Err(format!(
            "{what} {} is outside {}{}] facade units (a facade of at most 1 km at 1 mm per unit)",
            shown(v),
            if positive { "(0, " } else { "[0, " },
            shown(MAX_FACADE_UNITS)
        ))
    }
}

/// `v` for a message: plain for ordinary magnitudes, in exponent form for huge or tiny ones.
fn shown(v: f64) -> String {
    if v != 0.0 && v.is_finite() && !(1e-4..1e6).contains(&v.abs()) {
        format!("{v:e}")
    } else {
        format!("{v}")
    }
}

/// Checks a generated facade's size in metres (`what` names it, e.g. the factor it was made
/// at) against [`MAX_FACADE_METRES`].
pub fn check_extent(what: &str, width_m: f64, height_m: f64) -> Result<(), String> {
    let ok = |v: f64| v.is_finite() && v > 0.0 && v <= MAX_FACADE_METRES;
    if ok(width_m) && ok(height_m) {
        Ok(())
    } else {
        Err(format!(
            "{what}: the facade would be {} × {} m, outside (0, {MAX_FACADE_METRES}] m each way",
            shown(width_m),
            shown(height_m)
        ))
    }
}

/// The line (from 1) of `text` that defines rule `name`.
fn line_of_rule(text: &str, name: &str) -> Option<usize> {
    text.lines()
        .position(|l| l.split_once("-->").is_some_and(|(n, _)| n.trim() == name))
        .map(|i| i + 1)
}

/// `message` ("rule NAME: …", as derivation errors read) with the line of rule NAME in
/// `text` in front, when it has one.
pub fn with_line(text: &str, message: String) -> String {
    let name = message
        .strip_prefix("rule ")
        .and_then(|m| m.split([':', ' ']).next());
    match name.and_then(|n| line_of_rule(text, n)) {
        Some(line) => format!("line {line}: {message}"),
        None => message,
    }
}

/// Reads the rule file `path` (within `max_file_bytes`) and checks that it derives at its own
/// size within the limits. Errors name the file and the line: a syntax error, a number out of
/// range, an unknown rule, or a rule whose derivation makes more than `max_elements` shapes.
pub fn read_rules(path: &Path) -> Result<Grammar, FacadeError> {
    let err = |message: String| FacadeError::File {
        path: path.to_path_buf(),
        message,
    };
    let text = limits::read_to_string(path).map_err(|e| err(e.to_string()))?;
    let grammar = Grammar::parse(&text).map_err(err)?;
    grammar
        .derive(grammar.size.0, grammar.size.1)
        .map_err(|e| err(with_line(&text, e)))?;
    Ok(grammar)
}

impl Grammar {
    /// The rule file: one rule per line, `Name --> split(y) { 12: A | ~30: B }`,
    /// `Name --> repeat(x, 43.5) { Tile }`, `Name --> window`,
    /// `Name --> insert(window, window_cross)`; the axiom first, with the
    /// parsed size in a header comment.
    pub fn to_text(&self) -> String {
        let mut s = String::new();
        let _ = writeln!(
            s,
            "// facade grammar (CGA-like): fixed sizes in facade units, ~w a floating weight\n// axiom {} size {} {}",
            self.axiom,
            fmt_num(self.size.0),
            fmt_num(self.size.1)
        );
        let mut names: Vec<&String> = self.rules.keys().collect();
        names.sort_by_key(|n| (*n != &self.axiom, n.as_str()));
        for name in names {
            let _ = write!(s, "{name} --> ");
            match &self.rules[name] {
                Body::Leaf(c) => {
                    let _ = writeln!(s, "{}", c.name());
                }
                Body::Insert { class, element } => {
                    let _ = writeln!(s, "insert({}, {element})", class.name());
                }
                Body::Repeat { dir, size, rule } => {
                    let _ = writeln!(s, "repeat({}, {}) {{ {rule} }}", dir.name(), fmt_num(*size));
                }
                Body::Split { dir, parts } => {
                    let p: Vec<String> = parts
                        .iter()
                        .map(|(sz, r)| match sz {
                            Size::Fixed(v) => format!("{}: {r}", fmt_num(*v)),
                            Size::Floating(v) => format!("~{}: {r}", fmt_num(*v)),
                        })
                        .collect();
                    let _ = writeln!(s, "split({}) {{ {} }}", dir.name(), p.join(" | "));
                }
            }
        }
        s
    }

    /// Reads a rule file written by [`Grammar::to_text`] (or by hand in the same syntax).
    /// Errors give the line number and what was expected.
    pub fn parse(text: &str) -> Result<Grammar, String> {
        let mut rules = BTreeMap::new();
        let (mut axiom, mut size) = (None, None);
        for (ln, raw) in text.lines().enumerate() {
            let line = raw.trim();
            let err = |m: &str| format!("line {}: {m}: `{line}`", ln + 1);
            if let Some(c) = line.strip_prefix("//") {
                let w: Vec<&str> = c.split_whitespace().collect();
                if w.len() == 5 && w[0] == "axiom" && w[2] == "size" {
                    axiom = Some(w[1].to_string());
                    let (a, b) = (w[3].parse::<f64>(), w[4].parse::<f64>());
                    match (a, b) {
                        (Ok(a), Ok(b)) => {
                            for v in [a, b] {
                                check_number(v, "the axiom's size", true).map_err(|m| err(&m))?;
                            }
                            size = Some((a, b))
                        }
                        _ => return Err(err("the axiom's size is not two numbers")),
                    }
                }
                continue;
            }
            if line.is_empty() {
                continue;
            }
            let (name, rhs) = line
                .split_once("-->")
                .ok_or_else(|| err("expected `Name --> body`"))?;
            let name = name.trim();
            if name.is_empty() || !name.chars().all(|c| c.is_alphanumeric() || c == '_') {
                return Err(err("a rule name is letters, digits and _"));
            }
            let rhs = rhs.trim();
            let body = if let Some(class) = Class::from_name(rhs) {
                Body::Leaf(class)
            } else if let Some(args) = rhs
                .strip_prefix("insert(")
                .and_then(|a| a.strip_suffix(')'))
            {
                let (c, e) = args
                    .split_once(',')
                    .ok_or_else(|| err("insert takes (class, element)"))?;
                let class = Class::from_name(c.trim())
                    .ok_or_else(|| err("insert's class is window, wall, door, balcony, …"))?;
                let element = e.trim();
                if element.is_empty() || !element.chars().all(|c| c.is_alphanumeric() || c == '_') {
                    return Err(err("an element name is letters, digits and _"));
                }
                Body::Insert {
                    class,
                    element: element.to_string(),
                }
            } else {
                let (head, inner) = rhs
                    .split_once('{')
                    .and_then(|(h, r)| r.trim_end().strip_suffix('}').map(|i| (h.trim(), i)))
                    .ok_or_else(|| {
                        err("expected a class name, split(..) { .. } or repeat(..) { .. }")
                    })?;
                let args = head
                    .split_once('(')
                    .and_then(|(op, a)| a.strip_suffix(')').map(|a| (op.trim(), a)))
                    .ok_or_else(|| err("expected split(dir) or repeat(dir, size)"))?;
                let dir_of = |s: &str| match s.trim() {
                    "x" => Ok(Dir::X),
                    "y" => Ok(Dir::Y),
                    _ => Err(err("direction must be x or y")),
                };
                match args.0 {
                    "split" => {
                        let dir = dir_of(args.1)?;
                        let mut parts = Vec::new();
                        for p in inner.split('|') {
                            let (sz, r) = p
                                .split_once(':')
                                .ok_or_else(|| err("a split part is `size: Rule`"))?;
                            let sz = sz.trim();
                            let number = |s: &str, what: &str| -> Result<f64, String> {
                                let v = s.parse().map_err(|_| err(&format!("bad {what}")))?;
                                check_number(v, what, false).map_err(|m| err(&m))
                            };
                            let size = match sz.strip_prefix('~') {
                                Some(w) => Size::Floating(number(w, "floating weight")?),
                                None => Size::Fixed(number(sz, "size")?),
                            };
                            parts.push((size, r.trim().to_string()));
                        }
                        Body::Split { dir, parts }
                    }
                    "repeat" => {
                        let (d, s) = args
                            .1
                            .split_once(',')
                            .ok_or_else(|| err("repeat takes (dir, size)"))?;
                        let size = s.trim().parse().map_err(|_| err("bad repeat size"))?;
                        Body::Repeat {
                            dir: dir_of(d)?,
                            size: check_number(size, "repeat size", true).map_err(|m| err(&m))?,
                            rule: inner.trim().to_string(),
                        }
                    }
                    _ => return Err(err("unknown operation (split, repeat)")),
                }
            };
            if rules.insert(name.to_string(), body).is_some() {
                return Err(err("rule defined twice"));
            }
        }
        let axiom = axiom.ok_or("missing `// axiom Name size W H` header")?;
        let size = size.ok_or("missing the axiom's size")?;
        let g = Grammar { rules, axiom, size };
        g.check()?;
        Ok(g)
    }

    /// Every referenced rule exists and every size is finite and non-negative.
    pub fn check(&self) -> Result<(), String> {
        if !self.rules.contains_key(&self.axiom) {
            return Err(format!("the axiom {} has no rule", self.axiom));
        }
        for (name, body) in &self.rules {
            let refs: Vec<&String> = match body {
                Body::Leaf(_) | Body::Insert { .. } => Vec::new(),
                Body::Repeat { rule, size, .. } => {
                    if !(*size > 0.0 && size.is_finite()) {
                        return Err(format!("rule {name}: repeat size {size} must be positive"));
                    }
                    vec![rule]
                }
                Body::Split { parts, .. } => {
                    for (s, _) in parts {
                        let v = match s {
                            Size::Fixed(v) | Size::Floating(v) => *v,
                        };
                        if !(v >= 0.0 && v.is_finite()) {
                            return Err(format!("rule {name}: size {v} must be ≥ 0"));
                        }
                    }
                    parts.iter().map(|p| &p.1).collect()
                }
            };
            if let Some(r) = refs.iter().find(|r| !self.rules.contains_key(r.as_str())) {
                return Err(format!("rule {name} refers to unknown rule {r}"));
            }
        }
        Ok(())
    }
}

/// Shortest decimal that reads back to the same f64 (Rust's `Display`), but integers without
/// a fraction.
fn fmt_num(v: f64) -> String {
    format!("{v}")
}
