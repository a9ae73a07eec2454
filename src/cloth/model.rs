//! `ClothModel`: the fixed part of a cloth (mesh, masses, force elements, material), built
//! once per topology from a grid or from any triangle mesh with rest coordinates.

use std::sync::Arc;

use super::buckling::arc_connection::ArcConnection;
use super::buckling::buckling_side::{turns_left, FlexionSide};
use super::elements::material::{Direction, FabricParameters, MaterialLaw};
use super::elements::{BendLine, Hinge, ShearQuad, Spring, SpringKind};
use super::ClothError;
use crate::geometry::{grid_mesh, Topology, TriMesh};

/// The fixed description of a cloth: its mesh, per-particle masses and areas, force elements
/// and material law.
#[derive(Debug, Clone)]
pub struct ClothModel {
    /// The mesh; `mesh.positions` are the initial positions.
    pub mesh: TriMesh,
    /// Particle masses (kg): areal density × the particle's share of the rest area.
    pub mass: Vec<f64>,
    /// Particle rest areas (m²), used for air drag.
    pub area: Vec<f64>,
    /// Stretch and shear springs.
    pub springs: Vec<Spring>,
    /// Shear elements of grid cells.
    pub shear_quads: Vec<ShearQuad>,
    /// Grid-line bending elements.
    pub bend_lines: Vec<BendLine>,
    /// Dihedral bending hinges.
    pub hinges: Vec<Hinge>,
    /// Choi–Ko's interlaced connections (empty without Choi–Ko).
    pub arcs: Vec<ArcConnection>,
    /// The fabric parameters the model was built from.
    pub fabric: FabricParameters,
    /// The material law every element asks.
    pub law: Arc<dyn MaterialLaw>,
    /// Grid size (columns, rows) when built by [`ClothModel::grid`].
    pub grid: Option<(usize, usize)>,
    /// Whether Choi & Ko's buckling model is on (see [`ClothModel::enable_choi_ko`]).
    pub choi_ko: bool,
    /// Choi–Ko's connections as the choice of their buckling side sees them (see
    /// [`super::buckling::buckling_side`]); empty without Choi–Ko.
    pub flexion_sides: Vec<FlexionSide>,
    /// Seed of the random side a flat Choi–Ko connection buckles to.
    pub choi_ko_seed: u64,
}

impl ClothModel {
    /// A `width` × `height` rectangle of `nx` × `ny` particles, flat in the XY plane at z = 0
    /// (see [`grid_mesh`]), with warp springs along x, weft springs along y, a shear element
    /// per cell (measured through its diagonals) and bending lines along both directions.
    pub fn grid(
        width: f64,
        height: f64,
        nx: usize,
        ny: usize,
        fabric: FabricParameters,
    ) -> Result<Self, ClothError> {
        fabric.validate().map_err(ClothError::Parameter)?;
        let mesh = grid_mesh(width, height, nx, ny)?;
        let (dx, dy) = (width / (nx - 1) as f64, height / (ny - 1) as f64);
        let id = |i: usize, j: usize| i * nx + j;
        // width of fabric a grid line stands for: half at the border
        let wy = |i: usize| if i == 0 || i == ny - 1 { 0.5 * dy } else { dy };
        let wx = |j: usize| if j == 0 || j == nx - 1 { 0.5 * dx } else { dx };
        let mut springs = Vec::new();
        let mut bend_lines = Vec::new();
        let mut shear_quads = Vec::new();
        let warp = SpringKind::Stretch { warp_weight: 1.0 };
        let weft = SpringKind::Stretch { warp_weight: 0.0 };
        for i in 0..ny {
            for j in 0..nx {
                if j + 1 < nx {
                    springs.push(Spring {
                        a: id(i, j),
                        b: id(i, j + 1),
                        rest: dx,
                        area: wy(i) * dx,
                        kind: warp,
                    });
                }
                if i + 1 < ny {
                    springs.push(Spring {
                        a: id(i, j),
                        b: id(i + 1, j),
                        rest: dy,
                        area: wx(j) * dy,
                        kind: weft,
                    });
                }
                if i + 1 < ny && j + 1 < nx {
                    shear_quads.push(ShearQuad::new(
                        [id(i, j), id(i + 1, j + 1), id(i, j + 1), id(i + 1, j)],
                        dx,
                        dy,
                    ));
                }
                if j >= 1 && j + 1 < nx {
                    bend_lines.push(BendLine::new(
                        [id(i, j - 1), id(i, j), id(i, j + 1)],
                        dx,
                        dx,
                        wy(i),
                        Direction::Warp,
                    ));
                }
                if i >= 1 && i + 1 < ny {
                    bend_lines.push(BendLine::new(
                        [id(i - 1, j), id(i, j), id(i + 1, j)],
                        dy,
                        dy,
                        wx(j),
                        Direction::Weft,
                    ));
                }
            }
        }
        let area = mesh.vertex_rest_areas();
        let mass = area.iter().map(|a| a * fabric.density).collect();
        Ok(ClothModel {
            mesh,
            mass,
            area,
            springs,
            shear_quads,
            bend_lines,
            hinges: Vec::new(),
            arcs: Vec::new(),
            law: Arc::new(fabric.linear_law()),
            fabric,
            grid: Some((nx, ny)),
            choi_ko: false,
            flexion_sides: Vec::new(),
            choi_ko_seed: 1,
        })
    }

    /// A cloth from any triangle mesh whose `rest` holds the flat pattern coordinates:
    /// a stretch spring per edge (stiffness blended between warp and weft by the edge's rest
    /// direction), a shear spring across each interior edge (between the opposite vertices)
    /// and a dihedral hinge per interior edge.
    pub fn from_mesh(mesh: TriMesh, fabric: FabricParameters) -> Result<Self, ClothError> {
        fabric.validate().map_err(ClothError::Parameter)?;
        mesh.validate()?;
        let topo = Topology::of(&mesh);
        let n = mesh.vertex_count();
        // summed area of triangles incident to each edge
        let tri_area: Vec<f64> = (0..mesh.triangles.len())
            .map(|t| mesh.rest_area(t))
            .collect();
        let mut edge_area = std::collections::BTreeMap::new();
        for (t, tri) in mesh.triangles.iter().enumerate() {
            for k in 0..3 {
                let (p, q) = (tri[k], tri[(k + 1) % 3]);
                *edge_area.entry((p.min(q), p.max(q))).or_insert(0.0) += tri_area[t];
            }
        }
        let rest_vec = |p: usize, q: usize| {
            let (a, b) = (mesh.rest[p], mesh.rest[q]);
            (b[0] - a[0], b[1] - a[1])
        };
        let mut springs = Vec::with_capacity(topo.edges.len() + topo.hinges.len());
        for e in &topo.edges {
            let (du, dv) = rest_vec(e.a, e.b);
            let l2 = du * du + dv * dv;
            let rest = l2.sqrt();
            if rest <= 0.0 {
                return Err(ClothError::Parameter(format!(
                    "edge {}–{} has zero rest length",
                    e.a, e.b
                )));
            }
            // k = E · ΣA / L0²: exact for axis-aligned edges of a right-triangle grid
            let area = edge_area[&(e.a, e.b)];
            springs.push(Spring {
                a: e.a,
                b: e.b,
                rest,
                area,
                kind: SpringKind::Stretch {
                    warp_weight: du * du / l2,
                },
            });
        }
        let mut hinges = Vec::with_capacity(topo.hinges.len());
        for h in &topo.hinges {
            let a0 = edge_area[&(h.a.min(h.b), h.a.max(h.b))];
            let (cu, cv) = rest_vec(h.c, h.d);
            let cross = (cu * cu + cv * cv).sqrt();
            if cross > 0.0 {
                springs.push(Spring {
                    a: h.c,
                    b: h.d,
                    rest: cross,
                    area: 2.0 * a0 / 3.0,
                    kind: SpringKind::Shear,
                });
            }
            let (du, dv) = rest_vec(h.a, h.b);
            let l2 = du * du + dv * dv;
            // curvature direction is perpendicular to the edge: its warp share is dv²/l²
            hinges.push(Hinge {
                nodes: [h.a, h.b, h.c, h.d],
                edge: l2.sqrt(),
                area: a0,
                warp_weight: dv * dv / l2,
                weight: 1.0,
                seam: false,
            });
        }
        let area = mesh.vertex_rest_areas();
        let mass = area.iter().map(|a| a * fabric.density).collect();
        debug_assert_eq!(area.len(), n);
        Ok(ClothModel {
            mesh,
            mass,
            area,
            springs,
            shear_quads: Vec::new(),
            bend_lines: Vec::new(),
            hinges,
            arcs: Vec::new(),
            law: Arc::new(fabric.linear_law()),
            fabric,
            grid: None,
            choi_ko: false,
            flexion_sides: Vec::new(),
            choi_ko_seed: 1,
        })
    }

    /// Switches to Choi & Ko's buckling model: bending is carried by interlaced connections
    /// ([`ArcConnection`], whose arc is as long as the fabric it spans, so a stretched fabric
    /// is not pushed apart) that buckle into arcs when compressed: between
    /// particles two apart along each grid line (replacing the bending lines) or, on a
    /// triangle mesh, between the opposite vertices of each pair of triangles sharing an edge
    /// (replacing the hinges). Each connection stands for the fabric its element stood for, so
    /// a linear law's bending energy at a given curvature is unchanged. The stretch springs keep
    /// the measured law in compression: giving them the buckling force too (Choi & Ko's
    /// type-1 connections) let a pushed border crumple in its plane (strains from −90 % to
    /// +490 %, 5 J of spring energy on `scripts/buckle_cylinder.rhai`). With the contact
    /// friction fixed and contacts at rest it no longer crumples, but it stores the push as in-plane
    /// shortening (5–7 % of the springs shorter by 1 %, no visible wrinkles, 0.021–0.030 J at
    /// rest against 0.016–0.025 J without type-1 on seeds 1–8). Since flat connections start
    /// their arcs on a chosen side ([`super::buckling::buckling_side`]), the flat square no longer keeps
    /// half its springs compressed with type-1, but the cloth on the cylinder still stores the
    /// push in its plane (6.5 % of the springs compressed, 0.0265 J against 0.0139 J without a
    /// model, seeds 1–8, 2026-12-05).
    pub fn enable_choi_ko(&mut self) {
        if self.choi_ko {
            return;
        }
        let rest = &self.mesh.rest;
        let dist = |p: usize, q: usize| {
            let (du, dv) = (rest[q][0] - rest[p][0], rest[q][1] - rest[p][1]);
            (
                (du * du + dv * dv).sqrt(),
                du * du / (du * du + dv * dv).max(1e-300),
            )
        };
        for e in std::mem::take(&mut self.bend_lines) {
            let [a, b, c] = e.nodes;
            let (len, _) = dist(a, c);
            // the middle's neighbour across the line (grids only carry bending lines)
            if let Some((nx, ny)) = self.grid {
                let (i, j) = (b / nx, b % nx);
                let other = match e.dir {
                    Direction::Warp if i + 1 < ny => Some(b + nx),
                    Direction::Warp if i > 0 => Some(b - nx),
                    Direction::Weft if j + 1 < nx => Some(b + 1),
                    Direction::Weft if j > 0 => Some(b - 1),
                    _ => None,
                };
                if let Some(o) = other {
                    self.flexion_sides.push(FlexionSide {
                        ends: [a, c],
                        middle: [b, b],
                        across: [b, o],
                        rest: len,
                        front: turns_left(rest, [a, c], [b, o]),
                    });
                }
            }
            let spring = Spring {
                a,
                b: c,
                rest: len,
                area: e.area,
                kind: SpringKind::Flexion {
                    warp_weight: if e.dir == Direction::Warp { 1.0 } else { 0.0 },
                },
            };
            let path0 = dist(a, b).0 + dist(b, c).0;
            self.arcs.push(ArcConnection::new(spring, [b, b], path0));
        }
        // hinges across seams stay: their wings' rest coordinates lie on different pieces
        let (seams, fabric): (Vec<Hinge>, Vec<Hinge>) = std::mem::take(&mut self.hinges)
            .into_iter()
            .partition(|h| h.seam);
        self.hinges = seams;
        for h in fabric {
            let [e0, e1, c, d] = h.nodes;
            let (len, warp_weight) = dist(c, d);
            if len > 0.0 {
                self.flexion_sides.push(FlexionSide {
                    ends: [c, d],
                    middle: [e0, e1],
                    across: [e0, e1],
                    rest: len,
                    front: turns_left(rest, [c, d], [e0, e1]),
                });
                let spring = Spring {
                    a: c,
                    b: d,
                    rest: len,
                    area: h.area,
                    kind: SpringKind::Flexion { warp_weight },
                };
                // the rest path from c through the shared edge's midpoint to d
                let mid = [
                    0.5 * (rest[e0][0] + rest[e1][0]),
                    0.5 * (rest[e0][1] + rest[e1][1]),
                ];
                let leg = |p: usize| {
                    ((rest[p][0] - mid[0]).powi(2) + (rest[p][1] - mid[1]).powi(2)).sqrt()
                };
                self.arcs
                    .push(ArcConnection::new(spring, [e0, e1], leg(c) + leg(d)));
            }
        }
        self.choi_ko = true;
    }

    /// Moves every particle along `dir` by a seeded pseudo-random amount, uniform in
    /// ±`amplitude`/2: the imperfection that lets a flat cloth pushed in its plane buckle.
    /// The same seed gives the same positions, bit for bit (SplitMix64).
    pub fn perturb(&mut self, dir: crate::geometry::Vec3, amplitude: f64, seed: u64) {
        let mut rng = crate::geometry::SplitMix64::new(seed);
        for p in &mut self.mesh.positions {
            *p += dir * (amplitude * (rng.uniform() - 0.5));
        }
    }

    /// Moves the particles as a uniform in-plane strain would: x stretched by `1 + ex` and y by
    /// `1 + ey` about the centre of the positions' bounding box (negative: compressed). The
    /// rest shape is kept, so the cloth starts strained: a sheet held on its borders this way
    /// is under uniform tension or compression from the first step.
    pub fn prestrain(&mut self, ex: f64, ey: f64) {
        let (mut lo, mut hi) = (
            crate::geometry::Vec3::repeat(f64::INFINITY),
            crate::geometry::Vec3::repeat(f64::NEG_INFINITY),
        );
        for p in &self.mesh.positions {
            lo = lo.inf(p);
            hi = hi.sup(p);
        }
        let c = (lo + hi) * 0.5;
        for p in &mut self.mesh.positions {
            p.x = c.x + (p.x - c.x) * (1.0 + ex);
            p.y = c.y + (p.y - c.y) * (1.0 + ey);
        }
    }

    /// Number of particles.
    pub fn particle_count(&self) -> usize {
        self.mass.len()
    }

    /// Replaces the material law (e.g. a measured one) while keeping the elements.
    pub fn set_law(&mut self, law: Arc<dyn MaterialLaw>) {
        self.law = law;
    }

    /// All particle pairs coupled by some element (for the matrix pattern), unsorted.
    pub fn coupled_pairs(&self) -> Vec<(usize, usize)> {
        let mut pairs = Vec::new();
        for s in &self.springs {
            pairs.push((s.a, s.b));
        }
        for q in &self.shear_quads {
            pairs.extend([(q.nodes[0], q.nodes[1]), (q.nodes[2], q.nodes[3])]);
        }
        for e in &self.bend_lines {
            let [a, b, c] = e.nodes;
            pairs.extend([(a, b), (b, c), (a, c)]);
        }
        for h in &self.hinges {
            let n = h.nodes;
            for p in 0..4 {
                for q in p + 1..4 {
                    pairs.push((n[p], n[q]));
                }
            }
        }
        for c in &self.arcs {
            let n = c.nodes;
            for p in 0..4 {
                for q in p + 1..4 {
                    if n[p] != n[q] {
                        pairs.push((n[p], n[q]));
                    }
                }
            }
        }
        pairs
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Vec3;

    #[test]
    fn choi_ko_replaces_bending_lines_by_flexion_connections_of_the_same_fabric() {
        let fabric = FabricParameters::default();
        let mut m = ClothModel::grid(0.1, 0.05, 11, 6, fabric).unwrap();
        let lines = m.bend_lines.clone();
        let set = |m: &ClothModel| {
            let mut p: Vec<(usize, usize)> = m
                .coupled_pairs()
                .into_iter()
                .map(|(a, b)| (a.min(b), a.max(b)))
                .collect();
            p.sort_unstable();
            p.dedup();
            p
        };
        let pairs = set(&m);
        m.enable_choi_ko();
        assert!(m.bend_lines.is_empty() && m.choi_ko);
        let flex: Vec<&Spring> = m.arcs.iter().map(|c| &c.spring).collect();
        assert_eq!(flex.len(), lines.len());
        for (c, e) in m.arcs.iter().zip(&lines) {
            assert_eq!(c.nodes[2..], [e.nodes[1], e.nodes[1]]);
            assert!((c.path0 - c.spring.rest).abs() < 1e-15);
        }
        // the matrix pattern keeps the same couplings (a–c of each line)
        assert_eq!(set(&m), pairs);
        // a flexion connection bent into an arc of curvature κ stores the energy the bending
        // line stood for: area · ½ B κ² (linear law)
        let law = m.law.clone();
        let kappa = 20.0;
        for (s, e) in flex.iter().zip(&lines) {
            assert_eq!((s.a, s.b), (e.nodes[0], e.nodes[2]));
            let theta = 0.5 * kappa * s.rest;
            let chord = s.rest * theta.sin() / theta;
            let ev = s.eval(&*law, &Vec3::zeros(), &Vec3::new(chord, 0.0, 0.0));
            let (_, _, w) = law.bending(e.dir, kappa);
            assert!((ev.energy / (e.area * w) - 1.0).abs() < 1e-9);
            assert!(ev.tension < 0.0 && ev.transverse == 0.0);
            // slack when stretched
            let ev = s.eval(&*law, &Vec3::zeros(), &Vec3::new(1.01 * s.rest, 0.0, 0.0));
            assert_eq!(ev.tension, 0.0);
        }
    }
}
