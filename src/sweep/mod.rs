//! Sweeps: many independent `emilion run` processes described by one manifest (TOML), each
//! with its own `--set` values and its own folder `out/<sweep>/<id>/`, run on this machine
//! ([`local`]) or as a Slurm job array ([`slurm`]), and collected into one table
//! ([`mod@collect`]). The manifest ([`manifest`]) expands into runs with stable ids ([`mod@expand`]);
//! a run's folder records its parameters, logs, exit status and a `done` marker written last
//! ([`run_dir`]), so a restarted sweep runs only what is missing.
//!
//! This layer starts the `emilion` binary as child processes; it does not link the scripting
//! layer, so a run behaves the same in a sweep and alone. Guide: docs/sweeps.md.

pub mod collect;
pub mod error;
pub mod expand;
pub mod local;
pub mod manifest;
pub mod run_dir;
pub mod slurm;

pub use collect::{collect, Collected};
pub use error::SweepError;
pub use expand::{expand, Run};
pub use local::{run_local, LocalOptions, LocalSummary};
pub use manifest::Manifest;
pub use run_dir::{RunState, Sweep};
