//! A fuzz harness on stable Rust for every reader of the crate (see docs/fuzzing.md).
//!
//! ```sh
//! cargo run --release --example fuzz -- --reader obj --cases 1000000 --seed 1
//! cargo run --release --example fuzz -- --reader all --seconds 20      # measure the rates
//! cargo run --release --example fuzz -- --reader svg --replay tests/fuzz/svg/known
//! ```
//!
//! The process started by the user is a supervisor: it runs the cases in a worker child
//! (this program with `--worker`), which reports each case's index before reading it. A case
//! that panics is caught in the worker (`catch_unwind`) and reported; one that aborts, overflows
//! the stack or allocates past the ceiling (1 GiB live, a counting global allocator) kills the
//! worker; one that runs past the time limit (10 s) is killed by the supervisor. In each case the
//! supervisor regenerates the input from (seed, index), saves it under
//! `tests/fuzz/<reader>/crashes/` with a `.why` note, and starts a new worker after it.

mod alloc;
mod mutate;
mod script_gen;
mod targets;

use std::collections::HashMap;
use std::io::{BufRead, BufReader, Read, Write};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::{mpsc, Arc, Mutex};
use std::time::{Duration, Instant};

use targets::Target;

#[global_allocator]
static ALLOC: alloc::Counting = alloc::Counting;

/// The command line.
#[derive(Clone, Debug)]
struct Options {
    reader: String,
    cases: u64,
    seed: u64,
    start: u64,
    seconds: Option<f64>,
    timeout_s: f64,
    max_alloc_mb: usize,
    corpus: PathBuf,
    replay: Option<PathBuf>,
    image_seeds: Option<PathBuf>,
    worker: bool,
    save_max: usize,
    print: bool,
}

fn usage() -> ! {
    eprintln!(
        "usage: fuzz --reader NAME|all [--cases N] [--seed S] [--start I] [--seconds T]\n\
         \x20           [--timeout-s 10] [--max-alloc-mb 1024] [--corpus tests/fuzz] [--save-max 3]\n\
         \x20      fuzz --reader NAME --replay FILE_OR_DIR\n\
         \x20      fuzz --reader NAME --seed S --start I --print   (case I's input to stdout)\n\
         readers: {}",
        targets::all()
            .iter()
            .map(|t| t.name)
            .collect::<Vec<_>>()
            .join(", ")
    );
    std::process::exit(2)
}

fn parse_options() -> Options {
    let mut o = Options {
        reader: String::new(),
        cases: 1_000_000,
        seed: 1,
        start: 0,
        seconds: None,
        timeout_s: 10.0,
        max_alloc_mb: 1024,
        corpus: PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/fuzz"),
        replay: None,
        image_seeds: None,
        worker: false,
        save_max: 3,
        print: false,
    };
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        let mut val = || args.next().unwrap_or_else(|| usage());
        match a.as_str() {
            "--reader" => o.reader = val(),
            "--cases" => o.cases = val().parse().unwrap_or_else(|_| usage()),
            "--seed" => o.seed = val().parse().unwrap_or_else(|_| usage()),
            "--start" => o.start = val().parse().unwrap_or_else(|_| usage()),
            "--seconds" => o.seconds = Some(val().parse().unwrap_or_else(|_| usage())),
            "--timeout-s" => o.timeout_s = val().parse().unwrap_or_else(|_| usage()),
            "--max-alloc-mb" => o.max_alloc_mb = val().parse().unwrap_or_else(|_| usage()),
            "--corpus" => o.corpus = PathBuf::from(val()),
            "--replay" => o.replay = Some(PathBuf::from(val())),
            "--save-max" => o.save_max = val().parse().unwrap_or_else(|_| usage()),
            "--worker" => o.worker = true,
            "--print" => o.print = true,
            "--write-image-seeds" => {
                o.image_seeds = Some(PathBuf::from(val()));
                o.reader = "image".into();
            }
            _ => usage(),
        }
    }
    if o.reader.is_empty() {
        usage();
    }
    o
}

fn main() {
    let o = parse_options();
    alloc::set_ceiling(o.max_alloc_mb << 20);
    if let Some(dir) = &o.image_seeds {
        write_image_seeds(dir);
        return;
    }
    if o.reader == "all" && !o.worker && o.replay.is_none() {
        for t in targets::all() {
            let mut one = o.clone();
            one.reader = t.name.to_string();
            supervise(&one);
        }
        return;
    }
    let target = targets::by_name(&o.reader).unwrap_or_else(|| usage());
    if o.print {
        let seeds = seeds(&o.corpus, &target);
        let _ = std::io::stdout().write_all(&input(&o, &target, &seeds, o.start));
    } else if let Some(path) = &o.replay {
        replay(&target, path);
    } else if o.worker {
        work(&o, &target);
    } else {
        supervise(&o);
    }
}

/// The seed inputs of a target: the files directly in its corpus folder, sorted.
fn seeds(corpus: &Path, target: &Target) -> Vec<Vec<u8>> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(corpus.join(target.name))
        .map(|d| d.flatten().map(|e| e.path()).collect())
        .unwrap_or_default();
    files.retain(|p| p.is_file() && is_case_file(p));
    files.sort();
    files.iter().filter_map(|p| std::fs::read(p).ok()).collect()
}

/// Whether a corpus file is an input (not a note).
fn is_case_file(p: &Path) -> bool {
    let name = p.file_name().and_then(|n| n.to_str()).unwrap_or("");
    !(name.starts_with('.') || name.ends_with(".why") || name.ends_with(".md"))
}

/// The input of case `index`.
fn input(o: &Options, target: &Target, seeds: &[Vec<u8>], index: u64) -> Vec<u8> {
    if target.name == "script" {
        script_gen::program(o.seed, index)
    } else {
        mutate::case(o.seed, index, seeds, target.dictionary, target.text)
    }
}

// ---- the worker -----------------------------------------------------------------------------

thread_local! {
    static PANIC: std::cell::RefCell<String> = const { std::cell::RefCell::new(String::new()) };
}

fn quiet_panics() {
    std::panic::set_hook(Box::new(|info| {
        let msg = info
            .payload()
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| info.payload().downcast_ref::<String>().cloned())
            .unwrap_or_default();
        let at = info
            .location()
            .map(|l| format!("{}:{}", l.file(), l.line()))
            .unwrap_or_default();
        PANIC.with(|p| *p.borrow_mut() = format!("{at}: {msg}"));
    }));
}

fn work(o: &Options, target: &Target) {
    quiet_panics();
    let seeds = seeds(&o.corpus, target);
    let stdout = std::io::stdout();
    let mut out = stdout.lock();
    let (mut max_peak, mut max_case) = (0usize, o.start);
    for i in o.start..o.cases {
        let data = input(o, target, &seeds, i);
        let _ = writeln!(out, "@@ s {i}");
        let _ = out.flush();
        let before = alloc::live();
        alloc::reset_peak();
        let r = catch_unwind(AssertUnwindSafe(|| (target.run)(&data)));
        let peak = alloc::peak().saturating_sub(before);
        if peak > max_peak {
            (max_peak, max_case) = (peak, i);
            let _ = writeln!(out, "@@ m {peak} {i}");
        }
        if r.is_err() {
            let msg = PANIC.with(|p| p.borrow().replace('\n', " | "));
            let _ = writeln!(out, "@@ p {i} {msg}");
        }
    }
    let _ = writeln!(out, "@@ end {max_peak} {max_case}");
    let _ = out.flush();
}

// ---- the supervisor -------------------------------------------------------------------------

enum Event {
    Line(String),
    Closed,
}

/// What one run of a reader found.
#[derive(Default)]
struct Findings {
    /// Signature → (kind, cases, saved files).
    by_signature: HashMap<String, (usize, Vec<String>)>,
    total: usize,
}

fn supervise(o: &Options) {
    let target = targets::by_name(&o.reader).unwrap_or_else(|| usage());
    let seeds = seeds(&o.corpus, &target);
    let exe = std::env::current_exe().expect("the harness's own path");
    let started = Instant::now();
    let deadline = o.seconds.map(|s| started + Duration::from_secs_f64(s));
    let mut findings = Findings::default();
    let (mut next, mut done, mut max_peak, mut max_case) = (o.start, 0u64, 0usize, 0u64);
    let mut last_report = Instant::now();
    eprintln!(
        "fuzz {}: {} seed inputs, cases {}..{}, seed {}",
        target.name,
        seeds.len(),
        o.start,
        o.cases,
        o.seed
    );
    'workers: while next < o.cases {
        let mut child = Command::new(&exe)
            .args(["--worker", "--reader", target.name])
            .args(["--seed", &o.seed.to_string()])
            .args([
                "--start",
                &next.to_string(),
                "--cases",
                &o.cases.to_string(),
            ])
            .args(["--max-alloc-mb", &o.max_alloc_mb.to_string()])
            .arg("--corpus")
            .arg(&o.corpus)
            .env("RAYON_NUM_THREADS", "1")
            .env("RUST_BACKTRACE", "0")
            .stdin(Stdio::null())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .expect("starting a worker");
        let (tx, rx) = mpsc::channel();
        let stdout = child.stdout.take().expect("worker stdout");
        std::thread::spawn(move || {
            for line in BufReader::new(stdout).lines() {
                let Ok(line) = line else { break };
                if tx.send(Event::Line(line)).is_err() {
                    return;
                }
            }
            let _ = tx.send(Event::Closed);
        });
        let tail = Arc::new(Mutex::new(Vec::<u8>::new()));
        let mut stderr = child.stderr.take().expect("worker stderr");
        let tail_w = Arc::clone(&tail);
        std::thread::spawn(move || {
            let mut buf = [0u8; 4096];
            while let Ok(n) = stderr.read(&mut buf) {
                if n == 0 {
                    break;
                }
                let mut t = tail_w.lock().unwrap_or_else(|e| e.into_inner());
                t.extend_from_slice(&buf[..n]);
                let excess = t.len().saturating_sub(16384);
                t.drain(..excess);
            }
        });
        let mut current: Option<u64> = None;
        let pid = child.id();
        let (mut case_wall, mut case_cpu) = (Instant::now(), cpu_seconds(pid));
        loop {
            if deadline.is_some_and(|d| Instant::now() > d) {
                let _ = child.kill();
                let _ = child.wait();
                break 'workers;
            }
            match rx.recv_timeout(Duration::from_secs_f64(o.timeout_s.min(1.0))) {
                Ok(Event::Line(line)) => {
                    let mut w = line.splitn(4, ' ');
                    match (w.next(), w.next(), w.next()) {
                        (Some("@@"), Some("s"), Some(i)) => {
                            if current.is_some() {
                                done += 1;
                            }
                            current = i.parse().ok();
                            (case_wall, case_cpu) = (Instant::now(), cpu_seconds(pid));
                        }
                        (Some("@@"), Some("p"), Some(i)) => {
                            let i: u64 = i.parse().unwrap_or(0);
                            let msg = w.next().unwrap_or("").to_string();
                            record(o, &target, &seeds, &mut findings, i, "panic", &msg);
                        }
                        (Some("@@"), Some("m"), Some(peak)) => {
                            let at: u64 = w.next().and_then(|s| s.parse().ok()).unwrap_or(0);
                            let peak = peak.parse().unwrap_or(0);
                            if peak > max_peak {
                                (max_peak, max_case) = (peak, at);
                            }
                        }
                        (Some("@@"), Some("end"), Some(peak)) => {
                            if current.is_some() {
                                done += 1;
                            }
                            let at: u64 = w.next().and_then(|s| s.parse().ok()).unwrap_or(0);
                            let peak = peak.parse().unwrap_or(0);
                            if peak > max_peak {
                                (max_peak, max_case) = (peak, at);
                            }
                            let _ = child.wait();
                            break 'workers;
                        }
                        _ => {}
                    }
                    if last_report.elapsed() > Duration::from_secs(10) {
                        last_report = Instant::now();
                        progress(&target, done, started, &findings);
                    }
                }
                Ok(Event::Closed) | Err(mpsc::RecvTimeoutError::Disconnected) => {
                    let status = child.wait().ok();
                    std::thread::sleep(Duration::from_millis(50));
                    let text =
                        String::from_utf8_lossy(&tail.lock().unwrap_or_else(|e| e.into_inner()))
                            .to_string();
                    let (kind, why) = death(status, &text);
                    let i = current.unwrap_or(next);
                    record(o, &target, &seeds, &mut findings, i, &kind, &why);
                    done += 1;
                    next = i + 1;
                    continue 'workers;
                }
                Err(mpsc::RecvTimeoutError::Timeout) => {
                    // A hang is a case that spends `timeout_s` of the worker's CPU time (or
                    // HANG_WALL_FACTOR times that in wall time): on a loaded machine a case
                    // waiting for a core is not hanging.
                    let cpu = cpu_seconds(pid) - case_cpu;
                    let wall = case_wall.elapsed().as_secs_f64();
                    if cpu < o.timeout_s && wall < HANG_WALL_FACTOR * o.timeout_s {
                        continue;
                    }
                    let _ = child.kill();
                    let _ = child.wait();
                    let i = current.unwrap_or(next);
                    let why = format!(
                        "no answer after {cpu:.0} s of CPU time ({wall:.0} s wall; limit {} s of CPU)",
                        o.timeout_s
                    );
                    record(o, &target, &seeds, &mut findings, i, "hang", &why);
                    done += 1;
                    next = i + 1;
                    continue 'workers;
                }
            }
        }
    }
    progress(&target, done, started, &findings);
    eprintln!(
        "fuzz {}: done: {} cases in {:.1} s ({:.0} cases/s), largest allocation peak {:.1} MB (case {}), {} findings in {} kinds",
        target.name,
        done,
        started.elapsed().as_secs_f64(),
        done as f64 / started.elapsed().as_secs_f64(),
        max_peak as f64 / 1e6,
        max_case,
        findings.total,
        findings.by_signature.len()
    );
    let mut sigs: Vec<_> = findings.by_signature.iter().collect();
    sigs.sort_by_key(|s| std::cmp::Reverse(s.1 .0));
    for (sig, (n, files)) in sigs {
        eprintln!("  {n:>6} × {sig}\n         saved: {}", files.join(", "));
    }
}

/// Wall time, as a multiple of the CPU-time limit, after which a case is a hang however little
/// CPU it got (a worker blocked for ever).
const HANG_WALL_FACTOR: f64 = 6.0;

/// CPU seconds (user + system) that process `pid` has used, from `/proc/PID/stat`; 0 where that
/// cannot be read (then only the wall-time bound applies).
fn cpu_seconds(pid: u32) -> f64 {
    const TICKS_PER_SECOND: f64 = 100.0; // Linux's USER_HZ on every common platform
    let Ok(stat) = std::fs::read_to_string(format!("/proc/{pid}/stat")) else {
        return 0.0;
    };
    // the fields after the command name (which may hold spaces) in parentheses
    let Some(rest) = stat.rsplit_once(')').map(|(_, r)| r) else {
        return 0.0;
    };
    let f: Vec<&str> = rest.split_whitespace().collect();
    // utime and stime are fields 14 and 15 of the line, 12 and 13 after the name
    let ticks = |k: usize| f.get(k).and_then(|v| v.parse::<f64>().ok()).unwrap_or(0.0);
    (ticks(11) + ticks(12)) / TICKS_PER_SECOND
}

fn progress(target: &Target, done: u64, started: Instant, f: &Findings) {
    let s = started.elapsed().as_secs_f64();
    eprintln!(
        "fuzz {}: {done} cases, {s:.0} s, {:.0} cases/s, {} findings",
        target.name,
        done as f64 / s.max(1e-9),
        f.total
    );
}

/// The kind and reason of a worker's death, from its exit status and the end of its stderr.
fn death(status: Option<std::process::ExitStatus>, stderr: &str) -> (String, String) {
    let lines: Vec<&str> = stderr.lines().collect();
    // The panic message (a panic in a thread other than the case's, or while panicking),
    // else the last line that is not a note.
    let last = match lines.iter().rposition(|l| l.contains("panicked at")) {
        Some(k) => lines[k..(k + 2).min(lines.len())].join(" "),
        None => lines
            .iter()
            .rev()
            .find(|l| !l.trim().is_empty() && !l.starts_with("note:"))
            .unwrap_or(&"")
            .to_string(),
    };
    if let Some(l) = stderr
        .lines()
        .rev()
        .find(|l| l.contains("memory allocation of"))
    {
        return ("alloc".into(), l.to_string());
    }
    if stderr.contains("overflowed its stack") {
        return ("stack-overflow".into(), last);
    }
    #[cfg(unix)]
    {
        use std::os::unix::process::ExitStatusExt;
        if let Some(sig) = status.and_then(|s| s.signal()) {
            return (format!("signal-{sig}"), last);
        }
    }
    let code = status.and_then(|s| s.code()).unwrap_or(-1);
    (format!("exit-{code}"), last)
}

/// Saves the input of case `i` (the first `save_max` of each signature) and counts it.
fn record(
    o: &Options,
    target: &Target,
    seeds: &[Vec<u8>],
    f: &mut Findings,
    i: u64,
    kind: &str,
    why: &str,
) {
    // The signature: the kind and the reason without numbers that change between cases.
    let sig_text: String = why
        .chars()
        .map(|c| if c.is_ascii_digit() { '#' } else { c })
        .take(160)
        .collect();
    let sig = format!("{kind}: {sig_text}");
    f.total += 1;
    let entry = f.by_signature.entry(sig.clone()).or_default();
    entry.0 += 1;
    eprintln!("fuzz {}: case {i}: {kind}: {why}", target.name);
    if entry.1.len() >= o.save_max {
        return;
    }
    let dir = o.corpus.join(target.name).join("crashes");
    let _ = std::fs::create_dir_all(&dir);
    let name = format!("{kind}-s{}-c{i}.{}", o.seed, target.ext);
    let data = input(o, target, seeds, i);
    if std::fs::write(dir.join(&name), &data).is_ok() {
        let note = format!(
            "reader {}, seed {}, case {i}, {} bytes\n{kind}: {why}\n",
            target.name,
            o.seed,
            data.len()
        );
        let _ = std::fs::write(dir.join(format!("{name}.why")), note);
        entry.1.push(name);
    }
}

// ---- replay -------------------------------------------------------------------------------

fn replay(target: &Target, path: &Path) {
    quiet_panics();
    let mut files: Vec<PathBuf> = if path.is_dir() {
        std::fs::read_dir(path)
            .map(|d| d.flatten().map(|e| e.path()).collect())
            .unwrap_or_default()
    } else {
        vec![path.to_path_buf()]
    };
    files.retain(|p| p.is_file() && is_case_file(p));
    files.sort();
    for f in files {
        let data = std::fs::read(&f).unwrap_or_default();
        let t = Instant::now();
        alloc::reset_peak();
        let before = alloc::live();
        let r = catch_unwind(AssertUnwindSafe(|| (target.run)(&data)));
        let peak = alloc::peak().saturating_sub(before);
        let what = match r {
            Ok(Ok(())) => "ok".to_string(),
            Ok(Err(e)) => format!("error: {}", e.lines().next().unwrap_or("")),
            Err(_) => format!("PANIC: {}", PANIC.with(|p| p.borrow().clone())),
        };
        println!(
            "{}: {:.3} s, peak {:.1} MB: {what}",
            f.display(),
            t.elapsed().as_secs_f64(),
            peak as f64 / 1e6
        );
    }
}

/// Writes the image corpus: small pictures in every format the photo loader reads, drawn here
/// (a gradient with a few colours), so that no photo is copied into the repository.
fn write_image_seeds(dir: &Path) {
    use image::{DynamicImage, ImageFormat, Rgb, RgbImage, Rgba};
    std::fs::create_dir_all(dir).expect("the image corpus folder");
    let rgb = RgbImage::from_fn(7, 5, |x, y| Rgb([(x * 36) as u8, (y * 50) as u8, 128]));
    let images = [
        (
            "rgb.png",
            DynamicImage::ImageRgb8(rgb.clone()),
            ImageFormat::Png,
        ),
        (
            "gray.png",
            DynamicImage::ImageRgb8(rgb.clone()).grayscale(),
            ImageFormat::Png,
        ),
        (
            "rgba16.png",
            DynamicImage::ImageRgba16(image::ImageBuffer::from_fn(3, 4, |x, y| {
                Rgba([x as u16 * 9000, y as u16 * 7000, 65535, 30000])
            })),
            ImageFormat::Png,
        ),
        (
            "rgb.jpg",
            DynamicImage::ImageRgb8(rgb.clone()),
            ImageFormat::Jpeg,
        ),
        (
            "rgb.bmp",
            DynamicImage::ImageRgb8(rgb.clone()),
            ImageFormat::Bmp,
        ),
        (
            "rgb.tif",
            DynamicImage::ImageRgb8(rgb.clone()),
            ImageFormat::Tiff,
        ),
        (
            "rgb.tga",
            DynamicImage::ImageRgb8(rgb.clone()),
            ImageFormat::Tga,
        ),
        (
            "rgb.ppm",
            DynamicImage::ImageRgb8(rgb.clone()),
            ImageFormat::Pnm,
        ),
        (
            "rgba.webp",
            DynamicImage::ImageRgba8(DynamicImage::ImageRgb8(rgb).to_rgba8()),
            ImageFormat::WebP,
        ),
    ];
    for (name, img, format) in images {
        let path = dir.join(name);
        match img.save_with_format(&path, format) {
            Ok(()) => println!("wrote {}", path.display()),
            Err(e) => println!("{name}: {e}"),
        }
    }
}
