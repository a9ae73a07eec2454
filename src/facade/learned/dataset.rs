//! Labelled facade folders as the learned classifier reads them: `DIR/images/STEM.*` with
//! `DIR/labels/STEM.png`, the layout (CMP index labels or LabelMeFacade colour labels)
//! detected from the first label file, label maps read into [`Element`]s and predictions
//! written back in the folder's own format. CMP's held-out part is fixed here.

use std::path::{Path, PathBuf};

use super::super::error::FacadeError;
use super::super::report::labelled_images;
use super::classes::{Element, CMP_PALETTE};

/// How a folder's label maps are coded.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Layout {
    /// CMP Facade: palette PNGs whose pixel values are class indices 1–12.
    Cmp,
    /// LabelMeFacade: RGB(A) PNGs of the nine class colours.
    LabelMe,
}

impl Layout {
    /// Lower-case name.
    pub fn name(self) -> &'static str {
        match self {
            Layout::Cmp => "cmp",
            Layout::LabelMe => "labelmefacade",
        }
    }
}

/// Every CMP facade at a position `k` (in name order) with `k % CMP_HOLDOUT_EVERY ==
/// CMP_HOLDOUT_EVERY - 1` is held out of training (positions 3, 7, 11, …: 75 of 303).
pub const CMP_HOLDOUT_EVERY: usize = 4;

/// Whether the `k`-th stem (name order) of a CMP folder is held out for evaluation.
pub fn is_cmp_holdout(k: usize) -> bool {
    k % CMP_HOLDOUT_EVERY == CMP_HOLDOUT_EVERY - 1
}

/// A class per pixel, row-major.
#[derive(Debug, Clone, PartialEq)]
pub struct ElementMap {
    /// Columns.
    pub width: u32,
    /// Rows.
    pub height: u32,
    /// Class of pixel (x, y) at `y · width + x`.
    pub classes: Vec<Element>,
}

fn file_err(path: &Path, message: impl Into<String>) -> FacadeError {
    FacadeError::File {
        path: path.to_path_buf(),
        message: message.into(),
    }
}

/// The labelled stems of `dir` and its layout, detected from the first label map (a palette
/// PNG is CMP, any other PNG LabelMeFacade). An error names the folder when it holds no
/// labelled photo.
pub fn labelled_folder(dir: &Path) -> Result<(Vec<String>, Layout), FacadeError> {
    let stems = labelled_images(dir)?;
    let first = stems.first().ok_or_else(|| {
        file_err(
            dir,
            "no labelled photo (images/STEM.* with labels/STEM.png)",
        )
    })?;
    let layout = detect_layout(&label_path(dir, first))?;
    Ok((stems, layout))
}

/// `dir/labels/STEM.png`.
pub fn label_path(dir: &Path, stem: &str) -> PathBuf {
    dir.join("labels").join(format!("{stem}.png"))
}

/// The layout of one label file: indexed colour is CMP, anything else LabelMeFacade.
pub fn detect_layout(path: &Path) -> Result<Layout, FacadeError> {
    let bytes = crate::limits::read(path).map_err(|e| file_err(path, e.to_string()))?;
    let decoder = png::Decoder::new(std::io::Cursor::new(&bytes));
    let reader = decoder
        .read_info()
        .map_err(|e| file_err(path, format!("not a PNG label map: {e}")))?;
    Ok(match reader.info().color_type {
        png::ColorType::Indexed => Layout::Cmp,
        _ => Layout::LabelMe,
    })
}

/// Reads a label map of `layout` into elements; a value outside the dataset's classes is an
/// error naming the file and the pixel.
pub fn read_elements(path: &Path, layout: Layout) -> Result<ElementMap, FacadeError> {
    match layout {
        Layout::Cmp => read_cmp(path),
        Layout::LabelMe => {
            let img = crate::geometry::image::read_rgb(path)?;
            let (width, height) = img.dimensions();
            let mut classes = Vec::with_capacity(width as usize * height as usize);
            for (x, y, p) in img.enumerate_pixels() {
                let c = Element::from_labelmefacade(p.0).ok_or(FacadeError::UnknownColour {
                    path: path.to_path_buf(),
                    x,
                    y,
                    rgb: p.0,
                })?;
                classes.push(c);
            }
            Ok(ElementMap {
                width,
                height,
                classes,
            })
        }
    }
}

/// A CMP palette PNG: 8-bit indices 1–12.
fn read_cmp(path: &Path) -> Result<ElementMap, FacadeError> {
    crate::limits::check_file(path).map_err(|e| file_err(path, e.to_string()))?;
    let bytes = crate::limits::read(path).map_err(|e| file_err(path, e.to_string()))?;
    let mut decoder = png::Decoder::new(std::io::Cursor::new(&bytes));
    decoder.set_transformations(png::Transformations::IDENTITY);
    let mut reader = decoder
        .read_info()
        .map_err(|e| file_err(path, format!("not a PNG label map: {e}")))?;
    let info = reader.info();
    let (width, height) = (info.width, info.height);
    if info.color_type != png::ColorType::Indexed || info.bit_depth != png::BitDepth::Eight {
        return Err(file_err(
            path,
            format!(
                "a CMP label map must be an 8-bit palette PNG, this is {:?} {:?}",
                info.color_type, info.bit_depth
            ),
        ));
    }
    crate::geometry::image::photo_formats::check_pixels(
        &path.display().to_string(),
        width as u64,
        height as u64,
    )
    .map_err(|e| file_err(path, e.to_string()))?;
    let size = reader
        .output_buffer_size()
        .ok_or_else(|| file_err(path, "image too large"))?;
    let mut buf = vec![0u8; size];
    let frame = reader
        .next_frame(&mut buf)
        .map_err(|e| file_err(path, format!("cannot decode: {e}")))?;
    let mut classes = Vec::with_capacity(width as usize * height as usize);
    for y in 0..height as usize {
        let row = &buf[y * frame.line_size..y * frame.line_size + width as usize];
        for (x, &v) in row.iter().enumerate() {
            classes.push(Element::from_cmp(v).ok_or_else(|| {
                file_err(
                    path,
                    format!("pixel ({x}, {y}) has label index {v}, not a CMP class (1–12)"),
                )
            })?);
        }
    }
    Ok(ElementMap {
        width,
        height,
        classes,
    })
}

/// Writes `map` as a label PNG in `layout`'s own format (CMP: palette PNG of indices;
/// LabelMeFacade: RGB colours).
pub fn write_elements(map: &ElementMap, layout: Layout, path: &Path) -> Result<(), FacadeError> {
    let err = |e: String| file_err(path, e);
    if let Some(parent) = path.parent() {
        std::fs::create_dir_all(parent).map_err(|e| err(e.to_string()))?;
    }
    let mut bytes = Vec::new();
    match layout {
        Layout::Cmp => {
            let mut enc = png::Encoder::new(&mut bytes, map.width, map.height);
            enc.set_color(png::ColorType::Indexed);
            enc.set_depth(png::BitDepth::Eight);
            enc.set_palette(CMP_PALETTE.concat());
            let mut w = enc.write_header().map_err(|e| err(e.to_string()))?;
            let data: Vec<u8> = map.classes.iter().map(|c| c.to_cmp()).collect();
            w.write_image_data(&data).map_err(|e| err(e.to_string()))?;
            w.finish().map_err(|e| err(e.to_string()))?;
        }
        Layout::LabelMe => {
            let data: Vec<u8> = map
                .classes
                .iter()
                .flat_map(|c| c.to_labelmefacade())
                .collect();
            let img = image::RgbImage::from_raw(map.width, map.height, data)
                .ok_or_else(|| err("label map size mismatch".into()))?;
            img.write_to(
                &mut std::io::Cursor::new(&mut bytes),
                image::ImageFormat::Png,
            )
            .map_err(|e| err(e.to_string()))?;
        }
    }
    std::fs::write(path, bytes).map_err(|e| err(e.to_string()))
}
