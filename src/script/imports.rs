//! `import "name" as m;` in scripts: the module file `name.rhai` is found like every other path
//! a script names (from the script's folder, see [`paths`](super::paths)) and is read only
//! where the [sandbox](super::sandbox) allows, bounded by `max_file_bytes`. This replaces
//! Rhai's own file resolver, which would read any file from the working directory.

use std::cell::Cell;

use rhai::{Engine, EvalAltResult, Module, ModuleResolver, Position, Scope, Shared};

use super::convert::rt_err;
use super::paths::read_path;

/// Deepest chain of modules importing modules.
const MAX_IMPORT_DEPTH: usize = 16;

thread_local! {
    static DEPTH: Cell<usize> = const { Cell::new(0) };
}

/// The module resolver of every emilion engine.
#[derive(Debug, Default, Clone, Copy)]
pub struct ScriptModules;

impl ScriptModules {
    /// Reads, compiles and evaluates the module `path` (`.rhai` added when missing).
    fn load(engine: &Engine, path: &str) -> Result<Module, Box<EvalAltResult>> {
        let name = if path.ends_with(".rhai") {
            path.to_string()
        } else {
            format!("{path}.rhai")
        };
        let file = read_path(&name)?;
        let text = crate::limits::read_to_string(&file)
            .map_err(|e| rt_err(format!("{}: {e}", file.display())))?;
        let mut ast = engine.compile(&text).map_err(|e| {
            let (line, col) = (e.1.line().unwrap_or(0), e.1.position().unwrap_or(0));
            rt_err(format!("{}:{line}:{col}: {}", file.display(), e.0))
        })?;
        ast.set_source(file.display().to_string());
        Module::eval_ast_as_new(Scope::new(), &ast, engine)
    }
}

impl ModuleResolver for ScriptModules {
    fn resolve(
        &self,
        engine: &Engine,
        _source: Option<&str>,
        path: &str,
        pos: Position,
    ) -> Result<Shared<Module>, Box<EvalAltResult>> {
        let depth = DEPTH.with(|d| d.get());
        if depth >= MAX_IMPORT_DEPTH {
            return Err(rt_err(format!(
                "`import \"{path}\"`: modules import each other more than {MAX_IMPORT_DEPTH} deep"
            )));
        }
        DEPTH.with(|d| d.set(depth + 1));
        let module = Self::load(engine, path);
        DEPTH.with(|d| d.set(depth));
        module
            .map(Shared::new)
            .map_err(|e| EvalAltResult::ErrorInModule(path.to_string(), e, pos).into())
    }
}
