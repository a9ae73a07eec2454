//! Script bindings for garments: pattern files (garment tables, JSON, SVG, DXF-AAMA) as a
//! `Pattern` handle, written back as DXF-AAMA (`save_dxf`), and `garment::dress`, which
//! meshes, pre-positions and sews a pattern on the mannequin into a `Simulation`.

use std::path::Path;
use std::sync::Arc;

use rhai::{Map, INT};

use super::convert::{count, num, rt_err, update_from_map, RResult};
use super::kes::KesFabric;
use super::paths::{read_folder, read_path, write_path};
use super::{function, modules::ApiBuilder, register, Fabric, SimHandle};
use crate::body::Mannequin;
use crate::cloth::{FabricParameters, MaterialLaw, SimulationParameters};
use crate::garment::{dress, read_garment, read_pattern_json, read_pattern_svg, DressParameters};
use crate::garment::{write_pattern_dxf_with, DxfOptions, DxfUnits};
use crate::garment::{Pattern, PatternError, SvgOptions};
use crate::kes::lab::measured_fabric;

/// A pattern as a script handle (shared, never copied).
#[derive(Debug, Clone)]
pub struct PatternHandle(pub Arc<Pattern>);

fn perr(e: PatternError) -> Box<rhai::EvalAltResult> {
    rt_err(e.to_string())
}

/// Reads a pattern by its file's extension: `path` as the script gave it, `file` where it
/// leads ([`read_path`]).
fn read_any(path: &str, file: &Path) -> Result<Pattern, PatternError> {
    let p = file;
    if path.ends_with(".garment.json") {
        read_garment(p)
    } else if path.ends_with(".json") {
        read_pattern_json(p)?.expanded()
    } else if path.ends_with(".svg") {
        read_pattern_svg(p, &SvgOptions::default())?.expanded()
    } else if path.ends_with(".dxf") {
        crate::garment::read_pattern_dxf(p)?.expanded()
    } else {
        Err(PatternError::Parameter(format!(
            "{path}: unknown pattern format (expected .garment.json, .json, .svg or .dxf)"
        )))
    }
}

/// Checks that the SVG a garment table (`*.garment.json`) names may be read too (the sandbox);
/// other files, and tables that cannot be read, are left to the reader.
fn garment_svg_allowed(file: &Path) -> RResult<()> {
    if !file.to_string_lossy().ends_with(".garment.json") {
        return Ok(());
    }
    let Ok(text) = crate::limits::read_to_string(file) else {
        return Ok(());
    };
    let svg = serde_json::from_str::<serde_json::Value>(&text)
        .ok()
        .and_then(|v| v.get("svg")?.as_str().map(str::to_string));
    if let Some(svg) = svg {
        // `file` is absolute or the working directory's, so the SVG's path is made absolute
        let svg = file.parent().unwrap_or(Path::new("")).join(svg);
        let svg = std::path::absolute(&svg).unwrap_or(svg);
        read_path(&svg.to_string_lossy())?;
    }
    Ok(())
}

/// `garment::dress` for both kinds of fabric: a linear one, or a density with a measured law.
fn dress_on_mannequin(
    pattern: &Pattern,
    fabric: FabricParameters,
    law: Option<Arc<dyn MaterialLaw>>,
    mut m: Map,
) -> RResult<SimHandle> {
    let dir = match m.remove("makehuman") {
        Some(d) => read_folder(
            &d.into_string()
                .map_err(|t| rt_err(format!("`makehuman` must be a string, got {t}")))?,
        )?,
        None => crate::geometry::files::data_path("bodies/makehuman"),
    };
    let mut sp = SimulationParameters::default();
    if let Some(dt) = m.remove("dt") {
        sp.dt = num(&dt, "dt")?;
    }
    let mut params = DressParameters::default();
    if let Some(e) = m.remove("edge_length") {
        params.mesh.edge_length = num(&e, "edge_length")?;
    }
    if let Some(c) = m.remove("clearance") {
        params.preposition.clearance = num(&c, "clearance")?;
    }
    if let Some(l) = m.remove("relax_levels") {
        params.preposition.levels = count(&l, "relax_levels")?;
    }
    let mut grade = [1.0, 1.0];
    for (k, key) in ["body_girth", "body_height"].into_iter().enumerate() {
        if let Some(v) = m.remove(key) {
            grade[k] = num(&v, key)?;
        }
    }
    let params: DressParameters = update_from_map(&params, &m, "dress")?;
    let mut man = Mannequin::load_makehuman(&dir).map_err(|e| rt_err(e.to_string()))?;
    if grade != [1.0, 1.0] {
        man = man
            .graded(grade[0], grade[1])
            .map_err(|e| rt_err(e.to_string()))?;
    }
    let mut d = dress(pattern, fabric, &man, &params, sp).map_err(perr)?;
    if let Some(law) = law {
        d.simulation.set_material(law)?;
    }
    Ok(SimHandle::new(d.simulation))
}

/// Registers the garment functions.
pub fn register(engine: &mut ApiBuilder) {
    engine.register_type_with_name::<PatternHandle>("Pattern");
    function!(engine, "garment::pattern", alias = "garment_pattern", ["path: String", "Pattern"],
        "Reads a sewing pattern: a garment table (`*.garment.json`: an SVG, the parts used, folds,\npairs, placements and seams), a pattern in JSON, an SVG or a DXF-AAMA file. Pieces cut on the\nfold are unfolded and pairs doubled; the pattern is validated (closed, non-crossing outlines,\nmatching seam lengths) with errors naming file, piece and edge.",
        |path: &str| -> RResult<PatternHandle> { {
            let file = read_path(path)?;
            garment_svg_allowed(&file)?;
            Ok(PatternHandle(Arc::new(read_any(path, &file).map_err(perr)?)))
        } });
    register!(
        engine,
        "piece_count",
        ["pattern: Pattern", "int"],
        "Number of pieces (after unfolding and doubling).",
        |p: &mut PatternHandle| -> INT { p.0.pieces.len() as INT }
    );
    register!(
        engine,
        "seam_count",
        ["pattern: Pattern", "int"],
        "Number of seams.",
        |p: &mut PatternHandle| -> INT { p.0.seams.len() as INT }
    );
    function!(engine, "garment::dress", alias = "dress", ["pattern: Pattern", "fabric: Fabric", "options: Map", "Simulation"],
        "Meshes the pattern, pre-positions it around the MakeHuman mannequin at rest (no arrangement\npoints) and returns a simulation that sews it (seam threads shorten at `sewing_speed`, no\ngravity) and then drapes it, the mannequin as a collision body. Options: `makehuman` (dir,\ndefault `$EMILION_DATA/bodies/makehuman`), `dt` (s), and the `DressParameters` fields:\n`seam_stiffness` (N/m), `seam_max_force` (N), `sewing_speed` (m/s), `silhouette_cell` (m),\n`edge_length` (m, the mesh's target edge), `clearance` (m, kept from the skin) and\n`relax_levels` (levels of the pre-positioning's multi-resolution relaxation, 1 to 6, default 3);\n`body_girth` and `body_height` grade the mannequin to a size (factors across and up, default 1,\n0.5 to 2: `body::Mannequin::graded`), to match a pattern graded with `graded`.",
        |p: &mut PatternHandle, f: Fabric, m: Map| -> RResult<SimHandle> {
            dress_on_mannequin(&p.0, f.0, None, m)
        });
    function!(engine, "garment::dress", alias = "dress", ["pattern: Pattern", "fabric: KesFabric", "options: Map", "Simulation"],
        "As `garment::dress` with a fabric file (`kes::fabric`): the garment takes the fabric's areal density\nand its material law from its measurements (KES parameters or curves, uncalibrated).",
        |p: &mut PatternHandle, f: KesFabric, m: Map| -> RResult<SimHandle> {
            let (params, law) = measured_fabric(&f.0).map_err(rt_err)?;
            dress_on_mannequin(&p.0, params, Some(Arc::new(law)), m)
        });
    register!(engine, "graded", ["pattern: Pattern", "girth: float", "height: float", "Pattern"],
        "The pattern graded to another size: every piece scaled by `girth` across and `height` along\n(corners, curves, grain, notches, placement offsets; seam allowances kept), factors 0.5 to 2,\nthen validated (a seam that no longer matches is named). Dress it on a mannequin graded the\nsame way: `dress(p, fabric, #{ body_girth: girth, body_height: height })`.",
        |p: &mut PatternHandle, girth: f64, height: f64| -> RResult<PatternHandle> {
            Ok(PatternHandle(Arc::new(p.0.graded(girth, height).map_err(perr)?)))
        });
    register!(engine, "save_sheet", ["pattern: Pattern", "path: String", "()"],
        "Writes the pattern sheet (`.png` or `.svg`): the pieces side by side at 400 pixels per metre,\nnames, grain lines, notches, and each seam's two edges in its colour with its number.",
        |p: &mut PatternHandle, path: &str| -> RResult<()> {
            crate::garment::write_pattern_sheet(&write_path(path)?, &p.0, 400.0).map_err(rt_err)
        });
    register!(engine, "save_dxf", ["pattern: Pattern", "path: String", "()"],
        "Writes the pattern as a DXF-AAMA file (ASCII DXF R12) in millimetres: one block per piece\nwith its cut line (layer 1), sewing line (14), turn and curve points (2, 3), notches (4),\ngrain line (7), and as annotation text (layer 15) its corner names and placement; the\nseams as `Seam:` annotation texts. `garment::pattern` reads it back into the same pattern.",
        |p: &mut PatternHandle, path: &str| -> RResult<()> {
            write_pattern_dxf_with(&p.0, &write_path(path)?, &DxfOptions::default()).map_err(perr)
        });
    register!(engine, "save_dxf", ["pattern: Pattern", "path: String", "options: Map", "()"],
        "As `save_dxf(path)` with options: `units` (\"mm\" default, \"cm\", \"m\" or \"in\"; written as\n`$INSUNITS` and the AAMA `Units:` text).",
        |p: &mut PatternHandle, path: &str, m: Map| -> RResult<()> {
            let mut options = DxfOptions::default();
            for (k, v) in m {
                match k.as_str() {
                    "units" => {
                        let u = v.into_string().map_err(|t| {
                            rt_err(format!("`units` must be a string, got {t}"))
                        })?;
                        options.units = DxfUnits::parse(&u).map_err(perr)?;
                    }
                    other => {
                        return Err(rt_err(format!(
                            "save_dxf: unknown option `{other}` (expected `units`)"
                        )))
                    }
                }
            }
            write_pattern_dxf_with(&p.0, &write_path(path)?, &options).map_err(perr)
        });
    register!(
        engine,
        "seam_gap",
        ["sim: Simulation", "float"],
        "The largest distance between sewn vertices (m); 0 without seams.",
        |h: &mut SimHandle| -> RResult<f64> {
            let s = h.get()?;
            Ok(s.sewing
                .as_ref()
                .map_or(0.0, |w| w.max_gap(&s.model, &s.state.x)))
        }
    );
}
