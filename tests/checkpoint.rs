//! Checkpoint and resume (docs/checkpoints.md), with the release binary: a run killed with
//! SIGKILL after a checkpoint and resumed with `--resume` writes the same files, byte for byte,
//! as a run never interrupted — the walking mannequin's skirt (PNGs, OBJs, the statistics, the
//! USD, PC2 and glTF caches) killed at three points, and a tracking run. Wall-clock columns
//! (the statistics' timings, the tracking summary's seconds) differ between any two runs and
//! are left out of the comparison. Also: `sim.checkpoint`/`sim.resume` continue bit for bit,
//! and checkpoints of another scene or another run are refused with a clear message.

use std::collections::BTreeMap;
use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

use emilion::geometry::files::data_dir;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn temp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("emilion_ckpt_{name}_{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn have_data() -> bool {
    let ok = data_dir().join("bodies/makehuman").is_dir();
    if !ok {
        eprintln!(
            "skipped: the shared data folder {} is absent",
            data_dir().display()
        );
    }
    ok
}

fn emilion(cwd: &Path, args: &[String]) -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_emilion"));
    c.current_dir(cwd).args(args);
    c
}

/// Runs to the end; panics with its output on failure.
fn run_ok(cwd: &Path, args: &[String]) -> String {
    let o = emilion(cwd, args).output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr).to_string();
    assert!(
        o.status.success(),
        "emilion {args:?} failed:\n{err}\n{}",
        String::from_utf8_lossy(&o.stdout)
    );
    err
}

/// Runs until its `n`-th checkpoint line, then kills it with SIGKILL; returns that line.
fn run_and_kill(cwd: &Path, args: &[String], n: usize) -> String {
    let mut child = emilion(cwd, args)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let lines = BufReader::new(child.stderr.take().unwrap()).lines();
    let mut seen = 0;
    let mut last = String::new();
    for l in lines {
        let l = l.unwrap();
        if l.starts_with("checkpoint:") {
            seen += 1;
            last = l;
            if seen == n {
                child.kill().unwrap(); // SIGKILL
                break;
            }
        }
    }
    child.wait().unwrap();
    assert_eq!(seen, n, "the run ended before its checkpoint {n}");
    last
}

/// The files under `dir` (relative paths), without the temporary files an atomic write killed
/// half-way leaves (`.NAME.PID-N.tmp`).
fn files(dir: &Path) -> BTreeMap<PathBuf, Vec<u8>> {
    fn walk(base: &Path, dir: &Path, out: &mut BTreeMap<PathBuf, Vec<u8>>) {
        for e in std::fs::read_dir(dir).unwrap() {
            let p = e.unwrap().path();
            let name = p.file_name().unwrap().to_string_lossy().to_string();
            if p.is_dir() {
                walk(base, &p, out);
            } else if !(name.starts_with('.') && name.ends_with(".tmp")) {
                out.insert(
                    p.strip_prefix(base).unwrap().to_path_buf(),
                    std::fs::read(&p).unwrap(),
                );
            }
        }
    }
    let mut out = BTreeMap::new();
    walk(dir, dir, &mut out);
    out
}

/// A statistics CSV with its wall-clock columns emptied.
fn without_timings(csv: &[u8]) -> String {
    let text = String::from_utf8_lossy(csv);
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap_or("").split(',').collect();
    let timed: Vec<bool> = header.iter().map(|h| h.ends_with("_ms")).collect();
    assert!(timed.iter().any(|&t| t), "no timing columns in {header:?}");
    let mut out = header.join(",") + "\n";
    for l in lines {
        let row: Vec<&str> = l
            .split(',')
            .enumerate()
            .map(|(k, v)| if timed[k] { "" } else { v })
            .collect();
        out += &(row.join(",") + "\n");
    }
    out
}

/// A tracking summary without its wall-time figures.
fn without_seconds(json: &[u8]) -> serde_json::Value {
    let mut v: serde_json::Value = serde_json::from_slice(json).unwrap();
    let m = v.as_object_mut().unwrap();
    m.retain(|k, _| !k.contains("seconds") && k != "sequence");
    v
}

/// Asserts that the files of `a` and `b` are the same, byte for byte (wall-clock figures
/// aside).
fn assert_same_files(a: &Path, b: &Path) {
    let (fa, fb) = (files(a), files(b));
    assert_eq!(
        fa.keys().collect::<Vec<_>>(),
        fb.keys().collect::<Vec<_>>(),
        "the resumed run wrote other files"
    );
    for (p, bytes) in &fa {
        let other = &fb[p];
        let name = p.to_string_lossy();
        if name.ends_with("_stats.csv") {
            assert_eq!(
                without_timings(bytes),
                without_timings(other),
                "{name} differs"
            );
        } else if name.ends_with("summary.json") {
            assert_eq!(without_seconds(bytes), without_seconds(other), "{name}");
        } else {
            assert!(bytes == other, "{name} differs after resuming");
        }
    }
}

fn args(list: &[&str]) -> Vec<String> {
    list.iter().map(|s| s.to_string()).collect()
}

#[test]
fn a_walk_killed_at_three_frames_resumes_to_the_same_files() {
    if !have_data() {
        return;
    }
    let dir = temp("walk");
    let script = root().join("scripts/mannequin_walk.rhai");
    let base = |out: &str| {
        let mut a = args(&["run", script.to_str().unwrap()]);
        for s in [
            "seconds=0.25",
            "nx=32",
            "ny=12",
            "cache=all",
            "frame_objs=true",
            &format!("out={out}"),
        ] {
            a.extend(args(&["--set", s]));
        }
        a
    };
    run_ok(&dir, &base("whole"));
    // 18 frames; killed after the checkpoints of frames 2, 9 and 16 (every frame)
    for (k, n) in [2usize, 9, 16].into_iter().enumerate() {
        let out = format!("killed{k}");
        let ckpt = format!("walk{k}.ckpt");
        let mut first = base(&out);
        first.extend(args(&["--checkpoint", "1", "--checkpoint-file", &ckpt]));
        let line = run_and_kill(&dir, &first, n);
        assert!(line.contains(&format!("at {n} ")), "{line}");
        let mut again = base(&out);
        again.extend(args(&["--resume", &ckpt]));
        let err = run_ok(&dir, &again);
        assert!(
            err.contains(&format!("at {} ", n + 1)),
            "the resumed run goes on from frame {}: {err}",
            n + 1
        );
        assert_same_files(
            &dir.join("whole/mannequin_walk"),
            &dir.join(format!("{out}/mannequin_walk")),
        );
    }
    // a resumed run with other settings is refused, naming the file
    let mut other = base("other");
    other.extend(args(&["--set", "nx=30", "--resume", "walk0.ckpt"]));
    let o = emilion(&dir, &other).output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success());
    assert!(
        err.contains("walk0.ckpt") && err.contains("other --set values"),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn a_tracking_run_killed_after_two_frames_resumes_to_the_same_files() {
    if !have_data() {
        return;
    }
    let dir = temp("track");
    let motion = data_dir().join("motion/cmu_bvh/002_05.bvh");
    run_ok(
        &dir,
        &args(&[
            "run",
            root().join("scripts/make_sequence.rhai").to_str().unwrap(),
            "--set",
            &format!("motion={}", motion.display()),
            "--set",
            "out=seq",
            "--set",
            "frames=4",
        ]),
    );
    let track = |out: &str| {
        args(&[
            "run",
            root().join("scripts/track_body.rhai").to_str().unwrap(),
            "--set",
            "seq=seq",
            "--set",
            &format!("out={out}"),
            "--set",
            "particles=6",
        ])
    };
    run_ok(&dir, &track("whole"));
    let mut first = track("killed");
    first.extend(args(&["--checkpoint", "1", "--checkpoint-file", "t.ckpt"]));
    let line = run_and_kill(&dir, &first, 2);
    assert!(
        line.contains("track_body") && line.contains("at 2 "),
        "{line}"
    );
    let mut again = track("killed");
    again.extend(args(&["--resume", "t.ckpt"]));
    let err = run_ok(&dir, &again);
    assert!(err.contains("at 3 ") && !err.contains("at 2 "), "{err}");
    assert_same_files(&dir.join("whole"), &dir.join("killed"));
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn a_simulation_resumed_from_its_checkpoint_continues_bit_for_bit() {
    let dir = temp("script");
    let out = dir.to_str().unwrap().to_string();
    emilion::script::run_file(
        &root().join("scripts/checkpoint_resume.rhai"),
        &[("out".into(), out), ("n".into(), "16".into())],
    )
    .unwrap_or_else(|e| panic!("{e}"));
    let d = dir.join("checkpoint_resume");
    let (a, b) = (
        std::fs::read(d.join("first.obj")).unwrap(),
        std::fs::read(d.join("resumed.obj")).unwrap(),
    );
    assert!(!a.is_empty() && a == b);
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn a_checkpoint_of_another_scene_is_refused() {
    let dir = temp("other_scene");
    let ckpt = dir.join("a.ckpt");
    let script = dir.join("s.rhai");
    std::fs::write(
        &script,
        format!(
            "let a = simulation(cloth_grid(0.5, 0.5, 8, 8, fabric()));\n\
             a.run_steps(3);\n\
             a.checkpoint(\"{0}\");\n\
             let b = simulation(cloth_grid(0.5, 0.5, 9, 8, fabric()));\n\
             b.resume(\"{0}\");\n",
            ckpt.display()
        ),
    )
    .unwrap();
    let e = emilion::script::run_file(&script, &[]).unwrap_err();
    let msg = e.to_string();
    assert!(
        msg.contains("a.ckpt") && msg.contains("another scene"),
        "{msg}"
    );
    assert_eq!(e.position.map(|p| p.0), Some(5), "{msg}");
    // not a checkpoint at all
    std::fs::write(&ckpt, b"P6 not a checkpoint").unwrap();
    std::fs::write(
        &script,
        format!(
            "let b = simulation(cloth_grid(0.5, 0.5, 8, 8, fabric()));\nb.resume(\"{}\");\n",
            ckpt.display()
        ),
    )
    .unwrap();
    let msg = emilion::script::run_file(&script, &[])
        .unwrap_err()
        .to_string();
    assert!(msg.contains("not an emilion checkpoint"), "{msg}");
    let _ = std::fs::remove_dir_all(dir);
}
