//! C3D motion-capture files (c3d.org): the 3D points with their residuals, labels, rate and
//! units; analog channels are skipped. Our own reader rather than the `c3dio` crate: measured
//! on the driver swing, c3dio 0.8 panics on a header whose parameter block is 0 or whose data
//! block is 1 (slice index out of range) and returns 323 frames from a file cut in half with no
//! error; here every size from the file is checked against the file and against
//! [`crate::limits`] before it is used, and a short file is an error naming what is missing.

use super::c3d_bytes::Processor;
use super::c3d_params::Params;
use super::MarkerTrial;
use crate::body::BodyError;
use crate::geometry::export_frame::UpAxis;
use crate::geometry::Vec3;
use crate::limits;

const BLOCK: usize = 512;

/// Reads a C3D file (see [`parse_c3d`]).
pub fn read_c3d(path: &std::path::Path) -> Result<MarkerTrial, BodyError> {
    let bytes = limits::read(path).map_err(|source| BodyError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    parse_c3d(&bytes, &path.display().to_string())
}

/// The header fields the reader uses.
struct Header {
    param_block: usize,
    points: usize,
    analog_per_frame: usize,
    first: u16,
    last: u16,
    scale: f64,
    data_block: usize,
    rate: f64,
}

fn header(b: &[u8], proc: Processor) -> Header {
    let w = |i: usize| proc.u16([b[2 * i], b[2 * i + 1]]);
    let f = |i: usize| proc.f32([b[2 * i], b[2 * i + 1], b[2 * i + 2], b[2 * i + 3]]) as f64;
    Header {
        param_block: b[0] as usize,
        points: w(1) as usize,
        analog_per_frame: w(2) as usize,
        first: w(3),
        last: w(4),
        scale: f(6),
        data_block: w(8) as usize,
        rate: f(10),
    }
}

/// Reads the bytes of a C3D file named `file` (for errors) into a [`MarkerTrial`]: positions in
/// metres in the file's axes, invalid samples (negative residual) flagged.
pub fn parse_c3d(bytes: &[u8], file: &str) -> Result<MarkerTrial, BodyError> {
    let bad = |m: String| BodyError::invalid(file, m);
    if bytes.len() < BLOCK {
        return Err(bad(format!(
            "not a C3D file: {} bytes, shorter than the 512-byte header",
            bytes.len()
        )));
    }
    if bytes[1] != 0x50 {
        return Err(bad(format!(
            "not a C3D file: header byte 2 is {:#04x}, expected 0x50",
            bytes[1]
        )));
    }
    let param_block = bytes[0] as usize;
    if param_block < 2 {
        return Err(bad(format!(
            "bad header: parameter section starts at block {param_block} (expected 2 or more)"
        )));
    }
    let param_start = (param_block - 1) * BLOCK;
    if bytes.len() < param_start + 4 {
        return Err(bad(format!(
            "truncated: the parameter section (block {param_block}) is past the end ({} bytes)",
            bytes.len()
        )));
    }
    let proc = Processor::from_byte(bytes[param_start + 3]).ok_or_else(|| {
        bad(format!(
            "bad parameter section: processor type {} (expected 84 Intel, 85 DEC or 86 MIPS)",
            bytes[param_start + 3]
        ))
    })?;
    let h = header(&bytes[..BLOCK], proc);
    debug_assert_eq!(h.param_block, param_block);
    if h.data_block <= param_block {
        return Err(bad(format!(
            "bad header: data starts at block {}, not after the parameters (block {param_block})",
            h.data_block
        )));
    }
    let data_start = (h.data_block - 1) * BLOCK;
    if bytes.len() < data_start {
        return Err(bad(format!(
            "truncated: data should start at block {} (byte {data_start}) but the file has {} bytes",
            h.data_block,
            bytes.len()
        )));
    }
    let params = Params::parse(&bytes[param_start..data_start], proc).map_err(bad)?;
    read_points(&bytes[data_start..], &h, &params, proc, file)
}

/// The point section's description, from the parameters where present, else the header.
fn read_points(
    data: &[u8],
    h: &Header,
    params: &Params,
    proc: Processor,
    file: &str,
) -> Result<MarkerTrial, BodyError> {
    let bad = |m: String| BodyError::invalid(file, m);
    let lim = limits::get();
    let points = params
        .number("POINT", "USED", true)
        .map(|v| v as usize)
        .unwrap_or(h.points);
    limits::check_count(
        &format!("{file}: points"),
        points as u64,
        "max_particles",
        lim.max_particles,
    )
    .map_err(|e| bad(e.to_string()))?;
    if h.last < h.first {
        return Err(bad(format!(
            "bad header: last frame {} before first frame {}",
            h.last, h.first
        )));
    }
    let frames = (h.last - h.first) as usize + 1;
    limits::check_count(
        &format!("{file}: frames"),
        frames as u64,
        "max_frames",
        lim.max_frames,
    )
    .map_err(|e| bad(e.to_string()))?;
    let scale = params.number("POINT", "SCALE", false).unwrap_or(h.scale);
    let rate = params.number("POINT", "RATE", false).unwrap_or(h.rate);
    if !scale.is_finite() || scale == 0.0 {
        return Err(bad(format!(
            "bad POINT:SCALE {} (must be finite and non-zero)",
            limits::short(scale)
        )));
    }
    if !rate.is_finite() || rate <= 0.0 || rate > 1e6 {
        return Err(bad(format!(
            "bad POINT:RATE {} Hz (must be in (0, 1e6])",
            limits::short(rate)
        )));
    }
    let float = scale < 0.0;
    let word = if float { 4 } else { 2 };
    let per_frame = (4 * points + h.analog_per_frame) * word;
    let need = (frames as u64) * per_frame as u64;
    if (data.len() as u64) < need {
        return Err(bad(format!(
            "truncated: {frames} frames of {points} points and {} analog samples need {need} data bytes, the file holds {}",
            h.analog_per_frame,
            data.len()
        )));
    }
    let unit = units(params, file)?;
    let up = up_axis(params, file)?;
    let labels = labels(params, points);
    let n = limits::check_alloc(&format!("{file}: samples"), (frames * points) as u64, 32)
        .map_err(|e| bad(e.to_string()))?;
    let mut positions = Vec::with_capacity(n);
    let mut residuals = Vec::with_capacity(n);
    let abs_scale = scale.abs();
    for f in 0..frames {
        let frame = &data[f * per_frame..];
        for p in 0..points {
            let at = |k: usize| {
                let o = (4 * p + k) * word;
                if float {
                    proc.f32([frame[o], frame[o + 1], frame[o + 2], frame[o + 3]]) as f64
                } else {
                    proc.i16([frame[o], frame[o + 1]]) as f64 * abs_scale
                }
            };
            let r = if float {
                let v = at(3);
                if v.is_finite() {
                    v as i64
                } else {
                    -1
                }
            } else {
                let o = (4 * p + 3) * 2;
                proc.i16([frame[o], frame[o + 1]]) as i64
            };
            let q = Vec3::new(at(0), at(1), at(2)) * unit;
            if r < 0 {
                positions.push(Vec3::zeros());
                residuals.push(-1.0);
                continue;
            }
            if !(q.x.is_finite() && q.y.is_finite() && q.z.is_finite()) {
                return Err(bad(format!(
                    "frame {}: point `{}` is not a finite number ({}, {}, {}) though marked valid",
                    f + 1,
                    labels[p],
                    q.x,
                    q.y,
                    q.z
                )));
            }
            positions.push(q);
            residuals.push((r & 0xff) as f64 * abs_scale * unit);
        }
    }
    Ok(MarkerTrial::new(
        file.to_string(),
        labels,
        rate,
        frames,
        positions,
        residuals,
        up,
    ))
}

/// Metres per file unit from `POINT:UNITS` (millimetres when absent, the C3D default).
fn units(params: &Params, file: &str) -> Result<f64, BodyError> {
    let u = params
        .strings("POINT", "UNITS")
        .and_then(|v| v.into_iter().next())
        .unwrap_or_else(|| "mm".to_string());
    match u.to_ascii_lowercase().as_str() {
        "m" => Ok(1.0),
        "cm" => Ok(0.01),
        "mm" | "" => Ok(0.001),
        "in" | "inch" | "inches" => Ok(0.0254),
        other => Err(BodyError::invalid(
            file,
            format!("POINT:UNITS `{other}` is not a length unit (expected m, cm, mm or in)"),
        )),
    }
}

/// The file's up axis from `POINT:Y_SCREEN` (`+Y` or `+Z`; +Z when absent).
fn up_axis(params: &Params, file: &str) -> Result<UpAxis, BodyError> {
    let y = params
        .strings("POINT", "Y_SCREEN")
        .and_then(|v| v.into_iter().next())
        .unwrap_or_else(|| "+Z".to_string());
    match y.to_ascii_uppercase().as_str() {
        "+Y" => Ok(UpAxis::Y),
        "+Z" | "" => Ok(UpAxis::Z),
        other => Err(BodyError::invalid(
            file,
            format!("POINT:Y_SCREEN `{other}` is not supported (expected +Y or +Z)"),
        )),
    }
}

/// The labels of the points: `POINT:LABELS`, then `LABELS2`, …; missing ones are `P<i>`.
fn labels(params: &Params, points: usize) -> Vec<String> {
    let mut all = params.strings("POINT", "LABELS").unwrap_or_default();
    for k in 2..100 {
        match params.strings("POINT", &format!("LABELS{k}")) {
            Some(more) if all.len() < points => all.extend(more),
            _ => break,
        }
    }
    all.truncate(points);
    while all.len() < points {
        all.push(format!("P{}", all.len() + 1));
    }
    all
}
