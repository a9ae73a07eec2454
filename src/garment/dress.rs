//! `dress`: the whole way from a pattern to a garment ready to be sewn on a mannequin. The
//! pattern is meshed, pre-positioned around the body at rest, turned into a cloth model with
//! a seam thread per pair of matching vertices and a sewing schedule, and put in a simulation
//! with the body as a collision mesh and self-collision on (sewn vertices exempt). Stepping
//! the simulation then sews (threads shorten, no gravity) and drapes.

use std::time::Instant;

use super::mesh::graph::Adjacency;
use super::mesh::{mesh_pattern, GarmentMesh, MeshParameters};
use super::placement::preposition::{preposition, PrepositionParameters, PrepositionReport};
use super::seam_closure::close_crossed_seams;
use super::seam_hinges::seam_hinges;
use super::{BodyFrame, Pattern, PatternError, Silhouettes};
use crate::body::Mannequin;
use crate::cloth::{
    ClothModel, FabricParameters, Separation, Sewing, Simulation, SimulationParameters,
};
use crate::contact::{Body, ContactSettings, MeshBody, SimulationContact};
use crate::geometry::Vec3;

/// Settings of [`dress`].
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default)]
pub struct DressParameters {
    /// Meshing of the pieces.
    pub mesh: MeshParameters,
    /// Pre-positioning.
    pub preposition: PrepositionParameters,
    /// Stiffness of a seam thread (N/m).
    pub seam_stiffness: f64,
    /// Largest pull of a seam thread (N).
    pub seam_max_force: f64,
    /// Share of gravity acting while sewing (the garment settles onto the shoulders or hips
    /// as it is sewn).
    pub sewing_gravity: f64,
    /// How fast the seam threads shorten while sewing (m/s).
    pub sewing_speed: f64,
    /// Contact with the body and self-collision.
    pub contact: ContactSettings,
    /// Silhouette cell size (m).
    pub silhouette_cell: f64,
    /// Bending hinges across the seams once stitched (see [`super::seam_hinges`]).
    pub seam_hinges: bool,
}

impl Default for DressParameters {
    fn default() -> Self {
        DressParameters {
            mesh: MeshParameters::default(),
            preposition: PrepositionParameters::default(),
            seam_stiffness: 300.0,
            seam_max_force: 5.0,
            sewing_gravity: 0.3,
            sewing_speed: 0.3,
            contact: ContactSettings {
                self_collision: true,
                count_intersections: false,
                ..Default::default()
            },
            silhouette_cell: 0.005,
            seam_hinges: true,
        }
    }
}

/// Figures of a [`dress`] call.
#[derive(Debug, Clone, Default, serde::Serialize)]
pub struct DressReport {
    /// Vertices and triangles of the garment mesh.
    pub vertices: usize,
    /// Triangles of the garment mesh.
    pub triangles: usize,
    /// Seam threads.
    pub seam_pairs: usize,
    /// Meshing time (s).
    pub mesh_seconds: f64,
    /// Body frame, silhouettes and landmarks (s).
    pub body_seconds: f64,
    /// Pre-positioning.
    pub preposition: PrepositionReport,
    /// When the last seam thread reaches rest length 0 (simulated s).
    pub closing_time: f64,
    /// Crossings of a piece with itself left after the pre-positioned knots were smoothed
    /// open (see the pass-through zones).
    pub knots_left: usize,
    /// Crossings between the two pieces of a seam (not a centre seam) left after the
    /// stretches of seam near them were sewn shut at once.
    pub seam_crossings_left: usize,
    /// Intersecting edge–triangle pairs at the start of the simulation.
    pub crossings: usize,
}

/// A garment in its simulation, ready to be sewn and draped.
#[derive(Debug)]
pub struct Dressed {
    /// The meshed garment (pieces, seams).
    pub garment: GarmentMesh,
    /// The simulation: the garment as cloth, the body, the sewing schedule.
    pub simulation: Simulation,
    /// What was done.
    pub report: DressReport,
}

/// Meshes `pattern` (expanded and validated), pre-positions it around `mannequin` at rest and
/// builds the simulation that sews and drapes it in `fabric`.
pub fn dress(
    pattern: &Pattern,
    fabric: FabricParameters,
    mannequin: &Mannequin,
    params: &DressParameters,
    sim_params: SimulationParameters,
) -> Result<Dressed, PatternError> {
    let bad = |name: &str, v: f64| {
        PatternError::Parameter(format!("dress parameter `{name}` is invalid: {v}"))
    };
    if !(params.seam_stiffness.is_finite() && params.seam_stiffness > 0.0) {
        return Err(bad("seam_stiffness", params.seam_stiffness));
    }
    if !(params.seam_max_force.is_finite() && params.seam_max_force > 0.0) {
        return Err(bad("seam_max_force", params.seam_max_force));
    }
    if !(params.sewing_gravity.is_finite() && (0.0..=1.0).contains(&params.sewing_gravity)) {
        return Err(bad("sewing_gravity", params.sewing_gravity));
    }
    if !(params.sewing_speed.is_finite() && params.sewing_speed > 0.0) {
        return Err(bad("sewing_speed", params.sewing_speed));
    }
    params
        .contact
        .validate()
        .map_err(|e| PatternError::Parameter(e.to_string()))?;
    // before the meshing and pre-positioning, which take seconds
    sim_params
        .validate()
        .map_err(|e| PatternError::Parameter(e.to_string()))?;
    let t0 = Instant::now();
    let garment = mesh_pattern(pattern, &params.mesh)?;
    let t1 = Instant::now();
    let frame = BodyFrame::of(mannequin.rest_positions(), mannequin.triangles())?;
    let sil = Silhouettes::of(
        frame,
        mannequin.rest_positions(),
        mannequin.triangles(),
        params.silhouette_cell,
    )?;
    let marks = sil.landmarks()?;
    let skin = MeshBody::new(
        "mannequin",
        mannequin.rest_positions().to_vec(),
        mannequin.triangles(),
    )
    .map_err(|e| PatternError::Parameter(e.to_string()))?;
    let t2 = Instant::now();
    let (x, pre) = preposition(pattern, &garment, &sil, &marks, &skin, &params.preposition)?;
    let mut mesh = garment.mesh.clone();
    mesh.positions = x.clone();
    let cloth_err = |e: crate::cloth::ClothError| PatternError::Parameter(e.to_string());
    let mut model = ClothModel::from_mesh(mesh, fabric).map_err(cloth_err)?;
    let pairs: Vec<(usize, usize)> = garment
        .seams
        .iter()
        .flat_map(|s| s.pairs.iter().copied())
        .filter(|(a, b)| a != b)
        .collect();
    let mut sewing = Sewing::add_to(
        &mut model,
        &pairs,
        &x,
        (params.seam_stiffness, params.seam_max_force),
        params.sewing_speed,
    );
    if params.seam_hinges {
        sewing.add_hinges(&mut model, seam_hinges(&garment));
    }
    let mut sim = Simulation::new(model, sim_params).map_err(cloth_err)?;
    let contact = sim.add_contact();
    contact.settings = params.contact;
    contact.bodies.push(Body::mesh(skin));
    contact.set_welds(x.len(), &pairs);
    let x0 = sim.state.x.clone();
    let crossings = sim.contact_mut().self_intersections(&x0);
    let crossed = crossed_centre_pieces(pattern, &garment, &crossings);
    keep_to_sides(
        &garment,
        &crossed,
        &frame,
        params.preposition.clearance,
        &mut sim.state.x,
    );
    let knots_left = untangle_knots(&garment, &mut sim);
    // where two pieces cross at a seam joining them (not a centre seam), that stretch of the
    // seam is sewn shut at once
    let centre: Vec<usize> = centre_seams(pattern, &garment)
        .into_iter()
        .map(|c| c.0)
        .collect();
    let seam_crossings_left =
        close_crossed_seams(&garment, &centre, 2.0 * params.mesh.edge_length, &mut sim);
    let x = sim.state.x.clone();
    // where pre-positioning left two pieces of a centre seam crossing each other, or a piece
    // through itself (the crotch of trousers), they may pass through each other near there
    // while sewn
    let crossings = sim.contact_mut().self_intersections(&x);
    sewing.pass_through = pass_through_zones(pattern, &garment, &crossings, PASS_THROUGH);
    sewing.separation = separation(&garment, &sewing.pass_through, &x, &frame);
    let report = DressReport {
        vertices: x.len(),
        triangles: garment.mesh.triangles.len(),
        seam_pairs: pairs.len(),
        mesh_seconds: (t1 - t0).as_secs_f64(),
        body_seconds: (t2 - t1).as_secs_f64(),
        preposition: pre,
        closing_time: sewing.closing_time(),
        knots_left,
        seam_crossings_left,
        crossings: crossings.len(),
    };
    sewing.sewing_gravity = params.sewing_gravity;
    sim.sewing = Some(sewing);
    Ok(Dressed {
        garment,
        simulation: sim,
        report,
    })
}

/// The centre seams of a garment: seams joining two different pieces laid on the same side
/// of the body (a crotch seam, a centre back), as (seam index, piece of its first edge, piece
/// of its second edge).
fn centre_seams(pattern: &Pattern, garment: &GarmentMesh) -> Vec<(usize, usize, usize)> {
    let side = |k: usize| {
        pattern
            .pieces
            .iter()
            .find(|p| p.name == garment.pieces[k].name)
            .and_then(|p| p.placement.as_ref())
            .map(|pl| pl.side)
    };
    let mut out = Vec::new();
    for (id, seam) in garment.seams.iter().enumerate() {
        let Some(&(a, b)) = seam.pairs.first() else {
            continue;
        };
        let (Some(pa), Some(pb)) = (piece_of(garment, a), piece_of(garment, b)) else {
            continue;
        };
        if pa != pb && side(pa).is_some() && side(pa) == side(pb) {
            out.push((id, pa, pb));
        }
    }
    out
}

/// The piece holding vertex `v`.
fn piece_of(garment: &GarmentMesh, v: usize) -> Option<usize> {
    garment.pieces.iter().position(|p| p.vertices.contains(&v))
}

/// The pieces of the centre seams whose two pieces cross each other in `crossings`.
fn crossed_centre_pieces(
    pattern: &Pattern,
    garment: &GarmentMesh,
    crossings: &[([u32; 2], [u32; 3])],
) -> Vec<usize> {
    let mut out = Vec::new();
    for (_, pa, pb) in centre_seams(pattern, garment) {
        let crossed = crossings.iter().any(|(e, t)| {
            let (p, q) = (
                piece_of(garment, e[0] as usize),
                piece_of(garment, t[0] as usize),
            );
            (p, q) == (Some(pa), Some(pb)) || (p, q) == (Some(pb), Some(pa))
        });
        if crossed {
            out.extend([pa, pb]);
        }
    }
    out.sort_unstable();
    out.dedup();
    out
}

/// Moves each of `pieces` (the two halves of a centre seam laid through each other by
/// pre-positioning, such as a trouser's crotch extension over the other leg) to its own side
/// of the body's plane of symmetry (the side of the mean of its vertices): a vertex closer to
/// the plane than `margin` on its own side, or beyond it, gets the lateral coordinate
/// `s·g(s·lat)`, `g(u) = m/2 + (m/2) exp((u − m)/(m/2))`, which joins the identity smoothly
/// at `margin` and never reaches the plane. `g` is strictly increasing, so the map is
/// one-to-one and does not fold a piece through itself; the two halves no longer cross.
fn keep_to_sides(
    garment: &GarmentMesh,
    pieces: &[usize],
    frame: &BodyFrame,
    margin: f64,
    x: &mut [Vec3],
) {
    let half = 0.5 * margin;
    for &k in pieces {
        let range = garment.pieces[k].vertices.clone();
        let mean: f64 = range.clone().map(|v| frame.to_body(&x[v])[0]).sum();
        let s = if mean >= 0.0 { 1.0 } else { -1.0 };
        for v in range {
            let [lat, h, d] = frame.to_body(&x[v]);
            let u = s * lat;
            if u < margin {
                let g = half + half * ((u - margin) / half).exp();
                x[v] = frame.to_world(s * g, h, d);
            }
        }
    }
}

/// Smoothing rounds of [`untangle_knots`].
const KNOT_ROUNDS: usize = 48;

/// Opens the small knots pre-positioning can leave where a piece is laid through itself (a
/// few neighbouring triangles turned through each other at the crotch): the vertices of each
/// crossing of a piece with itself, and their neighbours, move halfway to the mean of their
/// neighbours, for up to `KNOT_ROUNDS` rounds or until none is left. Returns the crossings of
/// pieces with themselves left.
fn untangle_knots(garment: &GarmentMesh, sim: &mut Simulation) -> usize {
    let n = sim.state.x.len();
    let adjacency = Adjacency::new(&garment.mesh.triangles, n);
    let mut piece = vec![usize::MAX; n];
    for (k, p) in garment.pieces.iter().enumerate() {
        for v in p.vertices.clone() {
            piece[v] = k;
        }
    }
    let mut marked = vec![false; n];
    let mut left = 0;
    for round in 0..=KNOT_ROUNDS {
        let now = sim.state.x.clone();
        let knots: Vec<([u32; 2], [u32; 3])> = sim
            .contact_mut()
            .self_intersections(&now)
            .into_iter()
            .filter(|(e, t)| piece[e[0] as usize] == piece[t[0] as usize])
            .collect();
        let x = &mut sim.state.x;
        left = knots.len();
        if knots.is_empty() || round == KNOT_ROUNDS {
            break;
        }
        marked.fill(false);
        for (e, t) in &knots {
            for &v in e.iter().chain(t.iter()) {
                marked[v as usize] = true;
                for &u in adjacency.neighbours(v as usize) {
                    marked[u] = true;
                }
            }
        }
        let before = x.clone();
        for v in (0..n).filter(|&v| marked[v]) {
            let ring = adjacency.neighbours(v);
            if ring.is_empty() {
                continue;
            }
            let mean = ring.iter().map(|&u| before[u]).sum::<Vec3>() / ring.len() as f64;
            x[v] = 0.5 * (before[v] + mean);
        }
    }
    left
}

/// How far (m) a vertex of a crossing between the two halves of a centre seam moves towards
/// its own side per step while sewing.
const SEPARATION_STEP: f64 = 2e-3;

/// The sides of the symmetry plane that the pieces of each pass-through zone keep to (see
/// [`Separation`]): each piece's side is where the mean of its vertices lies at `x`; the
/// seam's own vertices, on the plane, are free. `None` without zones.
fn separation(
    garment: &GarmentMesh,
    zones: &[u32],
    x: &[Vec3],
    frame: &BodyFrame,
) -> Option<Separation> {
    if zones.is_empty() {
        return None;
    }
    let mut side = vec![0i8; x.len()];
    for (id, seam) in garment.seams.iter().enumerate() {
        let Some(&(a, b)) = seam.pairs.first() else {
            continue;
        };
        if zones[a] != id as u32 + 1 {
            continue;
        }
        for v0 in [a, b] {
            let Some(piece) = garment.pieces.iter().find(|p| p.vertices.contains(&v0)) else {
                continue;
            };
            // the sign of the summed lateral coordinates is the mean's
            let lateral: f64 = piece
                .vertices
                .clone()
                .map(|v| frame.to_body(&x[v])[0])
                .sum();
            let s = if lateral >= 0.0 { 1 } else { -1 };
            for v in piece.vertices.clone() {
                side[v] = s;
            }
        }
    }
    for seam in &garment.seams {
        for &(a, b) in &seam.pairs {
            if side[a] != 0 && side[b] != 0 && side[a] != side[b] {
                side[a] = 0;
                side[b] = 0;
            }
        }
    }
    Some(Separation {
        normal: frame.left,
        side,
        step: SEPARATION_STEP,
    })
}

/// Distance (m, along the pieces) from a centre seam within which its two pieces may pass
/// through each other while sewn.
const PASS_THROUGH: f64 = 0.06;

/// Reach of a piece's own pass-through zone, as a multiple of `PASS_THROUGH`.
const SELF_REACH_SCALE: f64 = 2.0;

/// One pass-through zone per centre seam (a seam joining two pieces laid on the same side of
/// the body: a crotch seam, a centre back): the vertices of both pieces within `reach` of it.
/// Pre-positioning keeps the two pieces on their own sides of the symmetry plane, but where
/// four pieces meet (the crotch point) they cannot close without passing each other; the
/// separation puts back any crossing this leaves. Also one zone per piece laid through itself
/// in `crossings` (intersecting edge–triangle pairs), within `SELF_REACH_SCALE · reach` of
/// those crossings. Empty when there is none.
fn pass_through_zones(
    pattern: &Pattern,
    garment: &GarmentMesh,
    crossings: &[([u32; 2], [u32; 3])],
    reach: f64,
) -> Vec<u32> {
    let piece_of = |v: usize| piece_of(garment, v);
    let adjacency = Adjacency::new(&garment.mesh.triangles, garment.flat.len());
    let mut zone = vec![0u32; garment.flat.len()];
    let mut any = false;
    for (id, _, _) in centre_seams(pattern, garment) {
        let seam = &garment.seams[id];
        let sources: Vec<usize> = seam.pairs.iter().flat_map(|&(a, b)| [a, b]).collect();
        let (dist, _) = adjacency.nearest(&sources, &garment.flat, reach);
        for (v, d) in dist.iter().enumerate() {
            if d.is_finite() {
                zone[v] = id as u32 + 1;
                any = true;
            }
        }
    }
    // a piece laid through itself (a fold of a crotch extension) may pass through itself
    // near where it does, so the fold can open while it is sewn
    for (k, piece) in garment.pieces.iter().enumerate() {
        let sources: Vec<usize> = crossings
            .iter()
            .filter(|(e, t)| {
                piece_of(e[0] as usize) == Some(k) && piece_of(t[0] as usize) == Some(k)
            })
            .flat_map(|(e, t)| {
                e.iter()
                    .chain(t.iter())
                    .map(|&v| v as usize)
                    .collect::<Vec<_>>()
            })
            .collect();
        if sources.is_empty() {
            continue;
        }
        let (dist, _) = adjacency.nearest(&sources, &garment.flat, SELF_REACH_SCALE * reach);
        let id = (garment.seams.len() + k + 1) as u32;
        for v in piece.vertices.clone() {
            if dist[v].is_finite() && zone[v] == 0 {
                zone[v] = id;
                any = true;
            }
        }
    }
    if any {
        zone
    } else {
        Vec::new()
    }
}
