//! Bézier-curve "muscles" on the face mesh (seed report §5.2.1: "special Bezier curves
//! ('muscles') which are defined on the mesh", deforming it by RBF interpolation).
//!
//! A muscle is a cubic Bézier curve whose four control points are anchored on mesh vertices,
//! with a displacement per control point per unit of activation. Activating the muscle moves
//! its control points; the moved curve is sampled ([`SAMPLES`] points) and each sample's
//! displacement (the Bernstein blend of the control displacements) is spread over the mesh
//! with the compact kernel `(1 − r/R)³ (3r/R + 1)` of the geodesic distance `r` from the
//! nearest sample, on the mesh graph with lips and eyelids cut apart
//! ([`crate::face::fap::zone`]) — so, as in the seed, the upper-lip curve does not drag the
//! lower lip, nor the reverse. The deformation is linear in the activation: each muscle is
//! precomputed as a sparse `(vertex, displacement per unit)` list and [`MuscleRig::apply`] is a
//! sum without allocation.
//!
//! The default set ([`MuscleRig::mediapipe`]) is defined on the MediaPipe mesh, displacements
//! in units of the mesh's eye separation so an adapted face keeps its proportions.

use super::fap::zone::{kernel, zone_field, ZoneGraph};
use super::fap::Fapus;
use super::model::FaceMesh;
use super::FaceError;
use crate::geometry::Vec3;

/// Samples per curve.
pub const SAMPLES: usize = 16;

/// One muscle: a cubic Bézier curve anchored on the mesh.
#[derive(Clone, Debug, PartialEq)]
pub struct Muscle {
    /// Name, e.g. `zygomatic_major_l` (`_l` = the subject's left, +x).
    pub name: String,
    /// Control points, as mesh vertices (the curve starts at the first and ends at the last).
    pub controls: [usize; 4],
    /// Displacement of each control point at activation 1 (m).
    pub moves: [Vec3; 4],
    /// Influence radius around the curve (m, geodesic).
    pub radius: f64,
}

/// Default muscle table: name, control vertices, moves (per control: direction × amount in
/// eye separations; `Toward(v)` = the unit direction from the control point to vertex `v`),
/// radius (× ES).
#[derive(Clone, Copy)]
enum Dir {
    /// A fixed direction.
    Fixed([f64; 3]),
    /// Towards a vertex.
    Toward(usize),
}

/// A default muscle: name, controls, per-control (direction, amount × ES), radius × ES.
type Spec = (&'static str, [usize; 4], [(Dir, f64); 4], f64);

use Dir::{Fixed, Toward};

const UP: Dir = Fixed([0.0, 1.0, 0.0]);
const FWD: Dir = Fixed([0.0, 0.0, 1.0]);
const NONE: (Dir, f64) = (Fixed([0.0, 0.0, 0.0]), 0.0);

/// The default muscles on the MediaPipe mesh: left (+x) versions; right ones are mirrored.
const LEFT_SPECS: &[Spec] = &[
    // Zygomatic major: from the lip corner up and out to the cheekbone; pulls the corner.
    (
        "zygomatic_major",
        [291, 410, 425, 352],
        [
            (Toward(352), 0.14),
            (Toward(352), 0.09),
            (Toward(352), 0.04),
            NONE,
        ],
        0.4,
    ),
    // Frontalis: along the brow, raising it (and the forehead above).
    (
        "frontalis",
        [285, 296, 334, 300],
        [(UP, 0.14), (UP, 0.16), (UP, 0.16), (UP, 0.12)],
        0.45,
    ),
    // Depressor anguli oris: from the lip corner down to the jaw line; pulls the corner down.
    (
        "depressor_anguli_oris",
        [291, 273, 422, 430],
        [
            (Toward(430), 0.12),
            (Toward(430), 0.06),
            (Toward(430), 0.02),
            NONE,
        ],
        0.35,
    ),
    // Corrugator: inner brow pulled down and towards the nose.
    (
        "corrugator",
        [336, 285, 296, 334],
        [
            (Fixed([-0.6, -0.8, 0.0]), 0.12),
            (Fixed([-0.6, -0.8, 0.0]), 0.1),
            (Fixed([-0.6, -0.8, 0.0]), 0.06),
            NONE,
        ],
        0.3,
    ),
    // Levator labii superioris: upper lip raised beside the nose.
    (
        "levator_labii",
        [267, 393, 327, 358],
        [(UP, 0.1), (UP, 0.08), (UP, 0.04), NONE],
        0.3,
    ),
];

/// Orbicularis oris halves (central, not mirrored): corners drawn in, middle pushed forward.
const CENTRAL_SPECS: &[Spec] = &[
    (
        "orbicularis_upper",
        [61, 37, 267, 291],
        [(Toward(0), 0.08), (FWD, 0.1), (FWD, 0.1), (Toward(0), 0.08)],
        0.3,
    ),
    (
        "orbicularis_lower",
        [61, 84, 314, 291],
        [
            (Toward(17), 0.08),
            (FWD, 0.1),
            (FWD, 0.1),
            (Toward(17), 0.08),
        ],
        0.3,
    ),
];

/// Muscles as linear, localised displacement fields.
#[derive(Clone, Debug, PartialEq)]
pub struct MuscleRig {
    /// The muscles, in rig order (the order of activations in [`MuscleRig::apply`]).
    pub muscles: Vec<Muscle>,
    /// Per muscle: `(vertex, displacement at activation 1 (m))`.
    displacements: Vec<Vec<(u32, Vec3)>>,
}

/// Point `t` of the cubic Bézier curve of `p`, and the Bernstein weights.
pub fn bezier(p: &[Vec3; 4], t: f64) -> (Vec3, [f64; 4]) {
    let s = 1.0 - t;
    let b = [s * s * s, 3.0 * s * s * t, 3.0 * s * t * t, t * t * t];
    (p[0] * b[0] + p[1] * b[1] + p[2] * b[2] + p[3] * b[3], b)
}

impl MuscleRig {
    /// The default muscles on a mesh in MediaPipe vertex order: `zygomatic_major_l/_r`,
    /// `frontalis_l/_r`, `depressor_anguli_oris_l/_r`, `corrugator_l/_r`,
    /// `levator_labii_l/_r`, `orbicularis_upper`, `orbicularis_lower`.
    pub fn mediapipe(mesh: &FaceMesh) -> Result<MuscleRig, FaceError> {
        let graph = ZoneGraph::mediapipe(mesh)?;
        let es = Fapus::mediapipe(mesh)?.es;
        let mirror = mesh.mirror_map();
        let p = &mesh.positions;
        let build = |name: String, spec: &Spec, mirrored: bool| -> Muscle {
            let m = |v: usize| if mirrored { mirror[v] } else { v };
            let controls = spec.1.map(m);
            let mut moves = [Vec3::zeros(); 4];
            for (k, &(dir, amount)) in spec.2.iter().enumerate() {
                let d = match dir {
                    Fixed(d) => {
                        let d = Vec3::from(d);
                        let d = if mirrored {
                            Vec3::new(-d.x, d.y, d.z)
                        } else {
                            d
                        };
                        d.try_normalize(0.0).unwrap_or_else(Vec3::zeros)
                    }
                    Toward(v) => (p[m(v)] - p[controls[k]])
                        .try_normalize(0.0)
                        .unwrap_or_else(Vec3::zeros),
                };
                moves[k] = d * (amount * es);
            }
            Muscle {
                name,
                controls,
                moves,
                radius: spec.3 * es,
            }
        };
        let mut muscles = Vec::new();
        for spec in LEFT_SPECS {
            muscles.push(build(format!("{}_l", spec.0), spec, false));
            muscles.push(build(format!("{}_r", spec.0), spec, true));
        }
        for spec in CENTRAL_SPECS {
            muscles.push(build(spec.0.to_string(), spec, false));
        }
        MuscleRig::new(mesh, &graph, muscles)
    }

    /// A rig of given muscles on a mesh (MediaPipe order, for the lip and eyelid cuts). Fails
    /// on a control vertex out of range or a non-positive radius.
    pub fn new(
        mesh: &FaceMesh,
        graph: &ZoneGraph,
        muscles: Vec<Muscle>,
    ) -> Result<MuscleRig, FaceError> {
        let p = &mesh.positions;
        let mut displacements = Vec::with_capacity(muscles.len());
        for m in &muscles {
            if let Some(&v) = m.controls.iter().find(|&&v| v >= p.len()) {
                return Err(FaceError::parameter(
                    &m.name,
                    format!("control vertex {v} out of range (mesh of {})", p.len()),
                ));
            }
            if !(m.radius.is_finite() && m.radius > 0.0) {
                return Err(FaceError::parameter(&m.name, "radius must be positive"));
            }
            let cp = m.controls.map(|v| p[v]);
            let mut sources = Vec::with_capacity(SAMPLES);
            let mut vectors = Vec::with_capacity(SAMPLES);
            for s in 0..SAMPLES {
                let t = s as f64 / (SAMPLES - 1) as f64;
                let (x, b) = bezier(&cp, t);
                let d =
                    m.moves[0] * b[0] + m.moves[1] * b[1] + m.moves[2] * b[2] + m.moves[3] * b[3];
                // The sample enters the mesh graph at its nearest vertex.
                let (v, dist) = p
                    .iter()
                    .enumerate()
                    .map(|(i, q)| (i, (q - x).norm()))
                    .min_by(|a, b| a.1.total_cmp(&b.1))
                    .unwrap_or((0, 0.0));
                sources.push((v, dist));
                vectors.push(d);
            }
            let r = m.radius;
            displacements.push(zone_field(graph, &sources, &vectors, |_, d| kernel(d / r)));
        }
        Ok(MuscleRig {
            muscles,
            displacements,
        })
    }

    /// Number of muscles.
    pub fn len(&self) -> usize {
        self.muscles.len()
    }

    /// Whether the rig has no muscle.
    pub fn is_empty(&self) -> bool {
        self.muscles.is_empty()
    }

    /// Rig index of the muscle called `name`.
    pub fn index_of(&self, name: &str) -> Option<usize> {
        self.muscles.iter().position(|m| m.name == name)
    }

    /// Sparse field of muscle `k` at activation 1: `(vertex, displacement (m))`; empty when
    /// `k` is out of range.
    pub fn displacement(&self, k: usize) -> &[(u32, Vec3)] {
        self.displacements.get(k).map_or(&[], |d| d.as_slice())
    }

    /// `out = neutral + Σ activations[k] × field of muscle k`. No allocation once `out` has
    /// its size; missing activations count as 0, extra ones and vertices past `neutral` are
    /// ignored.
    pub fn apply(&self, neutral: &[Vec3], activations: &[f64], out: &mut Vec<Vec3>) {
        out.clear();
        out.extend_from_slice(neutral);
        for (field, &a) in self.displacements.iter().zip(activations) {
            if a == 0.0 {
                continue;
            }
            for &(i, d) in field {
                if let Some(o) = out.get_mut(i as usize) {
                    *o += d * a;
                }
            }
        }
    }
}
