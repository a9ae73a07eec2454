//! What a DXF-AAMA file says in annotation text (layer 15) beyond the AAMA piece and style
//! texts: corner names, seams and placements, so that a pattern written by
//! [`crate::garment::write_pattern_dxf`] reads back with the same corners, seams and placements.
//! AAMA has no seams; CAD systems show these texts as notes and otherwise ignore them.
//!
//! - `Corner: <name>` — a TEXT in a piece's block, inserted at the corner it names. The first
//!   corner label in the block is the outline's first corner.
//! - `Seam: <name> | <piece>: <from> > <to> | <piece>: <from> > <to>[ | aligned]` — a TEXT in
//!   the ENTITIES section: edge `a` then edge `b` (each from corner `from` counter-clockwise to
//!   corner `to`); `aligned` when `a.from` meets `b.from`.
//! - `Placement: side=<front|back> anchor=<corner> level=<landmark> x=<x> dz=<dz>` — a TEXT in a
//!   piece's block; `x` and `dz` in the file's units.

use crate::garment::pattern::{EdgeRef, Placement, Seam, Side};

/// The key of a corner label.
pub(crate) const CORNER: &str = "corner";
/// The key of a seam text.
pub(crate) const SEAM: &str = "seam";
/// The key of a placement text.
pub(crate) const PLACEMENT: &str = "placement";

/// Characters a name may not hold in these texts (they separate the fields).
const RESERVED: &[char] = &['|', '>', ':', '\r', '\n'];

/// An error when `name` (of a `what`) cannot be written in an annotation text.
pub(crate) fn check_name(name: &str, what: &str) -> Result<(), String> {
    if name.trim().is_empty() || name.trim() != name || name.contains(RESERVED) {
        return Err(format!(
            "{what} name '{name}' cannot be written to DXF: it must be non-empty, without \
             leading or trailing spaces, '|', '>', ':' or line breaks"
        ));
    }
    Ok(())
}

/// The text of a corner label.
pub(crate) fn corner_text(name: &str) -> String {
    format!("Corner: {name}")
}

/// The text of a seam.
pub(crate) fn seam_text(s: &Seam) -> Result<String, String> {
    check_name(&s.name, "seam")?;
    let mut t = format!("Seam: {}", s.name);
    for e in [&s.a, &s.b] {
        check_name(&e.piece, "piece")?;
        check_name(&e.from, "corner")?;
        check_name(&e.to, "corner")?;
        t += &format!(" | {}: {} > {}", e.piece, e.from, e.to);
    }
    if s.aligned {
        t += " | aligned";
    }
    Ok(t)
}

/// Reads the value of a `Seam:` text (what follows the key).
pub(crate) fn parse_seam(value: &str) -> Result<Seam, String> {
    let fields: Vec<&str> = value.split('|').map(str::trim).collect();
    let bad = || {
        format!(
            "seam text 'Seam: {value}' is not 'Seam: NAME | PIECE: FROM > TO | PIECE: FROM > TO \
             [| aligned]'"
        )
    };
    let aligned = match fields.len() {
        3 => false,
        4 if fields[3].eq_ignore_ascii_case("aligned") => true,
        _ => return Err(bad()),
    };
    let edge = |f: &str| -> Option<EdgeRef> {
        let (piece, ends) = f.rsplit_once(':')?;
        let (from, to) = ends.split_once('>')?;
        let e = EdgeRef {
            piece: piece.trim().to_string(),
            from: from.trim().to_string(),
            to: to.trim().to_string(),
        };
        (!e.piece.is_empty() && !e.from.is_empty() && !e.to.is_empty()).then_some(e)
    };
    match (fields[0], edge(fields[1]), edge(fields[2])) {
        (name, Some(a), Some(b)) if !name.is_empty() => Ok(Seam {
            name: name.to_string(),
            a,
            b,
            aligned,
        }),
        _ => Err(bad()),
    }
}

/// The text of a placement; `per_m` file units per metre.
pub(crate) fn placement_text(p: &Placement, per_m: f64) -> Result<String, String> {
    check_name(&p.anchor, "corner")?;
    check_name(&p.level, "level")?;
    if !(p.x.is_finite() && p.dz.is_finite()) || p.level.contains(' ') || p.anchor.contains(' ') {
        return Err(format!(
            "placement of corner '{}' cannot be written: x and dz must be finite, the anchor \
             and level without spaces",
            p.anchor
        ));
    }
    let side = match p.side {
        Side::Front => "front",
        Side::Back => "back",
    };
    Ok(format!(
        "Placement: side={side} anchor={} level={} x={} dz={}",
        p.anchor,
        p.level,
        p.x * per_m,
        p.dz * per_m
    ))
}

/// Reads the value of a `Placement:` text; `per_m` file units per metre.
pub(crate) fn parse_placement(value: &str, per_m: f64) -> Result<Placement, String> {
    let bad = |why: &str| format!("placement text 'Placement: {value}': {why}");
    let mut p = Placement {
        side: Side::Front,
        anchor: String::new(),
        x: 0.0,
        level: String::new(),
        dz: 0.0,
    };
    for field in value.split_whitespace() {
        let (k, v) = field
            .split_once('=')
            .ok_or_else(|| bad(&format!("'{field}' is not KEY=VALUE")))?;
        let number = || -> Result<f64, String> {
            v.parse::<f64>()
                .ok()
                .filter(|x| x.is_finite())
                .map(|x| x / per_m)
                .ok_or_else(|| bad(&format!("{k} '{v}' is not a finite number")))
        };
        match k.to_ascii_lowercase().as_str() {
            "side" if v.eq_ignore_ascii_case("front") => p.side = Side::Front,
            "side" if v.eq_ignore_ascii_case("back") => p.side = Side::Back,
            "side" => return Err(bad(&format!("side '{v}' is not front or back"))),
            "anchor" => p.anchor = v.to_string(),
            "level" => p.level = v.to_string(),
            "x" => p.x = number()?,
            "dz" => p.dz = number()?,
            _ => return Err(bad(&format!("unknown key '{k}'"))),
        }
    }
    if p.anchor.is_empty() || p.level.is_empty() {
        return Err(bad("anchor and level are required"));
    }
    Ok(p)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn seam_text_reads_back() {
        let e = |p: &str, f: &str, t: &str| EdgeRef {
            piece: p.into(),
            from: f.into(),
            to: t.into(),
        };
        let s = Seam {
            name: "side left".into(),
            a: e("front_l", "c2", "c3'"),
            b: e("back", "c3'", "c2"),
            aligned: true,
        };
        let t = seam_text(&s).unwrap();
        assert_eq!(
            t,
            "Seam: side left | front_l: c2 > c3' | back: c3' > c2 | aligned"
        );
        assert_eq!(parse_seam(t.strip_prefix("Seam:").unwrap()).unwrap(), s);
        assert!(parse_seam("x | a: b | c: d > e").is_err());
        let bad = Seam {
            name: "a|b".into(),
            ..s
        };
        assert!(seam_text(&bad).unwrap_err().contains("'a|b'"));
    }

    #[test]
    fn placement_text_reads_back_in_file_units() {
        let p = Placement {
            side: Side::Back,
            anchor: "c0".into(),
            x: 0.125,
            level: "shoulder".into(),
            dz: -0.026,
        };
        let t = placement_text(&p, 1000.0).unwrap();
        assert_eq!(
            t,
            "Placement: side=back anchor=c0 level=shoulder x=125 dz=-26"
        );
        let q = parse_placement(t.strip_prefix("Placement:").unwrap(), 1000.0).unwrap();
        assert_eq!(q.side, Side::Back);
        assert!((q.x - 0.125).abs() < 1e-15 && (q.dz + 0.026).abs() < 1e-15);
        assert!(parse_placement("side=up anchor=c0 level=hip", 1.0).is_err());
        assert!(parse_placement("anchor=c0 level=hip x=nan", 1.0).is_err());
    }
}
