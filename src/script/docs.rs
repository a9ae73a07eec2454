//! API documentation generated from the engine's own metadata: `api.md` (a section per
//! module with its functions, then the global methods and properties, then the old flat names
//! kept as aliases; signatures and doc comments) and `api.json` (rhai's function metadata, each
//! function marked with its `module` and, for an alias, the function it stands for). The REPL's
//! `help` reads the same entries.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use rhai::Engine;
use serde_json::Value;

use super::modules::{alias_target, MODULES};

/// One registered function overload.
#[derive(Debug, Clone, PartialEq, Eq, PartialOrd, Ord)]
pub struct ApiEntry {
    /// The static module of a module function (`cloth`); `None` for the global methods,
    /// properties and aliases.
    pub module: Option<String>,
    /// Name as scripts use it: `cloth::grid`, `run`, or `.time` for a property.
    pub name: String,
    /// Full signature, e.g. `cloth::grid(width: float, …) -> Cloth`.
    pub signature: String,
    /// Doc text without the `///` markers.
    pub doc: String,
}

impl ApiEntry {
    /// The `module::name` this entry is an alias of (an old flat name kept for one release).
    pub fn alias_of(&self) -> Option<&str> {
        alias_target(&self.doc)
    }
}

/// Strips `///` / `/** */` markers from rhai doc comments.
fn doc_text(comments: &[serde_json::Value]) -> String {
    let mut lines = Vec::new();
    for c in comments.iter().filter_map(|c| c.as_str()) {
        for l in c.lines() {
            let l = l.trim_start();
            let l = l
                .strip_prefix("///")
                .or_else(|| l.strip_prefix("/**"))
                .unwrap_or(l);
            let l = l.strip_suffix("*/").unwrap_or(l);
            lines.push(l.strip_prefix(' ').unwrap_or(l).to_string());
        }
    }
    lines.join("\n").trim().to_string()
}

/// Parameters (name, type) and return type of a signature `f(a: A, b: B) -> R`.
fn split_signature(sig: &str) -> (Vec<(String, String)>, String) {
    let open = sig.find('(').unwrap_or(sig.len());
    let close = sig.rfind(')').unwrap_or(sig.len());
    let args = sig.get(open + 1..close).unwrap_or("");
    let mut params: Vec<(String, String)> = args
        .split(", ")
        .filter(|a| !a.is_empty())
        .map(|a| match a.split_once(':') {
            Some((n, t)) => (n.trim().to_string(), t.trim().to_string()),
            None => (a.trim().to_string(), "?".to_string()),
        })
        .collect();
    while params.len() < 2 {
        params.push(("value".into(), "?".into()));
    }
    let ret = sig
        .get(close + 1..)
        .and_then(|r| r.split_once("->"))
        .map(|(_, r)| r.trim().to_string());
    (params, ret.unwrap_or_else(|| "()".into()))
}

/// The entry of one function of rhai's metadata, in `module` (`None`: global).
fn entry(f: &Value, module: Option<&str>) -> ApiEntry {
    let raw = f["name"].as_str().unwrap_or("");
    let sig = f["signature"].as_str().unwrap_or(raw).to_string();
    let doc = doc_text(
        f["docComments"]
            .as_array()
            .map(Vec::as_slice)
            .unwrap_or(&[]),
    );
    let (name, signature) = if let Some(p) = raw.strip_prefix("get$") {
        let (args, ret) = split_signature(&sig);
        (format!(".{p}"), format!("{}.{p} -> {ret}", args[0].0))
    } else if let Some(p) = raw.strip_prefix("set$") {
        let (args, _) = split_signature(&sig);
        (
            format!(".{p}"),
            format!("{}.{p} = {}: {}", args[0].0, args[1].0, args[1].1),
        )
    } else if let Some(m) = module {
        (format!("{m}::{raw}"), format!("{m}::{sig}"))
    } else {
        (raw.to_string(), sig)
    };
    ApiEntry {
        module: module.map(str::to_string),
        name,
        signature,
        doc,
    }
}

/// The engine's function metadata (emilion's functions, not rhai's standard library).
fn metadata(engine: &Engine) -> Value {
    let json = engine.gen_fn_metadata_to_json(false).unwrap_or_default();
    serde_json::from_str(&json).unwrap_or_default()
}

/// Every function emilion registers (not rhai's standard library): the global ones, then each
/// module's, sorted by module, name and signature.
pub fn api_entries(engine: &Engine) -> Vec<ApiEntry> {
    let v = metadata(engine);
    let mut out: Vec<ApiEntry> = v["functions"]
        .as_array()
        .into_iter()
        .flatten()
        .map(|f| entry(f, None))
        .collect();
    for (m, module) in v["modules"].as_object().into_iter().flatten() {
        for f in module["functions"].as_array().into_iter().flatten() {
            out.push(entry(f, Some(m)));
        }
    }
    out.sort();
    out.dedup();
    out
}

/// Appends `## title` and, per name, its overloads' signatures and docs (properties after the
/// function of the same name).
fn append_section(md: &mut String, title: &str, intro: &str, entries: &[&ApiEntry]) {
    let mut groups: BTreeMap<String, Vec<&ApiEntry>> = BTreeMap::new();
    for e in entries {
        let key = e.name.trim_start_matches('.').to_string()
            + if e.name.starts_with('.') { " " } else { "" };
        groups.entry(key).or_default().push(e);
    }
    *md += &format!("\n## {title}\n\n{intro}\n");
    for entries in groups.values() {
        *md += &format!("\n### `{}`\n", entries[0].name);
        for e in entries {
            *md += &format!("\n```\n{}\n```\n", e.signature);
            if !e.doc.is_empty() {
                *md += &format!("\n{}\n", e.doc);
            }
        }
    }
}

/// The Markdown reference of the script API: a section per module, the global methods and
/// properties, and a table of the aliases.
pub fn api_markdown(engine: &Engine) -> String {
    let entries = api_entries(engine);
    let mut md = String::from(
        "# Emilion script API\n\nGenerated by `emilion doc` from the engine's metadata. Numbers marked `float`\n\
         also accept integers; units are SI (m, kg, s, N). Free functions (constructors, loaders,\n\
         experiments) live in modules and are called as `module::name(…)`, e.g.\n\
         `cloth::grid(0.5, 0.5, 10, 10, cloth::fabric())`. Methods and properties of the values they\n\
         return are global: `sim.run(1.0)`, `cloth.vertex_count`. Properties are read as\n\
         `obj.name` and, where a setter exists, assigned as `obj.name = value`. The old flat names\n\
         (`cloth_grid`, …) still work for one release; they are listed at the end.\n\nModules:\n\n",
    );
    for (m, doc) in MODULES {
        md += &format!("- `{m}`: {doc}\n");
    }
    for (m, doc) in MODULES {
        let in_module: Vec<&ApiEntry> = entries
            .iter()
            .filter(|e| e.module.as_deref() == Some(m))
            .collect();
        append_section(&mut md, &format!("Module `{m}`"), doc, &in_module);
    }
    let global: Vec<&ApiEntry> = entries
        .iter()
        .filter(|e| e.module.is_none() && e.alias_of().is_none())
        .collect();
    append_section(
        &mut md,
        "Methods and properties",
        "Global: called on a value, `value.name(…)` (or `name(value, …)`).",
        &global,
    );
    md += "\n## Aliases kept for one release\n\nOld flat names that still call the module function; use the module function.\n\n\
           | old name | module function |\n|---|---|\n";
    let mut aliases: Vec<(&str, &str)> = entries
        .iter()
        .filter_map(|e| e.alias_of().map(|t| (e.name.as_str(), t)))
        .collect();
    aliases.dedup();
    for (old, new) in aliases {
        md += &format!("| `{old}` | `{new}` |\n");
    }
    md
}

/// rhai's function metadata with each function marked with its `module` (`null`: global) and
/// each alias with `aliasOf`, the module function it stands for.
pub fn api_json(engine: &Engine) -> serde_json::Result<String> {
    fn mark(functions: &mut Value, module: Option<&str>) {
        for f in functions.as_array_mut().into_iter().flatten() {
            let alias = alias_target(&doc_text(
                f["docComments"]
                    .as_array()
                    .map(Vec::as_slice)
                    .unwrap_or(&[]),
            ))
            .map(str::to_string);
            if let Some(f) = f.as_object_mut() {
                f.insert("module".into(), module.into());
                if let Some(a) = alias {
                    f.insert("aliasOf".into(), a.into());
                }
            }
        }
    }
    let mut v: Value = serde_json::from_str(&engine.gen_fn_metadata_to_json(false)?)?;
    mark(&mut v["functions"], None);
    for (m, module) in v["modules"].as_object_mut().into_iter().flatten() {
        mark(&mut module["functions"], Some(m));
    }
    serde_json::to_string_pretty(&v)
}

/// Writes `api.md` and `api.json` into `out_dir` (created if needed); returns their paths.
pub fn write_docs(out_dir: &Path) -> std::io::Result<Vec<PathBuf>> {
    let engine = super::build_engine();
    std::fs::create_dir_all(out_dir)?;
    let md = out_dir.join("api.md");
    std::fs::write(&md, api_markdown(&engine))?;
    let json = out_dir.join("api.json");
    std::fs::write(&json, api_json(&engine).map_err(std::io::Error::other)?)?;
    Ok(vec![md, json])
}

/// Help for the REPL: every overload whose name (`module::name`, name or property name)
/// starts with `prefix` (all when empty, signatures only).
pub fn help_text(engine: &Engine, prefix: &str) -> String {
    let prefix = prefix.trim_start_matches('.');
    let mut s = String::new();
    for e in api_entries(engine)
        .iter()
        .filter(|e| e.name.trim_start_matches('.').starts_with(prefix))
    {
        s += &e.signature;
        s.push('\n');
        if !prefix.is_empty() {
            for l in e.doc.lines() {
                s += &format!("    {l}\n");
            }
        }
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::script::build_engine;

    #[test]
    fn every_function_is_documented() {
        let undocumented: Vec<_> = api_entries(&build_engine())
            .into_iter()
            .filter(|e| e.doc.is_empty())
            .map(|e| e.signature)
            .collect();
        assert!(undocumented.is_empty(), "no doc comment: {undocumented:?}");
    }

    #[test]
    fn every_alias_stands_for_a_module_function_with_its_parameters() {
        let entries = api_entries(&build_engine());
        let aliases: Vec<_> = entries.iter().filter(|e| e.alias_of().is_some()).collect();
        assert!(aliases.len() > 20, "{aliases:?}");
        for a in aliases {
            let target = a.alias_of().unwrap();
            let (_, params) = a.signature.split_at(a.name.len());
            let signature = format!("{target}{params}");
            assert!(
                entries.iter().any(|e| e.signature == signature),
                "alias {} has no module function {signature}",
                a.signature
            );
        }
        for e in entries.iter().filter(|e| e.module.is_some()) {
            assert!(e
                .name
                .starts_with(&format!("{}::", e.module.as_deref().unwrap())));
            assert!(e.alias_of().is_none(), "{}", e.name);
        }
    }

    #[test]
    fn the_reference_is_grouped_by_module() {
        let md = api_markdown(&build_engine());
        let at = |s: &str| md.find(s).unwrap_or_else(|| panic!("api.md lacks {s}"));
        assert!(at("## Module `cloth`") < at("### `cloth::grid`"));
        assert!(at("### `cloth::grid`") < at("## Module `garment`"));
        assert!(at("## Module `kes`") < at("### `kes::lab`"));
        assert!(at("## Methods and properties") < at("### `run`"));
        assert!(at("## Aliases kept for one release") < at("| `cloth_grid` | `cloth::grid` |"));
        assert!(md.contains("cloth::grid(width: float"));
        assert!(
            !md.contains("### `cloth_grid`"),
            "aliases only in their table"
        );
    }

    #[test]
    fn the_json_names_each_function_s_module() {
        let v: Value = serde_json::from_str(&api_json(&build_engine()).unwrap()).unwrap();
        let grid = v["modules"]["cloth"]["functions"]
            .as_array()
            .unwrap()
            .iter()
            .find(|f| f["name"] == "grid")
            .unwrap();
        assert_eq!(grid["module"], "cloth");
        let old = v["functions"]
            .as_array()
            .unwrap()
            .iter()
            .find(|f| f["name"] == "cloth_grid")
            .unwrap();
        assert_eq!(old["module"], Value::Null);
        assert_eq!(old["aliasOf"], "cloth::grid");
    }
}
