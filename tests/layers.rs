//! The house's layers: no import cycle between the top-level modules of `src/`, and no circle
//! between its files.
//!
//! Reads every `.rs` file under `src/` (comments and string literals removed), collects the
//! paths it names through `crate::`, `super::` and `self::` (in `use` trees and inline), and
//! resolves each to the file that defines it: a module's facade (`mod.rs`, or a file that
//! declares submodules) is looked through when it only re-exports the item with `pub use`.
//! A file declaring a submodule is not an edge to it (the parent owns the child); everything
//! else is. Strongly connected components of more than one node are cycles, listed with the
//! edges that make them.

use std::collections::{BTreeMap, BTreeSet};
use std::fs;
use std::path::{Path, PathBuf};

/// One source file: its module path and what it names.
struct SourceFile {
    module: Vec<String>,
    text: String,
    children: BTreeSet<String>,
    /// `pub use` re-exports: exported name → absolute path it points at.
    reexports: BTreeMap<String, Vec<String>>,
}

fn collect_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let mut entries: Vec<_> = fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    entries.sort();
    for p in entries {
        if p.is_dir() {
            collect_files(&p, out);
        } else if p.extension().is_some_and(|e| e == "rs") {
            out.push(p);
        }
    }
}

/// Module path of a file under `src/`: `a/b.rs` → `[a, b]`, `a/mod.rs` → `[a]`, `lib.rs` → `[]`.
fn module_of(rel: &Path) -> Vec<String> {
    let mut parts: Vec<String> = rel
        .components()
        .map(|c| c.as_os_str().to_string_lossy().into_owned())
        .collect();
    let last = parts.pop().unwrap();
    let stem = last.trim_end_matches(".rs").to_string();
    if stem != "mod" && !(parts.is_empty() && (stem == "lib" || stem == "main")) {
        parts.push(stem);
    }
    parts
}

/// The code with comments removed and string/char literals emptied.
fn strip(src: &str) -> String {
    let b = src.as_bytes();
    let mut out = String::with_capacity(src.len());
    let mut i = 0;
    while i < b.len() {
        let c = b[i];
        if c == b'/' && i + 1 < b.len() && b[i + 1] == b'/' {
            while i < b.len() && b[i] != b'\n' {
                i += 1;
            }
        } else if c == b'/' && i + 1 < b.len() && b[i + 1] == b'*' {
            let mut depth = 1;
            i += 2;
            while i < b.len() && depth > 0 {
                if b[i] == b'/' && i + 1 < b.len() && b[i + 1] == b'*' {
                    depth += 1;
                    i += 2;
                } else if b[i] == b'*' && i + 1 < b.len() && b[i + 1] == b'/' {
                    depth -= 1;
                    i += 2;
                } else {
                    i += 1;
                }
            }
        } else if c == b'r' && i + 1 < b.len() && (b[i + 1] == b'"' || b[i + 1] == b'#') && {
            // a raw string only where `r` starts a token
            i == 0 || !(b[i - 1].is_ascii_alphanumeric() || b[i - 1] == b'_')
        } {
            let mut j = i + 1;
            let mut hashes = 0;
            while j < b.len() && b[j] == b'#' {
                hashes += 1;
                j += 1;
            }
            if j < b.len() && b[j] == b'"' {
                j += 1;
                loop {
                    if j >= b.len() {
                        break;
                    }
                    if b[j] == b'"'
                        && b[j + 1..]
                            .iter()
                            .take(hashes)
                            .filter(|&&h| h == b'#')
                            .count()
                            == hashes
                    {
                        j += 1 + hashes;
                        break;
                    }
                    j += 1;
                }
                out.push_str("\"\"");
                i = j;
            } else {
                out.push('r');
                i += 1;
            }
        } else if c == b'"' {
            i += 1;
            while i < b.len() && b[i] != b'"' {
                if b[i] == b'\\' {
                    i += 1;
                }
                i += 1;
            }
            i += 1;
            out.push_str("\"\"");
        } else if c == b'\'' {
            // a char literal ('x', '\n', '\u{..}') or a lifetime ('a)
            if i + 2 < b.len() && b[i + 1] == b'\\' {
                let mut j = i + 2;
                while j < b.len() && b[j] != b'\'' {
                    j += 1;
                }
                i = j + 1;
                out.push_str("' '");
            } else {
                let ch_len = src[i + 1..].chars().next().map_or(1, |ch| ch.len_utf8());
                if i + 1 + ch_len < b.len() && b[i + 1 + ch_len] == b'\'' {
                    i += 2 + ch_len;
                    out.push_str("' '");
                } else {
                    out.push('\'');
                    i += 1;
                }
            }
        } else {
            let ch = src[i..].chars().next().unwrap();
            out.push(ch);
            i += ch.len_utf8();
        }
    }
    out
}

fn is_ident_byte(c: u8) -> bool {
    c.is_ascii_alphanumeric() || c == b'_'
}

/// Expands a `use` tree (`a::{b, c::{d, e}}`) into its paths.
fn expand_use_tree(tree: &str) -> Vec<Vec<String>> {
    fn split_top(s: &str) -> Vec<&str> {
        let mut parts = Vec::new();
        let (mut depth, mut start) = (0, 0);
        for (i, c) in s.char_indices() {
            match c {
                '{' => depth += 1,
                '}' => depth -= 1,
                ',' if depth == 0 => {
                    parts.push(&s[start..i]);
                    start = i + 1;
                }
                _ => {}
            }
        }
        parts.push(&s[start..]);
        parts
    }
    let tree: String = tree.chars().filter(|c| !c.is_whitespace()).collect();
    let mut out = Vec::new();
    for part in split_top(&tree) {
        if part.is_empty() {
            continue;
        }
        if let Some(brace) = part.find('{') {
            let prefix: Vec<String> = part[..brace]
                .split("::")
                .filter(|s| !s.is_empty())
                .map(String::from)
                .collect();
            let inner = &part[brace + 1..part.len() - 1];
            for sub in expand_use_tree(inner) {
                let mut p = prefix.clone();
                p.extend(sub);
                out.push(p);
            }
        } else {
            let segs: Vec<String> = part
                .split("::")
                .map(|s| s.split("@as@").next().unwrap().to_string())
                .collect();
            out.push(segs);
        }
    }
    out
}

/// `use` statements: (is it `pub`, the expanded paths).
fn use_statements(code: &str) -> Vec<(bool, Vec<Vec<String>>)> {
    let b = code.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while let Some(pos) = code[i..].find("use ") {
        let at = i + pos;
        i = at + 4;
        if at > 0 && is_ident_byte(b[at - 1]) {
            continue;
        }
        let before = code[..at].trim_end();
        let is_pub = before.ends_with("pub") || before.ends_with(')') && before.contains("pub(");
        let Some(end) = code[at..].find(';') else {
            break;
        };
        let tree = &code[at + 4..at + end];
        // keep spaces around `as` distinguishable
        let tree = tree.replace(" as ", "@as@");
        let paths = expand_use_tree(&tree)
            .into_iter()
            .map(|p| p.into_iter().filter(|s| !s.is_empty()).collect())
            .collect();
        out.push((is_pub, paths));
        i = at + end;
    }
    out
}

/// Inline paths starting with `crate::`, `super::` or `self::`.
fn inline_paths(code: &str) -> Vec<Vec<String>> {
    let b = code.as_bytes();
    let mut out = Vec::new();
    for start_kw in ["crate::", "super::", "self::"] {
        let mut i = 0;
        while let Some(pos) = code[i..].find(start_kw) {
            let at = i + pos;
            i = at + start_kw.len();
            if at > 0 && (is_ident_byte(b[at - 1]) || b[at - 1] == b':') {
                continue;
            }
            let mut j = at;
            while j < b.len() && (is_ident_byte(b[j]) || b[j] == b':') {
                j += 1;
            }
            let segs: Vec<String> = code[at..j]
                .split("::")
                .filter(|s| !s.is_empty())
                .map(String::from)
                .collect();
            out.push(segs);
        }
    }
    out
}

/// Child modules declared in the file (`mod x;` or `mod x { … }`).
fn declared_children(code: &str) -> BTreeSet<String> {
    let b = code.as_bytes();
    let mut out = BTreeSet::new();
    let mut i = 0;
    while let Some(pos) = code[i..].find("mod ") {
        let at = i + pos;
        i = at + 4;
        if at > 0 && is_ident_byte(b[at - 1]) {
            continue;
        }
        let name: String = code[at + 4..]
            .trim_start()
            .bytes()
            .take_while(|&c| is_ident_byte(c))
            .map(char::from)
            .collect();
        if !name.is_empty() {
            out.insert(name);
        }
    }
    out
}

/// Makes a path absolute from the module it is written in.
fn absolute(
    module: &[String],
    is_facade_file: bool,
    path: &[String],
    children: &BTreeSet<String>,
) -> Option<Vec<String>> {
    let first = path.first()?;
    // `self` of a non-mod file `a/b.rs` is `a::b`; `super` is `a`
    let mut base: Vec<String> = module.to_vec();
    let _ = is_facade_file;
    let mut rest = path;
    match first.as_str() {
        "crate" => {
            base.clear();
            rest = &path[1..];
        }
        "self" => rest = &path[1..],
        "super" => {
            while rest.first().is_some_and(|s| s == "super") {
                base.pop()?;
                rest = &rest[1..];
            }
        }
        name if children.contains(name) => {}
        _ => return None,
    }
    base.extend(rest.iter().filter(|s| *s != "self").cloned());
    Some(base)
}

struct Tree {
    files: BTreeMap<Vec<String>, SourceFile>,
}

impl Tree {
    /// The file a path lands in, looking through facades' re-exports.
    fn resolve(&self, path: &[String], depth: usize) -> Option<Vec<String>> {
        let mut best = None;
        for len in (0..=path.len()).rev() {
            if self.files.contains_key(&path[..len]) {
                best = Some(len);
                break;
            }
        }
        let len = best?;
        let module = path[..len].to_vec();
        let file = &self.files[&module];
        if depth < 8 && len < path.len() {
            if let Some(target) = file.reexports.get(&path[len]) {
                let mut t = target.clone();
                t.extend(path[len + 1..].iter().cloned());
                if let Some(r) = self.resolve(&t, depth + 1) {
                    return Some(r);
                }
            }
        }
        Some(module)
    }
}

fn load_tree() -> Tree {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut paths = Vec::new();
    collect_files(&src, &mut paths);
    let mut files = BTreeMap::new();
    for p in paths {
        let rel = p.strip_prefix(&src).unwrap();
        if rel == Path::new("main.rs") {
            continue;
        }
        let module = module_of(rel);
        let text = strip(&fs::read_to_string(&p).unwrap());
        let children = declared_children(&text);
        let mut reexports = BTreeMap::new();
        for (is_pub, paths) in use_statements(&text) {
            if !is_pub {
                continue;
            }
            for path in paths {
                if let Some(abs) = absolute(&module, true, &path, &children) {
                    if let Some(name) = abs.last() {
                        if name != "*" {
                            reexports.insert(name.clone(), abs);
                        }
                    }
                }
            }
        }
        files.insert(
            module.clone(),
            SourceFile {
                module,
                text,
                children,
                reexports,
            },
        );
    }
    Tree { files }
}

/// Edges between files: from → {to}, with each resolved path's file.
fn file_edges(tree: &Tree) -> BTreeMap<Vec<String>, BTreeSet<Vec<String>>> {
    let mut edges: BTreeMap<Vec<String>, BTreeSet<Vec<String>>> = BTreeMap::new();
    for (module, file) in &tree.files {
        let mut paths: Vec<Vec<String>> = use_statements(&file.text)
            .into_iter()
            .flat_map(|(_, p)| p)
            .collect();
        paths.extend(inline_paths(&file.text));
        let entry = edges.entry(module.clone()).or_default();
        for path in paths {
            let Some(abs) = absolute(&file.module, false, &path, &file.children) else {
                continue;
            };
            let Some(target) = tree.resolve(&abs, 0) else {
                continue;
            };
            // the file itself, the crate root, and the file's own submodules are not edges
            if &target == module || target.is_empty() {
                continue;
            }
            if target.len() > module.len() && target[..module.len()] == module[..] {
                continue;
            }
            entry.insert(target);
        }
    }
    edges
}

/// Strongly connected components with more than one node (Tarjan).
fn cycles<N: Ord + Clone>(edges: &BTreeMap<N, BTreeSet<N>>) -> Vec<Vec<N>> {
    struct State<N> {
        index: BTreeMap<N, usize>,
        low: BTreeMap<N, usize>,
        stack: Vec<N>,
        on_stack: BTreeSet<N>,
        next: usize,
        out: Vec<Vec<N>>,
    }
    fn visit<N: Ord + Clone>(v: &N, edges: &BTreeMap<N, BTreeSet<N>>, s: &mut State<N>) {
        s.index.insert(v.clone(), s.next);
        s.low.insert(v.clone(), s.next);
        s.next += 1;
        s.stack.push(v.clone());
        s.on_stack.insert(v.clone());
        for w in edges.get(v).into_iter().flatten() {
            if !s.index.contains_key(w) {
                visit(w, edges, s);
                let lw = s.low[w];
                let lv = s.low.get_mut(v).unwrap();
                *lv = (*lv).min(lw);
            } else if s.on_stack.contains(w) {
                let iw = s.index[w];
                let lv = s.low.get_mut(v).unwrap();
                *lv = (*lv).min(iw);
            }
        }
        if s.low[v] == s.index[v] {
            let mut comp = Vec::new();
            loop {
                let w = s.stack.pop().unwrap();
                s.on_stack.remove(&w);
                let done = &w == v;
                comp.push(w);
                if done {
                    break;
                }
            }
            if comp.len() > 1 {
                comp.sort();
                s.out.push(comp);
            }
        }
    }
    let mut s = State {
        index: BTreeMap::new(),
        low: BTreeMap::new(),
        stack: Vec::new(),
        on_stack: BTreeSet::new(),
        next: 0,
        out: Vec::new(),
    };
    for v in edges.keys() {
        if !s.index.contains_key(v) {
            visit(v, edges, &mut s);
        }
    }
    s.out
}

fn describe<N: Ord + Clone>(
    comps: &[Vec<N>],
    edges: &BTreeMap<N, BTreeSet<N>>,
    name: impl Fn(&N) -> String,
) -> String {
    let mut msg = String::new();
    for comp in comps {
        let set: BTreeSet<&N> = comp.iter().collect();
        msg.push_str(&format!(
            "cycle: {}\n",
            comp.iter().map(&name).collect::<Vec<_>>().join(", ")
        ));
        for a in comp {
            for b in edges.get(a).into_iter().flatten() {
                if set.contains(b) {
                    msg.push_str(&format!("    {} -> {}\n", name(a), name(b)));
                }
            }
        }
    }
    msg
}

fn file_name(m: &[String]) -> String {
    if m.is_empty() {
        "lib".into()
    } else {
        m.join("/")
    }
}

#[test]
fn no_cycle_between_top_level_modules() {
    let tree = load_tree();
    let files = file_edges(&tree);
    let mut modules: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for (from, tos) in &files {
        let Some(a) = from.first() else { continue };
        let entry = modules.entry(a.clone()).or_default();
        for to in tos {
            if let Some(b) = to.first() {
                if b != a {
                    entry.insert(b.clone());
                }
            }
        }
    }
    let comps = cycles(&modules);
    assert!(
        comps.is_empty(),
        "import cycles between top-level modules of src/:\n{}",
        describe(&comps, &modules, |m| m.clone())
    );
}

#[test]
fn no_circle_between_files() {
    let tree = load_tree();
    let edges = file_edges(&tree);
    let comps = cycles(&edges);
    assert!(
        comps.is_empty(),
        "file-level circles in src/:\n{}",
        describe(&comps, &edges, |m| file_name(m))
    );
}

#[test]
fn the_checker_sees_a_planted_cycle() {
    // two modules naming each other must be found (the test can fail)
    let mut edges: BTreeMap<&str, BTreeSet<&str>> = BTreeMap::new();
    edges.entry("cloth").or_default().insert("contact");
    edges.entry("contact").or_default().insert("cloth");
    edges.entry("geometry").or_default();
    assert_eq!(cycles(&edges), vec![vec!["cloth", "contact"]]);
    let paths = expand_use_tree("crate::cloth::{bcsr::Bcsr, pcg::{self, Pcg}}");
    assert_eq!(paths.len(), 3);
    assert_eq!(paths[0], vec!["crate", "cloth", "bcsr", "Bcsr"]);
}

/// The layer of each top-level module, bottom up (docs/architecture.md); modules of one layer
/// may use each other as long as they make no cycle.
const LAYERS: &[&[&str]] = &[
    &["limits"],
    &["geometry"],
    &["render"],
    &["body"],
    &["cloth", "shell"],
    &["contact"],
    &["garment", "kes"],
    &["tracking", "face", "facade"],
    &["scenes", "bench"],
    // sweeps start `emilion run` as child processes; they do not link the scripting layer
    &["sweep"],
    &["script"],
    // the binary's own modules (src/cli/, used by src/main.rs)
    &["cli"],
];

#[test]
fn modules_use_only_lower_layers() {
    let rank = |m: &str| LAYERS.iter().position(|layer| layer.contains(&m));
    let tree = load_tree();
    let mut wrong = BTreeSet::new();
    for (from, tos) in file_edges(&tree) {
        let Some(a) = from.first() else { continue };
        let ra = rank(a).unwrap_or_else(|| panic!("src/{a} has no layer in LAYERS"));
        for to in tos {
            let Some(b) = to.first() else { continue };
            let rb = rank(b).unwrap_or_else(|| panic!("src/{b} has no layer in LAYERS"));
            if rb > ra {
                wrong.insert(format!("{} -> {}", file_name(&from), file_name(&to)));
            }
        }
    }
    assert!(
        wrong.is_empty(),
        "imports from a lower layer into a higher one:\n{}",
        wrong.into_iter().collect::<Vec<_>>().join("\n")
    );
}
