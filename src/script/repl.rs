//! The interactive loop: a rustyline editor with history (`~/.emilion_history`), multi-line
//! input (a trailing `\` or unbalanced brackets continue with `...> `), tab completion of the
//! registered function names (`module::name` included), and one persistent Scope. Results print as `=> value`; errors
//! print and the loop goes on. On a non-terminal stdin it reads plain lines, without prompts.
//! The session is confined by the [sandbox](super::sandbox) (`emilion repl --trust` lifts it),
//! which its banner and its `sandbox` command state.

use std::io::{BufRead, IsTerminal, Write};
use std::path::{Path, PathBuf};
use std::rc::Rc;

use rhai::{Dynamic, Engine, Scope, AST};
use rustyline::completion::Completer;
use rustyline::error::ReadlineError;
use rustyline::highlight::Highlighter;
use rustyline::hint::Hinter;
use rustyline::validate::Validator;
use rustyline::{Context, Editor, Helper};

use super::paths::{confine, ScriptContext};
use super::run::ScriptError;
use super::sandbox::{Rules, Sandbox};
use super::{build_engine, describe, docs, function_names};

const PROMPT: &str = "emilion> ";
const MORE: &str = "...> ";

/// Tab completion over the engine's function names.
struct ReplHelper {
    names: Vec<String>,
}

/// The completions of the word that ends at `pos` in `line`: where the word starts and the
/// `names` it begins. A word may hold a module path, so `cloth::g` completes to `cloth::grid`
/// and `clo` to `cloth::…` as well as `cloth_…`.
pub fn completions(names: &[String], line: &str, pos: usize) -> (usize, Vec<String>) {
    let start = line[..pos]
        .rfind(|c: char| !(c.is_alphanumeric() || c == '_' || c == ':'))
        .map_or(0, |i| i + 1);
    let word = &line[start..pos];
    let found = names
        .iter()
        .filter(|n| !word.is_empty() && n.starts_with(word))
        .cloned()
        .collect();
    (start, found)
}

impl Completer for ReplHelper {
    type Candidate = String;
    fn complete(
        &self,
        line: &str,
        pos: usize,
        _: &Context<'_>,
    ) -> rustyline::Result<(usize, Vec<String>)> {
        Ok(completions(&self.names, line, pos))
    }
}
impl Hinter for ReplHelper {
    type Hint = String;
}
impl Highlighter for ReplHelper {}
impl Validator for ReplHelper {}
impl Helper for ReplHelper {}

/// Whether `input` is unfinished: a trailing `\`, or more brackets opened than closed
/// (outside strings and `//` comments).
pub fn needs_more(input: &str) -> bool {
    if input.trim_end().ends_with('\\') {
        return true;
    }
    let mut depth = 0i64;
    let mut chars = input.chars().peekable();
    let mut quote: Option<char> = None;
    while let Some(c) = chars.next() {
        match quote {
            Some(q) => {
                if c == '\\' {
                    chars.next();
                } else if c == q {
                    quote = None;
                }
            }
            None => match c {
                '"' | '`' => quote = Some(c),
                '/' if chars.peek() == Some(&'/') => {
                    while chars.next_if(|&c| c != '\n').is_some() {}
                }
                '(' | '[' | '{' => depth += 1,
                ')' | ']' | '}' => depth -= 1,
                _ => {}
            },
        }
    }
    depth > 0 || quote == Some('`')
}

/// The REPL's state: engine, persistent scope, the functions defined so far, and the
/// sandbox's rules (`None`: trusted).
pub struct Session {
    engine: Engine,
    scope: Scope<'static>,
    ast: AST,
    rules: Option<Rc<Rules>>,
}

/// What to do after a line.
enum Flow {
    Continue,
    Quit,
}

impl Session {
    /// A fresh session with every emilion function registered, trusted (no sandbox).
    pub fn new() -> Self {
        Session {
            engine: build_engine(),
            scope: Scope::new(),
            ast: AST::empty(),
            rules: None,
        }
    }

    /// A fresh session confined by `sandbox` (its rules for the REPL: the working directory,
    /// the data folder, `out/`, the folder of the script `init` run first, the extra folders).
    pub fn with_sandbox(sandbox: &Sandbox, init: Option<&Path>) -> Self {
        Session {
            rules: sandbox.rules_for_repl(init).map(Rc::new),
            ..Session::new()
        }
    }

    /// What the session may read and write, in words.
    pub fn sandbox_text(&self) -> String {
        match &self.rules {
            None => "no sandbox (--trust): reads and writes whatever you may".into(),
            Some(r) => format!(
                "sandbox: {}
(`emilion repl --trust` lifts it; `--allow-write DIR` and \
                 `--allow-read DIR` add a folder)",
                r.describe().replace('\n', "\nsandbox: ")
            ),
        }
    }

    /// Evaluates `input` in the persistent scope; functions it defines stay available.
    pub fn eval(&mut self, input: &str) -> Result<Dynamic, ScriptError> {
        let _rules = confine(self.rules.clone());
        let ast = self
            .engine
            .compile_with_scope(&self.scope, input)
            .map_err(|e| ScriptError::at("<repl>", input, e.1, e.0.to_string()))?;
        self.ast += ast;
        let r = self
            .engine
            .eval_ast_with_scope::<Dynamic>(&mut self.scope, &self.ast);
        self.ast.clear_statements();
        r.map_err(|e| ScriptError::from_rhai("<repl>", input, *e))
    }

    /// Handles one complete input: a command or code. Prints results and errors.
    fn handle(&mut self, input: &str, out: &mut impl Write) -> Flow {
        let cmd = input.trim();
        match cmd {
            "" => return Flow::Continue,
            "quit" | "exit" => return Flow::Quit,
            "sandbox" => {
                let _ = writeln!(out, "{}", self.sandbox_text());
                return Flow::Continue;
            }
            "help" => {
                let _ = writeln!(out, "Type Rhai code; `help NAME` shows the docs of the functions whose name starts with NAME\n(`help cloth::` for a module); `sandbox` says what may be read and written; `quit` or `exit` leaves. Functions:");
                let _ = write!(out, "{}", docs::help_text(&self.engine, ""));
                return Flow::Continue;
            }
            _ => {}
        }
        if let Some(pat) = cmd.strip_prefix("help ") {
            let text = docs::help_text(&self.engine, pat.trim());
            let _ = write!(
                out,
                "{}",
                if text.is_empty() {
                    format!("no function matches `{}`\n", pat.trim())
                } else {
                    text
                }
            );
            return Flow::Continue;
        }
        match self.eval(input) {
            Ok(v) if v.is_unit() => {}
            Ok(v) => {
                let _ = writeln!(out, "=> {}", describe(&v));
            }
            Err(e) => eprintln!("{e}"),
        }
        let _ = out.flush();
        Flow::Continue
    }

    /// Runs a script file in the session (its variables and functions stay); its relative
    /// paths are taken from its folder, those typed afterwards from the working directory.
    pub fn run_init(&mut self, path: &Path) -> Result<(), ScriptError> {
        let _context = ScriptContext::new(path, []).enter();
        let file = path.display().to_string();
        let src = crate::limits::read_to_string(path).map_err(|e| ScriptError {
            file: file.clone(),
            position: None,
            message: e.to_string(),
            source_line: None,
        })?;
        self.eval(&src)
            .map(|_| ())
            .map_err(|e| ScriptError { file, ..e })
    }
}

impl Default for Session {
    fn default() -> Self {
        Self::new()
    }
}

fn history_path() -> PathBuf {
    match std::env::var_os("HOME") {
        Some(h) => PathBuf::from(h).join(".emilion_history"),
        None => PathBuf::from(".emilion_history"),
    }
}

/// Runs the REPL on stdin confined by `sandbox`, after `init` if given.
pub fn repl(init: Option<&Path>, sandbox: &Sandbox) -> Result<(), String> {
    let mut session = Session::with_sandbox(sandbox, init);
    if let Some(p) = init {
        if let Err(e) = session.run_init(p) {
            eprintln!("{e}");
        }
    }
    let mut stdout = std::io::stdout();
    if !std::io::stdin().is_terminal() {
        let mut buf = String::new();
        for line in std::io::stdin().lock().lines() {
            let line = line.map_err(|e| e.to_string())?;
            push_line(&mut buf, &line);
            if needs_more(&buf) {
                continue;
            }
            let flow = session.handle(&std::mem::take(&mut buf), &mut stdout);
            if matches!(flow, Flow::Quit) {
                return Ok(());
            }
        }
        if !buf.trim().is_empty() {
            session.handle(&buf, &mut stdout);
        }
        return Ok(());
    }
    let mut rl: Editor<ReplHelper, rustyline::history::DefaultHistory> =
        Editor::new().map_err(|e| e.to_string())?;
    let mut names = function_names(&session.engine);
    names.retain(|n| !n.contains('$'));
    names.extend(["help", "quit", "exit"].map(String::from));
    rl.set_helper(Some(ReplHelper { names }));
    let hist = history_path();
    let _ = rl.load_history(&hist);
    println!("emilion REPL: type `help` for the functions, `quit` to leave.");
    println!("{}", session.sandbox_text());
    let mut buf = String::new();
    loop {
        match rl.readline(if buf.is_empty() { PROMPT } else { MORE }) {
            Ok(line) => {
                push_line(&mut buf, &line);
                if needs_more(&buf) {
                    continue;
                }
                let input = std::mem::take(&mut buf);
                let _ = rl.add_history_entry(input.trim_end());
                if matches!(session.handle(&input, &mut stdout), Flow::Quit) {
                    break;
                }
            }
            Err(ReadlineError::Interrupted) => buf.clear(),
            Err(ReadlineError::Eof) => break,
            Err(e) => return Err(e.to_string()),
        }
    }
    let _ = rl.save_history(&hist);
    Ok(())
}

/// Appends a line to the pending input, dropping a continuation `\`.
fn push_line(buf: &mut String, line: &str) {
    if buf.trim_end().ends_with('\\') {
        let keep = buf.trim_end().len() - 1;
        buf.truncate(keep);
    }
    buf.push_str(line);
    buf.push('\n');
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn module_paths_complete() {
        let mut names = function_names(&build_engine());
        names.retain(|n| !n.contains('$'));
        let line = "let c = cloth::gr";
        let (start, found) = completions(&names, line, line.len());
        assert_eq!(start, "let c = ".len());
        assert_eq!(found, ["cloth::grid"]);
        let (_, found) = completions(&names, "kes::", 5);
        assert!(found.contains(&"kes::lab".to_string()), "{found:?}");
        assert!(found.iter().all(|n| n.starts_with("kes::")), "{found:?}");
        let (_, found) = completions(&names, "x = cloth_g", 11);
        assert_eq!(found, ["cloth_grid"], "the old names still complete");
    }
}
