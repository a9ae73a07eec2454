//! Export of the 52 ARKit blendshapes, the de-facto interchange set of face rigs (Blender,
//! Unity, Unreal, three.js): each shape defined on the face mesh as a combination of FAPs and
//! muscles ([`crate::face::expressions::Slider`]), written as a binary glTF (`.glb`) whose
//! mesh has one morph target per shape, named through `mesh.extras.targetNames` (the
//! convention Blender and three.js read), plus a CSV summary.
//!
//! Names and order are Apple's (`ARFaceAnchor.BlendShapeLocation`, grouped as documented:
//! left eye, right eye, mouth and jaw, eyebrows, cheeks, nose, tongue). `Left` is the
//! subject's left (+x on the MediaPipe mesh). Shapes the mesh cannot represent are zero
//! displacement fields: the eye-gaze shapes `eyeLook{Down,In,Out,Up}{Left,Right}` (the
//! canonical mesh has no eyeballs) and `tongueOut` (no tongue).

use std::io::Write;
use std::path::Path;

use super::expressions::{combination, Slider};
use super::fap::FapRig;
use super::model::FaceMesh;
use super::muscles::MuscleRig;
use super::FaceError;
use crate::geometry::files::write_atomic;
use crate::geometry::gltf::{write_glb_mesh, GlbMesh, GlbMorphTarget, GlbPrimitive};
use crate::geometry::Vec3;

/// The 52 ARKit blendshape names, in Apple's documented order.
pub const ARKIT_NAMES: [&str; 52] = [
    "eyeBlinkLeft",
    "eyeLookDownLeft",
    "eyeLookInLeft",
    "eyeLookOutLeft",
    "eyeLookUpLeft",
    "eyeSquintLeft",
    "eyeWideLeft",
    "eyeBlinkRight",
    "eyeLookDownRight",
    "eyeLookInRight",
    "eyeLookOutRight",
    "eyeLookUpRight",
    "eyeSquintRight",
    "eyeWideRight",
    "jawForward",
    "jawLeft",
    "jawRight",
    "jawOpen",
    "mouthClose",
    "mouthFunnel",
    "mouthPucker",
    "mouthLeft",
    "mouthRight",
    "mouthSmileLeft",
    "mouthSmileRight",
    "mouthFrownLeft",
    "mouthFrownRight",
    "mouthDimpleLeft",
    "mouthDimpleRight",
    "mouthStretchLeft",
    "mouthStretchRight",
    "mouthRollLower",
    "mouthRollUpper",
    "mouthShrugLower",
    "mouthShrugUpper",
    "mouthPressLeft",
    "mouthPressRight",
    "mouthLowerDownLeft",
    "mouthLowerDownRight",
    "mouthUpperUpLeft",
    "mouthUpperUpRight",
    "browDownLeft",
    "browDownRight",
    "browInnerUp",
    "browOuterUpLeft",
    "browOuterUpRight",
    "cheekPuff",
    "cheekSquintLeft",
    "cheekSquintRight",
    "noseSneerLeft",
    "noseSneerRight",
    "tongueOut",
];

/// Definition of one ARKit shape at weight 1: FAPs as fractions of their range, muscles as
/// activations. Empty for the shapes the mesh cannot represent (see the module docs).
pub fn arkit_definition(name: &str) -> Option<Slider> {
    let f: &[(u8, f64)] = match name {
        "eyeBlinkLeft" => &[(19, 1.0)],
        "eyeBlinkRight" => &[(20, 1.0)],
        "eyeSquintLeft" => &[(21, 0.4), (19, 0.15), (41, 0.3)],
        "eyeSquintRight" => &[(22, 0.4), (20, 0.15), (42, 0.3)],
        "eyeWideLeft" => &[(19, -1.0)],
        "eyeWideRight" => &[(20, -1.0)],
        "jawForward" => &[(14, 1.0)],
        "jawLeft" => &[(15, -1.0)],
        "jawRight" => &[(15, 1.0)],
        "jawOpen" => &[(3, 1.0)],
        "mouthClose" => &[(4, 1.0), (5, 1.0)],
        "mouthFunnel" => &[(16, 0.6), (17, 0.6), (4, -0.4), (5, -0.4)],
        "mouthPucker" => &[(16, 1.0), (17, 1.0), (6, -0.5), (7, -0.5)],
        "mouthLeft" => &[(6, 0.6), (7, -0.6)],
        "mouthRight" => &[(6, -0.6), (7, 0.6)],
        "mouthSmileLeft" => &[(12, 0.4), (6, 0.2)],
        "mouthSmileRight" => &[(13, 0.4), (7, 0.2)],
        "mouthFrownLeft" => &[(12, -0.3)],
        "mouthFrownRight" => &[(13, -0.3)],
        "mouthDimpleLeft" => &[(6, 0.5)],
        "mouthDimpleRight" => &[(7, 0.5)],
        "mouthStretchLeft" => &[(6, 0.8), (12, -0.3)],
        "mouthStretchRight" => &[(7, 0.8), (13, -0.3)],
        "mouthRollLower" => &[(5, 0.5), (16, -0.6)],
        "mouthRollUpper" => &[(4, 0.5), (17, -0.6)],
        "mouthShrugLower" => &[(5, 0.7), (16, 0.4)],
        "mouthShrugUpper" => &[(4, -0.5), (17, 0.3)],
        "mouthPressLeft" => &[(8, 0.4), (10, 0.4)],
        "mouthPressRight" => &[(9, 0.4), (11, 0.4)],
        "mouthLowerDownLeft" => &[(10, -1.0)],
        "mouthLowerDownRight" => &[(11, -1.0)],
        "mouthUpperUpLeft" => &[(8, -1.0)],
        "mouthUpperUpRight" => &[(9, -1.0)],
        "browDownLeft" => &[(31, -0.8), (33, -0.8), (35, -0.8), (37, 0.5)],
        "browDownRight" => &[(32, -0.8), (34, -0.8), (36, -0.8), (38, 0.5)],
        "browInnerUp" => &[(31, 1.0), (32, 1.0)],
        "browOuterUpLeft" => &[(35, 1.0)],
        "browOuterUpRight" => &[(36, 1.0)],
        "cheekPuff" => &[(39, 1.0), (40, 1.0)],
        "cheekSquintLeft" => &[(41, 1.0)],
        "cheekSquintRight" => &[(42, 1.0)],
        "noseSneerLeft" => &[(61, 0.6), (63, 0.3), (8, -0.3)],
        "noseSneerRight" => &[(62, 0.6), (63, 0.3), (9, -0.3)],
        n if ARKIT_NAMES.contains(&n) => &[],
        _ => return None,
    };
    let m: &[(&str, f64)] = match name {
        "mouthSmileLeft" => &[("zygomatic_major_l", 1.0)],
        "mouthSmileRight" => &[("zygomatic_major_r", 1.0)],
        "mouthFrownLeft" => &[("depressor_anguli_oris_l", 1.0)],
        "mouthFrownRight" => &[("depressor_anguli_oris_r", 1.0)],
        "mouthFunnel" => &[("orbicularis_upper", 0.5), ("orbicularis_lower", 0.5)],
        "mouthPucker" => &[("orbicularis_upper", 1.0), ("orbicularis_lower", 1.0)],
        "browDownLeft" => &[("corrugator_l", 0.5)],
        "browDownRight" => &[("corrugator_r", 0.5)],
        "noseSneerLeft" => &[("levator_labii_l", 0.7)],
        "noseSneerRight" => &[("levator_labii_r", 0.7)],
        _ => &[],
    };
    Some(Slider::new(name, (0.0, 1.0), f, m))
}

/// The 52 shapes as dense displacement fields (m) on a mesh of `n` vertices, in
/// [`ARKIT_NAMES`] order.
pub fn arkit_displacements(
    faps: &FapRig,
    muscles: &MuscleRig,
    n: usize,
) -> Result<Vec<(String, Vec<Vec3>)>, FaceError> {
    ARKIT_NAMES
        .iter()
        .map(|&name| {
            let s = arkit_definition(name)
                .ok_or_else(|| FaceError::Failed(format!("no definition for `{name}`")))?;
            Ok((
                name.to_string(),
                combination(faps, muscles, n, &s.faps, &s.muscles)?,
            ))
        })
        .collect()
}

/// Writes `mesh` (its positions as the neutral face) as binary glTF with the 52 ARKit morph
/// targets of the rigs, and next to it `<stem>.csv`: `name,max_displacement_m,vertex` per
/// shape. The glTF mesh has `POSITION`, `NORMAL`, `TEXCOORD_0` (v flipped to glTF's top-left
/// origin), `u32` indices, 52 `POSITION` morph targets, zero default weights and
/// `extras.targetNames`. Files are written to a temporary name and renamed. Errors name the
/// file.
pub fn write_arkit_glb(
    path: &Path,
    mesh: &FaceMesh,
    faps: &FapRig,
    muscles: &MuscleRig,
) -> Result<(), FaceError> {
    let n = mesh.positions.len();
    let fail = |m: String| FaceError::Failed(format!("{}: {m}", path.display()));
    mesh.validate(&path.display().to_string())?;
    if n == 0 || mesh.triangles.is_empty() {
        return Err(fail("nothing to write: empty mesh".into()));
    }
    let shapes = arkit_displacements(faps, muscles, n)?;
    let f32s = |v: &[Vec3]| -> Vec<[f32; 3]> {
        v.iter()
            .map(|p| [p.x as f32, p.y as f32, p.z as f32])
            .collect()
    };
    let pos = f32s(&mesh.positions);
    let normals: Vec<[f32; 3]> = mesh
        .vertex_normals()
        .iter()
        .map(|v| {
            if v.norm() > 0.5 {
                [v.x as f32, v.y as f32, v.z as f32]
            } else {
                [0.0, 0.0, 1.0]
            }
        })
        .collect();
    let displacements: Vec<Vec<[f32; 3]>> = shapes.iter().map(|(_, d)| f32s(d)).collect();
    let targets: Vec<GlbMorphTarget> = shapes
        .iter()
        .zip(&displacements)
        .map(|((name, _), d)| GlbMorphTarget {
            name,
            displacements: d,
        })
        .collect();
    let uvs: Vec<[f32; 2]> = mesh
        .uvs
        .iter()
        .map(|uv| [uv[0] as f32, (1.0 - uv[1]) as f32])
        .collect();
    let indices: Vec<u32> = mesh.triangles.iter().flatten().copied().collect();
    let primitives = [GlbPrimitive {
        indices: 0..indices.len(),
        material: None,
    }];
    let glb = GlbMesh {
        positions: &pos,
        normals: &normals,
        uvs: Some(&uvs),
        morph_targets: &targets,
        indices: &indices,
        primitives: &primitives,
        texture: None,
        animation: None,
    };
    write_glb_mesh(path, &glb).map_err(|e| FaceError::Failed(e.to_string()))?;
    let mut csv = String::from("name,max_displacement_m,vertex\n");
    for (name, d) in &shapes {
        let (i, m) = d
            .iter()
            .enumerate()
            .map(|(i, v)| (i, v.norm()))
            .fold((0, 0.0), |a, b| if b.1 > a.1 { b } else { a });
        csv.push_str(&format!("{name},{m:.6e},{i}\n"));
    }
    let csv_path = path.with_extension("csv");
    write_atomic(&csv_path, |w: &mut dyn Write| w.write_all(csv.as_bytes()))
        .map_err(|e| FaceError::io(&csv_path, e))
}
