//! The parameter section of a C3D file: groups and parameters read into a table, every offset
//! and size checked against the section before it is used.
//!
//! A record is `name length (i8, negative = locked)`, `group id (i8, negative = a group)`, the
//! name, a signed 16-bit offset to the next record (counted from the offset's own position),
//! then for a parameter its type (−1 char, 1 byte, 2 int16, 4 float), its dimensions and data.

use std::collections::HashMap;

use super::c3d_bytes::Processor;

/// One parameter's type, dimensions and raw bytes.
#[derive(Clone, Debug)]
pub(crate) struct Param {
    /// −1 char, 1 byte, 2 int16, 4 float.
    pub kind: i8,
    /// Dimensions (empty for a scalar).
    pub dims: Vec<usize>,
    /// The data, `|kind| · Π dims` bytes.
    pub data: Vec<u8>,
}

/// The parameters of a file, by `(GROUP, NAME)` in upper case.
#[derive(Debug, Default)]
pub(crate) struct Params {
    table: HashMap<(String, String), Param>,
    proc: Processor,
}

/// Most records in a parameter section (a 127-block section holds at most ~13,000).
const MAX_RECORDS: usize = 100_000;

impl Params {
    /// Reads the records of `section` (the parameter blocks, its 4-byte header included).
    pub(crate) fn parse(section: &[u8], proc: Processor) -> Result<Params, String> {
        let mut groups: HashMap<u8, String> = HashMap::new();
        let mut pending: Vec<(u8, String, Param)> = Vec::new();
        let mut pos = 4usize;
        for _ in 0..MAX_RECORDS {
            if pos + 2 > section.len() {
                break;
            }
            let name_len = (section[pos] as i8).unsigned_abs() as usize;
            let id = section[pos + 1] as i8;
            if name_len == 0 || id == 0 {
                break;
            }
            let name_end = pos + 2 + name_len;
            let offset_at = name_end;
            if offset_at + 2 > section.len() {
                return Err(format!(
                    "parameter record at byte {pos} runs past the parameter section"
                ));
            }
            let name = ascii(&section[pos + 2..name_end]).to_ascii_uppercase();
            let next = proc.i16([section[offset_at], section[offset_at + 1]]);
            let body = offset_at + 2;
            if id > 0 {
                let param = parse_param(section, body, &name)?;
                pending.push((id as u8, name.clone(), param));
            } else {
                groups.insert(id.unsigned_abs(), name.clone());
            }
            if next == 0 {
                break;
            }
            if next < 0 {
                return Err(format!(
                    "parameter record `{name}` at byte {pos}: offset to the next record is negative ({next})"
                ));
            }
            pos = offset_at + next as usize;
        }
        let mut table = HashMap::new();
        for (id, name, param) in pending {
            // parameters of an undeclared group are kept under a numbered name
            let group = groups.get(&id).cloned().unwrap_or_else(|| format!("#{id}"));
            table.insert((group, name), param);
        }
        Ok(Params { table, proc })
    }

    /// The parameter `group:name`, if present.
    pub(crate) fn get(&self, group: &str, name: &str) -> Option<&Param> {
        self.table.get(&(group.to_string(), name.to_string()))
    }

    /// The first value of a numeric parameter as f64 (int16 read unsigned when `unsigned`).
    pub(crate) fn number(&self, group: &str, name: &str, unsigned: bool) -> Option<f64> {
        let p = self.get(group, name)?;
        let d = &p.data;
        match p.kind {
            1 if !d.is_empty() => Some(d[0] as f64),
            2 if d.len() >= 2 => {
                let w = [d[0], d[1]];
                Some(if unsigned {
                    self.proc.u16(w) as f64
                } else {
                    self.proc.i16(w) as f64
                })
            }
            4 if d.len() >= 4 => Some(self.proc.f32([d[0], d[1], d[2], d[3]]) as f64),
            _ => None,
        }
    }

    /// A character parameter as its strings: dimensions `[length, count…]`, each trimmed.
    pub(crate) fn strings(&self, group: &str, name: &str) -> Option<Vec<String>> {
        let p = self.get(group, name)?;
        if p.kind != -1 {
            return None;
        }
        let len = p.dims.first().copied().unwrap_or(p.data.len()).max(1);
        Some(
            p.data
                .chunks(len)
                .map(|c| ascii(c).trim().to_string())
                .collect(),
        )
    }
}

/// One parameter's body at `body`: type, dimensions, data.
fn parse_param(section: &[u8], body: usize, name: &str) -> Result<Param, String> {
    let short = || format!("parameter `{name}` at byte {body} runs past the parameter section");
    let kind = *section.get(body).ok_or_else(short)? as i8;
    if !matches!(kind, -1 | 1 | 2 | 4) {
        return Err(format!(
            "parameter `{name}` at byte {body}: unknown data type {kind} (expected -1, 1, 2 or 4)"
        ));
    }
    let ndims = *section.get(body + 1).ok_or_else(short)? as usize;
    let dims_end = body + 2 + ndims;
    let dims: Vec<usize> = section
        .get(body + 2..dims_end)
        .ok_or_else(short)?
        .iter()
        .map(|&d| d as usize)
        .collect();
    // at most 7 dimensions of at most 255: the product fits in u64
    let count: u64 = dims.iter().map(|&d| d as u64).product();
    let bytes = count
        .checked_mul(kind.unsigned_abs() as u64)
        .filter(|&b| b <= section.len() as u64)
        .ok_or_else(short)? as usize;
    let data = section
        .get(dims_end..dims_end + bytes)
        .ok_or_else(short)?
        .to_vec();
    Ok(Param { kind, dims, data })
}

/// Bytes as text, non-ASCII bytes replaced.
fn ascii(b: &[u8]) -> String {
    b.iter()
        .map(|&c| {
            if c.is_ascii() && c != 0 {
                c as char
            } else {
                ' '
            }
        })
        .collect()
}
