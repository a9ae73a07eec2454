//! MPEG-4 facial animation parameters (FAPs) implemented directly on the MediaPipe face mesh,
//! as the seed report's second animation mechanism (§5.2.1: "deformation only within special
//! zones of the face by activating one of the pre-defined facial animation points").
//!
//! Each FAP of a [`FapRig`] is one MPEG-4 feature point on a MediaPipe vertex (or a few
//! vertices moving together), a direction (the MPEG-4 one: `open_jaw` down, `raise_*` up,
//! `stretch_l_*` towards the subject's left = +x, `close_t_*_eyelid` down onto the lower lid,
//! …), a FAP unit measured on the mesh it is built from ([`Fapus`]) and an influence zone: the
//! compact kernel `(1 − r/R)³ (3r/R + 1)` of the geodesic distance to the feature point on the
//! mesh graph with the lips and the eyelids cut apart ([`zone`]), so a lower-lip FAP never
//! moves the upper lip, an upper-eyelid FAP never moves the lower lid, and the reverse.
//! `open_jaw`, `thrust_jaw` and `shift_jaw` move the whole lower jaw (a plateau of weight 1 out
//! to the lower inner lip, then the kernel). Eyelid FAPs move every vertex of the lid rim
//! towards its partner on the other lid, so at the top of the range the lid closes along its
//! whole length.
//!
//! A value `v` of FAP `k` displaces its feature point by `v / 1024 × FAPU` along its
//! direction; the rig stores per FAP the sparse list `(vertex, displacement per FAP unit)`
//! and [`FapRig::apply`] is a linear, allocation-free sum of them.

#[path = "fap_table.rs"]
mod table;
#[path = "fap_zone.rs"]
pub mod zone;

use self::table::Seeds::{Jaw, Lid, Points};
use self::table::{side, Spec, MID_LID, SIDE_RAMP, SPECS};
use self::zone::{kernel, plateau_kernel, side_mask, zone_field, ZoneGraph};
use super::model::FaceMesh;
use super::FaceError;
use crate::geometry::Vec3;

/// FAPs a photometric tracker observes well (jaw, lower lip, lip corners, eyelids, brows).
pub const TRACKED_FAPS: [u8; 10] = [3, 5, 6, 7, 12, 13, 19, 20, 33, 34];

/// The MPEG-4 face animation parameter units (FAPU), measured on a neutral face.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FapUnit {
    /// Mouth width.
    Mw,
    /// Mouth–nose separation.
    Mns,
    /// Eye–nose separation.
    Ens,
    /// Eye separation.
    Es,
    /// Iris diameter (by MPEG-4's definition the opening between the eyelids).
    Irisd,
}

/// FAP unit lengths of one mesh (m; a FAP value of 1024 moves its point by one of them).
///
/// On the MediaPipe mesh (MPEG-4 feature point → vertex): pupils 3.5/3.6 = mean of the eye
/// corners and the mid-lid rim vertices (33, 133, 159, 145 right; 263, 362, 386, 374 left);
/// nose bottom 9.15 = vertex 2; inner upper lip middle 2.2 = 13; mouth corners 8.3/8.4 =
/// 291/61. `mw = |p291 − p61|`, `mns = y2 − y13`, `ens = pupil.y − y2` (mean of both
/// pupils), `es = |left pupil − right pupil|`, `irisd` = mean over both eyes of the distance
/// between the mid upper and lower lid vertices (159–145, 386–374).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Fapus {
    /// Mouth width (m).
    pub mw: f64,
    /// Mouth–nose separation (m).
    pub mns: f64,
    /// Eye–nose separation (m).
    pub ens: f64,
    /// Eye separation (m).
    pub es: f64,
    /// Iris diameter = eyelid opening (m).
    pub irisd: f64,
}

/// Right pupil stand-ins (outer and inner corner, mid upper and lower lid).
const RIGHT_EYE: [usize; 4] = [33, 133, 159, 145];
/// Left pupil stand-ins, mirrors of [`RIGHT_EYE`].
const LEFT_EYE: [usize; 4] = [263, 362, 386, 374];

impl Fapus {
    /// The units of a mesh in MediaPipe vertex order. Fails when the mesh is too small or any
    /// unit is not a positive finite length.
    pub fn mediapipe(mesh: &FaceMesh) -> Result<Fapus, FaceError> {
        let p = &mesh.positions;
        if p.len() < super::model::MEDIAPIPE_VERTICES {
            return Err(FaceError::parameter(
                "mesh",
                format!(
                    "FAPUs need the MediaPipe vertex order, got {} vertices",
                    p.len()
                ),
            ));
        }
        let mean = |ids: &[usize]| ids.iter().map(|&i| p[i]).sum::<Vec3>() / ids.len() as f64;
        let (rp, lp) = (mean(&RIGHT_EYE), mean(&LEFT_EYE));
        let f = Fapus {
            mw: (p[291] - p[61]).norm(),
            mns: p[2].y - p[13].y,
            ens: 0.5 * (rp.y + lp.y) - p[2].y,
            es: (lp - rp).norm(),
            irisd: 0.5 * ((p[159] - p[145]).norm() + (p[386] - p[374]).norm()),
        };
        for (name, v) in [
            ("MW", f.mw),
            ("MNS", f.mns),
            ("ENS", f.ens),
            ("ES", f.es),
            ("IRISD", f.irisd),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(FaceError::Failed(format!(
                    "FAPU {name} = {v} m on this mesh: not a positive length (is it a face in \
                     MediaPipe order, y up?)"
                )));
            }
        }
        Ok(f)
    }

    /// The length of one unit (m).
    pub fn get(&self, unit: FapUnit) -> f64 {
        match unit {
            FapUnit::Mw => self.mw,
            FapUnit::Mns => self.mns,
            FapUnit::Ens => self.ens,
            FapUnit::Es => self.es,
            FapUnit::Irisd => self.irisd,
        }
    }
}

/// One facial animation parameter of a [`FapRig`].
#[derive(Clone, Debug, PartialEq)]
pub struct FapDef {
    /// MPEG-4 FAP number (3..=68).
    pub number: u8,
    /// MPEG-4 name, e.g. `open_jaw`.
    pub name: String,
    /// Useful range of the value, in FAP units (value / 1024 × FAPU is the displacement).
    pub range: (f64, f64),
    /// Its unit.
    pub unit: FapUnit,
    /// The MediaPipe vertex of its feature point.
    pub feature_vertex: usize,
    /// Unit direction in which a positive value moves the feature point.
    pub direction: Vec3,
    /// Radius of its influence zone beyond any plateau (m, geodesic).
    pub radius: f64,
}

/// FAPs as linear, localised displacement fields on a mesh.
#[derive(Clone, Debug, PartialEq)]
pub struct FapRig {
    /// The parameters, in rig order (the order of `values` in [`FapRig::apply`]).
    pub faps: Vec<FapDef>,
    /// The FAP units of the mesh the rig was built on.
    pub fapus: Fapus,
    /// Per FAP: `(vertex, displacement per FAP unit (m))`, in vertex order.
    displacements: Vec<Vec<(u32, Vec3)>>,
}

impl FapRig {
    /// The rig of a mesh in MediaPipe vertex order, FAPUs measured on it (its neutral face).
    pub fn new(mesh: &FaceMesh) -> Result<FapRig, FaceError> {
        let graph = ZoneGraph::mediapipe(mesh)?;
        let fapus = Fapus::mediapipe(mesh)?;
        let p = &mesh.positions;
        let mut faps = Vec::with_capacity(SPECS.len());
        let mut displacements = Vec::with_capacity(SPECS.len());
        for &Spec(number, name, unit, seeds, dir, radius_es, range) in SPECS {
            // Lip and eyelid FAPs stay on their side of the mouth or eye (the corners, where
            // the rims meet, take half).
            let mask = side(number)
                .map(|(own, other)| side_mask(&graph, own, other, SIDE_RAMP * fapus.es));
            let masked = |v: usize| mask.as_ref().map_or(1.0, |m| m[v]);
            let fapu = fapus.get(unit);
            let radius = radius_es * fapus.es;
            let mut direction = Vec3::from(dir);
            let mut range = range;
            let per_unit = fapu / 1024.0;
            let (feature, field) = match seeds {
                Points(ids) => {
                    let sources: Vec<(usize, f64)> = ids.iter().map(|&i| (i, 0.0)).collect();
                    let vectors = vec![direction * per_unit; ids.len()];
                    let field = zone_field(&graph, &sources, &vectors, |v, d| {
                        masked(v) * kernel(d / radius)
                    });
                    (ids[0], field)
                }
                Jaw => {
                    let (dist, _) = graph.distances(&[(152, 0.0)]);
                    let inner = dist[14];
                    if !inner.is_finite() {
                        return Err(FaceError::Failed(
                            "the chin (152) and the lower lip (14) are not connected".into(),
                        ));
                    }
                    let field =
                        zone_field(&graph, &[(152, 0.0)], &[direction * per_unit], |v, d| {
                            masked(v) * plateau_kernel(d, inner, inner + radius)
                        });
                    (152, field)
                }
                Lid(rim, other) => {
                    let gap = p[other[MID_LID]] - p[rim[MID_LID]];
                    let g = gap.norm();
                    if g.is_nan() || g <= 0.0 {
                        return Err(FaceError::Failed(format!(
                            "{name}: the eyelids already touch at vertex {}",
                            rim[MID_LID]
                        )));
                    }
                    direction = gap / g;
                    // The value that brings the feature point onto the other lid.
                    let full = 1024.0 * g / fapu;
                    range = (-0.5 * full, full);
                    let sources: Vec<(usize, f64)> = rim.iter().map(|&i| (i, 0.0)).collect();
                    // Each rim vertex reaches its partner at `full`.
                    let vectors: Vec<Vec3> = rim
                        .iter()
                        .zip(other.iter())
                        .map(|(&a, &b)| (p[b] - p[a]) / full)
                        .collect();
                    let field = zone_field(&graph, &sources, &vectors, |v, d| {
                        masked(v) * kernel(d / radius)
                    });
                    (rim[MID_LID], field)
                }
            };
            faps.push(FapDef {
                number,
                name: name.to_string(),
                range,
                unit,
                feature_vertex: feature,
                direction,
                radius,
            });
            displacements.push(field);
        }
        Ok(FapRig {
            faps,
            fapus,
            displacements,
        })
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

    /// The sparse displacement field of FAP `k` (rig order): `(vertex, displacement in metres
    /// per FAP unit)`, in vertex order; empty for `k` out of range.
    pub fn displacement(&self, k: usize) -> &[(u32, Vec3)] {
        self.displacements.get(k).map_or(&[], |d| d.as_slice())
    }

    /// `out = neutral + Σ values[k] × displacement of FAP k` (values in FAP units, one per
    /// parameter of the rig). No allocation once `out` has its size.
    ///
    /// Extra values are ignored, missing ones count as 0, displacements of vertices past
    /// `neutral` are skipped: the call never panics.
    pub fn apply(&self, neutral: &[Vec3], values: &[f64], out: &mut Vec<Vec3>) {
        out.clear();
        out.extend_from_slice(neutral);
        for (field, &v) in self.displacements.iter().zip(values) {
            if v == 0.0 {
                continue;
            }
            for &(i, d) in field {
                if let Some(o) = out.get_mut(i as usize) {
                    *o += d * v;
                }
            }
        }
    }

    /// Values (rig order) from `(FAP number, value)` pairs; unknown numbers are an error.
    pub fn values(&self, pairs: &[(u8, f64)]) -> Result<Vec<f64>, FaceError> {
        let mut v = vec![0.0; self.len()];
        for &(n, x) in pairs {
            let k = self
                .index_of(n)
                .ok_or_else(|| FaceError::parameter("fap", format!("FAP {n} is not in the rig")))?;
            v[k] += x;
        }
        Ok(v)
    }
}
