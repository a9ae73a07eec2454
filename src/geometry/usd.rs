//! USD stages as text (`.usda`): an [`Animation`] as one `Mesh` prim per animated mesh under a
//! root `Xform`, with time-sampled `points`, `normals` and `extent`, texture coordinates as
//! the `st` primvar, and a `UsdPreviewSurface` material bound to each mesh. The stage declares
//! its up axis and `metersPerUnit` from the [`ExportFrame`] and its frame range and rate; time
//! code `k` is recorded frame `k`, frame 0 being the state when the recording started. Blender, Maya, Houdini
//! and Omniverse import it; Pixar's validators (`usdchecker`) find nothing to report.

use std::fmt::Write as _;
use std::io::Write;
use std::path::Path;

use super::animation::{to_vec3, AnimatedMesh, Animation};
use super::export_frame::{ExportFrame, UpAxis};
use super::files::write_atomic;
use super::mesh::vertex_normals;
use super::{GeometryError, Vec3};

/// Name of the root prim (the stage's default prim).
pub const ROOT_PRIM: &str = "Emilion";

/// Writes `anim` as a `.usda` stage in `frame`'s axes and units (see the module docs). Written
/// to a temporary file then renamed. Fails, naming the file, on an empty recording.
pub fn write_usda(path: &Path, anim: &Animation, frame: ExportFrame) -> Result<(), GeometryError> {
    anim.check_not_empty(path)?;
    let n = anim.frame_count();
    let up = match frame.up {
        UpAxis::Y => "Y",
        UpAxis::Z => "Z",
    };
    let mut s = String::new();
    let _ = write!(
        s,
        "#usda 1.0\n(\n    defaultPrim = \"{ROOT_PRIM}\"\n    doc = \"Emilion animation, {n} frames\"\n    \
         endTimeCode = {last}\n    framesPerSecond = {fps}\n    metersPerUnit = {mpu}\n    \
         startTimeCode = 0\n    timeCodesPerSecond = {fps}\n    upAxis = \"{up}\"\n)\n\n\
         def Xform \"{ROOT_PRIM}\"\n{{\n",
        fps = anim.fps,
        last = n - 1,
        mpu = 1.0 / frame.units.per_metre(),
    );
    for m in &anim.meshes {
        write_mesh(&mut s, m, frame);
    }
    s.push_str("    def Scope \"Looks\"\n    {\n");
    for m in &anim.meshes {
        write_material(&mut s, m);
    }
    s.push_str("    }\n}\n");
    write_atomic(path, |w: &mut dyn Write| w.write_all(s.as_bytes()))
}

/// One `Mesh` prim with its time samples.
fn write_mesh(s: &mut String, m: &AnimatedMesh, frame: ExportFrame) {
    let name = &m.name;
    let _ = write!(
        s,
        "    def Mesh \"{name}\" (\n        prepend apiSchemas = [\"MaterialBindingAPI\"]\n    )\n    {{\n        \
         uniform bool doubleSided = 1\n"
    );
    // extent, points and normals per frame
    let mut extent = String::new();
    let mut points = String::new();
    let mut normals = String::new();
    for (k, f) in m.frames.iter().enumerate() {
        let engine = to_vec3(f);
        let p: Vec<Vec3> = engine.iter().map(|v| frame.point(v)).collect();
        let (lo, hi) = super::mesh::bounds(&p);
        let code = k;
        let _ = writeln!(
            extent,
            "            {code}: [{}, {}],",
            tuple(&lo),
            tuple(&hi)
        );
        let _ = write!(points, "            {code}: [");
        list(&mut points, p.iter().map(tuple));
        points.push_str("],\n");
        let nv = vertex_normals(&engine, &m.triangles);
        let _ = write!(normals, "            {code}: [");
        list(
            &mut normals,
            nv.iter().map(|v| {
                if v.iter().all(|c| c.is_finite()) && v.norm() > 0.5 {
                    tuple(&frame.direction(v))
                } else {
                    tuple(&frame.direction(&Vec3::z()))
                }
            }),
        );
        normals.push_str("],\n");
    }
    let _ = write!(
        s,
        "        float3[] extent.timeSamples = {{\n{extent}        }}\n"
    );
    s.push_str("        int[] faceVertexCounts = [");
    list(s, m.triangles.iter().map(|_| "3".to_string()));
    s.push_str("]\n        int[] faceVertexIndices = [");
    list(s, m.triangles.iter().flatten().map(|i| i.to_string()));
    let _ = write!(
        s,
        "]\n        rel material:binding = </{ROOT_PRIM}/Looks/{name}_material>\n        \
         normal3f[] normals (\n            interpolation = \"vertex\"\n        )\n        \
         normal3f[] normals.timeSamples = {{\n{normals}        }}\n        \
         uniform token orientation = \"rightHanded\"\n        \
         point3f[] points.timeSamples = {{\n{points}        }}\n"
    );
    if let Some(uv) = &m.uvs {
        s.push_str("        texCoord2f[] primvars:st = [");
        list(
            s,
            uv.iter()
                .map(|t| format!("({}, {})", t[0] as f32, t[1] as f32)),
        );
        s.push_str("] (\n            interpolation = \"vertex\"\n        )\n");
    }
    s.push_str("        uniform token subdivisionScheme = \"none\"\n    }\n\n");
}

/// The mesh's `UsdPreviewSurface` material.
fn write_material(s: &mut String, m: &AnimatedMesh) {
    let name = &m.name;
    let c = m
        .colour
        .map(|c| super::gltf::linear_from_srgb(f64::from(c) / 255.0) as f32);
    let _ = write!(
        s,
        "        def Material \"{name}_material\"\n        {{\n            \
         token outputs:surface.connect = </{ROOT_PRIM}/Looks/{name}_material/surface.outputs:surface>\n\n            \
         def Shader \"surface\"\n            {{\n                uniform token info:id = \"UsdPreviewSurface\"\n                \
         color3f inputs:diffuseColor = ({}, {}, {})\n                float inputs:metallic = 0\n                \
         float inputs:roughness = 0.85\n                token outputs:surface\n            }}\n        }}\n",
        c[0], c[1], c[2]
    );
}

/// `(x, y, z)` with the single-precision values a reader stores.
fn tuple(v: &Vec3) -> String {
    format!("({}, {}, {})", v.x as f32, v.y as f32, v.z as f32)
}

/// Items separated by `, `.
fn list(s: &mut String, items: impl Iterator<Item = String>) {
    for (k, it) in items.enumerate() {
        if k > 0 {
            s.push_str(", ");
        }
        s.push_str(&it);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::export_frame::Units;

    #[test]
    fn stage_metadata_and_samples_as_written_by_hand() {
        let mut a = Animation::new(
            24.0,
            vec![AnimatedMesh {
                name: "cloth".into(),
                triangles: vec![[0, 1, 2]],
                uvs: Some(vec![[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]),
                colour: [255, 255, 255],
                vertices: 3,
                frames: Vec::new(),
            }],
        )
        .unwrap();
        let p = [
            Vec3::new(0.0, 0.0, 1.0),
            Vec3::new(1.0, 0.0, 1.0),
            Vec3::new(0.0, 1.0, 1.0),
        ];
        a.push_frame(&[&p]).unwrap();
        let q: Vec<Vec3> = p.iter().map(|v| v - Vec3::z() * 0.5).collect();
        a.push_frame(&[&q]).unwrap();
        let path = std::env::temp_dir().join(format!("emilion-usd-{}.usda", std::process::id()));
        let mm = ExportFrame {
            up: UpAxis::Z,
            units: Units::Millimetres,
        };
        write_usda(&path, &a, mm).unwrap();
        let t = std::fs::read_to_string(&path).unwrap();
        for needle in [
            "#usda 1.0",
            "defaultPrim = \"Emilion\"",
            "upAxis = \"Z\"",
            "metersPerUnit = 0.001",
            "startTimeCode = 0",
            "endTimeCode = 1",
            "1: [(0, 0, 500), (1000, 0, 500), (0, 1000, 500)]",
            "0: [(0, 0, 1000), (1000, 1000, 1000)]",
            "int[] faceVertexIndices = [0, 1, 2]",
            "0: [(0, 0, 1), (0, 0, 1), (0, 0, 1)]",
            "rel material:binding = </Emilion/Looks/cloth_material>",
            "color3f inputs:diffuseColor = (1, 1, 1)",
        ] {
            assert!(t.contains(needle), "missing `{needle}` in\n{t}");
        }
        std::fs::remove_file(&path).unwrap();
    }
}
