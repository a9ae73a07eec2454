//! The `emilion sweep` subcommands: `run` a manifest locally (`--local -j N`) or as a Slurm
//! job array (`--slurm [--dry-run]`), `task` (one run, what an array task calls), `list` the
//! runs and their states, and `collect` the results (docs/sweeps.md).

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::Context;
use clap::Subcommand;
use emilion::sweep::{self, LocalOptions, RunState, Sweep};

/// What `emilion sweep` does.
#[derive(Subcommand)]
pub enum SweepCommand {
    /// Runs the missing runs of a sweep, here (`--local -j N`, the default) or as a Slurm job
    /// array (`--slurm`).
    Run {
        /// The manifest (TOML).
        manifest: PathBuf,
        /// Runs on this machine (the default).
        #[arg(long, conflicts_with = "slurm")]
        local: bool,
        /// Child processes at a time (local).
        #[arg(short = 'j', long = "jobs", default_value_t = 1)]
        jobs: usize,
        /// Writes an `sbatch --array` script and submits it.
        #[arg(long)]
        slurm: bool,
        /// With `--slurm`: only writes the script and the runs list.
        #[arg(long, requires = "slurm")]
        dry_run: bool,
        /// Runs the failed runs again too.
        #[arg(long)]
        retry_failed: bool,
        /// Output root instead of the manifest's `out`.
        #[arg(long, value_name = "DIR")]
        out: Option<PathBuf>,
    },
    /// Runs one run of a sweep by its id (what each Slurm array task calls).
    Task {
        /// The manifest (TOML).
        manifest: PathBuf,
        /// The run's id (`emilion sweep list`).
        #[arg(long)]
        id: String,
        /// Output root instead of the manifest's `out`.
        #[arg(long, value_name = "DIR")]
        out: Option<PathBuf>,
    },
    /// Lists the runs of a sweep: index, id, state, parameters.
    List {
        /// The manifest (TOML).
        manifest: PathBuf,
        /// Output root instead of the manifest's `out`.
        #[arg(long, value_name = "DIR")]
        out: Option<PathBuf>,
    },
    /// Collects each run's last `key=value` line into results.csv and summary.md (and the
    /// manifest's plots) in the sweep's folder.
    Collect {
        /// The manifest (TOML).
        manifest: PathBuf,
        /// Output root instead of the manifest's `out`.
        #[arg(long, value_name = "DIR")]
        out: Option<PathBuf>,
    },
}

fn load(manifest: &Path, out: Option<&Path>) -> anyhow::Result<Sweep> {
    Ok(Sweep::load(manifest, out)?)
}

fn exe() -> anyhow::Result<PathBuf> {
    std::env::current_exe().context("cannot find the emilion binary (current_exe)")
}

/// Runs a sweep subcommand.
pub fn sweep_command(cmd: SweepCommand) -> anyhow::Result<ExitCode> {
    match cmd {
        SweepCommand::Run {
            manifest,
            local: _,
            jobs,
            slurm,
            dry_run,
            retry_failed,
            out,
        } => {
            let s = load(&manifest, out.as_deref())?;
            if slurm {
                return run_slurm(&s, dry_run, retry_failed);
            }
            let opts = LocalOptions {
                jobs,
                retry_failed,
                exe: exe()?,
                progress: true,
            };
            let summary = sweep::run_local(&s, &opts)?;
            for f in &summary.failed {
                eprintln!("failed: {}", f.report());
            }
            if summary.skipped_failed > 0 {
                eprintln!(
                    "{} failed run(s) left as they were: rerun them with --retry-failed",
                    summary.skipped_failed
                );
            }
            println!(
                "runs={} ran={} skipped_complete={} done={} failed={} folder={}",
                s.runs.len(),
                summary.ran,
                summary.skipped_done,
                summary.done,
                summary.failed.len(),
                s.manifest.sweep_dir().display()
            );
            Ok(if summary.failed.is_empty() {
                ExitCode::SUCCESS
            } else {
                ExitCode::FAILURE
            })
        }
        SweepCommand::Task { manifest, id, out } => {
            let s = load(&manifest, out.as_deref())?;
            let run = s.find(&id)?;
            if s.state(run) == RunState::Done {
                println!("{id}: complete already");
                return Ok(ExitCode::SUCCESS);
            }
            match s.execute(run, &exe()?)? {
                RunState::Done => Ok(ExitCode::SUCCESS),
                state => {
                    eprintln!("{id}: {state:?}");
                    Ok(ExitCode::FAILURE)
                }
            }
        }
        SweepCommand::List { manifest, out } => {
            let s = load(&manifest, out.as_deref())?;
            for r in &s.runs {
                let state = match s.state(r) {
                    RunState::Done => "done".to_string(),
                    RunState::Missing => "missing".to_string(),
                    RunState::Failed(why) => format!("failed ({why})"),
                };
                let sets: Vec<String> = r.sets.iter().map(|(k, v)| format!("{k}={v}")).collect();
                println!("{}\t{}\t{}\t{}", r.index, r.id, state, sets.join(" "));
            }
            Ok(ExitCode::SUCCESS)
        }
        SweepCommand::Collect { manifest, out } => {
            let s = load(&manifest, out.as_deref())?;
            let c = sweep::collect(&s)?;
            println!("{}", c.csv.display());
            println!("{}", c.md.display());
            for p in &c.other {
                println!("{}", p.display());
            }
            println!(
                "complete={} failed={} missing={}",
                c.counts[0], c.counts[1], c.counts[2]
            );
            Ok(ExitCode::SUCCESS)
        }
    }
}

fn run_slurm(s: &Sweep, dry_run: bool, retry_failed: bool) -> anyhow::Result<ExitCode> {
    let Some(job) = sweep::slurm::write_job(s, &exe()?, retry_failed)? else {
        println!("every run is complete: nothing to submit");
        return Ok(ExitCode::SUCCESS);
    };
    println!("{}", job.script.display());
    println!("{}", job.runs_list.display());
    if dry_run {
        println!("tasks={} (not submitted: --dry-run)", job.tasks);
        return Ok(ExitCode::SUCCESS);
    }
    if !sweep::slurm::available() {
        anyhow::bail!(
            "sbatch not found: submit {} yourself, or use --dry-run",
            job.script.display()
        );
    }
    let id = sweep::slurm::submit(&job)?;
    println!("tasks={} job={id}", job.tasks);
    Ok(ExitCode::SUCCESS)
}
