//! The files of one analysed photo: the diagnostic overlay (always, also when the analysis
//! failed), the rectified photo, the parse as a LabelMeFacade-coloured label map, the rule
//! file, and 3D facades (OBJ+MTL and glTF, textured with the rectified photo, with the library
//! elements the grammar inserts) generated from the grammar at the photo's width and at other
//! widths.

use std::io::Cursor;
use std::path::{Path, PathBuf};

use image::{ImageFormat, Rgb, RgbImage};

use super::analysis::Analysis;
use super::element_library::{insert_elements, Library};
use super::error::FacadeError;
use super::facade_export::{appearance, write_glb_textured, write_obj_mtl};
use super::facade_mesh::{build, check_closed, FacadeMesh, MeshParams};
use super::grammar::Grammar;
use super::labels::{Class, LabelMap};
use super::overlay;
use super::rasterize::rasterize;
use super::rule_file::check_extent;
use super::segments;
use crate::geometry::LookAtCamera;
use crate::geometry::Vec3;
use crate::render::{render_png, RenderMesh};

/// Storey height (m) a floor of the parse stands for when the facade is built in 3D.
pub const STOREY_M: f64 = 3.2;

/// What to write.
#[derive(Debug, Clone, PartialEq)]
pub struct OutputOptions {
    /// Widths of the generated 3D facades, as multiples of the photo's (heights unchanged).
    pub widths: Vec<f64>,
    /// Heights of the generated 3D facades, as multiples of the photo's (widths unchanged).
    pub heights: Vec<f64>,
}

impl Default for OutputOptions {
    fn default() -> Self {
        OutputOptions {
            widths: vec![1.0, 0.75, 1.5],
            heights: vec![],
        }
    }
}

fn file_err(path: &Path, message: impl ToString) -> FacadeError {
    FacadeError::File {
        path: path.to_path_buf(),
        message: message.to_string(),
    }
}

/// Writes a PNG atomically.
pub fn write_png(path: &Path, img: &RgbImage) -> Result<(), FacadeError> {
    let mut bytes = Vec::new();
    img.write_to(&mut Cursor::new(&mut bytes), ImageFormat::Png)
        .map_err(|e| file_err(path, e))?;
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(|e| file_err(dir, e))?;
    }
    let tmp = path.with_extension("png.tmp");
    std::fs::write(&tmp, &bytes).map_err(|e| file_err(&tmp, e))?;
    std::fs::rename(&tmp, path).map_err(|e| file_err(path, e))
}

/// A label map in the LabelMeFacade colours (ignore black).
pub fn label_picture(map: &LabelMap) -> RgbImage {
    RgbImage::from_fn(map.width, map.height, |x, y| {
        Rgb(match map.at(x, y) {
            Class::Window => [0, 0, 128],
            Class::Wall => [128, 0, 0],
            Class::Door => [128, 128, 0],
            Class::Background => [0, 128, 128],
            Class::Balcony => [128, 0, 128],
            Class::Ignore => [0, 0, 0],
        })
    })
}

/// Renders a generated facade (flat colours per surface) from the front, a little to the right
/// and above, to a PNG.
pub fn render_facade(path: &Path, mesh: &FacadeMesh) -> Result<(), FacadeError> {
    let (mut lo, mut hi) = (Vec3::repeat(f64::INFINITY), Vec3::repeat(f64::NEG_INFINITY));
    for p in &mesh.positions {
        lo = lo.inf(p);
        hi = hi.sup(p);
    }
    if !(lo.iter().chain(hi.iter()).all(|c| c.is_finite())) {
        return Err(file_err(path, "nothing to render: empty facade"));
    }
    let (size, center) = (hi - lo, 0.5 * (lo + hi));
    let (width, height) = (800u32, 600u32);
    let fov: f64 = 40.0;
    // far enough that the facade's width and height fit with a margin
    let fit = (size.y / (0.5 * fov.to_radians()).tan())
        .max(size.x / (0.5 * fov.to_radians()).tan() * height as f64 / width as f64)
        * 0.6;
    let camera = LookAtCamera {
        eye: center + Vec3::new(0.35, 0.2, 1.0).normalize() * (fit + size.z),
        target: center,
        up: Vec3::y(),
        fov_y_deg: fov,
        width,
        height,
    };
    let meshes: Vec<RenderMesh> = mesh
        .groups
        .iter()
        .map(|g| RenderMesh {
            positions: &mesh.positions,
            triangles: &mesh.triangles[g.triangles.clone()],
            color: appearance(g.surface)
                .srgb
                .map(|c| (c * 255.0).round().clamp(0.0, 255.0) as u8),
        })
        .collect();
    render_png(path, &meshes, &camera).map_err(|e| file_err(path, e))
}

/// Writes the outputs of `a` into `dir` as `STEM_overlay.png`, and when the parse succeeded
/// `STEM_rectified.png`, `STEM_labels.png`, `STEM.cga` (the rules) and, per width and height
/// factor, `STEM_wX.obj/.mtl/.glb` and a render `STEM_wX.png`. Returns the files written. The overlay is written first,
/// so it exists whatever fails later.
pub fn write_outputs(
    a: &Analysis,
    dir: &Path,
    stem: &str,
    opts: &OutputOptions,
) -> Result<Vec<PathBuf>, FacadeError> {
    let mut written = Vec::new();
    let overlay_path = dir.join(format!("{stem}_overlay.png"));
    let (grammar, structure) = match &a.parse {
        Ok(p) => p,
        Err(_) => {
            let segs = segments::detect(&a.gray);
            write_png(&overlay_path, &overlay::failure(&a.rectified, &segs))?;
            written.push(overlay_path);
            return Ok(written);
        }
    };
    let (w, h) = (a.gray.width as f64, a.gray.height as f64);
    let leaves = grammar
        .derive(w, h)
        .map_err(|e| file_err(&dir.join(format!("{stem}.cga")), e))?;
    let floor_rows: Vec<f64> = structure.floor_splits.iter().map(|&y| y as f64).collect();
    let tile_cols: Vec<f64> = structure.tile_splits.iter().map(|&x| x as f64).collect();
    write_png(
        &overlay_path,
        &overlay::structure(&a.rectified, &floor_rows, &tile_cols, &leaves),
    )?;
    written.push(overlay_path);
    let rect_path = dir.join(format!("{stem}_rectified.png"));
    write_png(&rect_path, &a.rectified)?;
    written.push(rect_path.clone());
    let labels_path = dir.join(format!("{stem}_labels.png"));
    write_png(
        &labels_path,
        &label_picture(&rasterize(&leaves, a.gray.width, a.gray.height).labels),
    )?;
    written.push(labels_path);
    let rules_path = dir.join(format!("{stem}.cga"));
    std::fs::write(&rules_path, grammar.to_text()).map_err(|e| file_err(&rules_path, e))?;
    written.push(rules_path);
    let params = MeshParams::new(STOREY_M / structure.floor.max(1) as f64, (w, h));
    written.extend(write_generated(
        grammar,
        &params,
        Some(&rect_path),
        dir,
        stem,
        opts,
    )?);
    Ok(written)
}

/// Writes the 3D facades that `grammar` generates, per width and height factor of its parsed
/// size (`opts`): `STEM_wX.obj/.mtl/.glb` (`STEM_hX…` for heights) with the library elements
/// its rules insert, textured with `texture` (the photo its sources refer to, of
/// `params.texture_size`) when given, and a render `STEM_wX.png`. Each mesh is checked to be
/// closed before it is written. Returns the files written.
pub fn write_generated(
    grammar: &Grammar,
    params: &MeshParams,
    texture: Option<&Path>,
    dir: &Path,
    stem: &str,
    opts: &OutputOptions,
) -> Result<Vec<PathBuf>, FacadeError> {
    let mut written = Vec::new();
    let (w, h) = grammar.size;
    let library =
        Library::builtin().map_err(|e| file_err(Path::new("assets/facade_elements"), e))?;
    let names = grammar.elements();
    let sizes: Vec<_> = opts
        .widths
        .iter()
        .map(|&f| (format!("w{f}"), f, 1.0, "widths"))
        .chain(
            opts.heights
                .iter()
                .map(|&f| (format!("h{f}"), 1.0, f, "heights")),
        )
        .collect();
    // every size within bounds before anything is derived or written
    for (_, fx, fy, what) in &sizes {
        let (wm, hm) = (w * fx * params.scale, h * fy * params.scale);
        let factor = fx * fy;
        check_extent(&format!("`{what}` factor {factor}"), wm, hm).map_err(|e| file_err(dir, e))?;
    }
    for (tag, fx, fy, _) in sizes {
        let obj = dir.join(format!("{stem}_{tag}.obj"));
        let leaves = grammar
            .derive(w * fx, h * fy)
            .map_err(|e| file_err(&obj, e))?;
        let mut mesh = build(&leaves, params).map_err(|e| file_err(&obj, e))?;
        insert_elements(&mut mesh, &leaves, &names, &library, params)
            .map_err(|e| file_err(&obj, e))?;
        check_closed(&mesh).map_err(|e| file_err(&obj, e))?;
        write_obj_mtl(&obj, &mesh, texture)?;
        let png = obj.with_extension("png");
        render_facade(&png, &mesh)?;
        written.push(png);
        let glb = obj.with_extension("glb");
        write_glb_textured(&glb, &mesh, texture)?;
        written.push(obj.with_extension("mtl"));
        written.push(obj);
        written.push(glb);
    }
    Ok(written)
}
