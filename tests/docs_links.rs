//! The documentation holds together: every relative link or image in `README.md`, in the
//! Markdown files under `docs/` and in `kawabata/*.md` points to a file that exists inside the
//! repository (not to `../shared/…` or anywhere else outside it), and the README stays a
//! user's README: at most 200 lines, opening with `cargo run --release` and
//! `cargo test --release` within its first 30 lines.
//!
//! A link target is what follows `](` up to the closing parenthesis (or the first space, before
//! an optional title); targets starting with `http:`, `https:`, `mailto:` or `#` are not
//! checked, and a `#anchor` is stripped before the path is resolved against the directory of
//! the file that holds it. Fenced code blocks are skipped. Uses only std.

use std::fs;
use std::path::{Path, PathBuf};

/// Most lines the README may have.
const README_MAX_LINES: usize = 200;
/// The two commands must appear within this many lines of the README's top.
const README_COMMANDS_WITHIN: usize = 30;

fn repo_root() -> PathBuf {
    fs::canonicalize(env!("CARGO_MANIFEST_DIR")).expect("the repository root exists")
}

/// The Markdown files whose links are checked: README.md, every `.md` under docs/ (any depth)
/// and kawabata/*.md, sorted.
fn markdown_files(root: &Path) -> Vec<PathBuf> {
    let mut files = vec![root.join("README.md")];
    let mut docs = Vec::new();
    collect_md(&root.join("docs"), true, &mut docs);
    collect_md(&root.join("kawabata"), false, &mut docs);
    docs.sort();
    files.extend(docs);
    files
}

fn collect_md(dir: &Path, recursive: bool, out: &mut Vec<PathBuf>) {
    let Ok(entries) = fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        let path = entry.path();
        if path.is_dir() {
            if recursive {
                collect_md(&path, true, out);
            }
        } else if path.extension().is_some_and(|e| e == "md") {
            out.push(path);
        }
    }
}

/// Every link or image target of `text` outside fenced code blocks, with its 1-based line.
fn link_targets(text: &str) -> Vec<(usize, String)> {
    let mut targets = Vec::new();
    let mut in_fence = false;
    for (k, line) in text.lines().enumerate() {
        let trimmed = line.trim_start();
        if trimmed.starts_with("```") || trimmed.starts_with("~~~") {
            in_fence = !in_fence;
            continue;
        }
        if in_fence {
            continue;
        }
        let mut rest = line;
        while let Some(at) = rest.find("](") {
            let after = &rest[at + 2..];
            let (target, consumed) = if let Some(inner) = after.strip_prefix('<') {
                match inner.find('>') {
                    Some(end) => (&inner[..end], end + 2),
                    None => (inner, inner.len() + 1),
                }
            } else {
                let end = after.find(')').unwrap_or(after.len());
                let inside = &after[..end];
                let target = inside.split_whitespace().next().unwrap_or("");
                (target, end)
            };
            targets.push((k + 1, target.to_string()));
            rest = &after[consumed.min(after.len())..];
        }
    }
    targets
}

/// Whether the link leaves the repository's files alone: web and mail links, and anchors
/// within the same file.
fn is_external_or_anchor(target: &str) -> bool {
    let lower = target.to_ascii_lowercase();
    lower.starts_with("http:")
        || lower.starts_with("https:")
        || lower.starts_with("mailto:")
        || target.starts_with('#')
}

/// Why `target`, written in `file`, does not point to a file of the repository; `None` if it
/// does.
fn check_target(root: &Path, file: &Path, target: &str) -> Option<String> {
    if target.is_empty() {
        return Some("empty link target".to_string());
    }
    let path = target.split('#').next().unwrap_or(target);
    let path = path.replace("%20", " ");
    let dir = file.parent().unwrap_or(root);
    let resolved = dir.join(&path);
    match fs::canonicalize(&resolved) {
        Err(_) => Some(format!("{} does not exist", resolved.display())),
        Ok(canonical) if !canonical.starts_with(root) => Some(format!(
            "{} lies outside the repository",
            canonical.display()
        )),
        Ok(_) => None,
    }
}

#[test]
fn every_relative_link_in_the_docs_points_to_a_file_of_the_repository() {
    let root = repo_root();
    let files = markdown_files(&root);
    assert!(
        files.iter().any(|f| f.starts_with(root.join("docs"))),
        "no Markdown file found under docs/"
    );
    let mut bad = Vec::new();
    let mut checked = 0;
    for file in &files {
        let text = match fs::read_to_string(file) {
            Ok(text) => text,
            Err(e) => {
                bad.push(format!("{}: cannot be read: {e}", file.display()));
                continue;
            }
        };
        let shown = file
            .strip_prefix(&root)
            .unwrap_or(file)
            .display()
            .to_string();
        for (line, target) in link_targets(&text) {
            if is_external_or_anchor(&target) {
                continue;
            }
            checked += 1;
            if let Some(why) = check_target(&root, file, &target) {
                bad.push(format!("{shown}:{line}: `{target}`: {why}"));
            }
        }
    }
    assert!(
        checked > 0,
        "no relative link found in {} files",
        files.len()
    );
    assert!(
        bad.is_empty(),
        "{} bad link(s) of {checked} checked:\n{}",
        bad.len(),
        bad.join("\n")
    );
}

#[test]
fn the_readme_is_short_and_opens_with_the_two_commands() {
    let root = repo_root();
    let text = fs::read_to_string(root.join("README.md")).expect("README.md can be read");
    let lines: Vec<&str> = text.lines().collect();
    assert!(
        lines.len() <= README_MAX_LINES,
        "README.md has {} lines, at most {README_MAX_LINES} allowed: move details into docs/",
        lines.len()
    );
    let top = &lines[..lines.len().min(README_COMMANDS_WITHIN)];
    for command in ["cargo run --release", "cargo test --release"] {
        assert!(
            top.iter().any(|l| l.contains(command)),
            "`{command}` is not within the first {README_COMMANDS_WITHIN} lines of README.md"
        );
    }
}

#[test]
fn link_targets_are_found_outside_code_blocks_only() {
    let text = "See [a](docs/a.md#x) and ![b](<img b.svg> \"t\").\n\
                ```\n[c](not/a/link.md)\n```\n[d](e.md \"title\") [w](https://x.org)\n";
    let found = link_targets(text);
    let expected: [(usize, &str); 4] = [
        (1, "docs/a.md#x"),
        (1, "img b.svg"),
        (5, "e.md"),
        (5, "https://x.org"),
    ];
    let found: Vec<(usize, &str)> = found.iter().map(|(l, t)| (*l, t.as_str())).collect();
    assert_eq!(found, expected);
    assert!(is_external_or_anchor("https://x.org"));
    assert!(is_external_or_anchor("#units"));
    assert!(!is_external_or_anchor("docs/a.md"));
}
