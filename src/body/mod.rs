//! Animated human bodies: the MakeHuman mannequin, skinned by linear blending and driven by
//! motion-capture clips, as the moving collider that garments are draped on.
//!
//! * [`Mannequin`] loads the MakeHuman base mesh (`base.obj`), its default skeleton
//!   (`default.mhskel`) and skinning weights (`default_weights.mhw`). Only the `body` group is
//!   kept as skin (helper and joint-marker groups are dropped, but their vertices still define
//!   the joints), compacted and split into outward-wound triangles. Positions are converted
//!   from MakeHuman's decimetres with y up (body facing +z) to the engine's world, metres
//!   with z up, `(x, y, z) ↦ (x, −z, y)·0.1` — the body then faces −y, its left side is +x —
//!   and shifted up so the lowest skin vertex stands on the floor z = 0.
//! * [`Pose`] holds one rigid transform per bone (identity = rest); [`Mannequin::skin`] blends
//!   them over the skin ([`skinning`]).
//! * [`Motion`] parses a BVH clip ([`bvh`]: CMU clips re-exported on the iClone `CC_Base` rig,
//!   centimetres, y up) and runs forward kinematics.
//! * [`Animation`] retargets a clip onto the mannequin ([`retarget`]): the rest poses of the
//!   two skeletons differ (MakeHuman stands in an A-pose, the BVH rig's zero pose is not a
//!   human stance at all), so joint rotations are not copied. Pelvis, chest and head take
//!   their orientation from the clip's hip, collar and eye lines, the spine and neck bend
//!   between them, and each limb segment is swung to point along the matching BVH bone;
//!   fingers, toes and face follow rigidly. Root travel is scaled to the mannequin's hip
//!   height, or removed ([`RetargetOptions::in_place`], the default) for draping on a
//!   treadmill. [`Animation::vertices_at`] gives the skin at any time, interpolated between
//!   frames.
//!
//! Typical figures (release build): loading the mannequin takes ~30 ms, retargeting ~5 ms
//! per 100 clip frames, [`Animation::vertices_at`] well under a millisecond for the 13,380
//! skin vertices.
//!
//! Errors are [`BodyError`]s naming the file and, for syntax errors, the line; malformed
//! input never panics.

pub mod bvh;
pub mod error;
pub mod grading;
pub mod markers;
pub mod retarget;
pub mod skeleton;
pub mod skinning;

use std::path::Path;

pub use bvh::{bvh_to_world, Motion};
pub use error::BodyError;
pub use markers::{read_c3d, MarkerTrial};
pub use retarget::{Animation, RetargetOptions};
pub use skeleton::{Bone, Joint, Skeleton};
pub use skinning::{Pose, SkinWeights};

use crate::geometry::obj::obj_polygons_from_text;
use crate::geometry::{GeometryError, Vec3};
use error::read_text;

/// Name of the OBJ group that is the visible skin of the MakeHuman base mesh.
pub const BODY_GROUP: &str = "body";

/// Converts a MakeHuman point (decimetres, y up, facing +z) to the engine's world (metres,
/// z up, facing −y): `(x, y, z) ↦ (x, −z, y)·0.1`.
pub fn makehuman_to_world(p: Vec3) -> Vec3 {
    Vec3::new(p.x, -p.z, p.y) * 0.1
}

/// The MakeHuman mannequin at rest: skin mesh, skeleton and skinning weights.
#[derive(Clone, Debug)]
pub struct Mannequin {
    /// Rest skin vertices (compacted to those the skin faces use).
    rest: Vec<Vec3>,
    /// Skin triangles, outward winding.
    triangles: Vec<[usize; 3]>,
    /// Index in the full base mesh of each skin vertex.
    base_index: Vec<usize>,
    /// Skin weights of the skin vertices.
    weights: SkinWeights,
    /// All base-mesh vertices (helpers included), world coordinates.
    base_rest: Vec<Vec3>,
    /// Skin weights of all base-mesh vertices (for the joint markers).
    base_weights: SkinWeights,
    skeleton: Skeleton,
}

/// Vertices and the faces of one group, read from an OBJ file.
struct ObjBody {
    positions: Vec<Vec3>,
    faces: Vec<Vec<usize>>,
}

/// Reads the positions (all groups, converted to the world) and the faces of group `group`
/// (0-based position indices) of a MakeHuman OBJ file, through the geometry's OBJ reader.
fn parse_obj(text: &str, file: &str, group: &str) -> Result<ObjBody, BodyError> {
    let obj = obj_polygons_from_text(text, Path::new(file)).map_err(|e| match e {
        GeometryError::Parse { line, message, .. } => BodyError::parse(file, line, message),
        other => BodyError::invalid(file, other.to_string()),
    })?;
    let faces: Vec<Vec<usize>> = obj
        .faces
        .iter()
        .filter(|f| obj.in_group(f, group))
        .map(|f| f.corners.iter().map(|c| c[0]).collect())
        .collect();
    if faces.is_empty() {
        return Err(BodyError::invalid(
            file,
            format!("no face in group '{group}'"),
        ));
    }
    let positions = obj.positions.into_iter().map(makehuman_to_world).collect();
    Ok(ObjBody { positions, faces })
}

/// Signed volume enclosed by a triangle mesh (positive for outward winding of a closed mesh).
pub fn signed_volume(positions: &[Vec3], triangles: &[[usize; 3]]) -> f64 {
    triangles
        .iter()
        .map(|t| positions[t[0]].dot(&positions[t[1]].cross(&positions[t[2]])))
        .sum::<f64>()
        / 6.0
}

impl Mannequin {
    /// Loads `base.obj`, `default.mhskel` and `default_weights.mhw` from a MakeHuman data
    /// folder (see the module docs for units and placement).
    pub fn load_makehuman(dir: &Path) -> Result<Mannequin, BodyError> {
        let obj_path = dir.join("base.obj");
        let skel_path = dir.join("default.mhskel");
        let weights_path = dir.join("default_weights.mhw");
        let obj_name = obj_path.display().to_string();
        let skel_name = skel_path.display().to_string();
        let weights_name = weights_path.display().to_string();

        let obj = parse_obj(&read_text(&obj_path)?, &obj_name, BODY_GROUP)?;
        let mut base_rest = obj.positions;
        let skel_text = read_text(&skel_path)?;
        let mut skeleton = Skeleton::parse_mhskel(&skel_text, &skel_name, &base_rest)?;
        let weights_text = read_text(&weights_path)?;
        let base_weights =
            SkinWeights::parse_mhw(&weights_text, &weights_name, &skeleton, base_rest.len())?;

        // compact the skin vertices, keeping the base mesh order
        let mut compact = vec![usize::MAX; base_rest.len()];
        for f in &obj.faces {
            for &v in f {
                compact[v] = 0;
            }
        }
        let mut base_index = Vec::new();
        for (v, c) in compact.iter_mut().enumerate() {
            if *c == 0 {
                *c = base_index.len();
                base_index.push(v);
            }
        }
        // feet on the floor
        let floor = base_index
            .iter()
            .map(|&v| base_rest[v].z)
            .fold(f64::INFINITY, f64::min);
        let lift = Vec3::new(0.0, 0.0, -floor);
        for p in &mut base_rest {
            *p += lift;
        }
        skeleton.translate(lift);
        let rest: Vec<Vec3> = base_index.iter().map(|&v| base_rest[v]).collect();

        // triangles: quads split along their shorter diagonal, larger polygons as fans
        let mut triangles = Vec::with_capacity(obj.faces.len() * 2);
        for f in &obj.faces {
            let f: Vec<usize> = f.iter().map(|&v| compact[v]).collect();
            if f.len() == 4 {
                let d02 = (rest[f[0]] - rest[f[2]]).norm_squared();
                let d13 = (rest[f[1]] - rest[f[3]]).norm_squared();
                if d02 <= d13 {
                    triangles.push([f[0], f[1], f[2]]);
                    triangles.push([f[0], f[2], f[3]]);
                } else {
                    triangles.push([f[0], f[1], f[3]]);
                    triangles.push([f[1], f[2], f[3]]);
                }
            } else {
                for k in 1..f.len() - 1 {
                    triangles.push([f[0], f[k], f[k + 1]]);
                }
            }
        }
        if signed_volume(&rest, &triangles) < 0.0 {
            for t in &mut triangles {
                t.swap(1, 2);
            }
        }
        let weights = base_weights.subset(&base_index);
        Ok(Mannequin {
            rest,
            triangles,
            base_index,
            weights,
            base_rest,
            base_weights,
            skeleton,
        })
    }

    /// Rest positions of the skin vertices (metres, z up, lowest vertex at z = 0).
    pub fn rest_positions(&self) -> &[Vec3] {
        &self.rest
    }

    /// Skin triangles (indices into [`Mannequin::rest_positions`]), wound outward.
    pub fn triangles(&self) -> &[[usize; 3]] {
        &self.triangles
    }

    /// Index in the full base mesh (`base.obj`, 0-based) of each skin vertex.
    pub fn base_indices(&self) -> &[usize] {
        &self.base_index
    }

    /// The skeleton (bones parents first, rest heads and tails, joints).
    pub fn skeleton(&self) -> &Skeleton {
        &self.skeleton
    }

    /// Bone names, in skeleton order (the order of [`Pose`] transforms).
    pub fn bone_names(&self) -> impl Iterator<Item = &str> {
        self.skeleton.bones().iter().map(|b| b.name.as_str())
    }

    /// Skinning weights of the skin vertices (normalised).
    pub fn weights(&self) -> &SkinWeights {
        &self.weights
    }

    /// The rest pose (all transforms the identity).
    pub fn rest_pose(&self) -> Pose {
        Pose::identity(self.skeleton.len())
    }

    /// Linear blend skinning: the skin vertices carried by the bone transforms of `pose`, into
    /// `out` (resized and reused). `pose` must have one transform per bone.
    pub fn skin(&self, pose: &Pose, out: &mut Vec<Vec3>) {
        assert_eq!(pose.len(), self.skeleton.len(), "one transform per bone");
        self.weights.skin(&self.rest, pose, out);
    }

    /// Position of joint `name` under `pose`: the mean of its marker vertices, each skinned
    /// with its own weights (so it shows what the skin does there, not just one bone).
    pub fn skinned_joint(&self, pose: &Pose, name: &str) -> Option<Vec3> {
        let j = self.skeleton.joint(name)?;
        let sum: Vec3 = j
            .vertices
            .iter()
            .map(|&v| self.base_weights.skin_vertex(v, self.base_rest[v], pose))
            .sum();
        Some(sum / j.vertices.len() as f64)
    }

    /// Head and tail of bone `bone` under `pose`, as skinned joint positions
    /// ([`Mannequin::skinned_joint`]).
    pub fn skinned_bone_ends(&self, pose: &Pose, bone: usize) -> (Vec3, Vec3) {
        let b = &self.skeleton.bones()[bone];
        let h = self.skinned_joint(pose, &b.head_joint).unwrap_or(b.head);
        let t = self.skinned_joint(pose, &b.tail_joint).unwrap_or(b.tail);
        (h, t)
    }
}
