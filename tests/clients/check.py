"""Reads Emilion's outputs with the tools people use, for the tests in tests/real_clients.rs.

Runs under a Python 3.13 venv holding `bpy` (Blender as a module) and `usd-core` (Pixar's USD).
Each mode prints one JSON object on its last line of output:

  check.py probe
      {"bpy": version or null, "usd": version or null}
  check.py usd-validate FILE
      {"errors": [...], "warnings": [...]}: Pixar's validators (UsdValidation, what usdchecker runs)
  check.py blender-import FILE [--pc2 CACHE] [--frames F1,F2,...]
      imports FILE (.obj, .glb, .usda) into an empty scene; for every mesh object: its name,
      vertex count and world-space bounds at the first frame, and with --frames its world-space
      vertices at those frames; the scene's frame range. With --pc2, adds Blender's Mesh Cache
      modifier reading CACHE (a PC2 file written in the OBJ's axes and units) to the imported object.
"""

import json
import sys


def probe():
    out = {"bpy": None, "usd": None}
    try:
        import bpy

        out["bpy"] = bpy.app.version_string
    except Exception:
        pass
    try:
        from pxr import Usd

        out["usd"] = ".".join(str(v) for v in Usd.GetVersion())
    except Exception:
        pass
    return out


def usd_validate(path):
    from pxr import Usd, UsdValidation

    stage = Usd.Stage.Open(path)
    validators = UsdValidation.ValidationRegistry().GetOrLoadAllValidators()
    found = UsdValidation.ValidationContext(validators).Validate(stage)
    errors, warnings = [], []
    for e in found:
        text = f"{e.GetName()}: {e.GetMessage()}"
        if e.GetType() == UsdValidation.ValidationErrorType.Error:
            errors.append(text)
        else:
            warnings.append(text)
    return {"errors": errors, "warnings": warnings}


def blender_import(path, frames, pc2):
    import bpy

    bpy.ops.wm.read_factory_settings(use_empty=True)
    lower = path.lower()
    if lower.endswith(".obj"):
        bpy.ops.wm.obj_import(filepath=path)
    elif lower.endswith(".glb") or lower.endswith(".gltf"):
        bpy.ops.import_scene.gltf(filepath=path)
    elif lower.endswith(".usda") or lower.endswith(".usd") or lower.endswith(".usdc"):
        bpy.ops.wm.usd_import(filepath=path)
    else:
        raise SystemExit(f"unknown file type: {path}")
    scene = bpy.context.scene
    meshes = [o for o in scene.objects if o.type == "MESH"]
    if pc2:
        for o in meshes:
            m = o.modifiers.new("cache", "MESH_CACHE")
            m.cache_format = "PC2"
            m.filepath = pc2
            m.frame_start = 0.0
            # the cache holds the OBJ's own coordinates (the importer turns +Y up into +Z up
            # with the object's rotation, not in the data): the modifier's axes stay as they are
    out = {
        "frame_start": scene.frame_start,
        "frame_end": scene.frame_end,
        "fps": scene.render.fps / scene.render.fps_base,
        "objects": [],
    }

    def world_vertices(o):
        deps = bpy.context.evaluated_depsgraph_get()
        ev = o.evaluated_get(deps)
        mesh = ev.to_mesh()
        mw = ev.matrix_world
        pts = [list(mw @ v.co) for v in mesh.vertices]
        ev.to_mesh_clear()
        return pts

    first = frames[0] if frames else scene.frame_start
    scene.frame_set(first)
    for o in meshes:
        pts = world_vertices(o)
        lo = [min(p[k] for p in pts) for k in range(3)]
        hi = [max(p[k] for p in pts) for k in range(3)]
        out["objects"].append(
            {"name": o.name, "vertices": len(pts), "min": lo, "max": hi, "frames": {}}
        )
    for f in frames:
        scene.frame_set(f)
        for o, rec in zip(meshes, out["objects"]):
            rec["frames"][str(f)] = world_vertices(o)
    return out


def main(argv):
    mode = argv[1]
    if mode == "probe":
        result = probe()
    elif mode == "usd-validate":
        result = usd_validate(argv[2])
    elif mode == "blender-import":
        path = argv[2]
        frames, pc2 = [], None
        rest = argv[3:]
        while rest:
            key, value = rest[0], rest[1]
            rest = rest[2:]
            if key == "--frames":
                frames = [int(f) for f in value.split(",") if f]
            elif key == "--pc2":
                pc2 = value
            else:
                raise SystemExit(f"unknown option {key}")
        result = blender_import(path, frames, pc2)
    else:
        raise SystemExit(f"unknown mode {mode}")
    print(json.dumps(result))


if __name__ == "__main__":
    main(sys.argv)
