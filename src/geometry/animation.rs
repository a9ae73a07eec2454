//! A recorded animation of triangle meshes with fixed topology: per mesh its triangles,
//! optional texture coordinates, a colour, and one set of vertex positions per frame (engine
//! frame: metres, +Z up; stored in single precision, what every cache format holds). The
//! writers of [`super::usd`], [`super::pc2`] and [`super::gltf::write_animated_glb`] turn it
//! into files; the simulation side fills it frame by frame.

use super::{GeometryError, Vec3};

/// Largest recording kept in memory (bytes of positions, all meshes and frames together).
pub const MAX_ANIMATION_BYTES: usize = 1 << 30;

/// One animated mesh.
#[derive(Debug, Clone, PartialEq)]
pub struct AnimatedMesh {
    /// Name (a USD prim name, a glTF primitive's material name): letters, digits and `_`,
    /// not starting with a digit.
    pub name: String,
    /// Triangles, indices into the positions.
    pub triangles: Vec<[usize; 3]>,
    /// Texture coordinates, one per vertex (for a cloth: its rest coordinates in metres).
    pub uvs: Option<Vec<[f64; 2]>>,
    /// Display colour, 8-bit sRGB.
    pub colour: [u8; 3],
    /// Vertex count.
    pub vertices: usize,
    /// Positions per recorded frame (metres, +Z up).
    pub frames: Vec<Vec<[f32; 3]>>,
}

/// Meshes recorded at a fixed frame rate, frame 0 (the state when recording started) first.
#[derive(Debug, Clone, PartialEq)]
pub struct Animation {
    /// Frames per second.
    pub fps: f64,
    /// The meshes, all with the same number of frames.
    pub meshes: Vec<AnimatedMesh>,
}

impl Animation {
    /// An empty recording at `fps` frames per second of meshes with the given names,
    /// triangles, texture coordinates and colours. Fails on a non-positive or non-finite
    /// `fps`, a bad name, a triangle index out of range or texture coordinates not one per
    /// vertex.
    pub fn new(fps: f64, meshes: Vec<AnimatedMesh>) -> Result<Self, GeometryError> {
        let invalid = |m: String| Err(GeometryError::Invalid(m));
        if !(fps.is_finite() && fps > 0.0) {
            return invalid(format!(
                "animation: frame rate {fps} must be finite and > 0"
            ));
        }
        for m in &meshes {
            let ok_start = m.name.chars().next().is_some_and(|c| !c.is_ascii_digit());
            if !ok_start
                || !m
                    .name
                    .chars()
                    .all(|c| c.is_ascii_alphanumeric() || c == '_')
            {
                return invalid(format!(
                    "animation: mesh name `{}` must be letters, digits and _, not starting with a digit",
                    m.name
                ));
            }
            if let Some(t) = m
                .triangles
                .iter()
                .find(|t| t.iter().any(|&i| i >= m.vertices))
            {
                return invalid(format!(
                    "animation: mesh `{}` has triangle {t:?} beyond its {} vertices",
                    m.name, m.vertices
                ));
            }
            if m.uvs.as_ref().is_some_and(|uv| uv.len() != m.vertices) {
                return invalid(format!(
                    "animation: mesh `{}` needs one texture coordinate per vertex",
                    m.name
                ));
            }
            if !m.frames.is_empty() {
                return invalid(format!("animation: mesh `{}` starts with frames", m.name));
            }
        }
        Ok(Animation { fps, meshes })
    }

    /// Frames recorded so far.
    pub fn frame_count(&self) -> usize {
        self.meshes.first().map_or(0, |m| m.frames.len())
    }

    /// Appends one frame: the positions of every mesh, in order. Fails, changing nothing, on
    /// a wrong number of meshes or vertices, a non-finite position, or when the recording
    /// would pass [`MAX_ANIMATION_BYTES`].
    pub fn push_frame(&mut self, positions: &[&[Vec3]]) -> Result<(), GeometryError> {
        let invalid = |m: String| Err(GeometryError::Invalid(format!("animation: {m}")));
        if positions.len() != self.meshes.len() {
            return invalid(format!(
                "{} meshes given for a recording of {}",
                positions.len(),
                self.meshes.len()
            ));
        }
        let per_frame: usize = self.meshes.iter().map(|m| 12 * m.vertices).sum();
        if per_frame * (self.frame_count() + 1) > MAX_ANIMATION_BYTES {
            return invalid(format!(
                "frame {} would take the recording past {} MiB: record every few frames or a coarser mesh",
                self.frame_count() + 1,
                MAX_ANIMATION_BYTES >> 20
            ));
        }
        for (m, p) in self.meshes.iter().zip(positions) {
            if p.len() != m.vertices {
                return invalid(format!(
                    "mesh `{}` has {} vertices, {} positions given",
                    m.name,
                    m.vertices,
                    p.len()
                ));
            }
            if let Some(i) = p.iter().position(|v| !v.iter().all(|c| c.is_finite())) {
                return invalid(format!(
                    "mesh `{}` vertex {i} is not finite at frame {}",
                    m.name,
                    self.frame_count() + 1
                ));
            }
        }
        for (m, p) in self.meshes.iter_mut().zip(positions) {
            m.frames.push(
                p.iter()
                    .map(|v| [v.x as f32, v.y as f32, v.z as f32])
                    .collect(),
            );
        }
        Ok(())
    }

    /// Fails, naming `path`, when nothing was recorded.
    pub fn check_not_empty(&self, path: &std::path::Path) -> Result<(), GeometryError> {
        if self.frame_count() == 0 || self.meshes.is_empty() {
            return Err(GeometryError::Invalid(format!(
                "{}: the recording has no frames",
                path.display()
            )));
        }
        Ok(())
    }
}

/// A frame's f32 positions as engine vectors.
pub fn to_vec3(frame: &[[f32; 3]]) -> Vec<Vec3> {
    frame
        .iter()
        .map(|p| Vec3::new(p[0].into(), p[1].into(), p[2].into()))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tri(name: &str) -> AnimatedMesh {
        AnimatedMesh {
            name: name.into(),
            triangles: vec![[0, 1, 2]],
            uvs: None,
            colour: [200, 100, 50],
            vertices: 3,
            frames: Vec::new(),
        }
    }

    #[test]
    fn frames_are_checked_before_anything_is_kept() {
        let mut a = Animation::new(24.0, vec![tri("cloth")]).unwrap();
        let p = [Vec3::zeros(), Vec3::x(), Vec3::y()];
        a.push_frame(&[&p]).unwrap();
        assert!(a.push_frame(&[&p[..2]]).is_err());
        let nan = [Vec3::zeros(), Vec3::x(), Vec3::new(f64::NAN, 0.0, 0.0)];
        let e = a.push_frame(&[&nan]).unwrap_err().to_string();
        assert!(e.contains("vertex 2") && e.contains("frame 2"), "{e}");
        assert_eq!(a.frame_count(), 1);
        assert!(Animation::new(0.0, vec![tri("a")]).is_err());
        assert!(Animation::new(24.0, vec![tri("1a")]).is_err());
        assert!(Animation::new(24.0, vec![tri("a b")]).is_err());
    }
}
