//! PC2 point caches (the format of Blender's Mesh Cache modifier, 3ds Max's Point Cache and
//! Maya's importers): a 32-byte header — `POINTCACHE2\0`, version 1, point count, start frame,
//! sample rate (frames between samples), sample count — then every sample's points as
//! little-endian `f32` triples. A cache goes with a rest mesh of the same vertex order (an OBJ
//! written beside it, in the same axes and units).

use std::io::Write;
use std::path::Path;

use super::animation::AnimatedMesh;
use super::export_frame::ExportFrame;
use super::files::write_atomic;
use super::{GeometryError, Vec3};

const SIGNATURE: &[u8; 12] = b"POINTCACHE2\0";
const HEADER: usize = 32;

/// A point cache read back.
#[derive(Debug, Clone, PartialEq)]
pub struct PointCache {
    /// Frame of the first sample.
    pub start_frame: f32,
    /// Frames between samples.
    pub sample_rate: f32,
    /// Points per sample.
    pub points: usize,
    /// The samples' points, as stored.
    pub samples: Vec<Vec<[f32; 3]>>,
}

/// Writes `mesh`'s frames as a PC2 cache in `frame`'s axes and units, first sample at frame
/// `start_frame`, one sample per frame. Written to a temporary file then renamed. Fails,
/// naming the file, on a mesh without frames or more than `i32::MAX` points or samples.
pub fn write_pc2(
    path: &Path,
    mesh: &AnimatedMesh,
    frame: ExportFrame,
    start_frame: f32,
) -> Result<(), GeometryError> {
    let invalid = |m: String| GeometryError::Invalid(format!("{}: {m}", path.display()));
    if mesh.frames.is_empty() {
        return Err(invalid(format!("mesh `{}` has no frames", mesh.name)));
    }
    let points = i32::try_from(mesh.vertices).map_err(|_| invalid("too many points".into()))?;
    let samples =
        i32::try_from(mesh.frames.len()).map_err(|_| invalid("too many samples".into()))?;
    let mut bytes = Vec::with_capacity(HEADER + 12 * mesh.vertices * mesh.frames.len());
    bytes.extend_from_slice(SIGNATURE);
    bytes.extend_from_slice(&1i32.to_le_bytes());
    bytes.extend_from_slice(&points.to_le_bytes());
    bytes.extend_from_slice(&start_frame.to_le_bytes());
    bytes.extend_from_slice(&1f32.to_le_bytes());
    bytes.extend_from_slice(&samples.to_le_bytes());
    for f in &mesh.frames {
        for p in f {
            let v = Vec3::new(p[0].into(), p[1].into(), p[2].into());
            let q = frame.point(&v);
            for c in [q.x, q.y, q.z] {
                bytes.extend_from_slice(&(c as f32).to_le_bytes());
            }
        }
    }
    write_atomic(path, |w: &mut dyn Write| w.write_all(&bytes))
}

/// Reads a PC2 cache. Fails, naming the file, on a wrong signature or version, negative
/// counts, or a length that does not match the header (no allocation beyond the file's size).
pub fn read_pc2(path: &Path) -> Result<PointCache, GeometryError> {
    let invalid = |m: String| GeometryError::Invalid(format!("{}: {m}", path.display()));
    let bytes = crate::limits::read(path).map_err(|e| invalid(e.to_string()))?;
    if bytes.len() < HEADER || &bytes[..12] != SIGNATURE {
        return Err(invalid(
            "not a PC2 point cache (no POINTCACHE2 header)".into(),
        ));
    }
    let int = |at: usize| i32::from_le_bytes(bytes[at..at + 4].try_into().unwrap());
    let float = |at: usize| f32::from_le_bytes(bytes[at..at + 4].try_into().unwrap());
    if int(12) != 1 {
        return Err(invalid(format!("PC2 version {} (1 expected)", int(12))));
    }
    let (points, samples) = (int(16), int(28));
    if points < 0 || samples < 0 {
        return Err(invalid(format!(
            "negative counts ({points} points, {samples} samples)"
        )));
    }
    let (points, samples) = (points as usize, samples as usize);
    let expected = (points as u128) * (samples as u128) * 12 + HEADER as u128;
    if expected != bytes.len() as u128 {
        return Err(invalid(format!(
            "{points} points × {samples} samples need {expected} bytes, the file has {}",
            bytes.len()
        )));
    }
    let mut at = HEADER;
    let mut out = Vec::with_capacity(samples);
    for _ in 0..samples {
        let mut s = Vec::with_capacity(points);
        for _ in 0..points {
            s.push([float(at), float(at + 4), float(at + 8)]);
            at += 12;
        }
        out.push(s);
    }
    Ok(PointCache {
        start_frame: float(20),
        sample_rate: float(24),
        points,
        samples: out,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::export_frame::{Units, UpAxis};

    #[test]
    fn header_by_hand_and_round_trip_in_millimetres() {
        let mesh = AnimatedMesh {
            name: "cloth".into(),
            triangles: vec![[0, 1, 2]],
            uvs: None,
            colour: [0, 0, 0],
            vertices: 3,
            frames: vec![
                vec![[0.0, 0.0, 1.0], [1.0, 0.0, 1.0], [0.0, 1.0, 1.0]],
                vec![[0.0, 0.0, 0.5], [1.0, 0.0, 0.5], [0.0, 1.0, 0.5]],
            ],
        };
        let path = std::env::temp_dir().join(format!("emilion-pc2-{}.pc2", std::process::id()));
        let mm = ExportFrame {
            up: UpAxis::Y,
            units: Units::Millimetres,
        };
        write_pc2(&path, &mesh, mm, 1.0).unwrap();
        let b = std::fs::read(&path).unwrap();
        assert_eq!(b.len(), 32 + 2 * 3 * 12);
        assert_eq!(&b[..11], b"POINTCACHE2");
        assert_eq!(b[16..20], 3i32.to_le_bytes());
        assert_eq!(b[28..32], 2i32.to_le_bytes());
        // second sample, third point: engine (0, 1, 0.5) m is (0, 500, −1000) mm, +Y up
        let at = 32 + 12 * 5;
        let f = |k: usize| f32::from_le_bytes(b[at + 4 * k..at + 4 * k + 4].try_into().unwrap());
        assert_eq!([f(0), f(1), f(2)], [0.0, 500.0, -1000.0]);
        let back = read_pc2(&path).unwrap();
        assert_eq!(
            (back.points, back.samples.len(), back.start_frame),
            (3, 2, 1.0)
        );
        assert_eq!(back.samples[1][2], [0.0, 500.0, -1000.0]);
        // a truncated file is refused, naming it
        std::fs::write(&path, &b[..b.len() - 4]).unwrap();
        let e = read_pc2(&path).unwrap_err().to_string();
        assert!(e.contains("emilion-pc2") && e.contains("bytes"), "{e}");
        std::fs::remove_file(&path).unwrap();
    }
}
