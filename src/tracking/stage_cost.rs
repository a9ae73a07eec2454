//! The image cost of a search stage that moves one part of the puppet (the head, an arm, a
//! leg), computed by difference. The rest of the puppet is rendered once when the stage
//! starts, and its render and per-pixel cost are kept for every camera and pyramid level
//! ([`StageBase`]). Each candidate then only skins, projects and draws the triangles that touch
//! the moving part over a copy of that render, and adds up the change where they show. The sum
//! is [`pose_cost`](super::cost::pose_cost)'s up to rounding (test), for a fraction of the
//! work: an arm is about a sixth of the tracking mesh, and rasterising is most of the
//! tracker's time.

use std::sync::atomic::{AtomicU64, Ordering};

use super::cost::{pixel_cost, Appearance, CostWorkspace, FrameViews};
use super::puppet::Puppet;
use crate::body::skinning::Pose;
use crate::render::raster::{draw_triangles, project_vertices, RasterTarget};

/// A stage whose moving triangles are at least this fraction of the mesh is not worth a base
/// (the trunk moves everything): [`StageBase::rebuild`] makes none.
pub const MAX_MOVING_FRACTION: f64 = 0.5;

/// Generations of bases, so a workspace knows which base its targets were last restored from.
static GENERATION: AtomicU64 = AtomicU64::new(1);

/// The part of the mesh a stage leaves still, rendered in one camera at one level.
#[derive(Clone, Debug)]
struct BaseView {
    target: RasterTarget,
    /// What each pixel costs as the still part covers it (0 where it does not, or where the
    /// pixel does not count).
    cost: Vec<f32>,
    /// The sum of `cost`.
    total: f64,
    /// Whether this level was rendered for the current stage.
    built: bool,
}

/// The still part of the puppet during one stage, and the moving part's triangles.
#[derive(Clone, Debug, Default)]
pub struct StageBase {
    generation: u64,
    /// Mesh vertices of the triangles that touch a moving vertex (global indices).
    vertices: Vec<u32>,
    /// Those triangles, indexing `vertices`.
    triangles: Vec<[u32; 3]>,
    /// Colours of `vertices`.
    colours: Vec<[f32; 3]>,
    /// The other triangles (global indices), drawn once into the base.
    still: Vec<[u32; 3]>,
    /// `views[camera][level]`.
    views: Vec<Vec<BaseView>>,
    /// Global index → index in `vertices` (`u32::MAX`: not there).
    local: Vec<u32>,
    /// Whether the last [`rebuild`](Self::rebuild) made a usable base.
    ready: bool,
}

/// The bones whose transform changes when any of the parameters `dofs` changes from
/// `params` (the driven bones and everything they carry).
pub fn moving_bones(puppet: &Puppet, params: &[f64], dofs: &[usize]) -> Vec<bool> {
    let mut base = Pose::identity(0);
    let mut moved = Pose::identity(0);
    puppet.pose_into(params, &mut base);
    let mut flags = vec![false; base.transforms().len()];
    let mut p = params.to_vec();
    for &k in dofs {
        for step in [0.3, -0.3] {
            p[k] = params[k] + step;
            puppet.pose_into(&p, &mut moved);
            for (f, (a, b)) in flags
                .iter_mut()
                .zip(base.transforms().iter().zip(moved.transforms()))
            {
                let d = a.inverse() * b;
                if d.translation.vector.norm() > 1e-12 || d.rotation.angle() > 1e-12 {
                    *f = true;
                }
            }
        }
        p[k] = params[k];
    }
    flags
}

impl StageBase {
    /// Renders the still part of the puppet at `params` into every camera at each of
    /// `levels`, the moving part being the mesh vertices on `moving` bones. Returns the
    /// fraction of the triangles that move; the base is only made (and
    /// [`cost`](Self::cost) only answers) when that fraction is below
    /// [`MAX_MOVING_FRACTION`].
    pub fn rebuild(
        &mut self,
        app: &Appearance,
        views: &FrameViews,
        params: &[f64],
        moving: &[bool],
        levels: &[usize],
        ws: &mut CostWorkspace,
    ) -> f64 {
        self.ready = false;
        let mesh = app.mesh;
        let n = mesh.rest.len();
        let on = |b: u32| moving.get(b as usize).copied().unwrap_or(false);
        let vertex_moves = |v: usize| {
            if app.lbs {
                (0..4).any(|k| mesh.lbs_weights[v][k] > 0.0 && on(mesh.lbs_bones[v][k]))
            } else {
                on(mesh.bone[v])
            }
        };
        let moves: Vec<bool> = (0..n).map(vertex_moves).collect();
        self.still.clear();
        self.triangles.clear();
        self.vertices.clear();
        self.local.clear();
        self.local.resize(n, u32::MAX);
        for t in &mesh.triangles {
            if t.iter().any(|&v| (v as usize) >= n) {
                continue;
            }
            if !t.iter().any(|&v| moves[v as usize]) {
                self.still.push(*t);
                continue;
            }
            let mut lt = [0u32; 3];
            for (l, &v) in lt.iter_mut().zip(t) {
                if self.local[v as usize] == u32::MAX {
                    self.local[v as usize] = self.vertices.len() as u32;
                    self.vertices.push(v);
                }
                *l = self.local[v as usize];
            }
            self.triangles.push(lt);
        }
        let fraction = self.triangles.len() as f64 / mesh.triangles.len().max(1) as f64;
        if fraction >= MAX_MOVING_FRACTION {
            return fraction;
        }
        ws.pose_mesh(app, params);
        let all_colours: &[[f32; 3]] = app.colours.unwrap_or(&ws.grey);
        self.colours.clear();
        self.colours
            .extend(self.vertices.iter().map(|&v| all_colours[v as usize]));
        let coloured = app.colours.is_some();
        let robust = views.robust;
        let cap = views.cover_cap;
        self.views.resize_with(views.views.len(), Vec::new);
        for (c, view) in views.views.iter().enumerate() {
            let bv = &mut self.views[c];
            if bv.len() != view.len() {
                *bv = view
                    .iter()
                    .map(|vl| {
                        let (w, h) = (vl.camera.width as usize, vl.camera.height as usize);
                        BaseView {
                            target: RasterTarget::new(w, h),
                            cost: vec![0.0; w * h],
                            total: 0.0,
                            built: false,
                        }
                    })
                    .collect();
            }
            for (l, (vl, b)) in view.iter().zip(bv.iter_mut()).enumerate() {
                b.built = false;
                if !levels.contains(&l) {
                    continue;
                }
                if let Some((x0, y0, x1, y1)) = b.target.touched() {
                    for y in y0..y1 {
                        b.cost[y * b.target.width + x0..y * b.target.width + x1].fill(0.0);
                    }
                }
                b.target.clear();
                project_vertices(&vl.camera, &ws.skinned, &mut ws.projected);
                draw_triangles(&mut b.target, &ws.projected, all_colours, &self.still);
                let mut total = 0.0f64;
                if let Some((x0, y0, x1, y1)) = b.target.touched() {
                    let w = b.target.width;
                    for y in y0..y1 {
                        for i in y * w + x0..y * w + x1 {
                            if b.target.depth[i] < f32::INFINITY && vl.active[i] {
                                let pc = pixel_cost(
                                    coloured,
                                    robust,
                                    cap,
                                    &vl.image.rgb[i],
                                    &b.target.rgb[i],
                                    vl.bg_cost[i],
                                );
                                b.cost[i] = pc;
                                total += pc as f64;
                            }
                        }
                    }
                }
                b.total = total;
                b.built = true;
            }
        }
        self.generation = GENERATION.fetch_add(1, Ordering::Relaxed);
        self.ready = true;
        fraction
    }

    /// The cost of pose `params` at `level` (as [`pose_cost`](super::cost::pose_cost)),
    /// provided `params` differs from the base's pose only in the stage's parameters; `None`
    /// when the base was not made for this level.
    pub fn cost(
        &self,
        app: &Appearance,
        views: &FrameViews,
        level: usize,
        params: &[f64],
        ws: &mut CostWorkspace,
    ) -> Option<f64> {
        if !self.ready || self.views.len() != views.views.len() {
            return None;
        }
        if !self
            .views
            .iter()
            .all(|v| v.get(level).is_some_and(|b| b.built))
        {
            return None;
        }
        app.puppet.pose_into(params, &mut ws.pose);
        app.mesh
            .skin_subset_into(&ws.pose, app.lbs, &self.vertices, &mut ws.moving);
        let coloured = app.colours.is_some();
        let robust = views.robust;
        let cap = views.cover_cap;
        let mut total = 0.0f64;
        for (c, view) in views.views.iter().enumerate() {
            let vl = &view[level];
            let base = &self.views[c][level];
            project_vertices(&vl.camera, &ws.moving, &mut ws.projected);
            let target = &mut ws.targets[c][level];
            let (generation, drawn) = ws.restored[c][level];
            let changed = (generation == self.generation).then(|| drawn.unwrap_or((0, 0, 0, 0)));
            if !target.restore_from(&base.target, changed) {
                return None;
            }
            let drawn = draw_triangles(target, &ws.projected, &self.colours, &self.triangles);
            ws.restored[c][level] = (self.generation, Some(drawn.unwrap_or((0, 0, 0, 0))));
            let mut delta = 0.0f64;
            if let Some((x0, y0, x1, y1)) = drawn {
                let w = target.width;
                for y in y0..y1 {
                    for i in y * w + x0..y * w + x1 {
                        if target.depth[i] < base.target.depth[i] && vl.active[i] {
                            let pc = pixel_cost(
                                coloured,
                                robust,
                                cap,
                                &vl.image.rgb[i],
                                &target.rgb[i],
                                vl.bg_cost[i],
                            );
                            delta += pc as f64 - base.cost[i] as f64;
                        }
                    }
                }
            }
            total += base.total + delta;
        }
        Some(total * (1u64 << (2 * level)) as f64 / 1000.0)
    }
}
