//! The script API's namespaces. Free functions (constructors, loaders, experiments) live in
//! static modules named for their domain: `cloth::grid`, `kes::lab`, `face::fit`, … Methods and
//! properties of the handle types stay global, so `sim.run(1.0)` and `cloth.vertex_count` read
//! as before. A module function registered with an alias also answers to its old flat name
//! (`cloth_grid`) for one release; the alias's doc comment says so and names the function.
//!
//! [`ApiBuilder`] is what every `register` function of this folder fills: it derefs to the
//! [`Engine`] (methods, properties, types) and collects the modules until [`ApiBuilder::finish`]
//! registers them as static modules.

use std::collections::BTreeMap;
use std::ops::{Deref, DerefMut};

use rhai::{Engine, Module};

/// The static modules, each with its doc line, in the order the reference lists them.
pub const MODULES: [(&str, &str); 8] = [
    (
        "cloth",
        "Fabrics, cloth models and the simulations that move them.",
    ),
    (
        "garment",
        "Sewing patterns and garments dressed on the mannequin.",
    ),
    (
        "kes",
        "The virtual Kawabata lab: fabric files, lab runs, summaries and damping.",
    ),
    (
        "facade",
        "Facade photos and label maps: analysis, rule files, baselines and scores.",
    ),
    (
        "face",
        "The face model: expressions, fitting to photos, synthetic sequences and tracking.",
    ),
    (
        "track",
        "The body tracker and the synthetic multi-camera sequences it is tested on.",
    ),
    ("plot", "Plots of series collected by a script."),
    (
        "shell",
        "The meshless Kirchhoff–Love shell (Galerkin on moving least squares) and its benchmarks.",
    ),
];

/// The start of every alias's doc comment, followed by the function's `module::name`.
const ALIAS_PREFIX: &str = "Alias of `";
/// The end of every alias's doc comment.
const ALIAS_SUFFIX: &str = "`, kept for one release.";

/// The doc comment of an old flat name kept for `target` (`module::name`).
pub fn alias_doc(target: &str) -> String {
    format!("{ALIAS_PREFIX}{target}{ALIAS_SUFFIX}")
}

/// The `module::name` an alias's doc text names, or `None` when the doc is not an alias's.
pub fn alias_target(doc: &str) -> Option<&str> {
    doc.trim()
        .strip_prefix(ALIAS_PREFIX)?
        .strip_suffix(ALIAS_SUFFIX)
}

/// The doc line of a module of [`MODULES`].
pub fn module_doc(name: &str) -> Option<&'static str> {
    MODULES.iter().find(|(m, _)| *m == name).map(|(_, d)| *d)
}

/// An engine being filled with the API: the engine itself (through `Deref`) for methods,
/// properties and types, and one [`Module`] per entry of [`MODULES`] for free functions.
pub struct ApiBuilder {
    engine: Engine,
    modules: BTreeMap<&'static str, Module>,
}

impl ApiBuilder {
    /// Starts from `engine` with every module of [`MODULES`] empty.
    pub fn new(engine: Engine) -> Self {
        let modules = MODULES
            .iter()
            .map(|&(name, doc)| {
                let mut m = Module::new();
                m.set_doc(doc);
                (name, m)
            })
            .collect();
        ApiBuilder { engine, modules }
    }

    /// The module `name` (one of [`MODULES`]).
    ///
    /// # Panics
    /// On a name outside [`MODULES`]: a registration mistake, caught by any test that builds
    /// the engine.
    pub fn module(&mut self, name: &str) -> &mut Module {
        self.modules
            .get_mut(name)
            .unwrap_or_else(|| panic!("script module `{name}` is not in MODULES"))
    }

    /// Registers the modules as static modules and returns the engine.
    pub fn finish(self) -> Engine {
        let mut engine = self.engine;
        for (name, module) in self.modules {
            engine.register_static_module(name, module.into());
        }
        engine
    }
}

impl Deref for ApiBuilder {
    type Target = Engine;
    fn deref(&self) -> &Engine {
        &self.engine
    }
}

impl DerefMut for ApiBuilder {
    fn deref_mut(&mut self) -> &mut Engine {
        &mut self.engine
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn alias_docs_name_their_function() {
        assert_eq!(alias_target(&alias_doc("cloth::grid")), Some("cloth::grid"));
        assert_eq!(alias_target("A rectangle of cloth."), None);
    }

    #[test]
    fn every_module_has_a_doc_line() {
        for (name, doc) in MODULES {
            assert_eq!(module_doc(name), Some(doc));
            assert!(!doc.is_empty());
        }
    }
}
