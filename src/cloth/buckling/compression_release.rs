//! The compression-release buckling model of the seed report (§5.4.4.1.2, Chen & Gagalowicz):
//! cloth is not left compressed. Each step, the most compressed stretch springs are found; the
//! particle at the spring's end is sent to where its three springs (two along the compression,
//! one across) all have their rest length again — an intersection of three spheres — and held
//! there for a few steps through the solver's constraint filter (S, z), so the rest of the
//! cloth follows by the dynamics. On a grid the three are its line neighbours and the nearer
//! neighbour across; on a triangle mesh, the spring's other end, the neighbour most nearly
//! opposite it in the pattern, and the most compressed neighbour roughly across (within 30° of
//! perpendicular). Three springs brought back to their rest length can stretch or compress the
//! others more than they were compressed (see
//! `a_release_never_strains_its_ring_more_than_it_relieves_regression`), so on both the
//! destination is then settled: from the chosen intersection, a few Gauss–Newton steps to
//! the least strain of the particle's whole ring of stretch springs (the sum of squared
//! strains), and the release is made only if that is below the ring's strain where the
//! particle is (the ring's elastic energy drops: the seed report's analysis, §5.4.4.1.3). Of the two
//! intersections, the one clear of the collision bodies (by the contact distance), then the
//! nearer, then the more curved is chosen; the remaining ties (a cloth flat to the last bit)
//! go to one side of the cloth drawn at random once per step, so a flat cloth buckles up or
//! down at random, reproducibly for one seed, and all its first wrinkles bulge the same way:
//! drawn for each particle on its own, neighbours went opposite ways and a triangle mesh ended
//! creased (0.0074 J stored at rest, against 1.6e-4 J now). When the near intersection lies in
//! a body, the far one is taken only within 0.75 of the spring's rest length ([`MAX_JUMP`]):
//! farther, the particle would jump through the cloth. Particles already in contact are not
//! released. The hold yields to cloth–cloth contact ([`Filter::hold_yielding`]): a particle
//! the self-collision response stops short of its destination is let go, and waits
//! `hold_steps` before it is released again.

use crate::cloth::constraints::{Filter, ParticleFilter};
use crate::cloth::elements::SpringKind;
use crate::cloth::model::ClothModel;
use crate::cloth::stage::{Obstacles, StepStage};
use crate::geometry::Vec3;

/// The farthest a release moves a particle to the far intersection, in rest lengths of the
/// spring it releases, when the near one lies in a body. On the cylinder with friction such
/// destinations lay up to 1.36 rest lengths away, through the cloth, and made the spring
/// energy leap from 0.008 to 0.046 J in one step at rest: the cloth never settled.
pub const MAX_JUMP: f64 = 0.75;

/// A held particle found farther than this from its destination (m) was stopped short by
/// cloth–cloth contact (the solver puts a held particle on its target to rounding).
pub const BLOCKED_TOL: f64 = 1e-9;

/// Gauss–Newton steps from the intersection to the ring's least strain.
pub const SETTLE_STEPS: usize = 4;

/// Options of the model.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ReleaseOptions {
    /// Springs compressed by more than this strain are released (e.g. 0.01).
    pub strain: f64,
    /// Steps a released particle is held at its destination.
    pub hold_steps: u32,
    /// Seed of the random choice between two equally good destinations.
    pub seed: u64,
}

impl Default for ReleaseOptions {
    fn default() -> Self {
        ReleaseOptions {
            strain: 0.01,
            hold_steps: 3,
            seed: 1,
        }
    }
}

/// The two points at distances `r` from the centres `c` (three spheres), if they exist:
/// `(q₊, q₋)`, mirror images through the centres' plane (`q₊` on the side of
/// (c₁ − c₀) × (c₂ − c₀)). `None` when the spheres have no common point or the centres are
/// collinear.
pub fn three_spheres(c: [Vec3; 3], r: [f64; 3]) -> Option<(Vec3, Vec3)> {
    let ex = c[1] - c[0];
    let d = ex.norm();
    if d <= 0.0 {
        return None;
    }
    let ex = ex / d;
    let a = c[2] - c[0];
    let i = ex.dot(&a);
    let ey = a - ex * i;
    let j = ey.norm();
    if j <= 1e-12 * d {
        return None;
    }
    let ey = ey / j;
    let ez = ex.cross(&ey);
    let x = (r[0] * r[0] - r[1] * r[1] + d * d) / (2.0 * d);
    let y = (r[0] * r[0] - r[2] * r[2] + i * i + j * j) / (2.0 * j) - i * x / j;
    let z2 = r[0] * r[0] - x * x - y * y;
    if z2.is_nan() || z2 < 0.0 {
        return None;
    }
    let z = z2.sqrt();
    let base = c[0] + ex * x + ey * y;
    Some((base + ez * z, base - ez * z))
}

/// Curvature through three points (seed §5.4.4.1.2): the turning angle of the polyline over
/// its mean segment length.
pub fn curvature3(p1: &Vec3, p2: &Vec3, p3: &Vec3) -> f64 {
    let (v1, v2) = (p2 - p1, p3 - p2);
    let (l1, l2) = (v1.norm(), v2.norm());
    if l1 <= 0.0 || l2 <= 0.0 {
        return 0.0;
    }
    let c = (v1.dot(&v2) / (l1 * l2)).clamp(-1.0, 1.0);
    2.0 * c.acos() / (l1 + l2)
}

/// The model's state: neighbours and rest lengths, and who is held where.
#[derive(Debug, Clone)]
pub struct CompressionRelease {
    options: ReleaseOptions,
    /// Grid size (0 × 0 for a triangle mesh).
    nx: usize,
    ny: usize,
    /// Rest spacing along x (warp) and y (weft) of a grid.
    rest: (f64, f64),
    /// A triangle mesh's neighbours by stretch springs: particle `m`'s are
    /// `adj[adj_ptr[m]..adj_ptr[m + 1]]` (neighbour, rest length); empty on a grid.
    adj_ptr: Vec<usize>,
    adj: Vec<(usize, f64)>,
    /// Rest (pattern) coordinates of the particles.
    pattern: Vec<[f64; 2]>,
    /// Stretch springs (a, b, rest).
    springs: Vec<(usize, usize, f64)>,
    /// Held particles: (particle, destination, steps left).
    held: Vec<(usize, Vec3, u32)>,
    /// Steps a particle whose hold was blocked by another layer waits before its next release.
    blocked: Vec<u32>,
    /// Scratch: particle already used this step.
    busy: Vec<bool>,
    /// Scratch: compressed springs (strain, spring).
    order: Vec<(f64, usize)>,
    rng: crate::geometry::SplitMix64,
    /// The side of this step's ties, once drawn.
    tie_side: Option<bool>,
    /// Releases performed so far.
    pub releases: u64,
}

impl CompressionRelease {
    /// The model for `model`'s cloth, a grid or any triangle mesh.
    pub fn new(model: &ClothModel, options: ReleaseOptions) -> Self {
        let n = model.particle_count();
        let springs: Vec<(usize, usize, f64)> = model
            .springs
            .iter()
            .filter(|s| matches!(s.kind, SpringKind::Stretch { .. }))
            .map(|s| (s.a, s.b, s.rest))
            .collect();
        let ((nx, ny), rest, adj_ptr, adj, pattern) = match model.grid {
            Some((nx, ny)) => {
                let r = &model.mesh.rest;
                (
                    (nx, ny),
                    (r[1][0] - r[0][0], r[nx][1] - r[0][1]),
                    Vec::new(),
                    Vec::new(),
                    model.mesh.rest.clone(),
                )
            }
            None => {
                let mut lists = vec![Vec::new(); n];
                for &(a, b, r) in &springs {
                    lists[a].push((b, r));
                    lists[b].push((a, r));
                }
                let mut ptr = vec![0];
                let mut adj = Vec::new();
                for mut l in lists {
                    l.sort_by_key(|e| e.0);
                    adj.extend(l);
                    ptr.push(adj.len());
                }
                ((0, 0), (0.0, 0.0), ptr, adj, model.mesh.rest.clone())
            }
        };
        CompressionRelease {
            options,
            nx,
            ny,
            rest,
            adj_ptr,
            adj,
            pattern,
            springs,
            held: Vec::new(),
            blocked: vec![0; n],
            busy: vec![false; n],
            order: Vec::new(),
            rng: crate::geometry::SplitMix64::new(options.seed),
            tie_side: None,
            releases: 0,
        }
    }

    fn is_grid(&self) -> bool {
        self.adj_ptr.is_empty()
    }

    /// The side (true: front) this step's ties go to, drawn at the first tie of the step.
    fn tie_side(&mut self) -> bool {
        match self.tie_side {
            Some(side) => side,
            None => {
                let side = self.rng.bit();
                self.tie_side = Some(side);
                side
            }
        }
    }

    /// Marks particle `m` and its neighbours busy (on a grid, all eight around it).
    fn occupy(&mut self, m: usize) {
        if !self.is_grid() {
            self.busy[m] = true;
            for k in self.adj_ptr[m]..self.adj_ptr[m + 1] {
                self.busy[self.adj[k].0] = true;
            }
            return;
        }
        let (i, j) = (m / self.nx, m % self.nx);
        for di in -1i64..=1 {
            for dj in -1i64..=1 {
                let (ii, jj) = (i as i64 + di, j as i64 + dj);
                if ii >= 0 && jj >= 0 && (ii as usize) < self.ny && (jj as usize) < self.nx {
                    self.busy[ii as usize * self.nx + jj as usize] = true;
                }
            }
        }
    }

    /// The destination that releases particle `m`'s springs along `along` (1 warp, nx weft),
    /// or `None` at the border, without an intersection, or when both intersections lie
    /// within the clearance of an obstacle.
    fn destination(
        &mut self,
        x: &[Vec3],
        m: usize,
        along: usize,
        obstacles: Obstacles<'_>,
    ) -> Option<Vec3> {
        let (i, j) = (m / self.nx, m % self.nx);
        let warp = along == 1;
        let inside_along = if warp {
            j >= 1 && j + 1 < self.nx
        } else {
            i >= 1 && i + 1 < self.ny
        };
        if !inside_along {
            return None;
        }
        let (r_along, r_across) = if warp {
            (self.rest.0, self.rest.1)
        } else {
            (self.rest.1, self.rest.0)
        };
        // the neighbour across: the side whose spring is shorter (more compressed)
        let across = if warp { self.nx } else { 1 };
        let has_prev = if warp { i >= 1 } else { j >= 1 };
        let has_next = if warp {
            i + 1 < self.ny
        } else {
            j + 1 < self.nx
        };
        let side = match (has_prev, has_next) {
            (true, true) => {
                if (x[m - across] - x[m]).norm() <= (x[m + across] - x[m]).norm() {
                    m - across
                } else {
                    m + across
                }
            }
            (true, false) => m - across,
            (false, true) => m + across,
            (false, false) => return None,
        };
        let q = self.choose(
            x,
            m,
            [m - along, m + along, side],
            [r_along, r_along, r_across],
            obstacles,
        )?;
        self.settle(x, m, q, obstacles)
    }

    /// On a triangle mesh, the destination that releases particle `m`'s spring to `partner`:
    /// three spheres around the partner, the neighbour most nearly opposite it in the pattern
    /// (at least 120° away) and the most compressed neighbour within 30° of perpendicular;
    /// `None` at a border without such neighbours.
    fn mesh_destination(
        &mut self,
        x: &[Vec3],
        m: usize,
        partner: usize,
        obstacles: Obstacles<'_>,
    ) -> Option<Vec3> {
        let pm = self.pattern[m];
        let unit = |k: usize| {
            let (du, dv) = (self.pattern[k][0] - pm[0], self.pattern[k][1] - pm[1]);
            let l = (du * du + dv * dv).sqrt();
            (du / l, dv / l)
        };
        let ring = &self.adj[self.adj_ptr[m]..self.adj_ptr[m + 1]];
        let along = unit(partner);
        let cos = |k: usize| {
            let d = unit(k);
            d.0 * along.0 + d.1 * along.1
        };
        let r_partner = ring.iter().find(|e| e.0 == partner)?.1;
        // most nearly opposite (ties: lower index, the ring is sorted)
        let mut opposite: Option<(usize, f64, f64)> = None;
        // most compressed across (ties: lower index)
        let mut across: Option<(usize, f64, f64)> = None;
        for &(k, r) in ring {
            if k == partner {
                continue;
            }
            let c = cos(k);
            if c <= -0.5 && opposite.is_none_or(|o| c < o.2) {
                opposite = Some((k, r, c));
            }
            let ratio = (x[k] - x[m]).norm() / r;
            if c.abs() <= 0.5 && across.is_none_or(|a| ratio < a.2) {
                across = Some((k, r, ratio));
            }
        }
        let ((o, ro, _), (a, ra, _)) = (opposite?, across?);
        let q = self.choose(x, m, [partner, o, a], [r_partner, ro, ra], obstacles)?;
        self.settle(x, m, q, obstacles)
    }

    /// Particle `m`'s ring of stretch springs: (neighbour, rest length) for each.
    fn ring(&self, m: usize) -> impl Iterator<Item = (usize, f64)> + '_ {
        let grid: [Option<(usize, f64)>; 4] = if self.is_grid() {
            let (i, j) = (m / self.nx, m % self.nx);
            [
                (j > 0).then(|| (m - 1, self.rest.0)),
                (j + 1 < self.nx).then(|| (m + 1, self.rest.0)),
                (i > 0).then(|| (m - self.nx, self.rest.1)),
                (i + 1 < self.ny).then(|| (m + self.nx, self.rest.1)),
            ]
        } else {
            [None; 4]
        };
        let mesh = if self.is_grid() {
            &[][..]
        } else {
            &self.adj[self.adj_ptr[m]..self.adj_ptr[m + 1]]
        };
        grid.into_iter().flatten().chain(mesh.iter().copied())
    }

    /// The strain of particle `m`'s ring of stretch springs were it at `p`: the sum of
    /// squared strains, compressed and stretched (the ring's elastic energy up to stiffness).
    pub fn ring_strain(&self, x: &[Vec3], m: usize, p: &Vec3) -> f64 {
        self.ring(m)
            .map(|(k, r)| ((x[k] - p).norm() / r - 1.0).powi(2))
            .sum()
    }

    /// From the intersection `q`, the point of least ring strain on its side (a few
    /// Gauss–Newton steps on the ring's strains, each kept only if it lowers them), if that
    /// lowers the ring's strain below where particle `m` is and lies clear of the bodies.
    /// Three springs brought back to their rest length can stretch or compress the others
    /// more than they were compressed (on a triangle mesh, the three of six others;
    /// `a_release_never_strains_its_ring_more_than_it_relieves_regression`); moving on to
    /// the ring's least strain keeps the side the intersection chose and relieves the whole
    /// ring. (Counting compression only, as meshes did until 2026-12-05, let releases stretch
    /// the ring: on the grid cylinder the spring energy then leapt to 0.17 J during the push,
    /// against 0.04 J without a model. Refusing such releases instead of settling them left
    /// the sleeve of `scripts/buckle_sleeve.rhai` with 5 % of its springs compressed: 98 % of
    /// its releases were refused.)
    fn settle(&self, x: &[Vec3], m: usize, q: Vec3, obstacles: Obstacles<'_>) -> Option<Vec3> {
        let mut p = q;
        let mut f = self.ring_strain(x, m, &p);
        for _ in 0..SETTLE_STEPS {
            let (mut jtj, mut jtr) = (crate::geometry::Mat3::zeros(), Vec3::zeros());
            for (k, r) in self.ring(m) {
                let d = p - x[k];
                let len = d.norm();
                if len <= 0.0 {
                    continue;
                }
                let g = d / (len * r);
                jtj += g * g.transpose();
                jtr += g * (len / r - 1.0);
            }
            // Levenberg damping: the ring's plane gives no curvature across it
            let damp = 1e-6 * jtj.trace().max(1e-300);
            let Some(step) = (jtj + crate::geometry::Mat3::identity() * damp)
                .lu()
                .solve(&-jtr)
            else {
                break;
            };
            let next = p + step;
            let g = self.ring_strain(x, m, &next);
            if g.is_nan() || g >= f {
                break;
            }
            (p, f) = (next, g);
        }
        (f < self.ring_strain(x, m, &x[m]) && obstacles.is_clear(&p)).then_some(p)
    }

    /// Of the two points at distances `r` from particles `cs` (the first two along the compression), the
    /// one clear of the obstacles, then the nearer to particle `m`, then the more curved, then
    /// the one on this step's random side of the cloth; `None` without an intersection, when
    /// both are blocked, or when one is and the other lies more than [`MAX_JUMP`] rest lengths
    /// away.
    fn choose(
        &mut self,
        x: &[Vec3],
        m: usize,
        cs: [usize; 3],
        r: [f64; 3],
        obstacles: Obstacles<'_>,
    ) -> Option<Vec3> {
        let at = x[m];
        let c = [x[cs[0]], x[cs[1]], x[cs[2]]];
        let (qp, qm) = three_spheres(c, r)?;
        // first by collision: never into a body, nor through the cloth. When the near
        // intersection lies in a body the other is across the centres' plane; from a particle
        // well off that plane the jump (up to 1.36 rest lengths on the cylinder) kicks the
        // cloth, so it is made only if short ([`MAX_JUMP`])
        let short = |q: Vec3| ((q - at).norm() <= MAX_JUMP * r[0]).then_some(q);
        match (obstacles.is_clear(&qp), obstacles.is_clear(&qm)) {
            (true, false) => return short(qp),
            (false, true) => return short(qm),
            (false, false) => return None,
            (true, true) => {}
        }
        let (dp, dm) = ((qp - at).norm(), (qm - at).norm());
        let tol = 1e-9 * r[0];
        if (dp - dm).abs() > tol {
            return Some(if dp < dm { qp } else { qm });
        }
        let (kp, km) = (curvature3(&c[0], &qp, &c[1]), curvature3(&c[0], &qm, &c[1]));
        if (kp - km).abs() > 1e-9 * kp.abs().max(1.0) {
            return Some(if kp > km { qp } else { qm });
        }
        // a tie: the side of the cloth drawn for this step, the same for every tie in it.
        // `qp` lies on the front (the side of the pattern's u × v) when the centres turn
        // counter-clockwise in the pattern.
        let p = &self.pattern;
        let (u, v) = (
            [p[cs[1]][0] - p[cs[0]][0], p[cs[1]][1] - p[cs[0]][1]],
            [p[cs[2]][0] - p[cs[0]][0], p[cs[2]][1] - p[cs[0]][1]],
        );
        let qp_in_front = u[0] * v[1] - u[1] * v[0] > 0.0;
        let front = self.tie_side();
        Some(if front == qp_in_front { qp } else { qm })
    }
}

impl StepStage for CompressionRelease {
    fn constrain(
        &mut self,
        x: &[Vec3],
        _v: &[Vec3],
        _t: f64,
        _dt: f64,
        filter: &mut Filter,
        obstacles: Obstacles<'_>,
    ) {
        self.busy.fill(false);
        self.tie_side = None;
        for b in &mut self.blocked {
            *b = b.saturating_sub(1);
        }
        // particles still held keep their destination, unless cloth–cloth contact stopped them
        // short of it (the hold yields, see `Filter::hold_yielding`): another layer is in the
        // way, and driving the particle on into it each step stretched the sleeve to 0.75 J
        self.held.retain(|h| h.2 > 0);
        let held = std::mem::take(&mut self.held);
        for &(m, q, left) in &held {
            if (x[m] - q).norm() > BLOCKED_TOL {
                self.blocked[m] = self.options.hold_steps.max(1);
                continue;
            }
            if matches!(filter.kind[m], ParticleFilter::Free) {
                filter.hold_yielding(m, q);
                self.held.push((m, q, left - 1));
                self.occupy(m);
            }
        }
        // the most compressed springs first (ties by index: deterministic)
        self.order.clear();
        for (k, &(a, b, rest)) in self.springs.iter().enumerate() {
            let strain = (x[b] - x[a]).norm() / rest - 1.0;
            if strain < -self.options.strain {
                self.order.push((strain, k));
            }
        }
        self.order
            .sort_unstable_by(|p, q| p.0.total_cmp(&q.0).then(p.1.cmp(&q.1)));
        let order = std::mem::take(&mut self.order);
        for &(_, k) in &order {
            let (a, b, _) = self.springs[k];
            for (m, partner) in [(b, a), (a, b)] {
                if self.busy[m]
                    || self.blocked[m] > 0
                    || !matches!(filter.kind[m], ParticleFilter::Free)
                {
                    continue;
                }
                let dest = if self.is_grid() {
                    let along = if b - a == 1 { 1 } else { self.nx };
                    self.destination(x, m, along, obstacles)
                } else {
                    self.mesh_destination(x, m, partner, obstacles)
                };
                if let Some(q) = dest {
                    filter.hold_yielding(m, q);
                    self.held
                        .push((m, q, self.options.hold_steps.saturating_sub(1)));
                    self.occupy(m);
                    self.releases += 1;
                    break;
                }
            }
        }
        self.order = order;
    }

    fn fingerprint(&self, f: &mut crate::geometry::checkpoint::Fingerprint) {
        f.str(&format!("{:?}", self.options))
            .u64(self.nx as u64)
            .u64(self.ny as u64)
            .u64(self.springs.len() as u64);
    }

    fn save_state(&self, e: &mut crate::geometry::checkpoint::Encoder) {
        e.usize(self.held.len());
        for (p, dest, left) in &self.held {
            e.usize(*p);
            e.vec3(dest);
            e.u32(*left);
        }
        e.usize(self.blocked.len());
        self.blocked.iter().for_each(|&b| e.u32(b));
        e.u64(self.rng.state());
        e.u8(match self.tie_side {
            None => 0,
            Some(false) => 1,
            Some(true) => 2,
        });
        e.u64(self.releases);
    }

    fn load_state(
        &mut self,
        d: &mut crate::geometry::checkpoint::Decoder,
    ) -> Result<(), crate::geometry::GeometryError> {
        let n = self.pattern.len();
        let held = d.len(36, "held particles")?;
        self.held = (0..held)
            .map(|_| Ok((d.usize("held particle")?, d.vec3("hold")?, d.u32("hold")?)))
            .collect::<Result<_, crate::geometry::GeometryError>>()?;
        if self.held.iter().any(|h| h.0 >= n) {
            return Err(d.error("a held particle the cloth does not have"));
        }
        let blocked = d.len(4, "blocked particles")?;
        if blocked != self.blocked.len() {
            return Err(d.error("blocked particles of another cloth"));
        }
        self.blocked = (0..blocked)
            .map(|_| d.u32("blocked"))
            .collect::<Result<_, _>>()?;
        self.rng = crate::geometry::SplitMix64::new(d.u64("random state")?);
        self.tie_side = match d.u8("tie side")? {
            0 => None,
            1 => Some(false),
            2 => Some(true),
            b => return Err(d.error(format!("tie side {b}"))),
        };
        self.releases = d.u64("releases")?;
        Ok(())
    }

    fn as_any(&self) -> &dyn std::any::Any {
        self
    }

    fn as_any_mut(&mut self) -> &mut dyn std::any::Any {
        self
    }
}

#[cfg(test)]
mod tests;
