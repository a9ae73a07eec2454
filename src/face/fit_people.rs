//! Fitting one face per person in a folder of photos: the photos are grouped into people
//! ([`group_people`]), each person's face is fitted from their own photos only
//! ([`fit_folder`](super::fit_run::fit_folder)'s steps), and the results are written per person
//! and summarised. With one person the outputs go straight into `out` (as they always have);
//! with several, into `out/<person>/`. Beside them, in `out`: `photos.csv` (a row per photo:
//! person, photo, landmark error) and `people.csv` (a row per person: photo count, mean and
//! largest landmark error, texture coverage, change from the generic face, output folder).

use std::path::{Path, PathBuf};

use super::adapt::{adapt, AdaptOptions};
use super::fit_run::{read_photo_set, write_fit_outputs, FitReport};
use super::model::FaceMesh;
use super::people::{group_people, Grouping};
use super::FaceError;

/// One person's fit.
#[derive(Clone, Debug, PartialEq)]
pub struct PersonFit {
    /// The person's name ([`PersonPhotos::name`](super::people::PersonPhotos::name)).
    pub name: String,
    /// Where their outputs are.
    pub dir: PathBuf,
    /// What the fit measured and wrote.
    pub report: FitReport,
}

impl PersonFit {
    /// Largest landmark error over the person's photos (% of IOD).
    pub fn max_error_iod_pct(&self) -> f64 {
        self.report
            .errors_iod_pct
            .iter()
            .copied()
            .fold(0.0, f64::max)
    }
}

/// Fits one face per person of `images` (grouped by `grouping`, landmarks in `pts_dir`, default
/// `images`) and writes the outputs under `out` (see the [module docs](self)). An error names
/// the person whose fit failed.
pub fn fit_people(
    images: &Path,
    pts_dir: Option<&Path>,
    out: &Path,
    grouping: Grouping,
    options: &AdaptOptions,
    texture_size: usize,
) -> Result<Vec<PersonFit>, FaceError> {
    let people = group_people(images, pts_dir, grouping)?;
    let generic = FaceMesh::mediapipe()?;
    let single = people.len() == 1;
    let mut fits = Vec::with_capacity(people.len());
    for person in &people {
        let in_person = |e: FaceError| match e {
            FaceError::Failed(m) => FaceError::Failed(format!("person {}: {m}", person.name)),
            other => other,
        };
        let photos = read_photo_set(&person.photos)?;
        let dir = if single {
            out.to_path_buf()
        } else {
            out.join(&person.name)
        };
        let fit = adapt(&generic, &photos.views, options).map_err(in_person)?;
        let report = write_fit_outputs(&fit, &photos, &dir, texture_size).map_err(in_person)?;
        fits.push(PersonFit {
            name: person.name.clone(),
            dir,
            report,
        });
    }
    write_summaries(&fits, out)?;
    Ok(fits)
}

/// Writes `out/photos.csv` and `out/people.csv`.
fn write_summaries(fits: &[PersonFit], out: &Path) -> Result<(), FaceError> {
    let mut photos = String::from("person,photo,landmark_err_iod_pct\n");
    let mut people = String::from(
        "person,photos,mean_landmark_err_iod_pct,max_landmark_err_iod_pct,texture_coverage,\
         mean_abs_change_mm,folder\n",
    );
    for f in fits {
        for (n, e) in f.report.names.iter().zip(&f.report.errors_iod_pct) {
            photos.push_str(&format!("{},{n},{e:.4}\n", f.name));
        }
        people.push_str(&format!(
            "{},{},{:.4},{:.4},{:.4},{:.4},{}\n",
            f.name,
            f.report.names.len(),
            f.report.mean_error_iod_pct(),
            f.max_error_iod_pct(),
            f.report.texture_coverage,
            f.report.mean_abs_change * 1000.0,
            f.dir.display()
        ));
    }
    for (name, text) in [("photos.csv", photos), ("people.csv", people)] {
        let path = out.join(name);
        std::fs::write(&path, text).map_err(|e| FaceError::io(&path, e))?;
    }
    Ok(())
}
