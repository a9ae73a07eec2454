//! (being written) MPEG-4 facial animation parameters on the face mesh.

use super::model::FaceMesh;
use super::FaceError;
use crate::geometry::Vec3;

/// One facial animation parameter of a [`FapRig`].
#[derive(Clone, Debug, PartialEq)]
pub struct FapDef {
    /// MPEG-4 FAP number (3..=68).
    pub number: u8,
    /// MPEG-4 name, e.g. `open_jaw`.
    pub name: String,
    /// Useful range of the value, in FAP units (value / 1024 × FAPU is the displacement).
    pub range: (f64, f64),
}

/// FAPs as linear, localised displacement fields on a mesh.
#[derive(Clone, Debug, PartialEq)]
pub struct FapRig {
    /// The parameters, in rig order (the order of `values` in [`FapRig::apply`]).
    pub faps: Vec<FapDef>,
}

impl FapRig {
    /// The rig of a mesh in MediaPipe vertex order, FAPUs measured on it (its neutral face).
    pub fn new(_mesh: &FaceMesh) -> Result<FapRig, FaceError> {
        Ok(FapRig { faps: Vec::new() })
    }

    /// Number of parameters.
    pub fn len(&self) -> usize {
        self.faps.len()
    }

    /// Whether the rig has no parameters.
    pub fn is_empty(&self) -> bool {
        self.faps.is_empty()
    }

    /// Rig index of FAP `number`.
    pub fn index_of(&self, number: u8) -> Option<usize> {
        self.faps.iter().position(|f| f.number == number)
    }

    /// `out = neutral + Σ values[k] × displacement of FAP k` (values in FAP units, one per
    /// parameter of the rig). No allocation once `out` has its size.
    pub fn apply(&self, neutral: &[Vec3], _values: &[f64], out: &mut Vec<Vec3>) {
        out.clear();
        out.extend_from_slice(neutral);
    }
}
