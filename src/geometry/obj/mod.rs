//! Wavefront OBJ files, the one reader and writer of the crate: [`write_obj_mesh`] writes any
//! mesh (texture coordinates, normals, groups, materials as options; [`write_obj`] is a
//! cloth's shape), and the reader parses the OBJ subset a mesh needs in double precision,
//! keeping the file's vertex order and naming lines in its errors ([`read_obj`] for a cloth
//! mesh with rest coordinates, [`read_obj_surface`] for a collision surface,
//! [`obj_polygons_from_text`] for polygons by group).

mod read;
mod write;

pub use read::{
    obj_mesh_from_text, obj_polygons_from_text, obj_surface_from_text, read_obj, read_obj_surface,
    ObjFace, ObjPolygons,
};
pub use write::{write_obj, write_obj_mesh, ObjGroup, ObjMesh};
