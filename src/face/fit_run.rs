//! Fitting the generic face to a folder of photos and writing what came out: the adapted mesh
//! textured from the photos (OBJ+MTL+PNG and glTF), per-photo overlays of the fitted model and
//! the landmarks, shaded renders of the textured model, the error map between the adapted and
//! the generic face, and the landmark errors (`fit.csv`).
//!
//! A folder holds photos (any of the
//! [`PHOTO_EXTENSIONS`](crate::geometry::image::PHOTO_EXTENSIONS): PNG, JPEG, PPM/PGM, TIFF,
//! BMP, WebP, TGA) and, for each photo to use, a `.pts` file of the same
//! stem (68 iBUG points, 300-W convention), in the same folder or in a separate one. Photos
//! without landmarks are skipped; a `.pts` file without its photo, or a folder without any
//! pair, is an error naming it.

use std::path::{Path, PathBuf};

use image::RgbImage;

use super::adapt::{adapt, AdaptOptions, FaceFit};
use super::align::similarity_align;
use super::error_map::{render_error_map, signed_distances};
use super::export::{write_glb, write_textured_obj};
use super::landmarks::{check_inside, landmark_positions, read_pts, PTS_PIXEL_ORIGIN};
use super::model::FaceMesh;
use super::people::{landmarked_photos, LandmarkedPhoto};
use super::preview::{preview_camera, shaded_render};
use super::texture_bake::bake_texture;
use super::view_fit::View;
use super::FaceError;
use crate::tracking::overlay::{draw_dot, draw_line};

/// Photos with their landmarks, ready to fit.
#[derive(Clone, Debug)]
pub struct PhotoSet {
    /// Stems of the photos (file names without extension).
    pub names: Vec<String>,
    /// The photos.
    pub images: Vec<RgbImage>,
    /// Their landmarks as views (crate pixel coordinates).
    pub views: Vec<View>,
}

/// Reads the photos of `images` that have a `.pts` file of the same stem in `pts_dir` (default:
/// the same folder), all as views of one person. Errors name the folder or file: unreadable
/// photo, malformed `.pts`, wrong point count, points outside the photo, no usable pair.
pub fn load_photos(images: &Path, pts_dir: Option<&Path>) -> Result<PhotoSet, FaceError> {
    let pairs = landmarked_photos(images, pts_dir)?;
    if pairs.is_empty() {
        return Err(FaceError::Landmarks {
            source_name: images.display().to_string(),
            message: format!(
                "no photo ({}) with a .pts file of the same stem in {}",
                crate::geometry::image::photo_formats::photo_extensions_list(),
                pts_dir.unwrap_or(images).display()
            ),
        });
    }
    read_photo_set(&pairs)
}

/// Reads `pairs` (photos and their landmark files) as one person's views. Errors name the
/// file: unreadable photo, malformed `.pts`, wrong point count, points outside the photo.
pub fn read_photo_set(pairs: &[LandmarkedPhoto]) -> Result<PhotoSet, FaceError> {
    let mut set = PhotoSet {
        names: Vec::new(),
        images: Vec::new(),
        views: Vec::new(),
    };
    for pair in pairs {
        let img = crate::geometry::image::read_photo(&pair.photo)?;
        let points = read_pts(&pair.pts)?;
        let source = pair.pts.display().to_string();
        check_inside(&points, img.width(), img.height(), &source)?;
        let landmarks = points
            .iter()
            .map(|p| [p[0] - PTS_PIXEL_ORIGIN, p[1] - PTS_PIXEL_ORIGIN])
            .collect();
        set.views
            .push(View::new(source, landmarks, img.width(), img.height()));
        set.images.push(img);
        set.names.push(pair.stem.clone());
    }
    Ok(set)
}

/// What [`write_fit_outputs`] measured and wrote.
#[derive(Clone, Debug, PartialEq)]
pub struct FitReport {
    /// Photo stems.
    pub names: Vec<String>,
    /// Landmark error per photo, % of its inter-ocular distance.
    pub errors_iod_pct: Vec<f64>,
    /// Fraction of the texture layout seen by some photo.
    pub texture_coverage: f64,
    /// Mean absolute distance between the adapted face and the generic face after similarity
    /// alignment (m).
    pub mean_abs_change: f64,
    /// Files written.
    pub files: Vec<PathBuf>,
}

impl FitReport {
    /// Mean landmark error over the photos (% of IOD).
    pub fn mean_error_iod_pct(&self) -> f64 {
        self.errors_iod_pct.iter().sum::<f64>() / self.errors_iod_pct.len().max(1) as f64
    }
}

/// Writes the outputs of a finished fit under `out` (see the [module docs](self)).
pub fn write_fit_outputs(
    fit: &FaceFit,
    photos: &PhotoSet,
    out: &Path,
    texture_size: usize,
) -> Result<FitReport, FaceError> {
    let errors: Vec<f64> = (0..photos.views.len())
        .map(|v| fit.landmark_error_iod_pct(v))
        .collect();
    check_fit(fit, &errors)?;
    std::fs::create_dir_all(out).map_err(|e| FaceError::io(out, e))?;
    let mut files = Vec::new();
    let mut csv = String::from("photo,landmark_err_iod_pct\n");
    for (n, e) in photos.names.iter().zip(&errors) {
        csv.push_str(&format!("{n},{e:.4}\n"));
    }
    let path = out.join("fit.csv");
    std::fs::write(&path, csv).map_err(|e| FaceError::io(&path, e))?;
    files.push(path);

    // texture from all photos
    let views: Vec<_> = fit.cameras.iter().zip(&photos.images).collect();
    let baked = bake_texture(&fit.mesh, &views, texture_size)?;
    write_textured_obj(out, "face", &fit.mesh, &baked.texture)?;
    for f in ["face.obj", "face.mtl", "face.png"] {
        files.push(out.join(f));
    }
    let glb = out.join("face.glb");
    write_glb(&glb, &fit.mesh, &baked.texture)?;
    files.push(glb);

    // overlays: the fitted mesh and the landmarks on each photo
    let model_points = landmark_positions(&fit.mesh);
    let edges = fit.mesh.edges();
    for ((name, img), (view, cam)) in photos
        .names
        .iter()
        .zip(&photos.images)
        .zip(photos.views.iter().zip(&fit.cameras))
    {
        let mut o = img.clone();
        let px: Vec<Option<[f64; 2]>> = fit.mesh.positions.iter().map(|p| cam.project(p)).collect();
        for &(a, b) in &edges {
            if let (Some(pa), Some(pb)) = (px[a], px[b]) {
                draw_line(&mut o, pa, pb, 0.6, [70, 200, 255]);
            }
        }
        for (i, l) in view.landmarks.iter().enumerate() {
            draw_dot(&mut o, *l, 1.6, [255, 60, 60]);
            if !super::landmarks::is_contour(i) {
                if let Some(p) = cam.project(&model_points[i]) {
                    draw_dot(&mut o, p, 1.2, [60, 255, 90]);
                }
            }
        }
        let path = out.join(format!("overlay_{name}.png"));
        o.save(&path).map_err(|e| FaceError::io(&path, e))?;
        files.push(path);
    }

    // shaded renders of the textured model
    for (label, yaw) in [("front", 0.0), ("left", 35.0), ("right", -35.0)] {
        let cam = preview_camera(&fit.mesh, yaw, 512, 512);
        let img = shaded_render(&fit.mesh, &fit.mesh.positions, &baked.texture, &cam);
        let path = out.join(format!("render_{label}.png"));
        img.save(&path).map_err(|e| FaceError::io(&path, e))?;
        files.push(path);
    }

    // error map: adapted vs generic, the generic aligned by a similarity
    let mut generic = fit.generic.clone();
    let change = match similarity_align(&fit.generic.positions, &fit.mesh.positions) {
        Some(s) => {
            for p in &mut generic.positions {
                *p = s.apply(p);
            }
            let d = signed_distances(&fit.mesh, &generic);
            let cam = preview_camera(&fit.mesh, 0.0, 512, 512);
            let path = out.join("error_map.png");
            let stats = render_error_map(&fit.mesh, &d, &cam, &path, 0.005)?;
            files.push(path);
            stats.mean_abs
        }
        None => f64::NAN,
    };
    Ok(FitReport {
        names: photos.names.clone(),
        errors_iod_pct: errors,
        texture_coverage: baked.coverage,
        mean_abs_change: change,
        files,
    })
}

/// Largest size of an adapted face as a multiple of the generic one's (bounding-box
/// diagonal): beyond it the adaptation has run away and the result is no face.
pub const MAX_FACE_GROWTH: f64 = 10.0;

/// Checks a finished fit before anything is written: every landmark error finite (a NaN or
/// infinite error is a failed fit, never a result), every vertex finite and the face at most
/// [`MAX_FACE_GROWTH`] times the generic one. Errors name the view (its landmark file).
pub fn check_fit(fit: &FaceFit, errors: &[f64]) -> Result<(), FaceError> {
    let name = |v: usize| {
        fit.views
            .get(v)
            .map_or_else(String::new, |v| v.name.clone())
    };
    if let Some(v) = errors.iter().position(|e| !e.is_finite()) {
        return Err(FaceError::Landmarks {
            source_name: name(v),
            message: format!(
                "the adaptation failed: the landmark error is {} (the landmarks cannot be fitted)",
                errors[v]
            ),
        });
    }
    let diagonal = |ps: &[crate::geometry::Vec3]| {
        let (lo, hi) = crate::geometry::mesh::bounds(ps);
        (hi - lo).norm()
    };
    let (got, generic) = (
        diagonal(&fit.mesh.positions),
        diagonal(&fit.generic.positions),
    );
    if !(got.is_finite() && got <= MAX_FACE_GROWTH * generic) {
        return Err(FaceError::Landmarks {
            source_name: (0..fit.views.len()).map(name).collect::<Vec<_>>().join(", "),
            message: format!(
                "the adaptation failed: the adapted face spans {got:.3e} m, more than {MAX_FACE_GROWTH} × the generic face's {generic:.3} m"
            ),
        });
    }
    Ok(())
}

/// The whole fit: photos with landmarks from `images` (and `pts_dir`), adaptation of the
/// MediaPipe canonical face, outputs under `out`.
pub fn fit_folder(
    images: &Path,
    pts_dir: Option<&Path>,
    out: &Path,
    options: &AdaptOptions,
    texture_size: usize,
) -> Result<(FaceFit, FitReport), FaceError> {
    let photos = load_photos(images, pts_dir)?;
    let generic = FaceMesh::mediapipe()?;
    let fit = adapt(&generic, &photos.views, options)?;
    let report = write_fit_outputs(&fit, &photos, out, texture_size)?;
    Ok((fit, report))
}
