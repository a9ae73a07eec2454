//! The sandbox of `emilion run` and its limits (issue 48, "a sandbox"), with the built binary:
//! a script reads only under its folder, the data folder, its output folders and the paths of
//! the command line, and writes only under `out/`, `--set out=DIR` and `--allow-write DIR`;
//! `--trust` lifts both; `--max-seconds` and `--max-memory` stop a run with a clear error. Each
//! script is written into a fresh folder and run from another fresh working directory.
#![cfg(feature = "scripting")]

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::Instant;

/// A fresh, empty folder.
fn fresh(name: &str) -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("sandbox")
        .join(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A script `source` in its own folder `NAME/script`; returns its path.
fn script(name: &str, source: &str) -> PathBuf {
    let dir = fresh(name).join("script");
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join(format!("{name}.rhai"));
    std::fs::write(&p, source).unwrap();
    p
}

/// Runs `emilion run SCRIPT ARGS…` from the fresh working directory `NAME/cwd`.
fn run(script: &Path, args: &[&str]) -> (Output, String, f64) {
    let cwd = script.parent().unwrap().parent().unwrap().join("cwd");
    std::fs::create_dir_all(&cwd).unwrap();
    let t = Instant::now();
    let o = Command::new(env!("CARGO_BIN_EXE_emilion"))
        .current_dir(&cwd)
        .arg("run")
        .arg(script)
        .args(args)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr).into_owned();
    (o, stderr, t.elapsed().as_secs_f64())
}

/// The first line of /etc/passwd, which no refusal may echo.
fn passwd_line() -> String {
    std::fs::read_to_string("/etc/passwd")
        .ok()
        .and_then(|t| t.lines().next().map(str::to_string))
        .unwrap_or_else(|| "root:x:0:0".into())
}

/// A script that reads `path` with a reader whose parse error would quote the file.
fn reads(path: &str) -> String {
    format!("facade::from_rules(\"{path}\", out_dir(), \"x\", #{{}});\n")
}

#[cfg(unix)]
#[test]
fn a_script_cannot_read_etc_passwd_directly_through_dots_or_through_a_link() {
    let first = passwd_line();
    for (name, path) in [
        ("passwd_direct", "/etc/passwd"),
        ("passwd_dots", "../../../../../../../../../../etc/passwd"),
        ("passwd_link", "link"),
        ("passwd_folder_link", "etc/passwd"),
        (
            "passwd_out_dots",
            "out/../../../../../../../../../../etc/passwd",
        ),
    ] {
        let p = script(name, &reads(path));
        let dir = p.parent().unwrap();
        std::os::unix::fs::symlink("/etc/passwd", dir.join("link")).unwrap();
        std::os::unix::fs::symlink("/etc", dir.join("etc")).unwrap();
        let (o, stderr, _) = run(&p, &[]);
        assert!(!o.status.success(), "{name} read /etc/passwd");
        assert!(
            stderr.contains("sandbox: may not read") && stderr.contains("/etc/passwd"),
            "{name}: {stderr}"
        );
        assert!(
            stderr.contains("--allow-read DIR") && stderr.contains("--trust"),
            "{name}: {stderr}"
        );
        assert!(!stderr.contains(&first), "{name} echoed the file: {stderr}");
    }
    // trusted, the reader opens it (and fails on its content, not on the sandbox)
    let p = script("passwd_trusted", &reads("/etc/passwd"));
    let (_, stderr, _) = run(&p, &["--trust"]);
    assert!(!stderr.contains("sandbox: may not"), "{stderr}");
}

#[test]
fn a_script_reads_its_folder_the_data_folder_and_the_command_lines_paths() {
    let p = script(
        "reads_allowed",
        "let f = kes::fabric(\"fabric.json\");\n\
         let g = kes::fabric(given);\n\
         print(\"read both\");\n",
    );
    let fabric =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/fabrics_small/shirting-cotton.json");
    std::fs::copy(&fabric, p.parent().unwrap().join("fabric.json")).unwrap();
    let given = format!("given={}", fabric.display());
    let (o, stderr, _) = run(&p, &["--set", &given]);
    assert!(o.status.success(), "{stderr}");
    // without the `--set` value, the same file is outside the sandbox
    let (o, stderr, _) = run(&p, &["--set", "given=elsewhere.json"]);
    assert!(!o.status.success());
    assert!(
        !stderr.contains("sandbox: may not"),
        "a --set path is readable: {stderr}"
    );
    let q = script(
        "reads_repository",
        &format!("kes::fabric(\"{}\");\n", fabric.display()),
    );
    let (o, stderr, _) = run(&q, &[]);
    assert!(
        !o.status.success() && stderr.contains("may not read"),
        "{stderr}"
    );
    let allow = format!("--allow-read={}", fabric.parent().unwrap().display());
    let (o, stderr, _) = run(&q, &[&allow]);
    assert!(o.status.success(), "{stderr}");
}

/// A script that saves a small cloth to `path`, a Rhai expression.
fn saves(path: &str) -> String {
    format!(
        "let sim = simulation(cloth_grid(1.0, 1.0, 4, 4, fabric()), #{{}});\n\
         sim.save_obj({path});\n"
    )
}

/// A string literal of Rhai.
fn lit(path: &Path) -> String {
    format!("\"{}\"", path.display())
}

#[test]
fn a_script_writes_only_under_its_output_folders_unless_allowed() {
    let elsewhere = fresh("write_elsewhere_target");
    let target = elsewhere.join("x/cloth.obj");
    let p = script("write_elsewhere", &saves(&lit(&target)));
    let (o, stderr, _) = run(&p, &[]);
    assert!(!o.status.success());
    assert!(
        stderr.contains("sandbox: may not write") && stderr.contains("--allow-write DIR"),
        "{stderr}"
    );
    assert!(!target.exists() && !elsewhere.join("x").exists());
    // nor beside its folder, nor out of `out/` by `..`
    for (name, path) in [
        ("write_script_folder", "\"cloth.obj\""),
        ("write_out_dots", "out_dir() + \"/../../cloth.obj\""),
    ] {
        let p = script(name, &saves(path));
        let (o, stderr, _) = run(&p, &[]);
        assert!(
            !o.status.success() && stderr.contains("may not write"),
            "{name}: {stderr}"
        );
    }
    let allow = format!("--allow-write={}", elsewhere.display());
    let (o, stderr, _) = run(&p, &[&allow]);
    assert!(o.status.success(), "{stderr}");
    assert!(target.is_file());
    std::fs::remove_file(&target).unwrap();
    let (o, stderr, _) = run(&p, &["--trust"]);
    assert!(o.status.success(), "{stderr}");
    assert!(target.is_file());
}

#[test]
fn out_and_the_set_out_folder_are_writable() {
    let p = script("write_out", &saves("out_dir() + \"/a/cloth.obj\""));
    let (o, stderr, _) = run(&p, &[]);
    assert!(o.status.success(), "{stderr}");
    let cwd = p.parent().unwrap().parent().unwrap().join("cwd");
    assert!(cwd.join("out/write_out/a/cloth.obj").is_file());
    let dest = fresh("write_set_out_dest");
    let q = script(
        "write_set_out",
        "let sim = simulation(cloth_grid(1.0, 1.0, 4, 4, fabric()), #{});\n\
         sim.save_obj(out + \"/cloth.obj\");\n",
    );
    let set = format!("out={}", dest.display());
    let (o, stderr, _) = run(&q, &["--set", &set]);
    assert!(o.status.success(), "{stderr}");
    assert!(dest.join("cloth.obj").is_file());
}

#[test]
fn imports_obey_the_read_rule() {
    let p = script(
        "imports",
        "import \"helper\" as h;\nprint(`helper says ${h::answer()}`);\n",
    );
    std::fs::write(
        p.parent().unwrap().join("helper.rhai"),
        "fn answer() { 42 }\n",
    )
    .unwrap();
    let (o, stderr, _) = run(&p, &[]);
    assert!(o.status.success(), "{stderr}");
    assert!(String::from_utf8_lossy(&o.stdout).contains("helper says 42"));
    let outside = fresh("imports_outside");
    std::fs::write(outside.join("m.rhai"), "fn answer() { 1 }\n").unwrap();
    let q = script(
        "imports_refused",
        &format!("import \"{}\" as m;\n", outside.join("m").display()),
    );
    let (o, stderr, _) = run(&q, &[]);
    assert!(
        !o.status.success() && stderr.contains("may not read"),
        "{stderr}"
    );
}

#[test]
fn max_seconds_stops_an_endless_loop_and_a_long_simulation() {
    for (name, source) in [
        ("endless_loop", "loop {}\n"),
        (
            "long_run",
            "let sim = simulation(cloth_grid(1.0, 1.0, 40, 40, fabric()), #{});\nsim.run(3000.0);\n",
        ),
    ] {
        let p = script(name, source);
        let (o, stderr, seconds) = run(&p, &["--max-seconds", "1"]);
        assert!(!o.status.success(), "{name} finished");
        assert!(
            stderr.contains("time limit") && stderr.contains("--max-seconds 1"),
            "{name}: {stderr}"
        );
        assert!(seconds < 10.0, "{name} took {seconds:.1} s");
        // stopped by the script's check (1) or, in a native call that never checks, by the
        // watchdog (4); never by a signal
        assert!(matches!(o.status.code(), Some(1 | 4)), "{name}: {:?}", o.status);
        println!("{name}: stopped after {seconds:.1} s: {}", stderr.trim());
    }
}

#[cfg(unix)]
#[test]
fn max_memory_stops_a_huge_cloth_with_an_error_not_a_signal() {
    let p = script(
        "huge_cloth",
        "let c = cloth_grid(1.0, 1.0, 1999, 1999, fabric());\nprint(\"built\");\n",
    );
    let (o, stderr, seconds) = run(&p, &["--max-memory", "200M"]);
    assert_eq!(o.status.code(), Some(3), "{stderr}");
    assert!(
        stderr.contains("error: the script passed its memory limit --max-memory 200M"),
        "{stderr}"
    );
    assert!(!String::from_utf8_lossy(&o.stdout).contains("built"));
    println!("stopped after {seconds:.1} s: {}", stderr.trim());
    // a small script stays well within the same limit
    let q = script("small_cloth", &saves("out_dir() + \"/small.obj\""));
    let (o, stderr, _) = run(&q, &["--max-memory", "200M"]);
    assert!(o.status.success(), "{stderr}");
}

#[cfg(unix)]
#[test]
fn a_device_as_a_script_is_refused_by_the_file_limit() {
    let (o, stderr, seconds) = run(&fresh("dev_zero").join("script/none.rhai"), &[]);
    assert!(
        !o.status.success() && stderr.contains("cannot read script"),
        "{stderr}"
    );
    let o = Command::new(env!("CARGO_BIN_EXE_emilion"))
        .args(["run", "/dev/zero", "--limit", "max_file_bytes=1000000"])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success());
    assert!(stderr.contains("max_file_bytes"), "{stderr}");
    assert!(seconds < 10.0);
}

#[test]
fn the_repl_states_its_sandbox() {
    let repl = |args: &[&str]| {
        let mut child = Command::new(env!("CARGO_BIN_EXE_emilion"))
            .arg("repl")
            .args(args)
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        child
            .stdin
            .take()
            .unwrap()
            .write_all(b"sandbox\nkes::fabric(\"/etc/passwd\")\n")
            .unwrap();
        let o = child.wait_with_output().unwrap();
        (
            String::from_utf8_lossy(&o.stdout).into_owned(),
            String::from_utf8_lossy(&o.stderr).into_owned(),
        )
    };
    let (stdout, stderr) = repl(&[]);
    assert!(
        stdout.contains("sandbox: reads under") && stdout.contains("sandbox: writes under"),
        "{stdout}"
    );
    assert!(stdout.contains("emilion repl --trust"), "{stdout}");
    assert!(stderr.contains("may not read /etc/passwd"), "{stderr}");
    let (stdout, stderr) = repl(&["--trust"]);
    assert!(stdout.contains("no sandbox"), "{stdout}");
    assert!(!stderr.contains("sandbox: may not"), "{stderr}");
}

#[test]
fn the_shipped_scripts_inputs_beside_them_are_copies_of_their_sources() {
    // the scripts of `scripts/` read only beside themselves and from the data folder (the
    // sandbox); these inputs are kept there as copies, which must not drift from the originals
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    for (copy, source) in [
        (
            "scripts/fabrics/shirting-cotton.json",
            "kawabata/fabrics/shirting-cotton.json",
        ),
        (
            "scripts/fabrics/suiting-hesc.json",
            "kawabata/fabrics/suiting-hesc.json",
        ),
        (
            "scripts/faces/astronaut.pts",
            "tests/data/faces/astronaut.pts",
        ),
    ] {
        let read = |p: &str| std::fs::read(root.join(p)).unwrap();
        assert!(read(copy) == read(source), "{copy} differs from {source}");
    }
}
