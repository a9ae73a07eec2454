//! Script bindings for contact: collision bodies (sphere, box, plane, OBJ mesh, the animated
//! mannequin), their friction, particles pinned to bodies, contact settings and the contact
//! read-outs (distance to bodies, penetrations, self-intersections).

use rhai::{Array, Dynamic, Engine, Map, INT};

use super::convert::{
    export_frame, finite, index, indices, rt_err, to_map, update_from_map, vec3, RResult,
};
use super::paths::{read_folder_opt, read_opt, read_path, write_path};
use super::{register, SimHandle};
use crate::body::RetargetOptions;
use crate::cloth::{ClothError, Simulation};
use crate::contact::character::mannequin_body;
use crate::contact::{
    Body, ContactError, ContactSettings, FrictionCoefficients, MeshBody, SimulationContact,
};
use crate::geometry::files::data_path;
use crate::geometry::{read_obj_surface, ExportFrame, Vec3};

fn contact_err(e: ContactError) -> Box<rhai::EvalAltResult> {
    ClothError::from(e).into()
}

fn add_body(h: &SimHandle, body: Result<Body, ContactError>) -> RResult<INT> {
    let body = body.map_err(contact_err)?;
    let mut s = h.get_mut()?;
    let contact = s.contact_mut();
    contact.bodies.push(body);
    Ok((contact.bodies.len() - 1) as INT)
}

fn v3(d: &Dynamic, what: &str) -> RResult<Vec3> {
    Ok(Vec3::from(vec3(d, what)?))
}

/// Writes body `b`'s current surface (a mesh body's triangles, or a tessellation of a sphere,
/// box or plane around the cloth) as OBJ in `frame`.
fn save_body_obj(sim: &Simulation, b: INT, path: &str, frame: ExportFrame) -> RResult<()> {
    let n = sim.contact().bodies.len();
    let body = sim
        .contact()
        .bodies
        .get(index(b, "body")?)
        .ok_or_else(|| rt_err(format!("body {b} does not exist ({n} bodies)")))?;
    let (lo, hi) = crate::geometry::mesh::bounds(&sim.state.x);
    let (p, t) = crate::contact::tessellate::body_mesh(body, &lo, &hi);
    let path = write_path(path)?;
    if let Some(d) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(d).map_err(|e| rt_err(format!("{}: {e}", d.display())))?;
    }
    crate::geometry::write_obj(&path, &p, &t, None, frame)?;
    Ok(())
}

/// Registers the contact functions of `Simulation`.
pub fn register(engine: &mut Engine) {
    register!(
        engine,
        "add_sphere",
        ["sim: Simulation", "center: Array", "radius: float", "int"],
        "Adds a static solid sphere; returns its body index.",
        |h: &mut SimHandle, c: Dynamic, r: Dynamic| -> RResult<INT> {
            add_body(h, Body::sphere(v3(&c, "center")?, finite(&r, "radius")?))
        }
    );
    register!(engine, "add_box", ["sim: Simulation", "center: Array", "size: Array", "int"],
        "Adds a static solid axis-aligned box of full size `[sx, sy, sz]` m; returns its body index.",
        |h: &mut SimHandle, c: Dynamic, s: Dynamic| -> RResult<INT> {
            add_body(h, Body::cuboid(v3(&c, "center")?, v3(&s, "size")?))
        });
    register!(engine, "add_plane", ["sim: Simulation", "point: Array", "normal: Array", "int"],
        "Adds a static plane through `point`; everything behind it (against `normal`) is solid.\nReturns its body index.",
        |h: &mut SimHandle, p: Dynamic, n: Dynamic| -> RResult<INT> {
            add_body(h, Body::plane(v3(&p, "point")?, v3(&n, "normal")?))
        });
    register!(engine, "add_cylinder", ["sim: Simulation", "center: Array", "axis: Array", "radius: float", "length: float", "int"],
        "Adds a static solid cylinder (flat caps, 96 facets around) centred at `center` along\n`axis`; returns its body index.",
        |h: &mut SimHandle, c: Dynamic, a: Dynamic, r: Dynamic, l: Dynamic| -> RResult<INT> {
            add_body(h, Body::cylinder(v3(&c, "center")?, v3(&a, "axis")?, finite(&r, "radius")?, finite(&l, "length")?, 96))
        });
    register!(engine, "add_obstacle", ["sim: Simulation", "path: String", "int"],
        "Adds a static triangle mesh read from an OBJ file (metres) as a body. Degenerate triangles\nare dropped; a non-manifold or inconsistently wound mesh is an error naming the edge.\nReturns its body index.",
        |h: &mut SimHandle, path: &str| -> RResult<INT> {
            let path = read_path(path)?;
            let (positions, triangles) = read_obj_surface(&path)?;
            add_body(h, MeshBody::new(&path.display().to_string(), positions, &triangles).map(Body::mesh))
        });
    register!(engine, "add_mannequin", ["sim: Simulation", "options: Map", "int"],
        "Adds the MakeHuman mannequin (feet on z = 0, facing −y) as a body, animated by a BVH clip:\n`#{motion: \"path.bvh\", in_place: true, start: 0.0, blend: 0.0, makehuman: \"dir\"}`. Without\n`motion` it stands still in its rest pose. With `blend` > 0 it moves from its rest pose into the\nclip's first frame over `blend` seconds before the clip plays (dress it at rest, then move);
`arm_spread` (degrees) tilts the upper arms outward so the hands clear wide hips. `makehuman` defaults to `$EMILION_DATA/bodies/makehuman`\n(`data_dir()`: `$EMILION_DATA`, else `../shared/data` from the repository); `in_place` removes the walk's forward travel;\n`start` is the clip time at simulation time 0. Returns its body index.",
        |h: &mut SimHandle, m: Map| -> RResult<INT> {
            const KEYS: [&str; 6] = ["motion", "in_place", "start", "makehuman", "blend", "arm_spread"];
            if let Some(k) = m.keys().find(|k| !KEYS.contains(&k.as_str())) {
                return Err(rt_err(format!("add_mannequin: unknown option `{k}` (known: {})", KEYS.join(", "))));
            }
            let text = |k: &str| -> RResult<Option<String>> {
                m.get(k).map(|v| v.clone().into_string().map_err(|t| rt_err(format!("`{k}` must be a string, got {t}")))).transpose()
            };
            let dir = read_folder_opt(text("makehuman")?.as_deref())?.unwrap_or_else(|| data_path("bodies/makehuman"));
            let motion = read_opt(text("motion")?.as_deref())?;
            let mut opt = RetargetOptions::default();
            if let Some(v) = m.get("in_place") {
                opt.in_place = v.as_bool().map_err(|t| rt_err(format!("`in_place` must be true or false, got {t}")))?;
            }
            if let Some(v) = m.get("start") {
                opt.start_time = finite(v, "start")?;
            }
            if let Some(v) = m.get("arm_spread") {
                opt.arm_spread_deg = finite(v, "arm_spread")?;
            }
            let blend = m.get("blend").map_or(Ok(0.0), |v| finite(v, "blend"))?;
            add_body(h, mannequin_body(&dir, motion.as_deref(), opt, blend))
        });
    register!(engine, "set_friction", ["sim: Simulation", "body: int", "static: float", "kinetic: float"],
        "Sets a body's static and kinetic friction coefficients (each combined with the fabric's by\ntheir mean; set the fabric's with `set_contact(#{mu_static: .., mu_kinetic: ..})`).",
        |h: &mut SimHandle, b: INT, s: Dynamic, k: Dynamic| -> RResult<()> {
            let f = FrictionCoefficients { static_: finite(&s, "static")?, kinetic: finite(&k, "kinetic")? };
            f.validate("body friction").map_err(contact_err)?;
            let mut sim = h.get_mut()?;
            let bodies = &mut sim.contact_mut().bodies;
            let n = bodies.len();
            let body = bodies.get_mut(index(b, "body")?)
                .ok_or_else(|| rt_err(format!("body {b} does not exist ({n} bodies)")))?;
            body.friction = f;
            Ok(())
        });
    register!(engine, "set_contact", ["sim: Simulation", "settings: Map"],
        "Changes contact settings from a map: thickness (m, cloth–body distance), friction of\nthe fabric (mu_static, mu_kinetic), self_collision (bool), self_thickness (m), self_friction,\nmax_push_speed (m/s), count_intersections (bool). Values are checked.",
        |h: &mut SimHandle, m: Map| -> RResult<()> {
            let mut sim = h.get_mut()?;
            let s: ContactSettings = update_from_map(&sim.contact().settings, &m, "contact")?;
            s.validate().map_err(contact_err)?;
            sim.contact_mut().settings = s;
            Ok(())
        });
    register!(
        engine,
        "contact_settings",
        ["sim: Simulation", "Map"],
        "The contact settings as a map (see `set_contact`).",
        |h: &mut SimHandle| -> RResult<Dynamic> { Ok(to_map(&h.get()?.contact().settings)) }
    );
    register!(engine, "pin_to_body", ["sim: Simulation", "particles: Array", "body: int"],
        "Makes particles follow a mesh body (e.g. a waistband on the mannequin): each keeps its\npresent offset from the body vertex nearest to it (in the body's rest pose), turning with it.",
        |h: &mut SimHandle, p: Array, b: INT| -> RResult<()> {
            let p = indices(&p, "particle")?;
            let mut sim = h.get_mut()?;
            let x = sim.state.x.clone();
            sim.contact_mut().pin_to_body(index(b, "body")?, &p, &x, None).map_err(contact_err)
        });
    register!(engine, "pin_to_body", ["sim: Simulation", "particles: Array", "body: int", "snap: Map"],
        "As `pin_to_body`, and draws the particles onto the body: `#{gap: 0.006, from: 0.0, to: 0.5}`\neases each offset, between simulation times `from` and `to` (s), to `gap` m along the body\nnormal (a waistband gathered onto the waist).",
        |h: &mut SimHandle, p: Array, b: INT, m: Map| -> RResult<()> {
            const KEYS: [&str; 3] = ["gap", "from", "to"];
            if let Some(k) = m.keys().find(|k| !KEYS.contains(&k.as_str())) {
                return Err(rt_err(format!("pin_to_body: unknown snap key `{k}` (known: {})", KEYS.join(", "))));
            }
            let get = |k: &str| m.get(k).ok_or_else(|| rt_err(format!("pin_to_body: snap needs `{k}`"))).and_then(|v| finite(v, k));
            let snap = (get("gap")?, get("from")?, get("to")?);
            let p = indices(&p, "particle")?;
            let mut sim = h.get_mut()?;
            let x = sim.state.x.clone();
            sim.contact_mut().pin_to_body(index(b, "body")?, &p, &x, Some(snap)).map_err(contact_err)
        });
    register!(engine, "save_body_obj", ["sim: Simulation", "body: int", "path: String"],
        "Writes a body's current surface (a mesh body's triangles, or a tessellation of a sphere,\nbox or plane around the cloth) as an OBJ file, +Y up in metres.",
        |h: &mut SimHandle, b: INT, path: &str| -> RResult<()> {
            save_body_obj(&*h.get()?, b, path, ExportFrame::Y_UP_METRES)
        });
    register!(engine, "save_body_obj", ["sim: Simulation", "body: int", "path: String", "options: Map", "()"],
        "Writes a body's current surface as an OBJ file with #{up: \"y\" | \"z\", units: \"m\" | \"cm\" |\n\"mm\"} (as `save_obj`).",
        |h: &mut SimHandle, b: INT, path: &str, m: Map| -> RResult<()> {
            save_body_obj(&*h.get()?, b, path, export_frame(&m)?)
        });
    register!(engine, "contact_report", ["sim: Simulation", "Map"],
        "Contact state now: #{bodies, min_distance (m, smallest signed vertex–body distance),\npenetrating (vertices inside bodies), intersections (intersecting cloth edge–triangle pairs)}\nand the last step's #{contacts, self_contacts, ccd_hits (continuous cloth–cloth hits),\nzone_rounds (impact-zone rounds), self_stopped (vertices the cloth–cloth response stopped),\ncollision_ms}.",
        |h: &mut SimHandle| -> RResult<Map> {
            let mut sim = h.get_mut()?;
            let x = sim.state.x.clone();
            let r = sim.contact_mut().report(&x);
            let st = sim.contact().stats;
            let mut m = Map::new();
            m.insert("bodies".into(), Dynamic::from_int(sim.contact().bodies.len() as INT));
            m.insert("min_distance".into(), Dynamic::from_float(r.min_distance));
            m.insert("penetrating".into(), Dynamic::from_int(r.penetrating as INT));
            m.insert("intersections".into(), Dynamic::from_int(r.intersections as INT));
            m.insert("contacts".into(), Dynamic::from_int(st.contacts as INT));
            m.insert("self_contacts".into(), Dynamic::from_int(st.self_contacts as INT));
            m.insert("ccd_hits".into(), Dynamic::from_int(st.ccd_hits as INT));
            m.insert("zone_rounds".into(), Dynamic::from_int(st.zone_rounds as INT));
            m.insert("self_stopped".into(), Dynamic::from_int(st.self_stopped as INT));
            m.insert("collision_ms".into(), Dynamic::from_float(st.collision_ms));
            Ok(m)
        });
    register!(engine, "self_intersections", ["sim: Simulation", "Array"],
        "The cloth's intersecting edge–triangle pairs now, each as #{edge: [a, b], triangle:\n[p, q, r]} (particle indices): where a garment passes through itself.",
        |h: &mut SimHandle| -> RResult<Array> {
            let mut sim = h.get_mut()?;
            let x = sim.state.x.clone();
            let ints = |v: &[u32]| v.iter().map(|&i| Dynamic::from_int(i as INT)).collect::<Array>();
            Ok(sim.contact_mut().self_intersections(&x).iter().map(|(e, t)| {
                let mut m = Map::new();
                m.insert("edge".into(), Dynamic::from_array(ints(e)));
                m.insert("triangle".into(), Dynamic::from_array(ints(t)));
                Dynamic::from_map(m)
            }).collect())
        });
}
