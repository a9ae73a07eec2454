//! Clothes-like vertex colours for the mannequin's skin, used to render synthetic sequences:
//! a striped shirt with sleeves of another colour, bare forearms, hands, neck and face, hair
//! on the top and back of the head, trousers with a subtle check, dark shoes.
//!
//! [`skin_positions`] and [`shaded_colours`] give the skin's shape and shaded colours in a
//! pose, into reused buffers, for rendering.
//!
//! Each skin vertex is classified by its dominant bone (largest skinning weight) and its rest
//! position, so the pattern moves with the body. Colours are linear floats in `0..255`. The
//! palette is chosen from `seed`; the result is deterministic.

use crate::body::{Mannequin, Pose};
use crate::geometry::{SplitMix64, Vec3};

/// What a skin vertex is dressed in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Garment {
    /// Shirt body (torso, collar bones), horizontally striped.
    Shirt,
    /// Shirt sleeves (upper arms).
    Sleeve,
    /// Bare skin (forearms, hands, neck, face).
    Skin,
    /// Hair (top and back of the head).
    Hair,
    /// Trousers (pelvis below the belt, legs).
    Trousers,
    /// Shoes (feet, toes).
    Shoes,
}

const SHIRTS: [([f32; 3], [f32; 3]); 5] = [
    ([200.0, 40.0, 40.0], [235.0, 225.0, 200.0]),
    ([40.0, 90.0, 190.0], [230.0, 230.0, 230.0]),
    ([30.0, 140.0, 80.0], [240.0, 210.0, 60.0]),
    ([230.0, 120.0, 20.0], [50.0, 50.0, 60.0]),
    ([120.0, 50.0, 160.0], [220.0, 220.0, 120.0]),
];
const SLEEVES: [[f32; 3]; 4] = [
    [240.0, 200.0, 30.0],
    [30.0, 170.0, 190.0],
    [210.0, 210.0, 215.0],
    [190.0, 40.0, 120.0],
];
const SKINS: [[f32; 3]; 4] = [
    [225.0, 180.0, 150.0],
    [200.0, 150.0, 115.0],
    [160.0, 110.0, 80.0],
    [110.0, 75.0, 55.0],
];
const HAIRS: [[f32; 3]; 3] = [[45.0, 30.0, 20.0], [20.0, 18.0, 18.0], [140.0, 100.0, 50.0]];
const TROUSERS: [[f32; 3]; 4] = [
    [40.0, 50.0, 90.0],
    [70.0, 70.0, 75.0],
    [150.0, 130.0, 95.0],
    [60.0, 80.0, 50.0],
];
const SHOES: [f32; 3] = [28.0, 24.0, 22.0];

/// The garment of a vertex from the name of its dominant bone (before the height rules).
fn garment_of_bone(name: &str) -> Garment {
    let base = name.split('.').next().unwrap_or(name);
    if base.starts_with("upperarm") {
        Garment::Sleeve
    } else if base.starts_with("lowerarm")
        || base.starts_with("wrist")
        || base.starts_with("finger")
        || base.starts_with("metacarpal")
        || base.starts_with("neck")
    {
        Garment::Skin
    } else if base.starts_with("upperleg") || base.starts_with("lowerleg") {
        Garment::Trousers
    } else if base.starts_with("foot") || base.starts_with("toe") {
        Garment::Shoes
    } else if base.starts_with("spine")
        || base == "root"
        || base.starts_with("pelvis")
        || base.starts_with("breast")
        || base.starts_with("clavicle")
        || base.starts_with("shoulder")
    {
        Garment::Shirt
    } else {
        // head, jaw, eyes and the face muscles
        Garment::Hair
    }
}

/// Rest heights and places that the rules below need, from the skeleton.
struct Landmarks {
    belt_z: f64,
    eye_z: f64,
    head_y: f64,
}

fn landmarks(mannequin: &Mannequin) -> Landmarks {
    let sk = mannequin.skeleton();
    let head_of = |n: &str| sk.bone_index(n).map(|b| sk.bones()[b].head);
    let top = mannequin
        .rest_positions()
        .iter()
        .map(|p| p.z)
        .fold(0.0f64, f64::max);
    let hip_z = head_of("upperleg01.L").map_or(0.5 * top, |p| p.z);
    let neck_z = head_of("neck01").map_or(0.82 * top, |p| p.z);
    let head = head_of("head").unwrap_or(Vec3::new(0.0, 0.0, 0.88 * top));
    let eye_z = head_of("eye.L").map_or(head.z + 0.08, |p| p.z);
    Landmarks {
        belt_z: hip_z + 0.2 * (neck_z - hip_z),
        eye_z,
        head_y: head.y,
    }
}

/// The garment of every skin vertex (see the module docs), in skin-vertex order.
pub fn garments(mannequin: &Mannequin) -> Vec<Garment> {
    let lm = landmarks(mannequin);
    let names: Vec<&str> = mannequin.bone_names().collect();
    mannequin
        .rest_positions()
        .iter()
        .enumerate()
        .map(|(v, p)| {
            let bone = dominant_bone(mannequin, v);
            let g = garment_of_bone(names.get(bone).copied().unwrap_or("root"));
            match g {
                Garment::Shirt if p.z < lm.belt_z => Garment::Trousers,
                Garment::Hair => {
                    let top = p.z > lm.eye_z + 0.035;
                    let back = p.y > lm.head_y + 0.03 && p.z > lm.eye_z - 0.06;
                    if top || back {
                        Garment::Hair
                    } else {
                        Garment::Skin
                    }
                }
                g => g,
            }
        })
        .collect()
}

/// Index of the bone with the largest skinning weight on skin vertex `v` (the first one on
/// ties; 0 for a vertex without influences).
pub fn dominant_bone(mannequin: &Mannequin, v: usize) -> usize {
    let mut best = (0, f64::NEG_INFINITY);
    for (b, w) in mannequin.weights().influences(v) {
        if w > best.1 {
            best = (b, w);
        }
    }
    best.0
}

/// One clothes-like colour per skin vertex (linear, `0..255`), from its dominant bone and rest
/// position: striped shirt, sleeves of another colour, skin, hair, trousers with a subtle
/// check, dark shoes. The palette and stripe width come from `seed`; deterministic.
pub fn clothing_colours(mannequin: &Mannequin, seed: u64) -> Vec<[f32; 3]> {
    let palette = Palette::of(seed);
    garments(mannequin)
        .iter()
        .zip(mannequin.rest_positions())
        .map(|(g, p)| palette.colour(*g, *p))
        .collect()
}

/// The colours of one seeded outfit (what [`clothing_colours`] paints on the skin, and the
/// colours of simulated garments over it).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Palette {
    shirt: ([f32; 3], [f32; 3]),
    sleeve: [f32; 3],
    skin: [f32; 3],
    hair: [f32; 3],
    trousers: [f32; 3],
    /// Height of a shirt stripe (m).
    stripe: f64,
}

impl Palette {
    /// The outfit drawn from `seed`.
    pub fn of(seed: u64) -> Palette {
        let mut rng = SplitMix64::new(seed ^ 0xC107_41E5_0000_0001);
        let shirt = SHIRTS[rng.below(SHIRTS.len())];
        let sleeve = SLEEVES[rng.below(SLEEVES.len())];
        let skin = SKINS[rng.below(SKINS.len())];
        let hair = HAIRS[rng.below(HAIRS.len())];
        let trousers = TROUSERS[rng.below(TROUSERS.len())];
        let stripe = rng.range(0.025, 0.045);
        Palette {
            shirt,
            sleeve,
            skin,
            hair,
            trousers,
            stripe,
        }
    }

    /// The colour of `garment` at rest position `p` (stripes across the shirt by height, a
    /// subtle check on the trousers).
    pub fn colour(&self, garment: Garment, p: Vec3) -> [f32; 3] {
        let check = 0.02;
        let scale = |c: [f32; 3], f: f32| [c[0] * f, c[1] * f, c[2] * f];
        match garment {
            Garment::Shirt => {
                if (p.z / self.stripe).floor() as i64 % 2 == 0 {
                    self.shirt.0
                } else {
                    self.shirt.1
                }
            }
            Garment::Sleeve => self.sleeve,
            Garment::Skin => self.skin,
            Garment::Hair => self.hair,
            Garment::Trousers => {
                let cell = (p.x / check).floor() as i64
                    + (p.y / check).floor() as i64
                    + (p.z / check).floor() as i64;
                scale(
                    self.trousers,
                    if cell.rem_euclid(2) == 0 { 0.92 } else { 1.08 },
                )
            }
            Garment::Shoes => SHOES,
        }
    }
}

/// Skin vertex positions under `pose`: linear blending, or rigid by dominant bone.
pub fn skin_positions(m: &Mannequin, pose: &Pose, dominant: Option<&[usize]>, out: &mut Vec<Vec3>) {
    match dominant {
        None => m.skin(pose, out),
        Some(d) => {
            out.clear();
            out.extend(
                m.rest_positions()
                    .iter()
                    .zip(d)
                    .map(|(p, &b)| pose.apply(b, *p)),
            );
        }
    }
}

/// Per-vertex colours: clothing times Lambert shading of the area-weighted vertex normals.
pub fn shaded_colours(
    skin: &[Vec3],
    tris: &[[u32; 3]],
    base: &[[f32; 3]],
    normals: &mut Vec<Vec3>,
    out: &mut Vec<[f32; 3]>,
    shading: bool,
) {
    out.clear();
    if !shading {
        out.extend_from_slice(base);
        return;
    }
    normals.clear();
    normals.resize(skin.len(), Vec3::zeros());
    for t in tris {
        let [a, b, c] = t.map(|i| i as usize);
        let n = (skin[b] - skin[a]).cross(&(skin[c] - skin[a]));
        normals[a] += n;
        normals[b] += n;
        normals[c] += n;
    }
    let light = Vec3::new(-0.35, -0.75, 0.56).normalize();
    out.extend(normals.iter().zip(base).map(|(n, c)| {
        let l = n
            .try_normalize(1e-20)
            .map_or(0.0, |n| n.dot(&light).max(0.0));
        let s = (0.55 + 0.45 * l) as f32;
        [c[0] * s, c[1] * s, c[2] * s]
    }));
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bones_map_to_garments() {
        assert_eq!(garment_of_bone("upperarm02.L"), Garment::Sleeve);
        assert_eq!(garment_of_bone("lowerarm01.R"), Garment::Skin);
        assert_eq!(garment_of_bone("toe3-2.L"), Garment::Shoes);
        assert_eq!(garment_of_bone("spine03"), Garment::Shirt);
        assert_eq!(garment_of_bone("upperleg01.R"), Garment::Trousers);
        assert_eq!(garment_of_bone("oris01"), Garment::Hair);
    }
}
