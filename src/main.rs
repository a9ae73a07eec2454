//! The `emilion` command: the demo scene (no arguments), `run` a script, the `repl`, API `doc`s
//! and the `bench` benchmark.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Context;
use clap::{Parser, Subcommand};

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
            let ckpt = script::checkpoint::CheckpointSettings {
                every: checkpoint.unwrap_or(0),
                file: checkpoint_file,
                resume,
            };
            if let Err(e) = script::checkpoint::configure(&file, &sets, &ckpt) {
                eprintln!("error: {e}");
                return Ok(ExitCode::FAILURE);
            }
            if let Err(e) = script::run_file(&file, &sets) {
                eprintln!("{e}");
                return Ok(ExitCode::FAILURE);
            }
        }
        Command::Repl { init } => {
            script::repl::repl(init.as_deref()).map_err(anyhow::Error::msg)?
        }
        Command::Doc { out_dir } => {
            for p in script::docs::write_docs(&out_dir)
                .with_context(|| format!("writing {}", out_dir.display()))?
            {
                println!("{}", p.display());
            }
        }
        Command::Bench { .. } => unreachable!("handled in run"),
    }
    Ok(ExitCode::SUCCESS)
}

#[cfg(not(feature = "scripting"))]
fn scripting(_: Command) -> anyhow::Result<ExitCode> {
    eprintln!("emilion was built without the `scripting` feature: run, repl and doc are disabled");
    Ok(ExitCode::from(2))
}
