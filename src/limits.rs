//! The stated limits on everything derived from input (sizes, counts, durations, allocations)
//! and the run's cancellation (a `--max-seconds` deadline): the bottom layer every module may
//! use. A limit is checked before the size is used, and a breach is an error that names the
//! parameter, the value and the limit, and how to raise it (`emilion run --limit NAME=VALUE`).
//!
//! The limits are process-wide: set once from the command line ([`set`]) before any work, read
//! everywhere with [`get`]. Tests keep the defaults.

use std::fmt;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::RwLock;
use std::time::{Duration, Instant};

/// The adjustable limits. Each field's doc states the default; `emilion run --limit NAME=VALUE`
/// sets one by its field name.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Limits {
    /// Most particles (vertices) of one cloth or mesh built from input: 4,000,000.
    pub max_particles: u64,
    /// Most simulation steps one call may run: 100,000,000.
    pub max_steps: u64,
    /// Most frames one call may run, render or record: 1,000,000.
    pub max_frames: u64,
    /// Most pixels of an image decoded or rendered: 100,000,000 (10000²).
    pub max_pixels: u64,
    /// Largest input file read whole (scripts, meshes, patterns, rule files), bytes: 1 GiB.
    pub max_file_bytes: u64,
    /// Largest single buffer derived from input, bytes: 4 GiB.
    pub max_alloc_bytes: u64,
    /// Deepest nesting of a structured input file (SVG groups, JSON, BVH joints): 256.
    pub max_nesting: u64,
    /// Most elements a rule or grammar may derive (facade tiles, repeats): 1,000,000.
    pub max_elements: u64,
}

impl Default for Limits {
    fn default() -> Self {
        Limits {
            max_particles: 4_000_000,
            max_steps: 100_000_000,
            max_frames: 1_000_000,
            max_pixels: 100_000_000,
            max_file_bytes: 1 << 30,
            max_alloc_bytes: 4 << 30,
            max_nesting: 256,
            max_elements: 1_000_000,
        }
    }
}

impl Limits {
    /// The names accepted by [`Limits::set_named`], with their current values.
    pub fn named(&self) -> [(&'static str, u64); 8] {
        [
            ("max_particles", self.max_particles),
            ("max_steps", self.max_steps),
            ("max_frames", self.max_frames),
            ("max_pixels", self.max_pixels),
            ("max_file_bytes", self.max_file_bytes),
            ("max_alloc_bytes", self.max_alloc_bytes),
            ("max_nesting", self.max_nesting),
            ("max_elements", self.max_elements),
        ]
    }

    /// Sets the limit `name` (a field name) to `value`.
    pub fn set_named(&mut self, name: &str, value: u64) -> Result<(), String> {
        let slot = match name {
            "max_particles" => &mut self.max_particles,
            "max_steps" => &mut self.max_steps,
            "max_frames" => &mut self.max_frames,
            "max_pixels" => &mut self.max_pixels,
            "max_file_bytes" => &mut self.max_file_bytes,
            "max_alloc_bytes" => &mut self.max_alloc_bytes,
            "max_nesting" => &mut self.max_nesting,
            "max_elements" => &mut self.max_elements,
            _ => {
                let names: Vec<_> = self.named().iter().map(|(n, _)| *n).collect();
                return Err(format!(
                    "unknown limit `{name}` (known: {})",
                    names.join(", ")
                ));
            }
        };
        *slot = value;
        Ok(())
    }
}

static LIMITS: RwLock<Option<Limits>> = RwLock::new(None);

/// The limits in force (the defaults unless [`set`] was called).
pub fn get() -> Limits {
    LIMITS
        .read()
        .map(|l| l.unwrap_or_default())
        .unwrap_or_default()
}

/// Sets the limits for the rest of the process (the command line does this once, first).
pub fn set(limits: Limits) {
    if let Ok(mut l) = LIMITS.write() {
        *l = Some(limits);
    }
}

/// A breached limit: what, how much, and the limit.
#[derive(Debug, Clone, PartialEq)]
pub struct LimitError {
    /// The parameter or input that asked for too much (`cloth_grid nx × ny`, `file.svg`).
    pub what: String,
    /// The value asked for, as text (it may not fit an integer).
    pub value: String,
    /// The limit's name in [`Limits`].
    pub limit: &'static str,
    /// The limit's value.
    pub max: u64,
}

impl fmt::Display for LimitError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} is {}, over the limit {} = {} (raise it with `emilion run --limit {}=N`)",
            self.what, self.value, self.limit, self.max, self.limit
        )
    }
}

impl std::error::Error for LimitError {}

/// A number as text for messages: as written when ordinary, in exponent form (`1e300`) when
/// huge or tiny, so an error never prints three hundred digits.
pub fn short(v: f64) -> String {
    let a = v.abs();
    if v.is_finite() && a != 0.0 && !(1e-4..1e9).contains(&a) {
        format!("{v:e}")
    } else {
        format!("{v}")
    }
}

/// Checks a count or size `value` (a float from a script or file: NaN, infinite and negative
/// values are refused too) against `max`, named `limit`; returns it as an integer.
pub fn check(what: &str, value: f64, limit: &'static str, max: u64) -> Result<u64, LimitError> {
    if value.is_finite() && value >= 0.0 && value <= max as f64 {
        Ok(value as u64)
    } else {
        Err(LimitError {
            what: what.to_string(),
            value: short(value),
            limit,
            max,
        })
    }
}

/// Checks an integer count against `max`, named `limit`.
pub fn check_count(
    what: &str,
    value: u64,
    limit: &'static str,
    max: u64,
) -> Result<u64, LimitError> {
    if value <= max {
        Ok(value)
    } else {
        Err(LimitError {
            what: what.to_string(),
            value: value.to_string(),
            limit,
            max,
        })
    }
}

/// Checks `count` elements of `elem_bytes` each against `max_alloc_bytes` before allocating.
pub fn check_alloc(what: &str, count: u64, elem_bytes: u64) -> Result<usize, LimitError> {
    let max = get().max_alloc_bytes;
    match count.checked_mul(elem_bytes) {
        Some(b) if b <= max => Ok(count as usize),
        _ => Err(LimitError {
            what: format!("{what} ({count} × {elem_bytes} bytes)"),
            value: format!("{} bytes", count as f64 * elem_bytes as f64),
            limit: "max_alloc_bytes",
            max,
        }),
    }
}

/// Checks a file's length against `max_file_bytes` before it is read whole.
pub fn check_file(path: &std::path::Path) -> Result<(), LimitError> {
    let max = get().max_file_bytes;
    let len = std::fs::metadata(path).map(|m| m.len()).unwrap_or(0);
    check_count(&path.display().to_string(), len, "max_file_bytes", max).map(|_| ())
}

/// Reads a text file whole, refusing one past `max_file_bytes` (also a device like
/// `/dev/zero`, read at most to the limit).
pub fn read_to_string(path: &std::path::Path) -> std::io::Result<String> {
    use std::io::Read;
    let max = get().max_file_bytes;
    let f = std::fs::File::open(path)?;
    let mut s = String::new();
    let n = f.take(max + 1).read_to_string(&mut s)?;
    if n as u64 > max {
        return Err(std::io::Error::other(format!(
            "{} is over the limit max_file_bytes = {max} (raise it with `emilion run --limit max_file_bytes=N`)",
            path.display()
        )));
    }
    Ok(s)
}

/// Reads a file's bytes whole, refusing one past `max_file_bytes`.
pub fn read(path: &std::path::Path) -> std::io::Result<Vec<u8>> {
    use std::io::Read;
    let max = get().max_file_bytes;
    let f = std::fs::File::open(path)?;
    let mut v = Vec::new();
    let n = f.take(max + 1).read_to_end(&mut v)?;
    if n as u64 > max {
        return Err(std::io::Error::other(format!(
            "{} is over the limit max_file_bytes = {max} (raise it with `emilion run --limit max_file_bytes=N`)",
            path.display()
        )));
    }
    Ok(v)
}

// ---- cancellation: the `--max-seconds` deadline -------------------------------------------

static CANCELLED: AtomicBool = AtomicBool::new(false);
/// The deadline as milliseconds after [`START`]; 0 = none.
static DEADLINE_MS: AtomicU64 = AtomicU64::new(0);
/// The budget given to [`set_deadline`], in milliseconds, for the error message.
static BUDGET_MS: AtomicU64 = AtomicU64::new(0);
static START: std::sync::OnceLock<Instant> = std::sync::OnceLock::new();

/// Sets a wall-time budget for the rest of the process, counted from now.
pub fn set_deadline(budget: Duration) {
    let start = *START.get_or_init(Instant::now);
    let ms = (start.elapsed() + budget).as_millis().max(1) as u64;
    BUDGET_MS.store(budget.as_millis() as u64, Ordering::Relaxed);
    DEADLINE_MS.store(ms, Ordering::Relaxed);
}

/// Asks every long loop to stop at its next check (a signal, a watchdog).
pub fn cancel() {
    CANCELLED.store(true, Ordering::Relaxed);
}

/// `Err` with the reason once the run is cancelled or past its deadline. Long loops (steps,
/// frames, tracker iterations, training rounds) call this once per iteration: it costs an
/// atomic load and, with a deadline, a clock read.
pub fn check_cancelled() -> Result<(), String> {
    if CANCELLED.load(Ordering::Relaxed) {
        return Err("the run was cancelled".into());
    }
    let d = DEADLINE_MS.load(Ordering::Relaxed);
    if d != 0 {
        let start = *START.get_or_init(Instant::now);
        if start.elapsed().as_millis() as u64 >= d {
            return Err(format!(
                "the run passed its time limit (--max-seconds {})",
                BUDGET_MS.load(Ordering::Relaxed) as f64 / 1e3
            ));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn checks_refuse_what_is_over_or_not_a_number() {
        assert_eq!(check("n", 10.0, "max_steps", 10), Ok(10));
        for bad in [11.0, -1.0, f64::NAN, f64::INFINITY, 1e300] {
            let e = check("cloth_grid nx", bad, "max_steps", 10).unwrap_err();
            assert!(e.to_string().contains("cloth_grid nx") && e.to_string().contains("max_steps"));
        }
        assert!(check_alloc("stats", u64::MAX, 8).is_err());
        assert!(check_alloc("stats", 100, 8).is_ok());
        assert_eq!(short(1e300), "1e300");
        assert_eq!(short(0.25), "0.25");
        assert_eq!(short(4000000.0), "4000000");
    }

    #[test]
    fn named_limits_round_trip() {
        let mut l = Limits::default();
        l.set_named("max_pixels", 7).unwrap();
        assert_eq!(l.max_pixels, 7);
        assert!(l
            .set_named("max_nothing", 1)
            .unwrap_err()
            .contains("max_pixels"));
    }
}
