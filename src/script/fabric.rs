//! Script bindings for fabrics and cloth models: the `Fabric` value type (a
//! [`FabricParameters`] with one property per field, checked on every assignment) and the
//! `Cloth` handle (a shared, immutable [`ClothModel`]) built from a grid or an OBJ file.

use std::fmt;

use rhai::{Dynamic, Map, Shared, INT};

use super::convert::{
    count, get_field, num, rt_err, to_map, update_field, update_from_map, RResult,
};
use super::paths::read_path;
use super::{function, getter, modules::ApiBuilder, register};
use crate::cloth::{ClothModel, FabricParameters};
use crate::geometry::read_obj;

/// A fabric as a script value: small, copied freely.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Fabric(pub FabricParameters);

impl fmt::Display for Fabric {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let p = &self.0;
        write!(
            f,
            "Fabric(density {} kg/m², stretch {}/{} N/m, shear {} N/m, bend {:e}/{:e} N·m, damping {}/{} s, drag {})",
            p.density, p.stretch_warp, p.stretch_weft, p.shear, p.bend_warp, p.bend_weft,
            p.stretch_damping, p.bend_damping, p.air_drag
        )
    }
}

/// A cloth model as a script handle: the model is shared, never copied per call.
#[derive(Debug, Clone)]
pub struct ClothHandle(pub Shared<ClothModel>);

impl fmt::Display for ClothHandle {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let m = &self.0;
        match m.grid {
            Some((nx, ny)) => write!(f, "Cloth(grid {nx}×{ny}, {} particles", m.particle_count())?,
            None => write!(f, "Cloth(mesh, {} particles", m.particle_count())?,
        }
        write!(
            f,
            ", {} triangles, {} springs)",
            m.mesh.triangles.len(),
            m.springs.len()
        )
    }
}

/// Fabric fields settable from scripts, with their documentation.
pub const FABRIC_FIELDS: [(&str, &str); 9] = [
    ("density", "Areal density (kg/m², > 0)."),
    ("stretch_warp", "Tensile rigidity along the warp (N/m)."),
    ("stretch_weft", "Tensile rigidity along the weft (N/m)."),
    ("shear", "Shear rigidity (N/m per radian)."),
    (
        "bend_warp",
        "Bending rigidity for curvature along the warp (N·m).",
    ),
    (
        "bend_weft",
        "Bending rigidity for curvature along the weft (N·m).",
    ),
    (
        "stretch_damping",
        "Stiffness-proportional damping of stretch and shear (s).",
    ),
    (
        "bend_damping",
        "Stiffness-proportional damping of bending (s).",
    ),
    ("air_drag", "Linear air drag per unit area (N·s/m³)."),
];

/// Checks fabric parameters, naming the first bad one.
fn checked(p: FabricParameters) -> RResult<Fabric> {
    p.validate().map_err(super::convert::rt_err)?;
    Ok(Fabric(p))
}

/// Registers `cloth::fabric`, its properties, `cloth::grid`, `cloth::cone`, `cloth::patch`,
/// `cloth::from_obj` and the `Cloth` methods and properties.
pub fn register(engine: &mut ApiBuilder) {
    engine.register_type_with_name::<Fabric>("Fabric");
    engine.register_type_with_name::<ClothHandle>("Cloth");

    function!(engine, "cloth::fabric", alias = "fabric", ["Fabric"],
        "The default fabric: a cotton-like woven (0.15 kg/m², 1000 N/m stretch, soft shear and bending).\nChange fields with `f.density = 0.2`.",
        Fabric::default);
    function!(engine, "cloth::fabric", alias = "fabric", ["params: Map", "Fabric"],
        "A fabric from a map of fields, e.g. `cloth::fabric(#{density: 0.2, stretch_warp: 800.0})`;\nunset fields keep their defaults. Unknown keys, negative or non-finite values are errors\nthat name the parameter.",
        |m: Map| -> RResult<Fabric> { checked(update_from_map(&FabricParameters::default(), &m, "fabric")?) });
    register!(
        engine,
        "to_map",
        ["fabric: Fabric", "Map"],
        "The fabric's fields as a map (SI units).",
        |f: &mut Fabric| -> Dynamic { to_map(&f.0) }
    );
    register!(
        engine,
        "to_string",
        ["fabric: Fabric", "String"],
        "One-line summary of a fabric.",
        |f: &mut Fabric| f.to_string()
    );
    register!(
        engine,
        "to_debug",
        ["fabric: Fabric", "String"],
        "One-line summary of a fabric.",
        |f: &mut Fabric| f.to_string()
    );
    for (name, doc) in FABRIC_FIELDS {
        getter!(
            engine,
            name,
            ["fabric: Fabric", "float"],
            doc,
            move |f: &mut Fabric| -> RResult<Dynamic> { get_field(&f.0, name, "fabric") }
        );
        rhai::FuncRegistration::new_setter(name)
            .with_params_info(["fabric: Fabric", "value: float"])
            .with_comments([super::convert::doc_comment(&format!(
                "{doc}\nChecked on assignment: must be finite and ≥ 0."
            ))])
            .register_into_engine(engine, move |f: &mut Fabric, v: Dynamic| -> RResult<()> {
                *f = checked(update_field(&f.0, name, &v, "fabric")?)?;
                Ok(())
            });
    }

    function!(engine, "cloth::grid", alias = "cloth_grid", ["width: float", "height: float", "nx: int", "ny: int", "fabric: Fabric", "Cloth"],
        "A `width` × `height` m rectangle of `nx` × `ny` particles, flat in the XY plane at z = 0,\ncentred at the origin. Particle (row i along y, column j along x) has index `i * nx + j`;\nthe y = +height/2 edge is \"top\".",
        |w: Dynamic, h: Dynamic, nx: INT, ny: INT, f: Fabric| -> RResult<ClothHandle> {
            let (w, h) = (num(&w, "width")?, num(&h, "height")?);
            let (nx, ny) = (count(&Dynamic::from_int(nx), "nx")?, count(&Dynamic::from_int(ny), "ny")?);
            Ok(ClothHandle(Shared::new(ClothModel::grid(w, h, nx, ny, f.0)?)))
        });
    function!(engine, "cloth::cone", alias = "cloth_cone", ["r_top: float", "r_bottom: float", "height: float", "n_around: int", "n_down: int", "fabric: Fabric", "base: Array", "slit: float", "Cloth"],
        "A truncated cone of cloth around the vertical axis through `base` (centre of its lower rim):\nradius `r_bottom` at the bottom, `r_top` at `height` above, cut from its exact flat pattern\n(an annular sector; equal radii give a cylinder). `n_around` × `n_down` particles; row i from\nthe bottom rim up, so the last `n_around` particles are the top rim. A slit of `slit` (a\nfraction of the circumference) is left open at the back (+y). An A-line skirt or a tube.",
        |rt: Dynamic, rb: Dynamic, h: Dynamic, na: INT, nd: INT, f: Fabric, base: Dynamic, slit: Dynamic| -> RResult<ClothHandle> {
            let (na, nd) = (count(&Dynamic::from_int(na), "n_around")?, count(&Dynamic::from_int(nd), "n_down")?);
            let base = crate::geometry::Vec3::from(super::convert::vec3(&base, "base")?);
            let mesh = crate::geometry::cone::cone_mesh(
                num(&rt, "r_top")?, num(&rb, "r_bottom")?, num(&h, "height")?, na, nd, base, num(&slit, "slit")?,
            )?;
            Ok(ClothHandle(Shared::new(ClothModel::from_mesh(mesh, f.0)?)))
        });
    function!(
        engine,
        "cloth::patch",
        alias = "cloth_patch",
        ["width: float", "height: float", "edge: float", "fabric: Fabric", "Cloth"],
        "A `width` × `height` m rectangle meshed with irregular triangles about `edge` m long (the\npattern mesher's constrained Delaunay), flat in the XY plane at z = 0, centred at the\norigin, the warp along x: a triangle-mesh cloth (hinges, no grid lines).",
        |w: Dynamic, h: Dynamic, e: Dynamic, f: Fabric| -> RResult<ClothHandle> {
            let mesh = crate::garment::mesh::patch::rectangle_mesh(
                num(&w, "width")?,
                num(&h, "height")?,
                num(&e, "edge")?,
            )
            .map_err(|e| rt_err(e.to_string()))?;
            Ok(ClothHandle(Shared::new(ClothModel::from_mesh(mesh, f.0)?)))
        }
    );
    function!(
        engine,
        "cloth::from_obj",
        alias = "cloth_obj",
        ["path: String", "fabric: Fabric", "Cloth"],
        "A cloth from an OBJ mesh whose texture coordinates are the flat pattern (m).",
        |path: &str, f: Fabric| -> RResult<ClothHandle> {
            let mesh = read_obj(&read_path(path)?)?;
            Ok(ClothHandle(Shared::new(ClothModel::from_mesh(mesh, f.0)?)))
        }
    );
    register!(
        engine,
        "translated",
        ["cloth: Cloth", "offset: Array", "Cloth"],
        "A copy of the cloth moved by `offset` [dx, dy, dz] m (its pattern is unchanged).",
        |c: &mut ClothHandle, d: Dynamic| -> RResult<ClothHandle> {
            let d = crate::geometry::Vec3::from(super::convert::vec3(&d, "offset")?);
            let mut m = (*c.0).clone();
            m.mesh.positions.iter_mut().for_each(|p| *p += d);
            Ok(ClothHandle(Shared::new(m)))
        }
    );
    register!(
        engine,
        "rotated",
        ["cloth: Cloth", "axis: Array", "degrees: float", "Cloth"],
        "A copy of the cloth turned by `degrees` about `axis` [x, y, z] through the origin
(right-hand rule; its pattern is unchanged).",
        |c: &mut ClothHandle, axis: Dynamic, deg: Dynamic| -> RResult<ClothHandle> {
            let axis = crate::geometry::Vec3::from(super::convert::vec3(&axis, "axis")?);
            let deg = num(&deg, "degrees")?;
            let Some(unit) = nalgebra::Unit::try_new(axis, 1e-12) else {
                return Err(rt_err("`axis` must not be zero"));
            };
            let r = nalgebra::Rotation3::from_axis_angle(&unit, deg.to_radians());
            let mut m = (*c.0).clone();
            m.mesh.positions.iter_mut().for_each(|p| *p = r * *p);
            Ok(ClothHandle(Shared::new(m)))
        }
    );
    register!(
        engine,
        "with_choi_ko",
        ["cloth: Cloth", "Cloth"],
        "A copy of the cloth with Choi & Ko's buckling model: bending is carried by interlaced
connections (two apart along grid lines, or across each pair of triangles) that buckle into
arcs when compressed, pushing their ends apart with the arc's force; stretch springs keep the
measured law. Connections compressed in a perfectly flat cloth bulge away from a collision
body, else all to one side of the cloth drawn (per step) from seed 1 (see `with_choi_ko(seed)`).",
        |c: &mut ClothHandle| -> RResult<ClothHandle> {
            let mut m = (*c.0).clone();
            m.enable_choi_ko();
            Ok(ClothHandle(Shared::new(m)))
        }
    );
    register!(
        engine,
        "with_choi_ko",
        ["cloth: Cloth", "seed: int", "Cloth"],
        "A copy of the cloth with Choi & Ko's buckling model (see `with_choi_ko()`), a connection
compressed in a perfectly flat cloth bulging to the side of the cloth drawn from `seed`: the same seed gives
the same wrinkles bit for bit, another may flip them.",
        |c: &mut ClothHandle, seed: INT| -> RResult<ClothHandle> {
            if seed < 0 {
                return Err(rt_err(format!(
                    "with_choi_ko: seed must be ≥ 0, got {seed}"
                )));
            }
            let mut m = (*c.0).clone();
            m.choi_ko_seed = seed as u64;
            m.enable_choi_ko();
            Ok(ClothHandle(Shared::new(m)))
        }
    );
    register!(
        engine,
        "perturbed",
        ["cloth: Cloth", "amplitude: float", "seed: int", "Cloth"],
        "A copy of the cloth whose particles are moved along z by seeded pseudo-random amounts,
uniform in ±amplitude/2 (m): the imperfection that lets a flat cloth pushed in its plane buckle.
The same seed gives bit-identical positions; another seed may flip the wrinkles.",
        |c: &mut ClothHandle, a: Dynamic, seed: INT| -> RResult<ClothHandle> {
            let a = super::convert::non_negative(&a, "amplitude")?;
            let mut m = (*c.0).clone();
            m.perturb(crate::geometry::Vec3::z(), a, seed as u64);
            Ok(ClothHandle(Shared::new(m)))
        }
    );
    register!(
        engine,
        "prestrained",
        [
            "cloth: Cloth",
            "strain_x: float",
            "strain_y: float",
            "Cloth"
        ],
        "A copy of the cloth whose particles are moved as by a uniform in-plane strain: x stretched
by 1 + strain_x and y by 1 + strain_y about the cloth's centre (negative: compressed). The rest
shape is kept, so a cloth held on its borders starts under uniform tension or compression.
Strains must be finite and above −1.",
        |c: &mut ClothHandle, ex: Dynamic, ey: Dynamic| -> RResult<ClothHandle> {
            let ex = super::convert::finite(&ex, "strain_x")?;
            let ey = super::convert::finite(&ey, "strain_y")?;
            for (v, name) in [(ex, "strain_x"), (ey, "strain_y")] {
                if v <= -1.0 {
                    return Err(rt_err(format!("{name} = {v} must be above -1")));
                }
            }
            let mut m = (*c.0).clone();
            m.prestrain(ex, ey);
            Ok(ClothHandle(Shared::new(m)))
        }
    );
    getter!(
        engine,
        "vertex_count",
        ["cloth: Cloth", "int"],
        "Number of particles.",
        |c: &mut ClothHandle| c.0.particle_count() as INT
    );
    getter!(
        engine,
        "triangle_count",
        ["cloth: Cloth", "int"],
        "Number of triangles.",
        |c: &mut ClothHandle| c.0.mesh.triangles.len() as INT
    );
    getter!(
        engine,
        "fabric",
        ["cloth: Cloth", "Fabric"],
        "The fabric the cloth was built with.",
        |c: &mut ClothHandle| Fabric(c.0.fabric)
    );
    register!(
        engine,
        "to_string",
        ["cloth: Cloth", "String"],
        "One-line summary of a cloth.",
        |c: &mut ClothHandle| c.to_string()
    );
    register!(
        engine,
        "to_debug",
        ["cloth: Cloth", "String"],
        "One-line summary of a cloth.",
        |c: &mut ClothHandle| c.to_string()
    );
}
