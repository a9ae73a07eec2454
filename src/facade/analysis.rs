//! The facade pipeline of one photo: read it, rectify it (four user corners, or the vanishing
//! points found in it), parse the rectified facade into its grammar, and keep what the
//! outputs need (the rectified colour photo for textures and overlays, the homography for
//! scoring against label maps), with the time of each stage.

use std::path::Path;
use std::time::Instant;

use image::RgbImage;

use super::element_library::Library;
use super::element_match::{recognise_elements, ElementMatch};
use super::error::FacadeError;
use super::grammar::Grammar;
use super::homography::{warp_rgb, Homography};
use super::parse::{parse_region, Priors};
use super::parse_structure::Structure;
use super::rect::Rect;
use super::vanishing::rectify;
use crate::geometry::image::{read_rgb, Gray};

/// How the photo is brought to a fronto-parallel view.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Rectify {
    /// Use the photo as it is (already rectified).
    None,
    /// From the dominant vanishing points.
    Auto,
    /// From the facade's four corners (top-left, top-right, bottom-right, bottom-left,
    /// photo pixels): the quadrilateral becomes an upright rectangle of its mean side lengths.
    Corners([[f64; 2]; 4]),
}

/// Options of the analysis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Options {
    /// Rectification.
    pub rectify: Rectify,
    /// Priors of the parse.
    pub priors: Priors,
    /// Least repetition strength (relative MI of floors and of tiles) for a facade.
    pub min_strength: f64,
    /// Least number of windows found one by one (each repeated in its row or column) that
    /// makes a facade of a photo whose floors and tiles repeat less than `min_strength` but
    /// at least `weak_strength`.
    pub min_windows: usize,
    /// See `min_windows` (noise repeats with a strength of about 0.012).
    pub weak_strength: f64,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            rectify: Rectify::Auto,
            priors: Priors::default(),
            min_strength: 0.03,
            min_windows: 8,
            weak_strength: 0.02,
        }
    }
}

/// What the analysis of one photo gives.
#[derive(Debug, Clone)]
pub struct Analysis {
    /// The photo as read.
    pub photo: RgbImage,
    /// Photo → rectified frame (identity when not rectified).
    pub homography: Homography,
    /// The rectified colour photo.
    pub rectified: RgbImage,
    /// The rectified photo's luma.
    pub gray: Gray,
    /// The parse, or why there is none.
    pub parse: Result<(Grammar, Structure), String>,
    /// Why rectification failed, when it did (the analysis then went on unrectified).
    pub rectification_failed: Option<String>,
    /// The library element recognised for the windows (and doors) of the parse, which its
    /// grammar inserts; empty when the parse failed.
    pub elements: Vec<ElementMatch>,
    /// (stage, seconds), in order.
    pub seconds: Vec<(&'static str, f64)>,
}

impl Analysis {
    /// Total seconds.
    pub fn total_seconds(&self) -> f64 {
        self.seconds.iter().map(|s| s.1).sum()
    }

    /// A one-line account of a failure (rectification or parse), or `None`.
    pub fn problem(&self) -> Option<String> {
        match (&self.parse, &self.rectification_failed) {
            (Err(e), Some(r)) => Some(format!("{e} (rectification failed: {r})")),
            (Err(e), None) => Some(e.clone()),
            (Ok(_), Some(r)) => Some(format!("rectification failed: {r}; parsed unrectified")),
            (Ok(_), None) => None,
        }
    }
}

/// Share of pixels outside the photo a facade region may keep.
pub const MAX_OUTSIDE: f64 = 0.01;

/// The largest upright rectangle of the rectified frame (`size`) that holds photo pixels
/// (at most [`MAX_OUTSIDE`] of it outside the warped photo): the bounding box, shrunk from the
/// side with the most outside pixels until the rest is almost all photo.
pub fn photo_region(h: &Homography, photo: (u32, u32), size: (u32, u32)) -> Rect {
    let (w, hh) = size;
    let inv = h.inverse();
    let inside: Vec<bool> = (0..hh)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .map(|(x, y)| {
            inv.as_ref()
                .and_then(|i| i.apply([x as f64 + 0.5, y as f64 + 0.5]))
                .is_some_and(|[u, v]| {
                    u >= 0.0 && v >= 0.0 && u <= photo.0 as f64 && v <= photo.1 as f64
                })
        })
        .collect();
    let at = |x: u32, y: u32| inside[(y * w + x) as usize];
    let mut r = Rect {
        x0: 0,
        y0: 0,
        x1: w,
        y1: hh,
    };
    loop {
        let (rw, rh) = (r.x1 - r.x0, r.y1 - r.y0);
        if rw < 4 || rh < 4 {
            return r;
        }
        let out_row = |y: u32| (r.x0..r.x1).filter(|&x| !at(x, y)).count() as f64 / rw as f64;
        let out_col = |x: u32| (r.y0..r.y1).filter(|&y| !at(x, y)).count() as f64 / rh as f64;
        let total: usize = (r.y0..r.y1)
            .map(|y| (r.x0..r.x1).filter(|&x| !at(x, y)).count())
            .sum();
        if total as f64 <= MAX_OUTSIDE * (rw as f64 * rh as f64) {
            return r;
        }
        let sides = [
            out_row(r.y0),
            out_row(r.y1 - 1),
            out_col(r.x0),
            out_col(r.x1 - 1),
        ];
        let k = (0..4)
            .max_by(|&a, &b| sides[a].total_cmp(&sides[b]).then(b.cmp(&a)))
            .unwrap_or(0);
        match k {
            0 => r.y0 += 1,
            1 => r.y1 -= 1,
            2 => r.x0 += 1,
            _ => r.x1 -= 1,
        }
    }
}

/// Analyses the photo at `path`. Only an unreadable photo is an error; a failed rectification
/// or parse is reported in the result (so the diagnostic overlay can still be drawn).
pub fn analyze(path: &Path, opts: &Options) -> Result<Analysis, FacadeError> {
    let t = Instant::now();
    let photo = read_rgb(path)?;
    let mut seconds = vec![("read", t.elapsed().as_secs_f64())];
    let t = Instant::now();
    let gray0 = Gray::from_rgb(&photo);
    let identity = Homography(nalgebra::Matrix3::identity());
    let (w0, h0) = (photo.width(), photo.height());
    let (mut homography, mut size, mut failed) = (identity, (w0, h0), None);
    match opts.rectify {
        Rectify::None => {}
        Rectify::Auto => match rectify(&gray0) {
            Ok(r) => {
                homography = r.h;
                size = (r.width, r.height);
            }
            Err(e) => failed = Some(e.to_string()),
        },
        Rectify::Corners(c) => {
            let d =
                |a: [f64; 2], b: [f64; 2]| ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)).sqrt();
            let (w, h) = (
                0.5 * (d(c[0], c[1]) + d(c[3], c[2])),
                0.5 * (d(c[0], c[3]) + d(c[1], c[2])),
            );
            match Homography::rectifying(&c, w, h) {
                Some(hm) if w >= 8.0 && h >= 8.0 => {
                    homography = hm;
                    size = (w.round() as u32, h.round() as u32);
                }
                _ => failed = Some(format!("corners {c:?} do not form a facade quadrilateral")),
            }
        }
    }
    let rectified = if homography == identity {
        photo.clone()
    } else {
        match warp_rgb(&photo, &homography, size.0, size.1) {
            Some(r) => r,
            None => {
                failed = Some("the homography is singular".into());
                homography = identity;
                photo.clone()
            }
        }
    };
    let gray = Gray::from_rgb(&rectified);
    seconds.push(("rectify", t.elapsed().as_secs_f64()));
    let t = Instant::now();
    let region = photo_region(&homography, (w0, h0), (gray.width, gray.height));
    let parsed = parse_region(&gray, region, &opts.priors).and_then(|(g, s)| {
        let strength = s.strength.0.min(s.strength.1);
        let windowed = strength >= opts.weak_strength && s.windows.len() >= opts.min_windows;
        if strength < opts.min_strength && !windowed {
            Err(format!(
                "no facade: floors and tiles hardly repeat (relative MI {:.3} and {:.3}, need ≥ {}, or ≥ {} with {} repeated windows; {} found)",
                s.strength.0,
                s.strength.1,
                opts.min_strength,
                opts.weak_strength,
                opts.min_windows,
                s.windows.len()
            ))
        } else {
            Ok((g, s))
        }
    });
    let mut parsed = parsed;
    let mut elements = Vec::new();
    match &mut parsed {
        Ok((g, s)) => {
            for (name, v) in ["floors", "tiles", "irreducible", "window", "windows"]
                .into_iter()
                .zip(s.seconds)
            {
                seconds.push((name, v));
            }
            let t = Instant::now();
            let library = Library::builtin().map_err(|message| FacadeError::File {
                path: "assets/facade_elements".into(),
                message,
            })?;
            elements = recognise_elements(g, &gray, &library);
            seconds.push(("elements", t.elapsed().as_secs_f64()));
        }
        Err(_) => seconds.push(("parse", t.elapsed().as_secs_f64())),
    }
    Ok(Analysis {
        photo,
        homography,
        rectified,
        gray,
        parse: parsed,
        rectification_failed: failed,
        elements,
        seconds,
    })
}
