//! Running a script file: `--set key=value` variables, the [sandbox](super::sandbox), and
//! errors reported as `FILE:LINE:COL: message` followed by the offending source line and a
//! caret.

use std::fmt;
use std::path::Path;
use std::rc::Rc;

use rhai::{Dynamic, Engine, EvalAltResult, Position, Scope};

use super::paths::{confine, ScriptContext};
use super::sandbox::Sandbox;
use super::{build_engine_with, EngineLimits};

/// A failed script: where, what, and the source line it points at.
#[derive(Debug, Clone)]
pub struct ScriptError {
    /// The script file (as given).
    pub file: String,
    /// 1-based line and column, when known.
    pub position: Option<(usize, usize)>,
    /// What went wrong.
    pub message: String,
    /// The source line at `position`.
    pub source_line: Option<String>,
}

impl fmt::Display for ScriptError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.position {
            Some((line, col)) => write!(f, "{}:{line}:{col}: {}", self.file, self.message)?,
            None => write!(f, "{}: {}", self.file, self.message)?,
        }
        if let (Some(src), Some((line, col))) = (&self.source_line, self.position) {
            let gutter = format!("{line} | ");
            write!(
                f,
                "\n{gutter}{src}\n{}^",
                " ".repeat(gutter.len() + col.saturating_sub(1))
            )?;
        }
        Ok(())
    }
}

impl std::error::Error for ScriptError {}

impl ScriptError {
    /// A script error for `file` with source `source` from a Rhai error. An error inside a
    /// script function points at the failing line inside it and names the calls that led there.
    pub fn from_rhai(file: &str, source: &str, err: EvalAltResult) -> Self {
        let mut calls = Vec::new();
        let mut err = err;
        while let EvalAltResult::ErrorInFunctionCall(name, _, inner, pos) = err {
            calls.push(format!(
                "in `{name}` called at line {}",
                pos.line().unwrap_or(0)
            ));
            err = *inner;
        }
        let pos = err.position();
        err.clear_position();
        let mut message = match &err {
            // stopped by `on_progress`: the reason (`--max-seconds`) is the token
            EvalAltResult::ErrorTerminated(reason, _) if reason.is_string() => reason.to_string(),
            _ => err.to_string(),
        };
        if matches!(err, EvalAltResult::ErrorDataRace(..)) {
            message += " (a callback must not capture the object whose method runs it: inside \
                         `sim.run(.., |t| ..)` use `this` or `t.sim` instead of `sim`)";
        }
        if !calls.is_empty() {
            calls.reverse();
            message = format!("{message} ({})", calls.join(", "));
        }
        Self::at(file, source, pos, message)
    }

    /// A script error at `pos` of `source`.
    pub fn at(file: &str, source: &str, pos: Position, message: String) -> Self {
        let position = match (pos.line(), pos.position()) {
            (Some(l), c) => Some((l, c.unwrap_or(1))),
            _ => None,
        };
        let source_line = position
            .and_then(|(l, _)| source.lines().nth(l - 1))
            .map(str::to_string);
        ScriptError {
            file: file.to_string(),
            position,
            message,
            source_line,
        }
    }
}

/// A `--set` value: integer, float, bool, else string.
pub fn parse_value(s: &str) -> Dynamic {
    if let Ok(i) = s.parse::<rhai::INT>() {
        Dynamic::from_int(i)
    } else if let Ok(f) = s.parse::<rhai::FLOAT>() {
        Dynamic::from_float(f)
    } else if let Ok(b) = s.parse::<bool>() {
        Dynamic::from_bool(b)
    } else {
        s.into()
    }
}

/// A scope holding the `--set` values as constants.
pub fn scope_with(sets: &[(String, String)]) -> Result<Scope<'static>, String> {
    let mut scope = Scope::new();
    for (k, v) in sets {
        let ok = k
            .chars()
            .next()
            .is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
            && k.chars().all(|c| c.is_ascii_alphanumeric() || c == '_');
        if !ok {
            return Err(format!("--set: `{k}` is not a valid variable name"));
        }
        scope.push_constant_dynamic(k.clone(), parse_value(v));
    }
    Ok(scope)
}

/// Runs `source` (named `file` in errors) in `scope` with `engine`.
pub fn run_source(
    engine: &Engine,
    file: &str,
    source: &str,
    scope: &mut Scope,
) -> Result<(), ScriptError> {
    let ast = engine.compile_with_scope(scope, source).map_err(|e| {
        let message = e.0.to_string();
        ScriptError::at(file, source, e.1, message)
    })?;
    engine
        .run_ast_with_scope(scope, &ast)
        .map_err(|e| ScriptError::from_rhai(file, source, *e))
}

/// Runs a script file with a fresh engine, `sets` defined as constants beforehand, trusted
/// (no sandbox: the caller is Rust code that chose the script). Relative paths in the script
/// are taken from its folder, those given by `sets` from the working directory (see
/// [`paths`](super::paths)). `emilion run` uses [`run_file_with`] and the default [`Sandbox`].
pub fn run_file(path: &Path, sets: &[(String, String)]) -> Result<(), ScriptError> {
    let options = RunOptions {
        sandbox: Sandbox::trusted(),
        ..RunOptions::default()
    };
    run_file_with(path, sets, &options)
}

/// How [`run_file_with`] runs a script. The default is what `emilion run` does without flags:
/// the sandbox on, the default engine limits.
#[derive(Debug, Clone, Default)]
pub struct RunOptions {
    /// Where the script may read and write.
    pub sandbox: Sandbox,
    /// The engine's limits (`emilion run --max-seconds` lifts the operation count: the time
    /// limit bounds the run instead).
    pub engine: EngineLimits,
}

/// [`run_file`] with `options`: confined by their sandbox, the script reads and writes only
/// where its rules allow ([`Sandbox::rules_for_script`]: its folder, the data folder, `out/`,
/// `--set out=DIR`, the `--set` paths and the sandbox's extra folders).
pub fn run_file_with(
    path: &Path,
    sets: &[(String, String)],
    options: &RunOptions,
) -> Result<(), ScriptError> {
    let file = path.display().to_string();
    let source = crate::limits::read_to_string(path).map_err(|e| ScriptError {
        file: file.clone(),
        position: None,
        message: format!("cannot read script: {e}"),
        source_line: None,
    })?;
    let mut scope = scope_with(sets).map_err(|message| ScriptError {
        file: file.clone(),
        position: None,
        message,
        source_line: None,
    })?;
    let engine = build_engine_with(options.engine);
    // the `--set` strings: paths among them are the working directory's
    let strings = sets
        .iter()
        .map(|(_, v)| v.as_str())
        .filter(|v| parse_value(v).is_string());
    let _context = ScriptContext::new(path, strings).enter();
    let string_sets = sets
        .iter()
        .filter(|(_, v)| parse_value(v).is_string())
        .map(|(k, v)| (k.as_str(), v.as_str()));
    let rules = options.sandbox.rules_for_script(path, string_sets);
    let _rules = confine(rules.map(Rc::new));
    run_source(&engine, &file, &source, &mut scope)
}
