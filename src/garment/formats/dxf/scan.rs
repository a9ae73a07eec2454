//! A light pass over the group codes of an ASCII DXF file, beside the `dxf` crate's parse.
//! The crate keeps no line numbers, skips entity types it does not know (HATCH, …) without a
//! word, and drops the rest of an entity whose number does not parse; this pass finds the line
//! of every entity in the BLOCKS and ENTITIES sections, its type and layer, and rejects numbers
//! that are not finite numbers, with their line.

/// One entity as written in the file.
#[derive(Debug, Clone)]
pub(crate) struct Record {
    /// The entity type (`LINE`, `HATCH`, …).
    pub kind: String,
    /// Its layer (code 8), empty when none is given.
    pub layer: String,
    /// 1-based line of its `0` group code.
    pub line: usize,
    /// The block it is in, `None` in the ENTITIES section.
    pub block: Option<String>,
    /// Whether an INSERT says attributes follow (code 66 = 1).
    attribs: bool,
}

/// The entities of a file, in file order.
#[derive(Debug, Default)]
pub(crate) struct Scan {
    pub records: Vec<Record>,
}

/// The entity types that the `dxf` crate (0.6) reads into an entity of its own.
const CRATE_KINDS: &[&str] = &[
    "3DFACE",
    "3DSOLID",
    "ACAD_PROXY_ENTITY",
    "ARC",
    "ARCALIGNEDTEXT",
    "ATTDEF",
    "ATTRIB",
    "BODY",
    "CIRCLE",
    "DIMENSION",
    "ELLIPSE",
    "HELIX",
    "IMAGE",
    "INSERT",
    "LEADER",
    "LIGHT",
    "LINE",
    "3DLINE",
    "LWPOLYLINE",
    "MLINE",
    "MTEXT",
    "OLEFRAME",
    "OLE2FRAME",
    "POINT",
    "POLYLINE",
    "RAY",
    "REGION",
    "RTEXT",
    "SECTION",
    "SEQEND",
    "SHAPE",
    "SOLID",
    "SPLINE",
    "TEXT",
    "TOLERANCE",
    "TRACE",
    "DGNUNDERLAY",
    "DWFUNDERLAY",
    "PDFUNDERLAY",
    "VERTEX",
    "WIPEOUT",
    "XLINE",
];

fn is_float_code(c: i32) -> bool {
    matches!(c, 10..=59 | 110..=149 | 210..=239 | 460..=469 | 1010..=1059)
}

fn is_int_code(c: i32) -> bool {
    matches!(c, 60..=79 | 90..=99 | 170..=179 | 270..=289 | 370..=389 | 400..=409 | 1060..=1071)
}

fn shorten(s: &str) -> String {
    let mut t: String = s.chars().take(40).collect();
    if t.len() < s.len() {
        t.push('…');
    }
    t
}

/// A fault found by the scan: 1-based line, what is wrong, and the block it is in.
pub(crate) type Fault = (usize, String, Option<String>);

/// Scans `data`; `Ok(None)` for a binary file.
pub(crate) fn scan(data: &[u8]) -> Result<Option<Scan>, Fault> {
    if data.starts_with(b"AutoCAD Binary DXF") || data.starts_with(b"AutoCAD DXB") {
        return Ok(None);
    }
    let text = String::from_utf8_lossy(data);
    let lines: Vec<&str> = text.split('\n').map(str::trim).collect();
    let mut out = Scan::default();
    let mut section: Option<String> = None;
    let mut want_section_name = false;
    let mut block: Option<String> = None;
    let mut in_block_header = false;
    let mut current: Option<usize> = None;
    let mut i = 0;
    while i + 1 < lines.len() {
        let (code_line, value) = (i + 1, lines[i + 1]);
        let code: i32 = match lines[i].parse() {
            Ok(c) => c,
            Err(_) if lines[i].is_empty() && lines[i + 1..].iter().all(|l| l.is_empty()) => break,
            Err(_) => {
                let found = shorten(lines[i]);
                let msg = format!("expected a group code, found '{found}'");
                let here = block.clone().filter(|b| !b.is_empty());
                return Err((code_line, msg, here));
            }
        };
        i += 2;
        let in_blocks = section.as_deref() == Some("BLOCKS");
        let here = || block.clone().filter(|b| in_blocks && !b.is_empty());
        if is_float_code(code) {
            match value.parse::<f64>() {
                Ok(v) if v.is_finite() => {}
                _ => {
                    let found = shorten(value);
                    let msg = format!("group code {code}: '{found}' is not a finite number");
                    return Err((code_line + 1, msg, here()));
                }
            }
        } else if is_int_code(code) && value.parse::<i64>().is_err() {
            let msg = format!("group code {code}: '{}' is not an integer", shorten(value));
            return Err((code_line + 1, msg, here()));
        }
        match code {
            0 => {
                current = None;
                match value {
                    "SECTION" => want_section_name = true,
                    "ENDSEC" => section = None,
                    "EOF" => break,
                    "BLOCK" if section.as_deref() == Some("BLOCKS") => {
                        block = Some(String::new());
                        in_block_header = true;
                    }
                    "ENDBLK" => {
                        block = None;
                        in_block_header = false;
                    }
                    kind => {
                        in_block_header = false;
                        let in_entities = section.as_deref() == Some("ENTITIES");
                        let in_block = section.as_deref() == Some("BLOCKS") && block.is_some();
                        if in_entities || in_block {
                            current = Some(out.records.len());
                            out.records.push(Record {
                                kind: kind.to_string(),
                                layer: String::new(),
                                line: code_line,
                                block: if in_entities { None } else { block.clone() },
                                attribs: false,
                            });
                        }
                    }
                }
            }
            2 if want_section_name => {
                section = Some(value.to_string());
                want_section_name = false;
            }
            2 if in_block_header => block = Some(value.to_string()),
            8 => {
                if let Some(r) = current.and_then(|k| out.records.get_mut(k)) {
                    if r.layer.is_empty() {
                        r.layer = value.to_string();
                    }
                }
            }
            66 => {
                if let Some(r) = current.and_then(|k| out.records.get_mut(k)) {
                    r.attribs = r.kind == "INSERT" && value == "1";
                }
            }
            _ => {}
        }
    }
    Ok(Some(out))
}

impl Scan {
    /// The lines of the entities of `block` (`None`: the ENTITIES section) in the order the
    /// `dxf` crate lists them, when that can be told for sure: `count` must match.
    pub(crate) fn lines_of(&self, block: Option<&str>, count: usize) -> Option<Vec<usize>> {
        let mut lines = Vec::new();
        // What the previous entity swallows: vertices, attributes, and their SEQEND.
        let mut absorbing: Option<&str> = None;
        let mut after_attribute = false;
        for r in self.records.iter().filter(|r| r.block.as_deref() == block) {
            let kind = r.kind.as_str();
            let absorbed = match (absorbing, kind) {
                (Some("POLYLINE"), "VERTEX") | (Some("INSERT"), "ATTRIB") => true,
                (Some(_), "SEQEND") => {
                    absorbing = None;
                    true
                }
                _ => {
                    absorbing = None;
                    false
                }
            };
            let mtext_of_attribute = after_attribute && kind == "MTEXT";
            after_attribute = matches!(kind, "ATTRIB" | "ATTDEF");
            if absorbed || mtext_of_attribute || !CRATE_KINDS.contains(&kind) {
                continue;
            }
            if kind == "POLYLINE" || (kind == "INSERT" && r.attribs) {
                absorbing = Some(if kind == "POLYLINE" {
                    "POLYLINE"
                } else {
                    "INSERT"
                });
            }
            lines.push(r.line);
        }
        (lines.len() == count).then_some(lines)
    }
}
