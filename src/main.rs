//! The `emilion` command: the demo scene (no arguments), `run` a script, the `repl`, API `doc`s
//! and the `bench` benchmark. A script runs in the sandbox (`--trust` lifts it) and within
//! `--max-memory` / `--max-seconds` when given ([`run_limits`]).

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Context;
use clap::{Args, Parser, Subcommand};

#[path = "cli/run_limits.rs"]
mod run_limits;
#[path = "cli/sweep_cmd.rs"]
mod sweep_cmd;

#[global_allocator]
static ALLOCATOR: run_limits::CountingAlloc = run_limits::CountingAlloc;

/// Cloth simulation with measured fabrics, scripted in Rhai.
#[derive(Parser)]
#[command(name = "emilion", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
    /// Output folder of the demo scene (no subcommand).
    #[arg(long, default_value = "out")]
    out: PathBuf,
}

#[derive(Subcommand)]
enum Command {
    /// Runs a Rhai script.
    Run {
        /// The script file.
        file: PathBuf,
        /// Defines a script constant before running: `--set key=value` (int, float, bool or string).
        #[arg(long = "set", value_name = "KEY=VALUE", value_parser = parse_set)]
        sets: Vec<(String, String)>,
        /// Raises or lowers a stated input limit: `--limit max_particles=10000000` (names and
        /// defaults in docs/limits.md).
        #[arg(long = "limit", value_name = "NAME=VALUE", value_parser = parse_set)]
        limits: Vec<(String, String)>,
        #[command(flatten)]
        sandbox: SandboxArgs,
        /// Ends the run once it has allocated more than this much memory (bytes, or with a
        /// suffix K, M, G, T: `4G`, `500M`), with an error and exit status 3.
        #[arg(long, value_name = "BYTES", value_parser = parse_memory)]
        max_memory: Option<(u64, String)>,
        /// Stops the script after this many seconds of wall time with an error (replacing the
        /// engine's operation limit); a native call that does not stop a few seconds later ends
        /// the process with exit status 4.
        #[arg(long, value_name = "S", value_parser = run_limits::parse_seconds)]
        max_seconds: Option<f64>,
        /// Checkpoints the run every EVERY frames of `run_frames` and of a tracking run (steps
        /// of `run` and `run_steps`), and when each such call ends (docs/checkpoints.md).
        #[arg(long, value_name = "EVERY")]
        checkpoint: Option<u64>,
        /// Where the checkpoint goes (default: the file resumed, else out/<script name>.ckpt).
        #[arg(long, value_name = "FILE")]
        checkpoint_file: Option<PathBuf>,
        /// Resumes a run killed after writing this checkpoint: the script runs again, finished
        /// calls take their saved end states, the call in progress continues.
        #[arg(long, value_name = "FILE")]
        resume: Option<PathBuf>,
    },
    /// Interactive Rhai prompt with every emilion function.
    Repl {
        /// A script to run first (its variables and functions stay available).
        init: Option<PathBuf>,
        #[command(flatten)]
        sandbox: SandboxArgs,
    },
    /// Writes the script API reference (api.md, api.json) into a folder.
    Doc {
        /// Output folder.
        out_dir: PathBuf,
    },
    /// Benchmarks the peer scenes; prints one JSON line per scene and size.
    Bench {
        /// Scenes, comma-separated: hang, drape, hang_self.
        #[arg(long, default_value = "hang")]
        scenes: String,
        /// Particles per side, comma-separated.
        #[arg(long, default_value = "32,64,128,256")]
        sizes: String,
        /// Timed runs per size (after one warm-up run).
        #[arg(long, default_value_t = 5)]
        runs: usize,
        /// Frames per run (5 substeps each).
        #[arg(long, default_value_t = 50)]
        frames: u32,
    },
    /// Sweeps: many runs of one script from a manifest, here or on Slurm (docs/sweeps.md).
    Sweep {
        #[command(subcommand)]
        command: sweep_cmd::SweepCommand,
    },
}

/// The sandbox flags of `run` and `repl` (docs/scripting.md, "Sandbox").
#[derive(Args)]
struct SandboxArgs {
    /// Lifts the sandbox: the script reads and writes whatever you may.
    #[arg(long)]
    trust: bool,
    /// Lets the script write (and read) under DIR too (repeatable).
    #[arg(long = "allow-write", value_name = "DIR")]
    allow_write: Vec<PathBuf>,
    /// Lets the script read under DIR too (repeatable).
    #[arg(long = "allow-read", value_name = "DIR")]
    allow_read: Vec<PathBuf>,
}

#[cfg(feature = "scripting")]
impl SandboxArgs {
    fn sandbox(self) -> emilion::script::Sandbox {
        emilion::script::Sandbox {
            trusted: self.trust,
            allow_write: self.allow_write,
            allow_read: self.allow_read,
        }
    }
}

fn parse_memory(s: &str) -> Result<(u64, String), String> {
    run_limits::parse_size(s).map(|b| (b, s.trim().to_string()))
}

fn parse_set(s: &str) -> Result<(String, String), String> {
    match s.split_once('=') {
        Some((k, v)) if !k.trim().is_empty() => Ok((k.trim().to_string(), v.to_string())),
        _ => Err(format!("expected KEY=VALUE, got `{s}`")),
    }
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match run(cli) {
        Ok(code) => code,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}

fn run(cli: Cli) -> anyhow::Result<ExitCode> {
    match cli.command {
        None => {
            for p in emilion::scenes::demo(&cli.out).context("demo scene")? {
                println!("{}", p.display());
            }
        }
        Some(Command::Bench {
            scenes,
            sizes,
            runs,
            frames,
        }) => {
            for scene in scenes.split(',') {
                for s in sizes.split(',') {
                    let n: usize = s
                        .trim()
                        .parse()
                        .with_context(|| format!("bad size `{s}`"))?;
                    let r = emilion::bench::bench_scene(scene.trim(), n, frames, runs)?;
                    println!("{}", serde_json::to_string(&r)?);
                }
            }
        }
        Some(Command::Sweep { command }) => return sweep_cmd::sweep_command(command),
        Some(cmd) => return scripting(cmd),
    }
    Ok(ExitCode::SUCCESS)
}

#[cfg(feature = "scripting")]
fn scripting(cmd: Command) -> anyhow::Result<ExitCode> {
    use emilion::script;
    match cmd {
        Command::Run {
            file,
            sets,
            limits,
            sandbox,
            max_memory,
            max_seconds,
            checkpoint,
            checkpoint_file,
            resume,
        } => {
            let mut l = emilion::limits::get();
            for (k, v) in &limits {
                let n: u64 = v
                    .trim()
                    .replace('_', "")
                    .parse()
                    .map_err(|_| anyhow::anyhow!("--limit {k}: `{v}` is not a whole number"))?;
                l.set_named(k, n)
                    .map_err(|e| anyhow::anyhow!("--limit: {e}"))?;
            }
            emilion::limits::set(l);
            if let Some((bytes, text)) = &max_memory {
                run_limits::set_max_memory(*bytes, text);
            }
            if let Some(s) = max_seconds {
                emilion::limits::set_deadline(std::time::Duration::from_secs_f64(s));
                run_limits::start_watchdog(s, &format!("{s}"));
            }
            let mut options = script::RunOptions {
                sandbox: sandbox.sandbox(),
                ..script::RunOptions::default()
            };
            if max_seconds.is_some() {
                // the time limit bounds the run instead of the operation count
                options.engine.max_operations = 0;
            }
            let ckpt = script::checkpoint::CheckpointSettings {
                every: checkpoint.unwrap_or(0),
                file: checkpoint_file,
                resume,
            };
            if let Err(e) = script::checkpoint::configure(&file, &sets, &ckpt) {
                eprintln!("error: {e}");
                return Ok(ExitCode::FAILURE);
            }
            if let Err(e) = script::run_file_with(&file, &sets, &options) {
                eprintln!("{e}");
                return Ok(ExitCode::FAILURE);
            }
        }
        Command::Repl { init, sandbox } => {
            script::repl::repl(init.as_deref(), &sandbox.sandbox()).map_err(anyhow::Error::msg)?
        }
        Command::Doc { out_dir } => {
            for p in script::docs::write_docs(&out_dir)
                .with_context(|| format!("writing {}", out_dir.display()))?
            {
                println!("{}", p.display());
            }
        }
        Command::Bench { .. } | Command::Sweep { .. } => unreachable!("handled in run"),
    }
    Ok(ExitCode::SUCCESS)
}

#[cfg(not(feature = "scripting"))]
fn scripting(_: Command) -> anyhow::Result<ExitCode> {
    eprintln!("emilion was built without the `scripting` feature: run, repl and doc are disabled");
    Ok(ExitCode::from(2))
}
