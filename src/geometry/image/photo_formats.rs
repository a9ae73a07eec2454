//! The photo formats the engine reads, in one place: the file extensions that count as photos
//! ([`PHOTO_EXTENSIONS`]: PNG, JPEG, the PNM family, TIFF, BMP, WebP, TGA, each decoded by the
//! `image` crate), the photos of a folder ([`photo_files`]), the photo of a given stem
//! ([`photo_with_stem`]) and reading one as 8-bit RGB with an error that names the file and
//! the formats it could have been ([`read_photo`]). Every place that lists or reads photos
//! (face photos with landmarks, facade photos, tracking frames and backgrounds) goes through
//! here, so they all accept the same formats and fail the same way. The size an image
//! declares in its header is checked against the `max_pixels` limit before it is decoded
//! ([`check_image_file`]), so a small file that decodes to gigabytes is refused.

use std::io;
use std::path::{Path, PathBuf};

use image::RgbImage;

use crate::geometry::GeometryError;
use crate::limits::{self, LimitError};

/// Extensions (lower case, no dot) of the photos the engine lists and reads: PNG, JPEG, the
/// PNM family (PPM, PGM, PBM, PAM), TIFF, BMP, WebP and TGA. Case does not matter in a file
/// name. Each is decoded by the `image` crate (its `png`, `jpeg`, `pnm`, `tiff`, `bmp`, `webp`
/// and `tga` features).
pub const PHOTO_EXTENSIONS: &[&str] = &[
    "png", "jpg", "jpeg", "jfif", "ppm", "pgm", "pbm", "pnm", "pam", "tif", "tiff", "bmp", "webp",
    "tga",
];

/// The readable extensions as a short list for messages: `png, jpg, jpeg, …`.
pub fn photo_extensions_list() -> String {
    PHOTO_EXTENSIONS.join(", ")
}

/// Whether `path` has one of the [`PHOTO_EXTENSIONS`] (any case).
pub fn is_photo(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| PHOTO_EXTENSIONS.contains(&e.to_ascii_lowercase().as_str()))
}

/// The photos of `dir` (files with one of the [`PHOTO_EXTENSIONS`], any case), sorted by path.
pub fn photo_files(dir: &Path) -> io::Result<Vec<PathBuf>> {
    let mut photos: Vec<PathBuf> = std::fs::read_dir(dir)?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| is_photo(p) && p.is_file())
        .collect();
    photos.sort();
    Ok(photos)
}

/// The photo `dir/STEM.EXT` for the first of the [`PHOTO_EXTENSIONS`] (or its upper-case
/// form) that exists, PNG first; `None` when there is none.
pub fn photo_with_stem(dir: &Path, stem: &str) -> Option<PathBuf> {
    PHOTO_EXTENSIONS.iter().find_map(|ext| {
        [ext.to_string(), ext.to_ascii_uppercase()]
            .into_iter()
            .map(|e| dir.join(format!("{stem}.{e}")))
            .find(|p| p.is_file())
    })
}

/// `dir/STEM.EXT` as [`photo_with_stem`] finds it, else `dir/STEM.default_ext` (the name a
/// "missing file" error then gives).
pub fn photo_with_stem_or(dir: &Path, stem: &str, default_ext: &str) -> PathBuf {
    photo_with_stem(dir, stem).unwrap_or_else(|| dir.join(format!("{stem}.{default_ext}")))
}

/// Checks an image of `width` × `height` pixels against the `max_pixels` limit (and that it
/// is not empty); `what` names it (a file, a parameter) in the error.
pub fn check_pixels(what: &str, width: u64, height: u64) -> Result<(), LimitError> {
    let max = limits::get().max_pixels;
    let n = width.saturating_mul(height);
    if n > max {
        return Err(LimitError {
            what: format!("{what} ({width} × {height})"),
            value: format!("{n} pixels"),
            limit: "max_pixels",
            max,
        });
    }
    Ok(())
}

/// An image reader on `path` with its format guessed from the content; `None` format when the
/// content is no image format the crate reads.
fn open_image(
    path: &Path,
) -> Result<image::ImageReader<io::BufReader<std::fs::File>>, GeometryError> {
    let err = |message: String| GeometryError::Image {
        path: path.to_path_buf(),
        message,
    };
    limits::check_file(path).map_err(|e| err(e.to_string()))?;
    image::ImageReader::open(path)
        .map_err(|e| err(e.to_string()))?
        .with_guessed_format()
        .map_err(|e| err(e.to_string()))
}

/// An image reader on bytes in memory, its format guessed from the content.
fn memory_image<'a>(
    data: &'a [u8],
    path: &Path,
) -> Result<image::ImageReader<io::Cursor<&'a [u8]>>, GeometryError> {
    image::ImageReader::new(io::Cursor::new(data))
        .with_guessed_format()
        .map_err(|e| GeometryError::Image {
            path: path.to_path_buf(),
            message: e.to_string(),
        })
}

fn undecodable(path: &Path, reason: String) -> GeometryError {
    GeometryError::Image {
        path: path.to_path_buf(),
        message: format!(
            "cannot be decoded as an image (readable formats: {}): {reason}",
            photo_extensions_list()
        ),
    }
}

/// The format and declared size of the image `reader` holds, checked: a known format, not
/// empty, within `max_pixels`.
fn check_header<R: io::BufRead + io::Seek>(
    reader: image::ImageReader<R>,
    path: &Path,
) -> Result<(image::ImageFormat, u32, u32), GeometryError> {
    let Some(format) = reader.format() else {
        return Err(undecodable(path, "unrecognised content".into()));
    };
    let (w, h) = reader
        .into_dimensions()
        .map_err(|e| undecodable(path, e.to_string()))?;
    if w == 0 || h == 0 {
        return Err(undecodable(path, format!("empty image ({w}×{h})")));
    }
    check_pixels("the image", u64::from(w), u64::from(h)).map_err(|e| GeometryError::Image {
        path: path.to_path_buf(),
        message: e.to_string(),
    })?;
    Ok((format, w, h))
}

/// The format and size (pixels) an image file declares in its header, read without decoding
/// it, after checking the file against `max_file_bytes` and the size against `max_pixels`
/// ([`check_pixels`]) and that it is not empty. Every image the engine decodes is checked
/// here first; the error names the file, its size and the limit.
pub fn check_image_file(path: &Path) -> Result<(image::ImageFormat, u32, u32), GeometryError> {
    check_header(open_image(path)?, path)
}

/// Decodes a checked reader into 8-bit RGB.
fn decode_rgb<R: io::BufRead + io::Seek>(
    reader: image::ImageReader<R>,
    path: &Path,
) -> Result<RgbImage, GeometryError> {
    let img = reader
        .decode()
        .map_err(|e| undecodable(path, e.to_string()))?;
    if img.width() == 0 || img.height() == 0 {
        return Err(undecodable(
            path,
            format!("empty image ({}×{})", img.width(), img.height()),
        ));
    }
    Ok(img.into_rgb8())
}

/// Reads a photo in any of the [`PHOTO_EXTENSIONS`] formats as 8-bit RGB (grey becomes three
/// equal channels, alpha is dropped, 16-bit is scaled to 8). The format is taken from the
/// file's content, not its name; the size its header declares is checked first
/// ([`check_image_file`]: `max_pixels`). An error names the file: missing or unreadable, too
/// large, or "cannot be decoded as an image" with the formats that can and the decoder's
/// reason.
pub fn read_photo(path: &Path) -> Result<RgbImage, GeometryError> {
    check_image_file(path)?;
    decode_rgb(open_image(path)?, path)
}

/// [`read_photo`] of a file's bytes already in memory; `path` names it in errors.
pub fn decode_photo(data: &[u8], path: &Path) -> Result<RgbImage, GeometryError> {
    check_header(memory_image(data, path)?, path)?;
    decode_rgb(memory_image(data, path)?, path)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_listed_extension_is_decoded_by_the_image_crate() {
        for ext in PHOTO_EXTENSIONS {
            let format = image::ImageFormat::from_extension(ext)
                .unwrap_or_else(|| panic!("{ext}: no image format"));
            assert!(format.reading_enabled(), "{ext}: {format:?} not enabled");
        }
        assert!(is_photo(Path::new("a/b.PPM")) && is_photo(Path::new("x.webp")));
        assert!(!is_photo(Path::new("x.pts")) && !is_photo(Path::new("png")));
    }
}
