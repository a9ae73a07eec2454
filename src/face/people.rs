//! Which photos show which person, so that each person gets a face of their own (see
//! `docs/faces.md`). A photo counts when a `.pts` landmark file of the same stem is beside it
//! (or in the landmark folder). The rule, [`Grouping`]:
//!
//! - [`Grouping::Names`] (the default): each subfolder of the photo folder that holds
//!   landmarked photos is one person, named after the subfolder; the photos directly in the
//!   folder are grouped by the name rule `<person>_<view>` (the stem cut at its last `_`:
//!   `alice_front.png` and `alice_left.png` are the person `alice`); photos whose stem has no
//!   `_` are together one person named after the folder, as a folder of one person's views
//!   (`front.png`, `left.png`) always was.
//! - [`Grouping::Folder`]: the photos directly in the folder are all one person (subfolders
//!   are not looked at).
//! - [`Grouping::Photo`]: every photo, in the folder and its subfolders, is a person of its
//!   own (landmark benchmarks such as 300-W, whose `indoor_001.png` … are all different
//!   people).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use super::FaceError;

/// How photos are grouped into people (see the [module docs](self)).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Grouping {
    /// Subfolders, then the `<person>_<view>` name rule; stems without `_` are one person.
    #[default]
    Names,
    /// Every photo of the folder is a view of one person.
    Folder,
    /// Every photo is a person of its own.
    Photo,
}

impl Grouping {
    /// `"names"`, `"folder"` or `"photo"`; an error names the parameter and the choices.
    pub fn parse(name: &str) -> Result<Self, FaceError> {
        match name {
            "names" => Ok(Grouping::Names),
            "folder" => Ok(Grouping::Folder),
            "photo" => Ok(Grouping::Photo),
            other => Err(FaceError::parameter(
                "group",
                format!("`{other}` is not one of \"names\", \"folder\", \"photo\""),
            )),
        }
    }
}

/// A photo with its landmark file.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct LandmarkedPhoto {
    /// File stem, the photo's name in outputs.
    pub stem: String,
    /// The photo.
    pub photo: PathBuf,
    /// Its `.pts` file.
    pub pts: PathBuf,
}

/// One person's photos.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PersonPhotos {
    /// The person's name (subfolder, name prefix, folder or photo stem).
    pub name: String,
    /// Their photos, sorted by path.
    pub photos: Vec<LandmarkedPhoto>,
}

/// The photos of `images` (not its subfolders) that have a `.pts` file of the same stem in
/// `pts_dir` (default: `images`), sorted. A `.pts` file without its photo is an error naming
/// it; an empty list is not an error here.
pub fn landmarked_photos(
    images: &Path,
    pts_dir: Option<&Path>,
) -> Result<Vec<LandmarkedPhoto>, FaceError> {
    let pts_dir = pts_dir.unwrap_or(images);
    let photos = crate::geometry::photo_files(images).map_err(|e| FaceError::io(images, e))?;
    let mut pairs = Vec::new();
    for photo in photos {
        let stem = photo
            .file_stem()
            .and_then(|s| s.to_str())
            .unwrap_or_default()
            .to_string();
        let pts = pts_dir.join(format!("{stem}.pts"));
        if pts.is_file() {
            pairs.push(LandmarkedPhoto { stem, photo, pts });
        }
    }
    // a landmark file without its photo is a mistake worth naming
    let mut orphans: Vec<PathBuf> = std::fs::read_dir(pts_dir)
        .map_err(|e| FaceError::io(pts_dir, e))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "pts"))
        .filter(|p| {
            let stem = p.file_stem().and_then(|s| s.to_str()).unwrap_or_default();
            !pairs.iter().any(|n| n.stem == stem)
        })
        .collect();
    orphans.sort();
    if let Some(p) = orphans.first() {
        return Err(FaceError::io(
            p,
            format!(
                "no photo of this stem ({}) in {}",
                crate::geometry::image::photo_formats::photo_extensions_list(),
                images.display()
            ),
        ));
    }
    Ok(pairs)
}

/// The person of a stem by the name rule: the part before the last `_` (both parts
/// non-empty), else `None`.
pub fn person_of_stem(stem: &str) -> Option<&str> {
    match stem.rsplit_once('_') {
        Some((person, view)) if !person.is_empty() && !view.is_empty() => Some(person),
        _ => None,
    }
}

/// The name of a folder for a person: its last component (`"face"` when it has none).
fn folder_name(dir: &Path) -> String {
    dir.file_name()
        .and_then(|s| s.to_str())
        .filter(|s| !s.is_empty() && *s != "." && *s != "..")
        .unwrap_or("face")
        .to_string()
}

/// The people of `images` under `grouping` (see the [module docs](self)), sorted by name;
/// `pts_dir` (default `images`) holds the `.pts` files, with the same subfolders. An error
/// when no photo has landmarks, naming the folders.
pub fn group_people(
    images: &Path,
    pts_dir: Option<&Path>,
    grouping: Grouping,
) -> Result<Vec<PersonPhotos>, FaceError> {
    let mut people: BTreeMap<String, Vec<LandmarkedPhoto>> = BTreeMap::new();
    let top = landmarked_photos(images, pts_dir)?;
    let folder = folder_name(images);
    for p in top {
        let name = match grouping {
            Grouping::Folder => folder.clone(),
            Grouping::Photo => p.stem.clone(),
            Grouping::Names => person_of_stem(&p.stem).unwrap_or(&folder).to_string(),
        };
        people.entry(name).or_default().push(p);
    }
    if grouping != Grouping::Folder {
        for sub in subfolders(images)? {
            let name = folder_name(&sub);
            let sub_pts = pts_dir.map(|d| d.join(&name));
            if sub_pts.as_ref().is_some_and(|d| !d.is_dir()) {
                continue; // no landmarks for this subfolder
            }
            for p in landmarked_photos(&sub, sub_pts.as_deref())? {
                let person = match grouping {
                    Grouping::Photo => format!("{name}/{}", p.stem),
                    _ => name.clone(),
                };
                people.entry(person).or_default().push(p);
            }
        }
    }
    if people.is_empty() {
        return Err(FaceError::Landmarks {
            source_name: images.display().to_string(),
            message: format!(
                "no photo ({}) with a .pts file of the same stem in {}",
                crate::geometry::image::photo_formats::photo_extensions_list(),
                pts_dir.unwrap_or(images).display()
            ),
        });
    }
    Ok(people
        .into_iter()
        .map(|(name, mut photos)| {
            photos.sort_by(|a, b| a.photo.cmp(&b.photo));
            PersonPhotos { name, photos }
        })
        .collect())
}

/// The subfolders of `dir` (not hidden), sorted.
fn subfolders(dir: &Path) -> Result<Vec<PathBuf>, FaceError> {
    let mut subs: Vec<PathBuf> = std::fs::read_dir(dir)
        .map_err(|e| FaceError::io(dir, e))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.is_dir())
        .filter(|p| {
            p.file_name()
                .and_then(|s| s.to_str())
                .is_some_and(|s| !s.starts_with('.'))
        })
        .collect();
    subs.sort();
    Ok(subs)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_name_rule_cuts_at_the_last_underscore() {
        assert_eq!(person_of_stem("alice_front"), Some("alice"));
        assert_eq!(person_of_stem("mary_jane_2"), Some("mary_jane"));
        assert_eq!(person_of_stem("front"), None);
        assert_eq!(person_of_stem("_1"), None);
        assert_eq!(person_of_stem("bob_"), None);
        assert!(Grouping::parse("people").is_err());
        assert_eq!(Grouping::parse("photo").unwrap(), Grouping::Photo);
    }
}
