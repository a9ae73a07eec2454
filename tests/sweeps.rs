//! Sweeps (docs/sweeps.md): manifest expansion (cartesian, zip, seeds, ranges, glob) in the
//! documented order with stable ids, bad manifests named, a local sweep of the tiny script
//! collected against the analytic sums, identical tables with one and two processes, a
//! restarted sweep running only what is missing, a failing run reported while the others
//! complete, and the Slurm script of a 618-run manifest. The cluster itself is tested by
//! tests/slurm/single_node.sh.

use std::path::{Path, PathBuf};

use emilion::sweep::{self, expand, LocalOptions, Manifest, Sweep};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// A fresh, empty folder under the target's test temp dir.
fn temp_dir(name: &str) -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("sweeps")
        .join(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Writes a manifest (and the tiny script beside it) into a fresh folder; returns its path.
fn manifest(name: &str, body: &str) -> PathBuf {
    let d = temp_dir(name);
    std::fs::copy(root().join("scripts/sweeps/tiny.rhai"), d.join("tiny.rhai")).unwrap();
    let p = d.join(format!("{name}.toml"));
    std::fs::write(
        &p,
        format!(
            "script = \"tiny.rhai\"\nout = \"{}\"\n{body}",
            d.join("out").display()
        ),
    )
    .unwrap();
    p
}

fn local(s: &Sweep, jobs: usize, retry_failed: bool) -> sweep::LocalSummary {
    let opts = LocalOptions {
        jobs,
        retry_failed,
        exe: PathBuf::from(env!("CARGO_BIN_EXE_emilion")),
        progress: false,
    };
    sweep::run_local(s, &opts).unwrap()
}

#[test]
fn expansion_is_cartesian_zipped_seeded_and_globbed_in_a_fixed_order() {
    let p = manifest(
        "expand",
        "[params]\nn = [1, 2]\nx = 0.5\n[zip]\na = [1, 2, 3]\nb = [\"u\", \"v\", \"w\"]\n\
         [seeds]\ncount = 2\nstart = 5\n[files]\nscript_file = \"*.rhai\"\n[ranges]\nrow = { start = 0, end = 5, step = 2 }\n",
    );
    std::fs::write(p.parent().unwrap().join("other.rhai"), "print(1);").unwrap();
    let m = Manifest::load(&p).unwrap();
    let runs = expand(&m).unwrap();
    // files 2 × n 2 × x 1 × zip 3 × row 3 × seeds 2
    assert_eq!(runs.len(), 2 * 2 * 3 * 3 * 2);
    // the documented order: files, params (sorted keys), zip, ranges, seeds (fastest)
    let keys: Vec<&str> = runs[0].sets.iter().map(|(k, _)| k.as_str()).collect();
    assert_eq!(keys, ["script_file", "n", "x", "a", "b", "row", "seed"]);
    assert!(
        runs[0]
            .id
            .starts_with("script_file-other_n-1_x-0.5_a-1_b-u_row-0_seed-5-"),
        "{}",
        runs[0].id
    );
    let values = |i: usize| -> Vec<String> {
        runs[i]
            .sets
            .iter()
            .skip(1)
            .map(|(_, v)| v.clone())
            .collect()
    };
    assert_eq!(values(0), ["1", "0.5", "1", "u", "0", "5"]);
    assert_eq!(values(1), ["1", "0.5", "1", "u", "0", "6"]);
    assert_eq!(values(2), ["1", "0.5", "1", "u", "2", "5"]);
    assert_eq!(values(6), ["1", "0.5", "2", "v", "0", "5"]);
    assert_eq!(values(18), ["2", "0.5", "1", "u", "0", "5"]);
    // files sorted by path: other.rhai before tiny.rhai, absolute
    assert!(
        runs[0].sets[0].1.ends_with("other.rhai") && Path::new(&runs[0].sets[0].1).is_absolute()
    );
    assert!(runs[36].sets[0].1.ends_with("tiny.rhai"));
    // a float stays a float for the script, an integer an integer
    assert!(runs.iter().all(|r| r.sets[2].1 == "0.5"));
}

#[test]
fn ids_are_stable_and_made_of_the_values() {
    let p = manifest("ids", "[params]\nn = [1, 20]\n[seeds]\ncount = 2\n");
    let m = Manifest::load(&p).unwrap();
    let ids: Vec<String> = expand(&m).unwrap().into_iter().map(|r| r.id).collect();
    assert_eq!(
        ids,
        ["n-1_seed-0", "n-1_seed-1", "n-20_seed-0", "n-20_seed-1"]
    );
    // the same manifest read again (another process, another day) gives the same ids
    let again: Vec<String> = expand(&Manifest::load(&p).unwrap())
        .unwrap()
        .into_iter()
        .map(|r| r.id)
        .collect();
    assert_eq!(ids, again);
    // values that cannot be a folder name are cleaned and hashed, still stable and distinct
    let p = manifest("ids_hashed", "[params]\nname = [\"a/b\", \"a b\"]\n");
    let ids: Vec<String> = expand(&Manifest::load(&p).unwrap())
        .unwrap()
        .into_iter()
        .map(|r| r.id)
        .collect();
    assert_ne!(ids[0], ids[1]);
    assert!(
        ids.iter()
            .all(|i| i.starts_with("name-a~b-") && !i.contains('/')),
        "{ids:?}"
    );
}

#[test]
fn bad_manifests_name_the_file_and_the_field() {
    let cases = [
        ("[params]\nn = []\n", "params.n"),
        ("[zip]\na = [1, 2]\nb = [1]\n", "zip.b"),
        ("[params]\nn = 1\n[seeds]\nname = \"n\"\ncount = 2\n", "already set"),
        ("[ranges]\nrow = { start = 0, end = 2000000 }\n", "max_elements"),
        ("[ranges]\nrow = { start = 5, end = 1 }\n", "ranges.row"),
        ("[params]\na = [1, 2, 3, 4, 5, 6, 7, 8, 9, 10]\nb = [1, 2, 3, 4, 5, 6, 7, 8, 9, 10]\n[ranges]\nrow = { start = 0, end = 100000 }\n", "max_elements"),
        ("[params]\n\"bad key\" = 1\n", "script constant"),
        ("[params]\nx = nan\n", "finite"),
        ("[files]\nf = \"*.nothing\"\n", "matches no file"),
        ("[resources]\nmemory = \"1G; rm -rf /\"\n", "resources.memory"),
        ("args = [\"--set\", \"n=1\"]\n", "args"),
        ("colour = 3\n", "colour"),
    ];
    for (i, (body, needle)) in cases.iter().enumerate() {
        let p = manifest(&format!("bad{i}"), body);
        let e = Manifest::load(&p)
            .and_then(|m| expand(&m).map(|_| ()))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains(&p.display().to_string()) && e.contains(needle),
            "{body}: {e}"
        );
    }
}

/// The `n`, `sum` columns of a results table: every complete run's sum is n(n+1)/2.
fn check_sums(csv: &str) {
    let mut lines = csv.lines();
    let head: Vec<&str> = lines.next().unwrap().split(',').collect();
    // every column once: a printed key that is also a parameter is not repeated
    for (i, h) in head.iter().enumerate() {
        assert!(!head[..i].contains(h), "column {h} twice in {head:?}");
    }
    let col = |name: &str| head.iter().position(|h| *h == name).unwrap();
    let (n, sum, status) = (col("n"), col("sum"), col("status"));
    for l in lines {
        let c: Vec<&str> = l.split(',').collect();
        if c[status] == "done" {
            let n: i64 = c[n].parse().unwrap();
            assert_eq!(c[sum].parse::<i64>().unwrap(), n * (n + 1) / 2, "{l}");
        }
    }
}

#[test]
fn one_and_two_processes_give_identical_tables() {
    let p = manifest(
        "jobs",
        "[params]\nn = [1, 2, 3, 10, 100]\n[zip]\nx = [0.0, 0.5]\nlabel = [\"zero\", \"half\"]\n",
    );
    let one = Sweep::load(&p, Some(&p.parent().unwrap().join("one"))).unwrap();
    let two = Sweep::load(&p, Some(&p.parent().unwrap().join("two"))).unwrap();
    let s1 = local(&one, 1, false);
    let s2 = local(&two, 2, false);
    assert_eq!((s1.ran, s1.done, s1.failed.len()), (10, 10, 0));
    assert_eq!((s2.ran, s2.done, s2.failed.len()), (10, 10, 0));
    let c1 = sweep::collect(&one).unwrap();
    let c2 = sweep::collect(&two).unwrap();
    let t1 = std::fs::read_to_string(&c1.csv).unwrap();
    assert_eq!(t1, std::fs::read_to_string(&c2.csv).unwrap());
    check_sums(&t1);
    assert_eq!(t1.lines().count(), 11);
    // sin(0.5) as Rust prints it, the analytic value to the last bit
    assert!(t1.contains(&format!("{}", 0.5f64.sin())), "{t1}");
    assert!(std::fs::read_to_string(&c1.md)
        .unwrap()
        .contains("10 complete, 0 failed, 0 missing"));
}

#[test]
fn a_restarted_sweep_runs_only_what_is_missing() {
    let p = manifest("restart", "[params]\nn = [1, 2, 3, 4, 5, 6]\n");
    let s = Sweep::load(&p, None).unwrap();
    assert_eq!(local(&s, 2, false).ran, 6);
    // a killed sweep: one run never started, one stopped midway (parameters and logs written,
    // no exit status, no done marker)
    let killed = s.run_dir(&s.runs[2]);
    std::fs::remove_file(killed.join("done")).unwrap();
    std::fs::remove_file(killed.join("status.json")).unwrap();
    std::fs::remove_dir_all(s.run_dir(&s.runs[5])).unwrap();
    let kept = std::fs::read_to_string(s.run_dir(&s.runs[0]).join("status.json")).unwrap();
    std::fs::write(
        s.run_dir(&s.runs[0]).join("stdout.log"),
        "n=1 sum=1 untouched=yes\n",
    )
    .unwrap();
    let again = local(&s, 2, false);
    assert_eq!((again.ran, again.skipped_done, again.done), (2, 4, 6));
    // the complete runs were not run again
    assert_eq!(
        std::fs::read_to_string(s.run_dir(&s.runs[0]).join("status.json")).unwrap(),
        kept
    );
    let csv = std::fs::read_to_string(sweep::collect(&s).unwrap().csv).unwrap();
    assert!(csv.contains("yes"), "{csv}");
    check_sums(&csv);
    // nothing left: a third start runs nothing
    assert_eq!(local(&s, 1, false).ran, 0);
}

#[test]
fn a_failing_run_is_reported_and_the_others_complete() {
    let p = manifest(
        "failing",
        "[params]\nn = [1, 2, 3, 4]\n[zip]\nfail = [false, true]\nx = [0.25, 0.75]\n",
    );
    let s = Sweep::load(&p, None).unwrap();
    let r = local(&s, 2, false);
    assert_eq!((r.ran, r.done, r.failed.len()), (8, 4, 4));
    let f = &r.failed[0];
    assert_eq!(f.run.id, "n-1_fail-true_x-0.75");
    let report = f.report();
    assert!(
        report.contains("fail=true") && report.contains("n=1"),
        "{report}"
    );
    assert!(
        f.error_tail
            .iter()
            .any(|l| l.contains("asked to fail (n=1)")),
        "{:?}",
        f.error_tail
    );
    let c = sweep::collect(&s).unwrap();
    assert_eq!(c.counts, [4, 4, 0]);
    let csv = std::fs::read_to_string(&c.csv).unwrap();
    assert_eq!(csv.matches(",FAILED,").count(), 4, "{csv}");
    check_sums(&csv);
    let md = std::fs::read_to_string(&c.md).unwrap();
    assert!(
        md.contains("## Failed runs") && md.contains("asked to fail (n=3)"),
        "{md}"
    );
    // restarted: failed runs are left alone unless retried
    let again = local(&s, 2, false);
    assert_eq!(
        (again.ran, again.skipped_failed, again.failed.len()),
        (0, 4, 4)
    );
    let retried = local(&s, 2, true);
    assert_eq!((retried.ran, retried.failed.len()), (4, 4));
}

#[test]
fn missing_runs_are_marked_in_the_table() {
    let p = manifest("missing", "[params]\nn = [1, 2, 3]\n");
    let s = Sweep::load(&p, None).unwrap();
    let c = sweep::collect(&s).unwrap();
    assert_eq!(c.counts, [0, 0, 3]);
    assert_eq!(
        std::fs::read_to_string(&c.csv)
            .unwrap()
            .matches(",MISSING,")
            .count(),
        3
    );
}

#[test]
fn the_slurm_script_has_one_task_per_pending_run() {
    let p = manifest(
        "slurm",
        "checkpoint = 5\n[ranges]\nrow = { start = 0, end = 618 }\n[resources]\nthreads = 2\nmemory = \"1G\"\ntime = \"00:10:00\"\nthrottle = 16\n",
    );
    let s = Sweep::load(&p, None).unwrap();
    let exe = PathBuf::from(env!("CARGO_BIN_EXE_emilion"));
    let job = sweep::slurm::write_job(&s, &exe, false).unwrap().unwrap();
    assert_eq!(job.tasks, 618);
    let text = std::fs::read_to_string(&job.script).unwrap();
    for line in [
        "#SBATCH --array=0-617%16",
        "#SBATCH --cpus-per-task=2",
        "#SBATCH --mem=1G",
        "#SBATCH --time=00:10:00",
        "#SBATCH --requeue",
    ] {
        assert!(text.contains(line), "{line} in\n{text}");
    }
    let list = std::fs::read_to_string(&job.runs_list).unwrap();
    let ids: Vec<&str> = list.lines().collect();
    assert_eq!(ids.len(), 618);
    assert_eq!((ids[0], ids[617]), ("row-0", "row-617"));
    // each task's command: the same `emilion run` with the run's checkpoint file
    let args = s.run_args(&s.runs[7], &s.run_dir(&s.runs[7]));
    assert!(
        args.windows(2).any(|w| w[0] == "--set" && w[1] == "row=7"),
        "{args:?}"
    );
    assert!(
        args.iter().any(|a| a.ends_with("row-7/run.ckpt")),
        "{args:?}"
    );
}

/// A run that takes about a second: `spin` loop steps, then one key=value line.
const SPIN_SCRIPT: &str = r#"
let n = if is_def_var("n") { n } else { 1 };
let spin = if is_def_var("spin") { spin } else { 1000 };
print(`started n=${n}`);
let s = 0;
for k in 0..spin { s += k % 7; }
print(`n=${n} sum=${n * (n + 1) / 2} spin=${s}`);
"#;

/// Loop steps of a spin run: about a second here (a loaded 2-core machine).
const SPIN_STEPS: i64 = 3_000_000;

/// The processes whose working folder lies under `dir` (the runs of a sweep there).
#[cfg(target_os = "linux")]
fn processes_in(dir: &Path) -> Vec<u32> {
    let mut pids = Vec::new();
    for e in std::fs::read_dir("/proc").unwrap().flatten() {
        let Ok(pid) = e.file_name().to_string_lossy().parse::<u32>() else {
            continue;
        };
        if let Ok(cwd) = std::fs::read_link(e.path().join("cwd")) {
            if cwd.starts_with(dir) {
                pids.push(pid);
            }
        }
    }
    pids
}

/// Polls `f` every 10 ms for at most `seconds`; whether it became true.
fn wait_for(seconds: f64, mut f: impl FnMut() -> bool) -> bool {
    let start = std::time::Instant::now();
    while start.elapsed().as_secs_f64() < seconds {
        if f() {
            return true;
        }
        std::thread::sleep(std::time::Duration::from_millis(10));
    }
    f()
}

#[cfg(target_os = "linux")]
#[test]
fn a_killed_sweep_leaves_no_orphans_and_its_restart_runs_only_the_missing_runs() {
    use std::process::{Command, Stdio};
    let d = temp_dir("killed");
    std::fs::write(d.join("spin.rhai"), SPIN_SCRIPT).unwrap();
    let p = d.join("killed.toml");
    std::fs::write(
        &p,
        format!(
            "script = \"spin.rhai\"\nout = \"{}\"\n[params]\nn = [1, 2, 3, 4, 5, 6]\nspin = {SPIN_STEPS}\n",
            d.join("out").display()
        ),
    )
    .unwrap();
    let s = Sweep::load(&p, None).unwrap();
    let sweep_dir = s.manifest.sweep_dir();
    let exe = env!("CARGO_BIN_EXE_emilion");
    let mut child = Command::new(exe)
        .args(["sweep", "run", p.to_str().unwrap(), "--local", "-j", "2"])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let done = |s: &Sweep| {
        s.runs
            .iter()
            .filter(|r| s.state(r) == sweep::RunState::Done)
            .count()
    };
    // kill it (SIGKILL) while runs are going, after at least one is complete
    let mut running = Vec::new();
    assert!(
        wait_for(120.0, || {
            running = processes_in(&sweep_dir);
            done(&s) >= 1 && !running.is_empty()
        }),
        "no run completed"
    );
    child.kill().unwrap();
    child.wait().unwrap();
    let done_before = done(&s);
    assert!(
        done_before < s.runs.len(),
        "every run ended before the kill"
    );
    // its children die with it: no orphan goes on writing into its run's folder
    assert!(
        wait_for(1.0, || processes_in(&sweep_dir).is_empty()),
        "orphans {:?} (running at the kill: {running:?})",
        processes_in(&sweep_dir)
    );
    let logs = |s: &Sweep| -> Vec<Option<String>> {
        s.runs
            .iter()
            .map(|r| std::fs::read_to_string(s.run_dir(r).join("status.json")).ok())
            .collect()
    };
    let status_before = logs(&s);
    // restarted: only the missing runs start
    let again = Command::new(exe)
        .args(["sweep", "run", p.to_str().unwrap(), "--local", "-j", "2"])
        .output()
        .unwrap();
    assert!(again.status.success(), "{again:?}");
    let line = String::from_utf8_lossy(&again.stdout).to_string();
    let missing = s.runs.len() - done_before;
    assert!(
        line.contains(&format!(
            "runs=6 ran={missing} skipped_complete={done_before} done=6 failed=0"
        )),
        "{line}"
    );
    for (r, (before, after)) in s.runs.iter().zip(status_before.iter().zip(logs(&s))) {
        // a run complete before the kill was not run again: its exit record is the same file
        if before.is_some() {
            assert_eq!(before.as_ref(), after.as_ref(), "{}", r.id);
        }
        let out = std::fs::read_to_string(s.run_dir(r).join("stdout.log")).unwrap();
        assert_eq!(out.matches("started").count(), 1, "{}: {out}", r.id);
    }
    assert_eq!(status_before.iter().flatten().count(), done_before);
    // the collected table is an uninterrupted sweep's
    let whole = Sweep::load(&p, Some(&d.join("whole"))).unwrap();
    assert_eq!(local(&whole, 2, false).done, 6);
    let t = std::fs::read_to_string(sweep::collect(&s).unwrap().csv).unwrap();
    let t_whole = std::fs::read_to_string(sweep::collect(&whole).unwrap().csv).unwrap();
    assert_eq!(t, t_whole);
    check_sums(&t);
}
