//! Rhai scripting: a thin layer that registers the engine's types and functions with a Rhai
//! [`Engine`] and owns nothing else. Scripts build fabrics, cloths and simulations, run them
//! and write meshes, statistics and pictures; all numeric work stays in Rust.
//!
//! Free functions live in static modules by domain (`cloth::grid`, `kes::lab`, `face::fit`, …;
//! see [`modules`]), methods and properties of the handles stay global (`sim.run(…)`).
//!
//! - [`modules`]: the modules, the builder that collects them, the old names kept as aliases;
//! - [`convert`]: error conversion, numbers and vectors, `…Parameters` ⇄ object maps;
//! - [`fabric`]: the `Fabric` value type and the `Cloth` handle (`cloth::fabric()`, `cloth::grid`, …);
//! - [`sim`]: the `Simulation` handle and its constraints; [`sim_run`]: stepping, runs with
//!   per-frame callbacks; [`checkpoint`]: checkpoints and resumed runs, [`captured`]: the
//!   variables their callbacks captured;
//! - [`contact`]: collision bodies, the mannequin, friction, contact settings and read-outs;
//! - [`output`]: positions, bounds, energies, OBJ/glTF/CSV/JSON/PNG output;
//! - [`kes`]: the virtual Kawabata lab (fabric files, rigs, fitting, summaries);
//! - [`facade`], [`facade_analysis`]: facade label maps, scores and the photo pipeline;
//! - [`facade_learned`]: the learned facade classifier (training, evaluation);
//! - [`tracking_sequence`], [`tracking`]: synthetic multi-camera sequences and the body tracker;
//! - [`paths`]: where a script's relative paths lead (its own folder), `script_dir()`,
//!   `data_dir()`, `out_dir()`; [`sandbox`]: what a script may read and write; [`imports`]:
//!   `import "module"` through the same rules;
//! - [`run`], [`repl`], [`docs`]: running a file, the interactive loop, API documentation.
//!
//! Big objects cross into Rhai as shared handles (`Shared<Locked<_>>`), never copied per call.

pub mod captured;
pub mod checkpoint;
pub mod contact;
pub mod convert;
pub mod docs;
pub mod fabric;
pub mod facade;
pub mod facade_analysis;
pub mod facade_learned;
pub mod face;
pub mod garment;
pub mod golf;
pub mod imports;
pub mod kes;
pub mod measure;
pub mod modules;
pub mod output;
pub mod paths;
pub mod repl;
pub mod run;
pub mod sandbox;
pub mod shell;
pub mod sim;
pub mod sim_run;
pub mod tracking;
pub mod tracking_sequence;

use rhai::{Dynamic, Engine};

use modules::ApiBuilder;

pub use fabric::{ClothHandle, Fabric};
pub use run::{run_file, run_file_with, RunOptions, ScriptError};
pub use sandbox::Sandbox;
pub use sim::SimHandle;

/// Registers a documented global function (a method or property of a handle): name, parameter
/// infos (the last one is the return type), doc text (plain lines, turned into `///` comments)
/// and the closure.
macro_rules! register {
    ($engine:expr, $name:expr, [$($p:expr),* $(,)?], $doc:expr, $f:expr) => {
        rhai::FuncRegistration::new($name)
            .with_params_info::<&str>([$($p),*])
            .with_comments([$crate::script::convert::doc_comment($doc)])
            .register_into_engine($engine, $f)
    };
}

/// Registers a documented property getter `obj.prop`.
macro_rules! getter {
    ($engine:expr, $prop:expr, [$($p:expr),* $(,)?], $doc:expr, $f:expr) => {
        rhai::FuncRegistration::new_getter($prop)
            .with_params_info::<&str>([$($p),*])
            .with_comments([$crate::script::convert::doc_comment($doc)])
            .register_into_engine($engine, $f)
    };
}
/// Registers a documented free function `module::name` into its module of the
/// [`ApiBuilder`](modules::ApiBuilder) (parameter infos and doc as for `register!`); with
/// `alias = "old_name"`, also registers the old flat name globally, documented as an alias kept
/// for one release.
macro_rules! function {
    ($engine:expr, $path:literal, alias = $alias:literal, [$($p:expr),* $(,)?], $doc:expr, $f:expr) => {{
        let f = $f;
        $crate::script::function!($engine, $path, [$($p),*], $doc, f.clone());
        rhai::FuncRegistration::new($alias)
            .with_params_info::<&str>([$($p),*])
            .with_comments([$crate::script::convert::doc_comment(
                &$crate::script::modules::alias_doc($path),
            )])
            .register_into_engine($engine, f)
    }};
    ($engine:expr, $path:literal, [$($p:expr),* $(,)?], $doc:expr, $f:expr) => {{
        let (module, name) = $path
            .split_once("::")
            .expect("a module function is named `module::name`");
        rhai::FuncRegistration::new(name)
            .with_namespace(rhai::FnNamespace::Internal)
            .with_params_info::<&str>([$($p),*])
            .with_comments([$crate::script::convert::doc_comment($doc)])
            .set_into_module($engine.module(module), $f)
    }};
}
pub(crate) use {function, getter, register};

/// Limits that keep a runaway script from hanging or exhausting memory.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EngineLimits {
    /// Script operations per run (a native `sim.run` counts as one); 0: no limit.
    pub max_operations: u64,
    /// Expression nesting depth (global, inside functions).
    pub max_expr_depths: (usize, usize),
    /// Longest string (bytes).
    pub max_string_size: usize,
    /// Largest array (elements).
    pub max_array_size: usize,
    /// Largest object map (entries).
    pub max_map_size: usize,
    /// Deepest script function recursion.
    pub max_call_levels: usize,
}

impl Default for EngineLimits {
    fn default() -> Self {
        EngineLimits {
            max_operations: 50_000_000,
            max_expr_depths: (128, 64),
            max_string_size: 16 << 20,
            max_array_size: 10_000_000,
            max_map_size: 100_000,
            max_call_levels: 64,
        }
    }
}

/// An engine with every emilion function registered and the default [`EngineLimits`].
pub fn build_engine() -> Engine {
    build_engine_with(EngineLimits::default())
}

/// Script operations between two checks of the run's deadline (`--max-seconds`).
const OPERATIONS_PER_CHECK: u64 = 4096;

/// An engine with every emilion function registered and the given limits. `print` goes to
/// stdout, `debug` to stderr; the run's deadline ([`limits::check_cancelled`]) stops a script
/// within a few thousand operations; `import` reads modules through the sandbox
/// ([`imports`]).
///
/// [`limits::check_cancelled`]: crate::limits::check_cancelled
pub fn build_engine_with(limits: EngineLimits) -> Engine {
    let mut engine = ApiBuilder::new(Engine::new());
    engine
        .set_max_operations(limits.max_operations)
        .set_max_expr_depths(limits.max_expr_depths.0, limits.max_expr_depths.1)
        .set_max_string_size(limits.max_string_size)
        .set_max_array_size(limits.max_array_size)
        .set_max_map_size(limits.max_map_size)
        .set_max_call_levels(limits.max_call_levels);
    engine.on_progress(|ops| {
        if ops % OPERATIONS_PER_CHECK != 0 {
            return None;
        }
        crate::limits::check_cancelled().err().map(Dynamic::from)
    });
    engine.set_module_resolver(imports::ScriptModules);
    engine.on_print(|s| println!("{s}"));
    engine.on_debug(|s, src, pos| match src {
        Some(src) => eprintln!("{src}:{pos:?}: {s}"),
        None => eprintln!("{pos:?}: {s}"),
    });
    fabric::register(&mut engine);
    sim::register(&mut engine);
    sim_run::register(&mut engine);
    checkpoint::register(&mut engine);
    contact::register(&mut engine);
    garment::register(&mut engine);
    output::register(&mut engine);
    measure::register(&mut engine);
    facade::register(&mut engine);
    facade_analysis::register(&mut engine);
    facade_learned::register(&mut engine);
    tracking::register(&mut engine);
    golf::register(&mut engine);
    face::register(&mut engine);
    tracking_sequence::register(&mut engine);
    kes::register(&mut engine);
    shell::register(&mut engine);
    paths::register(&mut engine);
    engine.finish()
}

/// A human-readable rendering of a script value (handles print their summary).
pub fn describe(v: &Dynamic) -> String {
    if let Some(f) = v.read_lock::<Fabric>() {
        return f.to_string();
    }
    if let Some(c) = v.read_lock::<ClothHandle>() {
        return c.to_string();
    }
    if let Some(s) = v.read_lock::<SimHandle>() {
        return s.to_string();
    }
    if v.is_string() {
        return format!("{v:?}");
    }
    v.to_string()
}

/// Names of the functions registered by emilion (not rhai's standard library), sorted and
/// deduplicated; module functions appear as `module::name`, property accessors as
/// `get$prop` / `set$prop`.
pub fn function_names(engine: &Engine) -> Vec<String> {
    let mut names: Vec<String> = engine
        .gen_fn_signatures(false)
        .iter()
        .map(|s| s.split('(').next().unwrap_or("").to_string())
        .collect();
    names.sort();
    names.dedup();
    names
}
