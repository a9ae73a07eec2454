//! The image cost of a candidate pose: the puppet is posed, skinned, rendered with its
//! learnt colours into every camera at one pyramid level, and compared with the images.
//!
//! Over the puppet's footprint in each camera the cost adds
//! `ρ(I − R) − ρ(I − B)`: a robust colour difference between the image `I` and the rendered
//! puppet `R`, minus the same difference between the image and the camera's background
//! model `B`. Summed over the footprint this equals, up to a constant, the robust difference
//! between the image and the puppet composited over the background, over the whole picture:
//! the second term is the background-consistency term, which rewards covering pixels that
//! do not look like the background and penalises covering pixels that do. Before the puppet
//! has colours (first frame) only the background term is used (a silhouette fit).
//! `ρ(d) = d² / (d² + σ²)` (Geman–McClure) on the RGB distance bounds the effect of
//! occluders, noise and shading changes. Images are divided by their lighting gain first.
//!
//! Each thread evaluates candidates in its own [`CostWorkspace`]; nothing is allocated per
//! evaluation.

use image::RgbImage;

use super::puppet::Puppet;
use super::puppet_mesh::TrackingMesh;
use super::pyramid::{build_pyramid, lighting_gain, Level};
use crate::body::skinning::Pose;
use crate::geometry::Camera;
use crate::geometry::Vec3;
use crate::render::raster::{draw_triangles, project_vertices, PixelBox, RasterTarget};

/// Without colours, what covering a pixel costs before the background term: covering a
/// background pixel (ρ(I − B) ≈ 0) costs this much, covering a foreground pixel
/// (ρ(I − B) ≈ 1) saves as much, so the silhouette cost is the symmetric difference between
/// the puppet's footprint and the foreground, up to a constant.
const SILHOUETTE_COVER: f32 = 0.5;

/// Geman–McClure robust function of a squared RGB distance.
#[derive(Clone, Copy, Debug)]
pub struct Robust {
    /// Scale σ (grey levels): distances well above it count about the same.
    pub sigma: f32,
}

impl Robust {
    /// `d² / (d² + σ²)`.
    #[inline]
    pub fn rho(&self, d2: f32) -> f32 {
        d2 / (d2 + self.sigma * self.sigma)
    }

    /// ρ of the distance between two colours.
    #[inline]
    pub fn rho_colours(&self, a: &[f32; 3], b: &[f32; 3]) -> f32 {
        let d2 = (a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2);
        self.rho(d2)
    }
}

/// One camera at one pyramid level: the scaled camera, the gain-normalised image and the
/// per-pixel background term ρ(I − B).
#[derive(Clone, Debug)]
pub struct ViewLevel {
    /// The camera at this level's resolution.
    pub camera: Camera,
    /// The current frame, divided by its lighting gain.
    pub image: Level,
    /// The background model at this level.
    pub background: Level,
    /// ρ(I − B) per pixel.
    pub bg_cost: Vec<f32>,
    /// Pixels that count: false where the scene never changes over the sequence (the image
    /// always looks like the background there), which is where a static occluder stands in
    /// front of the person or where the person never goes. Covering them costs nothing, so
    /// a limb hidden behind an occluder is placed by the cameras that see it.
    pub active: Vec<bool>,
}

/// Every camera at every pyramid level, for the current frame.
#[derive(Clone, Debug)]
pub struct FrameViews {
    /// `views[camera][level]`.
    pub views: Vec<Vec<ViewLevel>>,
    /// Lighting gain of the current frame per camera.
    pub gains: Vec<f32>,
    pub(super) robust: Robust,
    /// Most a puppet pixel may cost (1: no cap; ρ ≤ 1). Lower values make covering the
    /// background or an occluder cheaper (tried: 0.3 and 0.1 did not help on the punch).
    pub cover_cap: f32,
    scratch: Vec<f32>,
}

/// The camera scaled to pyramid level `level` (each level halves the size).
pub fn camera_at_level(camera: &Camera, level: usize) -> Camera {
    camera.scaled((1u32 << level) as f64)
}

impl FrameViews {
    /// Views of `cameras` with their background models (level 0, one per camera), with
    /// `levels` pyramid levels.
    pub fn new(cameras: &[Camera], backgrounds: &[Level], levels: usize, robust: Robust) -> Self {
        let views = cameras
            .iter()
            .zip(backgrounds)
            .map(|(cam, bg)| {
                let mut bgs = vec![bg.clone()];
                for l in 1..levels.max(1) {
                    let mut next = Level::default();
                    bgs[l - 1].half_into(&mut next);
                    bgs.push(next);
                }
                bgs.into_iter()
                    .enumerate()
                    .map(|(l, background)| ViewLevel {
                        camera: camera_at_level(cam, l),
                        image: Level::default(),
                        bg_cost: vec![0.0; background.rgb.len()],
                        active: vec![true; background.rgb.len()],
                        background,
                    })
                    .collect()
            })
            .collect();
        FrameViews {
            views,
            gains: vec![1.0; cameras.len()],
            robust,
            cover_cap: 1.0,
            scratch: Vec::new(),
        }
    }

    /// Number of pyramid levels.
    pub fn levels(&self) -> usize {
        self.views.first().map_or(0, Vec::len)
    }

    /// The robust function in use.
    pub fn robust(&self) -> Robust {
        self.robust
    }

    /// Marks the pixels that count, per camera at full resolution (see
    /// [`ViewLevel::active`]); a coarser pixel counts when at least two of its four do.
    pub fn set_active(&mut self, masks: &[Vec<bool>]) {
        for (view, mask) in self.views.iter_mut().zip(masks) {
            let mut current = mask.clone();
            let mut width = view[0].background.width;
            for (l, vl) in view.iter_mut().enumerate() {
                if l > 0 {
                    let (w, h) = (vl.background.width, vl.background.height);
                    let mut next = vec![true; w * h];
                    for y in 0..h {
                        for x in 0..w {
                            let i = 2 * y * width + 2 * x;
                            let n = [i, i + 1, i + width, i + width + 1]
                                .iter()
                                .filter(|&&j| current.get(j).copied().unwrap_or(true))
                                .count();
                            next[y * w + x] = n >= 2;
                        }
                    }
                    current = next;
                    width = w;
                }
                if current.len() == vl.active.len() {
                    vl.active.copy_from_slice(&current);
                }
            }
        }
    }

    /// Loads a new frame (one image per camera, sizes already checked): pyramid, lighting
    /// gain against the background, and the background term. Images beyond the cameras
    /// are ignored.
    pub fn set_frame(&mut self, images: &[RgbImage]) {
        let mut pyr = Vec::new();
        for (c, img) in images.iter().enumerate().take(self.views.len()) {
            let levels = self.views[c].len();
            build_pyramid(img, levels, &mut pyr);
            let gain = lighting_gain(&pyr[0], &self.views[c][0].background, &mut self.scratch)
                .clamp(0.2, 5.0);
            self.gains[c] = gain;
            for (l, level) in pyr.iter_mut().enumerate() {
                level.scale(1.0 / gain);
                let v = &mut self.views[c][l];
                std::mem::swap(&mut v.image, level);
                let r = self.robust;
                for ((out, i), b) in v
                    .bg_cost
                    .iter_mut()
                    .zip(&v.image.rgb)
                    .zip(&v.background.rgb)
                {
                    *out = r.rho_colours(i, b);
                }
            }
        }
    }
}

/// What is rendered: the puppet, its light mesh and per-vertex colours.
#[derive(Clone, Copy)]
pub struct Appearance<'a> {
    /// The puppet (pose parameters → bone transforms).
    pub puppet: &'a Puppet,
    /// The light mesh.
    pub mesh: &'a TrackingMesh,
    /// Colours per mesh vertex; `None` before they are learnt (silhouette cost only).
    pub colours: Option<&'a [[f32; 3]]>,
    /// Linear blend skinning instead of rigid (each vertex on its dominant bone).
    pub lbs: bool,
}

/// Per-thread buffers of the cost evaluation.
#[derive(Debug)]
pub struct CostWorkspace {
    /// Bone transforms of the candidate.
    pub pose: Pose,
    /// Skinned mesh vertices.
    pub skinned: Vec<Vec3>,
    pub(super) projected: Vec<[f32; 3]>,
    pub(super) grey: Vec<[f32; 3]>,
    /// `targets[camera][level]`.
    pub(super) targets: Vec<Vec<RasterTarget>>,
    /// The moving part's skinned vertices ([`super::stage_cost`]).
    pub(super) moving: Vec<Vec3>,
    /// Per camera and level: the [`super::stage_cost::StageBase`] generation the target was
    /// last restored from, and the box drawn since (`None`: unknown, restore everything).
    pub(super) restored: Vec<Vec<(u64, Option<PixelBox>)>>,
}

impl CostWorkspace {
    /// Buffers for `views` and a puppet whose mannequin has `bones` bones.
    pub fn new(views: &FrameViews, bones: usize, vertices: usize) -> Self {
        CostWorkspace {
            pose: Pose::identity(bones),
            skinned: vec![Vec3::zeros(); vertices],
            projected: Vec::with_capacity(vertices),
            grey: vec![[128.0; 3]; vertices],
            targets: views
                .views
                .iter()
                .map(|v| {
                    v.iter()
                        .map(|l| RasterTarget::new(l.image_width(), l.image_height()))
                        .collect()
                })
                .collect(),
            moving: Vec::with_capacity(vertices),
            restored: views
                .views
                .iter()
                .map(|v| vec![(0, None); v.len()])
                .collect(),
        }
    }

    /// Poses and skins the mesh for `params`.
    pub fn pose_mesh(&mut self, app: &Appearance, params: &[f64]) {
        app.puppet.pose_into(params, &mut self.pose);
        if app.lbs {
            app.mesh.skin_lbs_into(&self.pose, &mut self.skinned);
        } else {
            app.mesh.skin_rigid_into(&self.pose, &mut self.skinned);
        }
    }

    /// The rendered target of camera `c` at `level` after the last [`pose_cost`].
    pub fn target(&self, c: usize, level: usize) -> &RasterTarget {
        &self.targets[c][level]
    }
}

impl ViewLevel {
    fn image_width(&self) -> usize {
        self.camera.width as usize
    }
    fn image_height(&self) -> usize {
        self.camera.height as usize
    }
}

/// What covering one (active) pixel costs: `min(ρ(I − R) − ρ(I − B), cap)` with colours,
/// `SILHOUETTE_COVER − ρ(I − B)` without (`bg` = ρ(I − B)).
#[inline]
pub(super) fn pixel_cost(
    coloured: bool,
    robust: Robust,
    cap: f32,
    image: &[f32; 3],
    render: &[f32; 3],
    bg: f32,
) -> f32 {
    if coloured {
        (robust.rho_colours(image, render) - bg).min(cap)
    } else {
        SILHOUETTE_COVER - bg
    }
}

/// The cost of pose `params` at pyramid `level` (lower is better). Per pixel terms are
/// summed over cameras and scaled by `4^level / 1000`, so levels give comparable numbers.
pub fn pose_cost(
    app: &Appearance,
    views: &FrameViews,
    level: usize,
    params: &[f64],
    ws: &mut CostWorkspace,
) -> f64 {
    ws.pose_mesh(app, params);
    let robust = views.robust;
    let cover_cap = views.cover_cap;
    let mut total = 0.0f64;
    for (c, view) in views.views.iter().enumerate() {
        let vl = &view[level];
        project_vertices(&vl.camera, &ws.skinned, &mut ws.projected);
        let target = &mut ws.targets[c][level];
        target.clear();
        ws.restored[c][level] = (0, None);
        let colours = app.colours.unwrap_or(&ws.grey);
        draw_triangles(target, &ws.projected, colours, &app.mesh.triangles);
        let Some((x0, y0, x1, y1)) = target.touched() else {
            continue;
        };
        let w = target.width;
        let mut sum = 0.0f64;
        for y in y0..y1 {
            let row = y * w;
            for i in row + x0..row + x1 {
                if target.depth[i] < f32::INFINITY && vl.active[i] {
                    sum += pixel_cost(
                        app.colours.is_some(),
                        robust,
                        cover_cap,
                        &vl.image.rgb[i],
                        &target.rgb[i],
                        vl.bg_cost[i],
                    ) as f64;
                }
            }
        }
        total += sum;
    }
    total * (1u64 << (2 * level)) as f64 / 1000.0
}
