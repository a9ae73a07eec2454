//! Where a script's paths lead, and whether it may use them: a relative path written in a
//! script is taken from the script's folder, so a script runs from any working directory; a
//! path given on the command line (`--set key=PATH`, or one a script builds from such a value,
//! like `out + "/a.png"`) is taken from the working directory, as a shell user expects; code
//! typed at the REPL uses the working directory. Then the [sandbox](super::sandbox) in force
//! checks it. Every path-taking script function calls one of [`read_path`], [`write_path`],
//! [`read_folder`], [`write_folder`] (or their `_opt`/`_text` forms).
//!
//! The running script is recorded per thread by [`ScriptContext::enter`] for as long as the
//! returned guard lives (`run_file`, the REPL's first script); without one, paths are left as
//! given (the working directory's). The sandbox's rules are recorded likewise by [`confine`];
//! without rules (`--trust`, a Rust caller of `run_file`), every path is allowed.

use std::cell::RefCell;
use std::path::{Path, PathBuf};
use std::rc::Rc;

use rhai::ImmutableString;

use super::convert::{rt_err, RResult};
use super::register;
use super::sandbox::{Access, Rules};
use crate::geometry::files::data_dir;

/// The script being run: its folder, its name and the relative paths given on the command line.
#[derive(Debug, Clone, Default)]
pub struct ScriptContext {
    /// The script's folder, absolute.
    dir: PathBuf,
    /// The script's file name without its extension (`hang` for `scripts/hang.rhai`).
    name: String,
    /// The relative `--set` string values: a path that starts with one is the command line's.
    command_line: Vec<PathBuf>,
}

thread_local! {
    static CURRENT: RefCell<Option<ScriptContext>> = const { RefCell::new(None) };
    static RULES: RefCell<Option<Rc<Rules>>> = const { RefCell::new(None) };
}

/// Restores the previous sandbox rules when dropped.
#[must_use = "the rules last as long as the guard"]
pub struct RulesGuard(Option<Rc<Rules>>);

impl Drop for RulesGuard {
    fn drop(&mut self) {
        let previous = self.0.take();
        RULES.with(|r| *r.borrow_mut() = previous);
    }
}

/// Confines this thread's script functions to `rules` (`None`: no sandbox) until the guard
/// drops.
pub fn confine(rules: Option<Rc<Rules>>) -> RulesGuard {
    RulesGuard(RULES.with(|r| std::mem::replace(&mut *r.borrow_mut(), rules)))
}

/// Restores the previous context when dropped.
#[must_use = "the context lasts as long as the guard"]
pub struct ContextGuard(Option<ScriptContext>);

impl Drop for ContextGuard {
    fn drop(&mut self) {
        let previous = self.0.take();
        CURRENT.with(|c| *c.borrow_mut() = previous);
    }
}

impl ScriptContext {
    /// The context of the script file `script` run with `command_line`, the string values
    /// given by `--set` (a relative one is a path of the working directory).
    pub fn new<'a>(script: &Path, command_line: impl IntoIterator<Item = &'a str>) -> Self {
        let file = std::path::absolute(script).unwrap_or_else(|_| script.to_path_buf());
        let dir = file.parent().map_or_else(working_dir, Path::to_path_buf);
        let name = script
            .file_stem()
            .map_or_else(|| "script".into(), |s| s.to_string_lossy().into_owned());
        let command_line = command_line
            .into_iter()
            .map(PathBuf::from)
            .filter(|p| p.is_relative() && !p.as_os_str().is_empty())
            .collect();
        ScriptContext {
            dir,
            name,
            command_line,
        }
    }

    /// Makes this the running script's context on this thread until the guard drops.
    pub fn enter(self) -> ContextGuard {
        ContextGuard(CURRENT.with(|c| c.borrow_mut().replace(self)))
    }
}

/// The working directory, absolute (`.` if it cannot be read).
pub(crate) fn working_dir() -> PathBuf {
    std::env::current_dir().unwrap_or_else(|_| ".".into())
}

/// The path a script function opens or writes for the script-given `path`: absolute paths as
/// they are; a relative path that starts with a `--set` value as given (the working
/// directory's); any other relative path under the running script's folder. Without a running
/// script (the REPL), as given.
fn resolve(path: &str) -> PathBuf {
    let p = Path::new(path);
    if p.is_absolute() {
        return p.to_path_buf();
    }
    CURRENT.with(|c| match &*c.borrow() {
        Some(ctx) if !ctx.command_line.iter().any(|v| p.starts_with(v)) => ctx.dir.join(p),
        _ => p.to_path_buf(),
    })
}

/// The script-given `path` resolved ([`resolve`]) and checked against the sandbox in force
/// for `access`, as a folder of many files when `folder`.
fn checked(path: &str, access: Access, folder: bool) -> RResult<PathBuf> {
    let p = resolve(path);
    RULES
        .with(|r| match &*r.borrow() {
            None => Ok(()),
            Some(rules) if folder => rules.check_folder(&p, access),
            Some(rules) => rules.check(&p, access),
        })
        .map_err(rt_err)?;
    Ok(p)
}

/// A file the script reads (or a folder it lists), resolved and checked against the sandbox.
pub fn read_path(path: &str) -> RResult<PathBuf> {
    checked(path, Access::Read, false)
}

/// A file the script writes, resolved and checked against the sandbox (strictly inside a folder
/// it may write, so files written beside it are too).
pub fn write_path(path: &str) -> RResult<PathBuf> {
    checked(path, Access::Write, false)
}

/// A folder whose files the script reads (photos, a sequence, fabric files): [`read_path`],
/// and no link inside it may lead where the script may not read.
pub fn read_folder(path: &str) -> RResult<PathBuf> {
    checked(path, Access::Read, true)
}

/// A folder the script writes many files into: [`write_path`], and no link inside it may lead
/// where the script may not write.
pub fn write_folder(path: &str) -> RResult<PathBuf> {
    checked(path, Access::Write, true)
}

/// [`read_path`] of an optional path.
pub fn read_opt(path: Option<&str>) -> RResult<Option<PathBuf>> {
    path.map(read_path).transpose()
}

/// [`read_folder`] of an optional path.
pub fn read_folder_opt(path: Option<&str>) -> RResult<Option<PathBuf>> {
    path.map(read_folder).transpose()
}

/// [`read_path`] as text, for options the engine keeps as strings.
pub fn read_text(path: &str) -> RResult<String> {
    Ok(read_path(path)?.display().to_string())
}

/// [`read_folder`] as text, for options the engine keeps as strings.
pub fn read_folder_text(path: &str) -> RResult<String> {
    Ok(read_folder(path)?.display().to_string())
}

/// [`write_path`] as text, for writers that take strings.
pub fn write_text(path: &str) -> RResult<String> {
    Ok(write_path(path)?.display().to_string())
}

/// The running script's folder, absolute; the working directory at the REPL.
pub fn script_dir() -> PathBuf {
    CURRENT
        .with(|c| c.borrow().as_ref().map(|ctx| ctx.dir.clone()))
        .unwrap_or_else(working_dir)
}

/// The default output folder: `out/<script name>` under the working directory, absolute;
/// `out` at the REPL.
pub fn out_dir() -> PathBuf {
    let out = working_dir().join("out");
    CURRENT.with(|c| match &*c.borrow() {
        Some(ctx) => out.join(&ctx.name),
        None => out,
    })
}

/// A path as a script string.
fn text(p: PathBuf) -> ImmutableString {
    p.display().to_string().into()
}

/// Registers `script_dir()`, `data_dir()` and `out_dir()`.
pub fn register(engine: &mut rhai::Engine) {
    register!(
        engine,
        "script_dir",
        ["String"],
        "The running script's folder, absolute (the working directory at the REPL). A relative\n\
         path in a script is already taken from there; use it to hand a path to another program\n\
         or to print it.",
        || text(script_dir())
    );
    register!(
        engine,
        "data_dir",
        ["String"],
        "The shared data folder, absolute: `$EMILION_DATA` if set, else `../shared/data` beside\n\
         the repository emilion was built from. Build data paths from it:\n\
         `data_dir() + \"/motion/cmu_bvh/002_05.bvh\"`.",
        || text(data_dir())
    );
    register!(
        engine,
        "out_dir",
        ["String"],
        "The default output folder, absolute: `out/<script name>` under the working directory\n\
         (`out` at the REPL). Scripts use it when no `--set out=DIR` is given:\n\
         `let out = if is_def_var(\"out\") { out } else { out_dir() };`.",
        || text(out_dir())
    );
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn relative_paths_follow_the_script() {
        let script = Path::new("/somewhere/scripts/walk.rhai");
        let _g = ScriptContext::new(script, ["results"]).enter();
        assert_eq!(
            resolve("patterns/a.json"),
            Path::new("/somewhere/scripts/patterns/a.json")
        );
        assert_eq!(
            resolve("../x/y.obj"),
            Path::new("/somewhere/scripts/../x/y.obj")
        );
        assert_eq!(resolve("/abs/file.png"), Path::new("/abs/file.png"));
        // the command line's paths stay the working directory's
        assert_eq!(resolve("results"), Path::new("results"));
        assert_eq!(
            resolve("results/walk/a.png"),
            Path::new("results/walk/a.png")
        );
        // a prefix of a component is not the value
        assert_eq!(
            resolve("results_old/a.png"),
            Path::new("/somewhere/scripts/results_old/a.png")
        );
        assert_eq!(script_dir(), Path::new("/somewhere/scripts"));
        assert!(out_dir().ends_with("out/walk") && out_dir().is_absolute());
    }

    #[test]
    fn the_sandbox_checks_reads_and_writes_after_resolving() {
        let root = std::env::temp_dir().join(format!("emilion_paths_{}", std::process::id()));
        let (dir, out) = (root.join("scripts"), root.join("results"));
        std::fs::create_dir_all(&dir).unwrap();
        let script = dir.join("s.rhai");
        let out_text = out.display().to_string();
        let _g = ScriptContext::new(&script, []).enter();
        let sandbox = super::super::sandbox::Sandbox::default();
        let rules = sandbox.rules_for_script(&script, [("out", out_text.as_str())]);
        let _r = confine(rules.map(Rc::new));
        assert_eq!(read_path("a.json").unwrap(), dir.join("a.json"));
        assert!(read_path("../scripts/a.json").is_ok());
        for bad in ["/etc/passwd", "../../../../../../../../../etc/passwd"] {
            let e = read_path(bad).unwrap_err().to_string();
            assert!(
                e.contains("may not read") && e.contains("/etc/passwd"),
                "{e}"
            );
        }
        let written = out.join("a/b.png").display().to_string();
        assert!(write_path(&written).is_ok());
        assert!(write_folder(&out.display().to_string()).is_ok());
        let e = write_path("b.png").unwrap_err().to_string();
        assert!(
            e.contains("may not write") && e.contains("--allow-write"),
            "{e}"
        );
        {
            let _trusted = confine(None);
            assert!(write_path("b.png").is_ok());
        }
        assert!(write_path("b.png").is_err(), "the guard restores the rules");
    }

    #[test]
    fn without_a_script_paths_are_the_working_directorys() {
        assert_eq!(resolve("a/b.png"), Path::new("a/b.png"));
        assert_eq!(script_dir(), std::env::current_dir().unwrap());
        assert_eq!(out_dir(), std::env::current_dir().unwrap().join("out"));
        {
            let _g = ScriptContext::new(Path::new("/s/x.rhai"), []).enter();
            assert_eq!(resolve("a"), Path::new("/s/a"));
        }
        assert_eq!(
            resolve("a"),
            Path::new("a"),
            "the guard restores the context"
        );
    }
}
