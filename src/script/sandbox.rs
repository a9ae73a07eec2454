//! The script sandbox: which folders a script may read and write. Scripts and scenes are
//! shared like documents, so `emilion run` and the REPL confine them by default:
//!
//! - a script **reads** only under its own folder, the data folder (`data_dir()`), its output
//!   folders, the paths given on the command line (`--set` string values) and the folders of
//!   `--allow-read DIR` / `--allow-write DIR`;
//! - it **writes** only under its output folders: `out/` under the working directory (where
//!   `out_dir()` leads), the value of `--set out=DIR`, and the folders of `--allow-write DIR`;
//! - `--trust` lifts both.
//!
//! A path is normalised before it is checked (made absolute, its existing part resolved by the
//! file system: `..`, symbolic links), so `out/../../etc/passwd` or a link placed in the
//! script's folder that leads elsewhere are caught. A folder handed to a function that reads or
//! writes many files in it is also searched for links that lead out ([`Rules::check_folder`]).
//! The check happens before anything is opened: a refusal names the path and how to allow it,
//! never the file's contents.
//!
//! This module is the policy ([`Sandbox`], [`Rules`]); [`paths`](super::paths) applies it to the
//! running script's paths.

use std::fmt::Write as _;
use std::path::{Component, Path, PathBuf};

use crate::geometry::files::data_dir;

/// How a script run is confined (the command line's `--trust`, `--allow-write`,
/// `--allow-read`). The default is the sandbox, with no extra folders.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Sandbox {
    /// No confinement at all (`--trust`).
    pub trusted: bool,
    /// Extra folders the script may write (and read) under (`--allow-write DIR`).
    pub allow_write: Vec<PathBuf>,
    /// Extra folders the script may read under (`--allow-read DIR`).
    pub allow_read: Vec<PathBuf>,
}

impl Sandbox {
    /// No sandbox: the script reads and writes whatever its user may (`--trust`).
    pub fn trusted() -> Self {
        Sandbox {
            trusted: true,
            ..Sandbox::default()
        }
    }

    /// The rules for running the script file `script` with `strings`, the `--set` values that
    /// are strings, as (key, value) (`None` when trusted). Relative folders are the working
    /// directory's.
    pub fn rules_for_script<'a>(
        &self,
        script: &Path,
        strings: impl IntoIterator<Item = (&'a str, &'a str)>,
    ) -> Option<Rules> {
        if self.trusted {
            return None;
        }
        let mut rules = self.base_rules();
        let file = std::path::absolute(script).unwrap_or_else(|_| script.to_path_buf());
        if let Some(dir) = file.parent() {
            rules.allow_read(dir, "the script's folder");
        }
        for (key, value) in strings {
            if value.is_empty() {
                continue;
            }
            if key == "out" {
                rules.allow_write(Path::new(value), "--set out");
            } else {
                rules.allow_read(Path::new(value), "a --set path");
            }
        }
        Some(rules)
    }

    /// The rules of the REPL (`None` when trusted): code typed there reads under the working
    /// directory, and the script given first under its folder.
    pub fn rules_for_repl(&self, init: Option<&Path>) -> Option<Rules> {
        if self.trusted {
            return None;
        }
        let mut rules = self.base_rules();
        rules.allow_read(Path::new("."), "the working directory");
        let init = init.and_then(|p| std::path::absolute(p).ok());
        if let Some(dir) = init.as_deref().and_then(Path::parent) {
            rules.allow_read(dir, "the first script's folder");
        }
        Some(rules)
    }

    /// The data folder, `out/` and the `--allow-…` folders.
    fn base_rules(&self) -> Rules {
        let mut rules = Rules::default();
        rules.allow_read(&data_dir(), "the data folder");
        rules.allow_write(Path::new("out"), "out/");
        for d in &self.allow_write {
            rules.allow_write(d, "--allow-write");
        }
        for d in &self.allow_read {
            rules.allow_read(d, "--allow-read");
        }
        rules
    }
}

/// Read or write, for the checks and their messages.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Access {
    /// Opening a file or listing a folder.
    Read,
    /// Creating or replacing a file, creating a folder.
    Write,
}

/// The folders a confined script reads and writes under, normalised, each with what it is.
/// Every folder it may write it may also read.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Rules {
    read: Vec<(PathBuf, &'static str)>,
    write: Vec<(PathBuf, &'static str)>,
}

/// Most entries searched for outward links in one folder handed to a function.
const MAX_FOLDER_ENTRIES: usize = 1_000_000;
/// Deepest subfolder searched for outward links.
const MAX_FOLDER_DEPTH: usize = 4;

impl Rules {
    /// Allows reading under `dir` (relative: the working directory's), labelled `what`.
    pub fn allow_read(&mut self, dir: &Path, what: &'static str) {
        if let Ok(d) = normalise(dir) {
            self.read.push((d, what));
        }
    }

    /// Allows writing and reading under `dir` (relative: the working directory's).
    pub fn allow_write(&mut self, dir: &Path, what: &'static str) {
        if let Ok(d) = normalise(dir) {
            self.write.push((d.clone(), what));
            self.read.push((d, what));
        }
    }

    /// The folders `access` is allowed under.
    fn roots(&self, access: Access) -> &[(PathBuf, &'static str)] {
        match access {
            Access::Read => &self.read,
            Access::Write => &self.write,
        }
    }

    /// Whether the normalised path `real` lies under a folder allowed for `access`.
    fn allows(&self, access: Access, real: &Path) -> bool {
        self.roots(access).iter().any(|(r, _)| real.starts_with(r))
    }

    /// Checks that the file `path` (as the script function will open it) may be read or
    /// written: `Err` names the path, the access and how to allow it. A file written lies
    /// strictly inside a folder allowed (so the files a writer puts beside it, `STEM.csv` beside
    /// `STEM.png`, do too).
    pub fn check(&self, path: &Path, access: Access) -> Result<(), String> {
        let real = self.check_path(path, access)?;
        let is_root = self.roots(access).iter().any(|(r, _)| *r == real);
        if access == Access::Write && is_root {
            return Err(refusal(
                path,
                Some(&real),
                access,
                "a folder the script writes in, not a file",
            ));
        }
        Ok(())
    }

    /// `path` normalised, if `access` is allowed there.
    fn check_path(&self, path: &Path, access: Access) -> Result<PathBuf, String> {
        let real = normalise(path).map_err(|e| refusal(path, None, access, &e))?;
        if self.allows(access, &real) {
            Ok(real)
        } else {
            Err(refusal(path, Some(&real), access, "outside the sandbox"))
        }
    }

    /// [`Rules::check`] of a folder a function reads or writes many files in, also refusing a
    /// symbolic link inside it (to a depth of 4 folders) that leads where `access` is not
    /// allowed (for writing, a broken link too: writing through it would create its target).
    pub fn check_folder(&self, dir: &Path, access: Access) -> Result<(), String> {
        self.check_path(dir, access)?;
        let mut budget = MAX_FOLDER_ENTRIES;
        self.check_links(dir, access, MAX_FOLDER_DEPTH, &mut budget)
    }

    fn check_links(
        &self,
        dir: &Path,
        access: Access,
        depth: usize,
        budget: &mut usize,
    ) -> Result<(), String> {
        let Ok(entries) = std::fs::read_dir(dir) else {
            return Ok(()); // not a folder (yet): nothing inside to lead out
        };
        for entry in entries.flatten() {
            if *budget == 0 {
                return Err(refusal(
                    dir,
                    None,
                    access,
                    &format!("holds more than {MAX_FOLDER_ENTRIES} entries to check"),
                ));
            }
            *budget -= 1;
            let Ok(kind) = entry.file_type() else {
                continue;
            };
            let path = entry.path();
            if kind.is_symlink() {
                match std::fs::canonicalize(&path) {
                    Ok(real) if self.allows(access, &real) => {}
                    Ok(real) => {
                        return Err(refusal(&path, Some(&real), access, "outside the sandbox"))
                    }
                    Err(_) if access == Access::Read => {} // broken: nothing to read
                    Err(_) => return Err(refusal(&path, None, access, "a broken symbolic link")),
                }
            } else if kind.is_dir() && depth > 0 {
                self.check_links(&path, access, depth - 1, budget)?;
            }
        }
        Ok(())
    }

    /// The rules in words, one line per access (for the REPL's banner).
    pub fn describe(&self) -> String {
        let list = |roots: &[(PathBuf, &'static str)]| {
            let mut s = String::new();
            for (i, (p, what)) in roots.iter().enumerate() {
                let sep = if i == 0 { "" } else { ", " };
                let _ = write!(s, "{sep}{} ({what})", p.display());
            }
            s
        };
        format!(
            "reads under {}\nwrites under {}",
            list(&self.read),
            list(&self.write)
        )
    }
}

/// The refusal of `access` to `path` (leading to `real` when known) because of `why`.
fn refusal(path: &Path, real: Option<&Path>, access: Access, why: &str) -> String {
    let leads = match real {
        Some(r) if r != path => format!(" (which leads to {})", r.display()),
        _ => String::new(),
    };
    let (verb, how) = match access {
        Access::Read => (
            "read",
            "a script reads only under its folder, the data folder, its output folders and the \
             paths given on the command line; allow a folder with `--allow-read DIR`",
        ),
        Access::Write => (
            "write",
            "a script writes only under `out/`, `--set out=DIR` and the folders given with \
             `--allow-write DIR`; allow a folder with `--allow-write DIR`",
        ),
    };
    format!(
        "sandbox: may not {verb} {}{leads}: {why} ({how}, or lift the sandbox with `--trust`)",
        path.display()
    )
}

/// `path` made absolute (from the working directory) with its longest existing part resolved
/// by the file system (`..` and symbolic links, as `canonicalize`), and the rest (what does not
/// exist yet) normalised by its components. An existing part that cannot be resolved (a broken
/// link, a loop) is an error.
pub fn normalise(path: &Path) -> Result<PathBuf, String> {
    let abs = std::path::absolute(path).map_err(|e| e.to_string())?;
    let parts: Vec<Component> = abs.components().collect();
    let mut existing = parts.len();
    while existing > 1 {
        let prefix: PathBuf = parts[..existing].iter().collect();
        if std::fs::symlink_metadata(&prefix).is_ok() {
            break;
        }
        existing -= 1;
    }
    let prefix: PathBuf = parts[..existing].iter().collect();
    let mut real = std::fs::canonicalize(&prefix)
        .map_err(|e| format!("{} cannot be resolved ({e})", prefix.display()))?;
    for c in &parts[existing..] {
        match c {
            Component::ParentDir => {
                real.pop();
            }
            Component::Normal(s) => real.push(s),
            Component::CurDir | Component::RootDir | Component::Prefix(_) => {}
        }
    }
    Ok(real)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn temp(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("emilion_sandbox_{}_{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        std::fs::canonicalize(d).unwrap()
    }

    #[test]
    fn normalise_resolves_the_existing_part_and_folds_the_rest() {
        let d = temp("normalise");
        std::fs::create_dir_all(d.join("a/b")).unwrap();
        assert_eq!(
            normalise(&d.join("a/b/../c/x.png")).unwrap(),
            d.join("a/c/x.png")
        );
        assert_eq!(normalise(&d.join("a/new/../../x")).unwrap(), d.join("x"));
        assert_eq!(
            normalise(&d.join("a/b/../../../../../../../../etc/passwd")).unwrap(),
            Path::new("/etc/passwd")
        );
    }

    #[cfg(unix)]
    #[test]
    fn links_that_lead_out_are_refused() {
        let d = temp("links");
        let out = d.join("out");
        std::fs::create_dir_all(&out).unwrap();
        std::os::unix::fs::symlink("/etc", out.join("etc")).unwrap();
        std::os::unix::fs::symlink(d.join("nowhere"), out.join("broken")).unwrap();
        let mut rules = Rules::default();
        rules.allow_write(&out, "out/");
        assert!(rules.check(&out.join("a/b.png"), Access::Write).is_ok());
        let e = rules
            .check(&out.join("etc/passwd"), Access::Read)
            .unwrap_err();
        assert!(
            e.contains("/etc/passwd") && e.contains("may not read"),
            "{e}"
        );
        let e = rules.check(&out.join("broken"), Access::Write).unwrap_err();
        assert!(e.contains("cannot be resolved"), "{e}");
        assert!(rules
            .check(&out.join("../../outside.png"), Access::Write)
            .is_err());
        // the folder itself is allowed, a link inside it is not; a file written is inside it
        assert!(rules.check(&out, Access::Write).is_err());
        assert!(rules
            .check_folder(&d.join("out/sub"), Access::Write)
            .is_ok());
        let e = rules.check_folder(&out, Access::Write).unwrap_err();
        assert!(
            e.contains("--allow-write DIR") && e.contains("--trust"),
            "{e}"
        );
    }
}
