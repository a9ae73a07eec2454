//! Where files are and how they are written: the shared data folder ([`data_dir`]), atomic
//! file writing (temporary file in the same folder, then rename) shared by the mesh and
//! picture writers and the checks a mesh must pass before it is written. (The photos of a
//! folder: [`photo_files`](super::image::photo_files).)

use std::fs;
use std::io::{self, BufWriter, Write};
use std::path::Path;
use std::sync::atomic::{AtomicUsize, Ordering};

use super::{GeometryError, Vec3};

/// The shared data folder (meshes, bodies, motion clips, photos, fabric measurements), absolute:
/// `$EMILION_DATA` (a relative value is the working directory's), else `shared/data` beside the
/// repository emilion was built from (`../shared/data` from the repository root), whatever the
/// working directory.
pub fn data_dir() -> std::path::PathBuf {
    let dir: std::path::PathBuf = match std::env::var_os("EMILION_DATA") {
        Some(d) => d.into(),
        None => {
            let repo = Path::new(env!("CARGO_MANIFEST_DIR"));
            repo.parent().unwrap_or(repo).join("shared/data")
        }
    };
    std::path::absolute(&dir).unwrap_or(dir)
}

/// `rel` under the shared data folder ([`data_dir`]), e.g. `data_path("bodies/makehuman")`.
pub fn data_path(rel: impl AsRef<Path>) -> std::path::PathBuf {
    data_dir().join(rel)
}

/// Writes `path` through `write`, atomically: parent folders are created, the bytes go to a
/// temporary file in the same folder which is renamed over `path` only once complete, so a
/// failure never leaves a half-written file (nor touches an existing one). No `fsync`: this
/// guards against failed writes and concurrent readers, not against power loss.
pub(crate) fn write_atomic(
    path: &Path,
    write: impl FnOnce(&mut dyn Write) -> io::Result<()>,
) -> Result<(), GeometryError> {
    static COUNTER: AtomicUsize = AtomicUsize::new(0);
    let io_err = |source| GeometryError::Io {
        path: path.to_path_buf(),
        source,
    };
    let Some(name) = path.file_name() else {
        return Err(GeometryError::Invalid(format!(
            "{}: not a file path",
            path.display()
        )));
    };
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        fs::create_dir_all(dir).map_err(|source| GeometryError::Io {
            path: dir.to_path_buf(),
            source,
        })?;
    }
    let mut tmp_name = std::ffi::OsString::from(".");
    tmp_name.push(name);
    tmp_name.push(format!(
        ".{}-{}.tmp",
        std::process::id(),
        COUNTER.fetch_add(1, Ordering::Relaxed)
    ));
    let tmp = path.with_file_name(tmp_name);
    let written = fs::File::create(&tmp).and_then(|file| {
        let mut w = BufWriter::new(file);
        write(&mut w)?;
        w.flush()
    });
    let result = written.and_then(|()| fs::rename(&tmp, path));
    if let Err(e) = result {
        let _ = fs::remove_file(&tmp);
        return Err(io_err(e));
    }
    Ok(())
}

/// Checks that every triangle indexes an existing vertex and every position is finite, naming
/// `path` in the error: what a writer needs before it touches the file.
pub(crate) fn check_mesh(
    path: &Path,
    positions: &[Vec3],
    triangles: &[[usize; 3]],
) -> Result<(), GeometryError> {
    let n = positions.len();
    if let Some(i) = positions
        .iter()
        .position(|p| !p.iter().all(|c| c.is_finite()))
    {
        return Err(GeometryError::Invalid(format!(
            "{}: vertex {i} has a non-finite position {:?}",
            path.display(),
            [positions[i].x, positions[i].y, positions[i].z]
        )));
    }
    if let Some(t) = triangles.iter().position(|t| t.iter().any(|&i| i >= n)) {
        return Err(GeometryError::Invalid(format!(
            "{}: triangle {t} {:?} indexes a vertex out of range (mesh has {n} vertices)",
            path.display(),
            triangles[t]
        )));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn failed_write_leaves_old_file_and_no_temporary() {
        let dir = std::env::temp_dir().join(format!("emilion-files-{}", std::process::id()));
        let path = dir.join("nested").join("out.txt");
        write_atomic(&path, |w| w.write_all(b"old")).unwrap();
        let failing = write_atomic(&path, |w| {
            w.write_all(b"half")?;
            Err(io::Error::other("disk full"))
        });
        let e = failing.unwrap_err().to_string();
        assert!(e.contains("out.txt") && e.contains("disk full"), "{e}");
        assert_eq!(fs::read(&path).unwrap(), b"old");
        assert_eq!(fs::read_dir(path.parent().unwrap()).unwrap().count(), 1);
        assert!(write_atomic(Path::new(".."), |_| Ok(())).is_err());
        fs::remove_dir_all(&dir).unwrap();
    }
}
