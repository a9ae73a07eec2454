//! The limits `emilion run` puts on the whole process: `--max-memory` through a counting global
//! allocator, and `--max-seconds` through a watchdog thread that ends a run still busy well past
//! its deadline (a native call that never checks [`emilion::limits::check_cancelled`]).
//!
//! Both end the process at once, with a clear message on stderr and their own exit status
//! ([`EXIT_MEMORY`], [`EXIT_TIME`]): every output file is written atomically, so what was
//! already written stays whole. Without `--max-memory` the allocator costs one relaxed load and
//! a branch per allocation; with it, an atomic add besides.

use std::alloc::{GlobalAlloc, Layout, System};
use std::fmt::Write as _;
use std::sync::atomic::{AtomicBool, AtomicIsize, Ordering::Relaxed};
use std::sync::OnceLock;
use std::time::Duration;

/// Exit status of a run stopped by `--max-memory`.
pub const EXIT_MEMORY: i32 = 3;
/// Exit status of a run stopped by the watchdog, past `--max-seconds`.
pub const EXIT_TIME: i32 = 4;

/// The global allocator of the binary: the system's, counting the bytes in use.
pub struct CountingAlloc;

/// Whether a limit is set: the bytes are counted only then.
static COUNTING: AtomicBool = AtomicBool::new(false);
/// Bytes allocated and not yet freed since the limit was set (negative when more was freed than
/// allocated since then: the limit is then looser by what was allocated before it, a few KiB
/// of command-line parsing).
static IN_USE: AtomicIsize = AtomicIsize::new(0);
/// The memory limit in bytes.
static LIMIT: AtomicIsize = AtomicIsize::new(isize::MAX);
/// The limit as the user wrote it (`4G`), for the message.
static LIMIT_TEXT: OnceLock<String> = OnceLock::new();
/// Set by the first thread that ends the process.
static ENDING: AtomicBool = AtomicBool::new(false);

/// Counts `n` more bytes when counting; past the limit, ends the process.
#[inline]
fn grow(n: usize) {
    if COUNTING.load(Relaxed) {
        let n = n as isize;
        let now = IN_USE.fetch_add(n, Relaxed).wrapping_add(n);
        if now > LIMIT.load(Relaxed) {
            over_memory(n, now);
        }
    }
}

/// Counts `n` bytes fewer when counting.
#[inline]
fn shrink(n: usize) {
    if COUNTING.load(Relaxed) {
        IN_USE.fetch_sub(n as isize, Relaxed);
    }
}

unsafe impl GlobalAlloc for CountingAlloc {
    #[inline]
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        grow(layout.size());
        System.alloc(layout)
    }

    #[inline]
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        grow(layout.size());
        System.alloc_zeroed(layout)
    }

    #[inline]
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        shrink(layout.size());
        System.dealloc(ptr, layout)
    }

    #[inline]
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        if new_size > layout.size() {
            grow(new_size - layout.size());
        } else {
            shrink(layout.size() - new_size);
        }
        System.realloc(ptr, layout, new_size)
    }
}

/// Sets the memory limit: `bytes`, written `text` by the user.
pub fn set_max_memory(bytes: u64, text: &str) {
    let _ = LIMIT_TEXT.set(text.to_string());
    LIMIT.store(isize::try_from(bytes).unwrap_or(isize::MAX), Relaxed);
    COUNTING.store(true, Relaxed);
}

/// A message built on the stack (no allocation: it is written from inside the allocator).
struct StackText {
    buf: [u8; 512],
    len: usize,
}

impl std::fmt::Write for StackText {
    fn write_str(&mut self, s: &str) -> std::fmt::Result {
        let n = s.len().min(self.buf.len() - self.len);
        self.buf[self.len..self.len + n].copy_from_slice(&s.as_bytes()[..n]);
        self.len += n;
        Ok(())
    }
}

/// Writes `args` to stderr and ends the process with `code`, allocating nothing and running
/// no exit handlers (another thread may hold a lock the handlers need).
fn end(code: i32, args: std::fmt::Arguments) -> ! {
    if !ENDING.swap(true, Relaxed) {
        let mut text = StackText {
            buf: [0; 512],
            len: 0,
        };
        let _ = text.write_fmt(args);
        write_stderr(&text.buf[..text.len]);
    }
    exit_now(code)
}

#[cfg(unix)]
fn write_stderr(bytes: &[u8]) {
    use std::io::Write;
    use std::os::fd::FromRawFd;
    // fd 2 borrowed, never closed
    let mut f = std::mem::ManuallyDrop::new(unsafe { std::fs::File::from_raw_fd(2) });
    let _ = f.write_all(bytes);
}

#[cfg(not(unix))]
fn write_stderr(bytes: &[u8]) {
    use std::io::Write;
    let _ = std::io::stderr().write_all(bytes);
}

#[cfg(unix)]
fn exit_now(code: i32) -> ! {
    extern "C" {
        fn _exit(status: i32) -> !;
    }
    unsafe { _exit(code) }
}

#[cfg(not(unix))]
fn exit_now(code: i32) -> ! {
    std::process::exit(code)
}

#[cold]
#[inline(never)]
fn over_memory(asked: isize, in_use: isize) -> ! {
    let limit = LIMIT_TEXT.get().map_or("", String::as_str);
    end(
        EXIT_MEMORY,
        format_args!(
            "error: the script passed its memory limit --max-memory {limit} while allocating \
             {asked} bytes ({} MiB in use before); raise it with --max-memory SIZE\n",
            in_use.wrapping_sub(asked).max(0) >> 20
        ),
    )
}

/// Starts the watchdog: a run still going `grace` after `seconds` (2 s and a tenth of the
/// budget, at most a minute) is ended with [`EXIT_TIME`].
pub fn start_watchdog(seconds: f64, text: &str) {
    let grace = (2.0 + seconds / 10.0).min(60.0);
    let text = text.to_string();
    let _ = std::thread::Builder::new()
        .name("watchdog".into())
        .spawn(move || {
            std::thread::sleep(Duration::from_secs_f64(seconds + grace));
            end(
                EXIT_TIME,
                format_args!(
                    "error: the script passed its time limit --max-seconds {text} and did not \
                     stop within {grace:.1} s more (a native call that does not check the \
                     deadline); stopped\n"
                ),
            )
        });
}

/// A memory size: bytes, or a number with a suffix `K`, `M`, `G`, `T` (powers of 1024; `KB`,
/// `KiB` and lower case too), e.g. `4G`, `500M`, `1.5G`.
pub fn parse_size(s: &str) -> Result<u64, String> {
    let t = s.trim();
    let split = t
        .find(|c: char| !(c.is_ascii_digit() || c == '.' || c == '_'))
        .unwrap_or(t.len());
    let (number, unit) = t.split_at(split);
    let value: f64 = number
        .replace('_', "")
        .parse()
        .map_err(|_| format!("`{s}` is not a size (bytes, or a number with K, M, G or T)"))?;
    let unit = unit.trim().to_ascii_lowercase();
    let power = match unit.trim_end_matches("ib").trim_end_matches('b') {
        "" => 0,
        "k" => 1,
        "m" => 2,
        "g" => 3,
        "t" => 4,
        _ => return Err(format!("`{s}`: unknown unit `{unit}` (K, M, G or T)")),
    };
    let bytes = value * 1024f64.powi(power);
    if !(bytes.is_finite() && bytes >= 1.0 && bytes < u64::MAX as f64) {
        return Err(format!("`{s}` is not a usable memory size"));
    }
    Ok(bytes as u64)
}

/// A time budget in seconds: a positive number.
pub fn parse_seconds(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(v) if v.is_finite() && v > 0.0 && v < 1e9 => Ok(v),
        _ => Err(format!("`{s}` is not a positive number of seconds")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_take_binary_suffixes() {
        assert_eq!(parse_size("4G"), Ok(4 << 30));
        assert_eq!(parse_size("500M"), Ok(500 << 20));
        assert_eq!(parse_size("500mib"), Ok(500 << 20));
        assert_eq!(parse_size("1.5k"), Ok(1536));
        assert_eq!(parse_size("1_000"), Ok(1000));
        for bad in ["", "G", "4X", "-1G", "1e400", "0"] {
            assert!(parse_size(bad).is_err(), "{bad}");
        }
        assert_eq!(parse_seconds("1.5"), Ok(1.5));
        assert!(parse_seconds("0").is_err() && parse_seconds("inf").is_err());
    }
}
