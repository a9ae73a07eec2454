//! Named expression sliders (seed report §5.2.1, Figure 5: "Mouth width", "Mouth corners",
//! "Right eyebrow - surprise", …) and the six basic expressions (smile, surprise, anger,
//! sadness, disgust, fear). Each slider is a fixed linear combination of FAP values
//! ([`crate::face::fap`]) and muscle activations ([`crate::face::muscles`]); [`Expressions`]
//! precomputes one sparse displacement field per slider, so applying any mix of sliders is one
//! allocation-free linear sum.
//!
//! FAP amounts in [`Slider::faps`] are fractions of the FAP's range: `+0.5` = half of the
//! range's upper end, `−0.5` = half of its lower end (so an eyelid's `1` closes the eye on
//! any mesh); muscle amounts are activations.

use super::fap::FapRig;
use super::model::FaceMesh;
use super::muscles::MuscleRig;
use super::FaceError;
use crate::geometry::Vec3;

/// One named slider: a linear combination of FAPs and muscles at slider value 1.
#[derive(Clone, Debug, PartialEq)]
pub struct Slider {
    /// Name shown to the user, e.g. `Mouth width` or `smile`.
    pub name: String,
    /// Useful range of the slider value.
    pub range: (f64, f64),
    /// `(FAP number, fraction of its range)` at value 1.
    pub faps: Vec<(u8, f64)>,
    /// `(muscle name, activation)` at value 1.
    pub muscles: Vec<(String, f64)>,
}

impl Slider {
    /// A slider from static tables.
    pub fn new(
        name: &str,
        range: (f64, f64),
        faps: &[(u8, f64)],
        muscles: &[(&str, f64)],
    ) -> Slider {
        Slider {
            name: name.to_string(),
            range,
            faps: faps.to_vec(),
            muscles: muscles.iter().map(|(m, a)| (m.to_string(), *a)).collect(),
        }
    }
}

/// The value in FAP units of `fraction` of FAP `k`'s range.
pub fn fap_value(rig: &FapRig, k: usize, fraction: f64) -> f64 {
    let (lo, hi) = rig.faps[k].range;
    if fraction >= 0.0 {
        fraction * hi
    } else {
        -fraction * lo
    }
}

/// The dense displacement (m) of a combination of FAPs (fractions of their ranges) and
/// muscles (activations) on a mesh of `n` vertices. Unknown FAPs or muscles are errors.
pub fn combination(
    faps: &FapRig,
    muscles: &MuscleRig,
    n: usize,
    fap_amounts: &[(u8, f64)],
    muscle_amounts: &[(String, f64)],
) -> Result<Vec<Vec3>, FaceError> {
    let mut d = vec![Vec3::zeros(); n];
    for &(number, fraction) in fap_amounts {
        let k = faps.index_of(number).ok_or_else(|| {
            FaceError::parameter("fap", format!("FAP {number} is not in the rig"))
        })?;
        let v = fap_value(faps, k, fraction);
        for &(i, x) in faps.displacement(k) {
            if let Some(o) = d.get_mut(i as usize) {
                *o += x * v;
            }
        }
    }
    for (name, a) in muscle_amounts {
        let k = muscles
            .index_of(name)
            .ok_or_else(|| FaceError::parameter("muscle", format!("no muscle called `{name}`")))?;
        for &(i, x) in muscles.displacement(k) {
            if let Some(o) = d.get_mut(i as usize) {
                *o += x * *a;
            }
        }
    }
    Ok(d)
}

/// Named sliders as precomputed sparse displacement fields.
#[derive(Clone, Debug, PartialEq)]
pub struct Expressions {
    /// The sliders, in order (the order of values in [`Expressions::apply`]).
    pub sliders: Vec<Slider>,
    /// The FAP rig the sliders use.
    pub faps: FapRig,
    /// The muscles the sliders use.
    pub muscles: MuscleRig,
    /// Per slider: `(vertex, displacement at value 1 (m))`.
    fields: Vec<Vec<(u32, Vec3)>>,
}

impl Expressions {
    /// The default sliders ([`default_sliders`]) on a mesh in MediaPipe order.
    pub fn new(mesh: &FaceMesh) -> Result<Expressions, FaceError> {
        let faps = FapRig::new(mesh)?;
        let muscles = MuscleRig::mediapipe(mesh)?;
        Expressions::with_sliders(mesh.positions.len(), faps, muscles, default_sliders())
    }

    /// Given sliders over given rigs, for a mesh of `n` vertices. Fails on a slider naming an
    /// unknown FAP or muscle, or on two sliders of the same name.
    pub fn with_sliders(
        n: usize,
        faps: FapRig,
        muscles: MuscleRig,
        sliders: Vec<Slider>,
    ) -> Result<Expressions, FaceError> {
        let mut fields = Vec::with_capacity(sliders.len());
        for (k, s) in sliders.iter().enumerate() {
            if sliders[..k].iter().any(|o| o.name == s.name) {
                return Err(FaceError::parameter(&s.name, "two sliders of this name"));
            }
            let d = combination(&faps, &muscles, n, &s.faps, &s.muscles)
                .map_err(|e| FaceError::parameter(&s.name, e.to_string()))?;
            fields.push(
                d.into_iter()
                    .enumerate()
                    .filter(|(_, v)| *v != Vec3::zeros())
                    .map(|(i, v)| (i as u32, v))
                    .collect(),
            );
        }
        Ok(Expressions {
            sliders,
            faps,
            muscles,
            fields,
        })
    }

    /// Number of sliders.
    pub fn len(&self) -> usize {
        self.sliders.len()
    }

    /// Whether there is no slider.
    pub fn is_empty(&self) -> bool {
        self.sliders.is_empty()
    }

    /// Slider names, in order.
    pub fn names(&self) -> Vec<&str> {
        self.sliders.iter().map(|s| s.name.as_str()).collect()
    }

    /// Index of the slider called `name`.
    pub fn index_of(&self, name: &str) -> Option<usize> {
        self.sliders.iter().position(|s| s.name == name)
    }

    /// Sparse field of slider `k` at value 1 (empty for `k` out of range).
    pub fn displacement(&self, k: usize) -> &[(u32, Vec3)] {
        self.fields.get(k).map_or(&[], |d| d.as_slice())
    }

    /// `out = neutral + Σ values[k] × field of slider k`. No allocation once `out` has its
    /// size; missing values count as 0, extra values and vertices past `neutral` are ignored.
    pub fn apply(&self, neutral: &[Vec3], values: &[f64], out: &mut Vec<Vec3>) {
        out.clear();
        out.extend_from_slice(neutral);
        for (field, &v) in self.fields.iter().zip(values) {
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

    /// Values (slider order) from `(name, value)` pairs; unknown names are an error.
    pub fn values(&self, pairs: &[(&str, f64)]) -> Result<Vec<f64>, FaceError> {
        let mut v = vec![0.0; self.len()];
        for &(name, x) in pairs {
            let k = self
                .index_of(name)
                .ok_or_else(|| FaceError::parameter("slider", format!("no slider `{name}`")))?;
            v[k] += x;
        }
        Ok(v)
    }
}

/// The six basic expressions, in this order, as slider names.
pub const BASIC_EXPRESSIONS: [&str; 6] =
    ["smile", "surprise", "anger", "sadness", "disgust", "fear"];

/// The default sliders: the seed's interface sliders, then [`BASIC_EXPRESSIONS`].
pub fn default_sliders() -> Vec<Slider> {
    let s = Slider::new;
    let sym = (-1.0, 1.0);
    let pos = (0.0, 1.0);
    vec![
        s("Jaw", pos, &[(3, 1.0)], &[]),
        s("Lower lip", sym, &[(5, 1.0)], &[]),
        s("Upper lip", sym, &[(4, -1.0)], &[]),
        s("Lower lip prominence", sym, &[(16, 1.0)], &[]),
        s("Upper lip prominence", sym, &[(17, 1.0)], &[]),
        s("Mouth width", sym, &[(6, 1.0), (7, 1.0)], &[]),
        s("Mouth width - right side only", sym, &[(7, 1.0)], &[]),
        s("Mouth width - left side only", sym, &[(6, 1.0)], &[]),
        s("Mouth corners", sym, &[(12, 1.0), (13, 1.0)], &[]),
        s("Mouth corners - right side only", sym, &[(13, 1.0)], &[]),
        s("Mouth corners - left side only", sym, &[(12, 1.0)], &[]),
        s("Right eyelid", pos, &[(20, 1.0)], &[]),
        s("Left eyelid", pos, &[(19, 1.0)], &[]),
        s("Right eye (lower part)", pos, &[(22, 1.0)], &[]),
        s("Left eye (lower part)", pos, &[(21, 1.0)], &[]),
        s(
            "Right eyebrow - perplexity",
            sym,
            &[(32, 1.0), (36, -0.5)],
            &[],
        ),
        s(
            "Left eyebrow - perplexity",
            sym,
            &[(31, 1.0), (35, -0.5)],
            &[],
        ),
        s(
            "Right eyebrow - frown",
            pos,
            &[(38, 0.7), (32, -0.5)],
            &[("corrugator_r", 0.7)],
        ),
        s(
            "Left eyebrow - frown",
            pos,
            &[(37, 0.7), (31, -0.5)],
            &[("corrugator_l", 0.7)],
        ),
        s(
            "Right eyebrow - surprise",
            pos,
            &[(32, 0.6), (34, 0.7), (36, 0.5)],
            &[("frontalis_r", 0.3)],
        ),
        s(
            "Left eyebrow - surprise",
            pos,
            &[(31, 0.6), (33, 0.7), (35, 0.5)],
            &[("frontalis_l", 0.3)],
        ),
        s("Nose width", sym, &[(61, 1.0), (62, 1.0)], &[]),
        s("Right nostril - dilation", sym, &[(62, 1.0)], &[]),
        s("Left nostril - dilation", sym, &[(61, 1.0)], &[]),
        s("Right cheek - upper part (rise)", pos, &[(42, 1.0)], &[]),
        s("Left cheek - upper part (rise)", pos, &[(41, 1.0)], &[]),
        s(
            "Right cheek - central part (volume)",
            pos,
            &[(40, 1.0)],
            &[],
        ),
        s("Left cheek - central part (volume)", pos, &[(39, 1.0)], &[]),
        s(
            "smile",
            pos,
            &[
                (12, 0.3),
                (13, 0.3),
                (6, 0.3),
                (7, 0.3),
                (41, 0.4),
                (42, 0.4),
                (21, 0.2),
                (22, 0.2),
            ],
            &[("zygomatic_major_l", 1.0), ("zygomatic_major_r", 1.0)],
        ),
        s(
            "surprise",
            pos,
            &[
                (31, 0.6),
                (32, 0.6),
                (33, 0.7),
                (34, 0.7),
                (35, 0.5),
                (36, 0.5),
                (19, -0.6),
                (20, -0.6),
                (3, 0.4),
            ],
            &[("frontalis_l", 0.3), ("frontalis_r", 0.3)],
        ),
        s(
            "anger",
            pos,
            &[
                (37, 0.8),
                (38, 0.8),
                (31, -0.7),
                (32, -0.7),
                (33, -0.4),
                (34, -0.4),
                (19, 0.2),
                (20, 0.2),
                (4, 0.3),
                (5, 0.3),
                (61, 0.5),
                (62, 0.5),
            ],
            &[("corrugator_l", 1.0), ("corrugator_r", 1.0)],
        ),
        s(
            "sadness",
            pos,
            &[
                (31, 0.6),
                (32, 0.6),
                (35, -0.4),
                (36, -0.4),
                (19, 0.25),
                (20, 0.25),
                (5, 0.2),
            ],
            &[
                ("depressor_anguli_oris_l", 1.0),
                ("depressor_anguli_oris_r", 1.0),
            ],
        ),
        s(
            "disgust",
            pos,
            &[
                (4, -0.5),
                (63, 0.6),
                (61, 0.5),
                (62, 0.5),
                (41, 0.4),
                (42, 0.4),
                (37, 0.3),
                (38, 0.3),
                (31, -0.3),
                (32, -0.3),
            ],
            &[("levator_labii_l", 1.0), ("levator_labii_r", 1.0)],
        ),
        s(
            "fear",
            pos,
            &[
                (31, 0.8),
                (32, 0.8),
                (33, 0.5),
                (34, 0.5),
                (37, 0.4),
                (38, 0.4),
                (19, -0.5),
                (20, -0.5),
                (6, 0.5),
                (7, 0.5),
                (3, 0.2),
            ],
            &[],
        ),
    ]
}
