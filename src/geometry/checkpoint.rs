//! Checkpoint files: the versioned container every checkpoint is written in (a simulation's
//! state, a script run's calls, a tracker's progress) and the little-endian codec its payload
//! is encoded with. A file is
//!
//! ```text
//! "EMILCKPT"  magic, 8 bytes
//! u32         format version (FORMAT_VERSION)
//! str         kind ("simulation", "run", ...)
//! u64         fingerprint of the setup the state belongs to
//! u64, bytes  payload length and payload
//! u64         FNV-1a hash of the payload (a truncated or damaged file is refused)
//! ```
//!
//! (`str` is a u64 length and UTF-8 bytes.) Files are written atomically (a temporary file
//! renamed over the old one), so a run killed while writing leaves the previous checkpoint
//! whole. Reading never panics on a bad file: every read is bounds-checked, every length is
//! checked against the stated limits before anything is allocated.

use std::path::Path;

use super::files::write_atomic;
use super::{GeometryError, Vec3};

/// The first bytes of every checkpoint file.
pub const MAGIC: &[u8; 8] = b"EMILCKPT";
/// The format version this build writes.
pub const FORMAT_VERSION: u32 = 1;
/// The oldest format version this build reads.
pub const OLDEST_VERSION: u32 = 1;

/// A 64-bit FNV-1a hash, fed piece by piece: the fingerprint of a setup.
#[derive(Debug, Clone, Copy)]
pub struct Fingerprint(u64);

impl Default for Fingerprint {
    fn default() -> Self {
        Fingerprint(0xcbf2_9ce4_8422_2325)
    }
}

impl Fingerprint {
    /// Feeds bytes.
    pub fn bytes(&mut self, b: &[u8]) -> &mut Self {
        for &x in b {
            self.0 ^= u64::from(x);
            self.0 = self.0.wrapping_mul(0x0100_0000_01b3);
        }
        self
    }
    /// Feeds an integer.
    pub fn u64(&mut self, v: u64) -> &mut Self {
        self.bytes(&v.to_le_bytes())
    }
    /// Feeds a float, bit for bit.
    pub fn f64(&mut self, v: f64) -> &mut Self {
        self.u64(v.to_bits())
    }
    /// Feeds a string (length first, so that "ab","c" differs from "a","bc").
    pub fn str(&mut self, s: &str) -> &mut Self {
        self.u64(s.len() as u64).bytes(s.as_bytes())
    }
    /// The hash so far.
    pub fn value(&self) -> u64 {
        self.0
    }
}

/// FNV-1a of `b`.
fn hash(b: &[u8]) -> u64 {
    Fingerprint::default().bytes(b).value()
}

/// Encodes a checkpoint's payload, little-endian.
#[derive(Debug, Default, Clone)]
pub struct Encoder {
    /// The bytes so far.
    pub buf: Vec<u8>,
}

impl Encoder {
    /// An empty encoder.
    pub fn new() -> Self {
        Self::default()
    }
    /// A byte.
    pub fn u8(&mut self, v: u8) {
        self.buf.push(v);
    }
    /// A bool as a byte.
    pub fn bool(&mut self, v: bool) {
        self.u8(u8::from(v));
    }
    /// A 32-bit integer.
    pub fn u32(&mut self, v: u32) {
        self.buf.extend_from_slice(&v.to_le_bytes());
    }
    /// A 64-bit integer.
    pub fn u64(&mut self, v: u64) {
        self.buf.extend_from_slice(&v.to_le_bytes());
    }
    /// A count or index.
    pub fn usize(&mut self, v: usize) {
        self.u64(v as u64);
    }
    /// A float, bit for bit (NaN payloads included).
    pub fn f64(&mut self, v: f64) {
        self.u64(v.to_bits());
    }
    /// A single-precision float, bit for bit.
    pub fn f32(&mut self, v: f32) {
        self.u32(v.to_bits());
    }
    /// An optional float.
    pub fn opt_f64(&mut self, v: Option<f64>) {
        self.bool(v.is_some());
        if let Some(v) = v {
            self.f64(v);
        }
    }
    /// A string.
    pub fn str(&mut self, s: &str) {
        self.bytes(s.as_bytes());
    }
    /// A byte string, length first.
    pub fn bytes(&mut self, b: &[u8]) {
        self.usize(b.len());
        self.buf.extend_from_slice(b);
    }
    /// A vector.
    pub fn vec3(&mut self, v: &Vec3) {
        for c in v.iter() {
            self.f64(*c);
        }
    }
    /// Floats, length first.
    pub fn f64s(&mut self, v: &[f64]) {
        self.usize(v.len());
        v.iter().for_each(|&x| self.f64(x));
    }
    /// Vectors, length first.
    pub fn vec3s(&mut self, v: &[Vec3]) {
        self.usize(v.len());
        v.iter().for_each(|x| self.vec3(x));
    }
    /// Bools, length first.
    pub fn bools(&mut self, v: &[bool]) {
        self.usize(v.len());
        v.iter().for_each(|&x| self.bool(x));
    }
    /// Counts or indices, length first.
    pub fn usizes(&mut self, v: &[usize]) {
        self.usize(v.len());
        v.iter().for_each(|&x| self.usize(x));
    }
}

/// Decodes a checkpoint's payload; every read is checked, an error names what was being read.
#[derive(Debug)]
pub struct Decoder<'a> {
    buf: &'a [u8],
    pos: usize,
    /// The file, for messages.
    pub file: String,
}

impl<'a> Decoder<'a> {
    /// A decoder of `buf`, read from `file` (for messages).
    pub fn new(buf: &'a [u8], file: &str) -> Self {
        Decoder {
            buf,
            pos: 0,
            file: file.to_string(),
        }
    }

    /// An error about this file at the current position.
    pub fn error(&self, what: impl std::fmt::Display) -> GeometryError {
        GeometryError::Invalid(format!(
            "checkpoint {}: {what} (at byte {} of the payload)",
            self.file, self.pos
        ))
    }

    fn take(&mut self, n: usize, what: &str) -> Result<&'a [u8], GeometryError> {
        match self.pos.checked_add(n).filter(|&e| e <= self.buf.len()) {
            Some(end) => {
                let s = &self.buf[self.pos..end];
                self.pos = end;
                Ok(s)
            }
            None => Err(self.error(format!("truncated while reading {what}"))),
        }
    }

    /// Whether every byte was read.
    pub fn finished(&self) -> bool {
        self.pos == self.buf.len()
    }
    /// A byte.
    pub fn u8(&mut self, what: &str) -> Result<u8, GeometryError> {
        Ok(self.take(1, what)?[0])
    }
    /// A bool.
    pub fn bool(&mut self, what: &str) -> Result<bool, GeometryError> {
        match self.u8(what)? {
            0 => Ok(false),
            1 => Ok(true),
            b => Err(self.error(format!("{what}: {b} is not a bool"))),
        }
    }
    /// A 32-bit integer.
    pub fn u32(&mut self, what: &str) -> Result<u32, GeometryError> {
        let b = self.take(4, what)?;
        Ok(u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    }
    /// A 64-bit integer.
    pub fn u64(&mut self, what: &str) -> Result<u64, GeometryError> {
        let b = self.take(8, what)?;
        let mut a = [0u8; 8];
        a.copy_from_slice(b);
        Ok(u64::from_le_bytes(a))
    }
    /// A count or index (checked to fit the platform).
    pub fn usize(&mut self, what: &str) -> Result<usize, GeometryError> {
        let v = self.u64(what)?;
        usize::try_from(v).map_err(|_| self.error(format!("{what}: {v} is too large")))
    }
    /// A float.
    pub fn f64(&mut self, what: &str) -> Result<f64, GeometryError> {
        Ok(f64::from_bits(self.u64(what)?))
    }
    /// A single-precision float.
    pub fn f32(&mut self, what: &str) -> Result<f32, GeometryError> {
        Ok(f32::from_bits(self.u32(what)?))
    }
    /// An optional float.
    pub fn opt_f64(&mut self, what: &str) -> Result<Option<f64>, GeometryError> {
        Ok(if self.bool(what)? {
            Some(self.f64(what)?)
        } else {
            None
        })
    }
    /// A length of items of `elem` bytes each, checked against what is left to read (so no
    /// length read from a damaged file allocates more than the file holds).
    pub fn len(&mut self, elem: usize, what: &str) -> Result<usize, GeometryError> {
        let n = self.usize(what)?;
        let left = self.buf.len() - self.pos;
        if n.checked_mul(elem.max(1)).is_none_or(|b| b > left) {
            return Err(self.error(format!(
                "{what}: {n} items do not fit the {left} bytes left"
            )));
        }
        Ok(n)
    }
    /// A byte string.
    pub fn bytes(&mut self, what: &str) -> Result<&'a [u8], GeometryError> {
        let n = self.len(1, what)?;
        self.take(n, what)
    }
    /// A string.
    pub fn str(&mut self, what: &str) -> Result<String, GeometryError> {
        let b = self.bytes(what)?;
        String::from_utf8(b.to_vec()).map_err(|_| self.error(format!("{what} is not UTF-8")))
    }
    /// A vector.
    pub fn vec3(&mut self, what: &str) -> Result<Vec3, GeometryError> {
        Ok(Vec3::new(self.f64(what)?, self.f64(what)?, self.f64(what)?))
    }
    /// Floats.
    pub fn f64s(&mut self, what: &str) -> Result<Vec<f64>, GeometryError> {
        let n = self.len(8, what)?;
        (0..n).map(|_| self.f64(what)).collect()
    }
    /// Vectors.
    pub fn vec3s(&mut self, what: &str) -> Result<Vec<Vec3>, GeometryError> {
        let n = self.len(24, what)?;
        (0..n).map(|_| self.vec3(what)).collect()
    }
    /// Bools.
    pub fn bools(&mut self, what: &str) -> Result<Vec<bool>, GeometryError> {
        let n = self.len(1, what)?;
        (0..n).map(|_| self.bool(what)).collect()
    }
    /// Counts or indices.
    pub fn usizes(&mut self, what: &str) -> Result<Vec<usize>, GeometryError> {
        let n = self.len(8, what)?;
        (0..n).map(|_| self.usize(what)).collect()
    }
    /// Vectors that must number `n` (the state of `n` particles), read into `out`.
    pub fn vec3s_into(&mut self, out: &mut [Vec3], what: &str) -> Result<(), GeometryError> {
        let v = self.vec3s(what)?;
        if v.len() != out.len() {
            return Err(self.error(format!(
                "{what}: {} values, this setup has {}",
                v.len(),
                out.len()
            )));
        }
        out.copy_from_slice(&v);
        Ok(())
    }
}

/// A checkpoint as read from a file: its kind, fingerprint and payload.
#[derive(Debug, Clone, PartialEq)]
pub struct CheckpointFile {
    /// The format version it was written in.
    pub version: u32,
    /// What it holds ("simulation", "run", ...).
    pub kind: String,
    /// The fingerprint of the setup it belongs to.
    pub fingerprint: u64,
    /// The encoded state.
    pub payload: Vec<u8>,
}

/// The bytes of a checkpoint file of `kind` for a setup of fingerprint `fingerprint`.
pub fn encode_file(kind: &str, fingerprint: u64, payload: &[u8]) -> Vec<u8> {
    let mut e = Encoder::new();
    e.buf.extend_from_slice(MAGIC);
    e.u32(FORMAT_VERSION);
    e.str(kind);
    e.u64(fingerprint);
    e.bytes(payload);
    e.u64(hash(payload));
    e.buf
}

/// Writes a checkpoint file atomically (see the module's description).
pub fn write_file(
    path: &Path,
    kind: &str,
    fingerprint: u64,
    payload: &[u8],
) -> Result<(), GeometryError> {
    let bytes = encode_file(kind, fingerprint, payload);
    write_atomic(path, |w| w.write_all(&bytes))
}

/// Parses the bytes of a checkpoint file (`file` names it in errors): refuses another file, a
/// format version this build does not read, a kind other than `kind`, a damaged payload.
pub fn decode_file(bytes: &[u8], file: &str, kind: &str) -> Result<CheckpointFile, GeometryError> {
    if bytes.len() < MAGIC.len() || &bytes[..MAGIC.len()] != MAGIC {
        return Err(GeometryError::Invalid(format!(
            "{file}: not an emilion checkpoint (no EMILCKPT header)"
        )));
    }
    let mut d = Decoder::new(&bytes[MAGIC.len()..], file);
    let version = d.u32("format version")?;
    if !(OLDEST_VERSION..=FORMAT_VERSION).contains(&version) {
        return Err(GeometryError::Invalid(format!(
            "{file}: checkpoint format {version}, this build reads {}",
            if OLDEST_VERSION == FORMAT_VERSION {
                format!("{FORMAT_VERSION} only")
            } else {
                format!("{OLDEST_VERSION}–{FORMAT_VERSION}")
            }
        )));
    }
    let found = d.str("kind")?;
    if found != kind {
        return Err(GeometryError::Invalid(format!(
            "{file}: a `{found}` checkpoint, not a `{kind}` one"
        )));
    }
    let fingerprint = d.u64("fingerprint")?;
    let payload = d.bytes("payload")?.to_vec();
    let sum = d.u64("payload hash")?;
    if sum != hash(&payload) || !d.finished() {
        return Err(GeometryError::Invalid(format!(
            "{file}: the checkpoint is damaged (its payload does not match its hash)"
        )));
    }
    Ok(CheckpointFile {
        version,
        kind: found,
        fingerprint,
        payload,
    })
}

/// Reads a checkpoint file of `kind` (bounded by `max_file_bytes`), see [`decode_file`].
pub fn read_file(path: &Path, kind: &str) -> Result<CheckpointFile, GeometryError> {
    let bytes = crate::limits::read(path).map_err(|source| GeometryError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    decode_file(&bytes, &path.display().to_string(), kind)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_checkpoint_round_trips_and_damage_is_refused() {
        let mut e = Encoder::new();
        e.f64(f64::NAN);
        e.vec3s(&[Vec3::new(1.0, -0.0, 3.5)]);
        e.str("é");
        let bytes = encode_file("test", 42, &e.buf);
        let f = decode_file(&bytes, "t.ckpt", "test").unwrap();
        assert_eq!((f.version, f.fingerprint), (FORMAT_VERSION, 42));
        let mut d = Decoder::new(&f.payload, "t.ckpt");
        assert!(d.f64("x").unwrap().is_nan());
        let v = d.vec3s("v").unwrap();
        assert_eq!(v[0].y.to_bits(), (-0.0f64).to_bits());
        assert_eq!(d.str("s").unwrap(), "é");
        assert!(d.finished());
        // a truncated or flipped file, another kind, a newer version: clear errors
        let cut = decode_file(&bytes[..bytes.len() - 3], "t.ckpt", "test").unwrap_err();
        assert!(cut.to_string().contains("t.ckpt"), "{cut}");
        let mut flipped = bytes.clone();
        let k = bytes.len() - 12;
        flipped[k] ^= 1;
        let e = decode_file(&flipped, "t.ckpt", "test").unwrap_err();
        assert!(e.to_string().contains("damaged"), "{e}");
        let e = decode_file(&bytes, "t.ckpt", "run").unwrap_err();
        assert!(e.to_string().contains("not a `run`"), "{e}");
        let mut newer = bytes.clone();
        newer[8..12].copy_from_slice(&3u32.to_le_bytes());
        let e = decode_file(&newer, "t.ckpt", "test").unwrap_err();
        assert!(
            e.to_string()
                .contains("checkpoint format 3, this build reads 1"),
            "{e}"
        );
        let e = decode_file(b"PNG....", "t.ckpt", "test").unwrap_err();
        assert!(e.to_string().contains("not an emilion checkpoint"));
    }

    #[test]
    fn a_huge_length_in_a_damaged_payload_is_refused_before_allocating() {
        let mut e = Encoder::new();
        e.u64(u64::MAX / 2);
        let mut d = Decoder::new(&e.buf, "t.ckpt");
        let err = d.vec3s("positions").unwrap_err();
        assert!(err.to_string().contains("positions"), "{err}");
    }
}
