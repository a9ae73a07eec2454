//! Synthetic broadcast sequences of a real golf swing, with ground truth
//! ([`make_golf_sequence`]): the GEARS C3D swing is fitted with the puppet
//! ([`super::marker_fit`]) and its club ([`super::club`]); the golfer is that fitted body
//! with every segment length and the girth changed by a seeded factor within
//! ±[`GolfSequenceOptions::reshape`] (so the tracker's puppet, built on the plain mannequin,
//! is not the observed person), in clothes-like colours ([`super::clothing`]), holding the
//! club; filmed by broadcast cameras ([`broadcast_cameras`]: face-on, down the line, from
//! behind, high) at 640×480 and 50 fps, with motion blur from the shutter time (each frame is
//! the mean of [`GolfSequenceOptions::blur_samples`] instants over the shutter's opening), in
//! front of real photos, with changing light and noise ([`super::sequence_render`]).
//!
//! A BVH clip instead of a capture ([`super::golf_motion`]) gives the same sequence of
//! another motion (a CMU walk, a dance), without a club: the puppet is fitted to the
//! retargeted mannequin's joints, then reshaped and dressed the same way.
//!
//! The swing's parameters are fitted on every [`GolfSequenceOptions::fit_every`]-th capture
//! frame and interpolated linearly in time between them; the club is carried in the lead
//! hand's bone frame (its grip held at one place in the hand, the shaft turned as captured,
//! moved to the reshaped hand), so the reshaped golfer holds it.
//!
//! # Output layout
//!
//! The layout of [`super::sequence`] (read by [`super::sequence_files::Sequence::open`], so
//! the body tracker reads it as any sequence), with `sequence.json` also holding a `golf`
//! object (capture file, proportions, shutter, camera roles), and besides:
//!
//! ```text
//! DIR/club.csv               frame,time,grip_x,grip_y,grip_z,head_x,head_y,head_z (metres)
//! DIR/truth_metrics.csv      the golf metrics of the ground truth (joints and club at the
//!                            frames' times), with its _rotation and _speed plots
//! ```

use std::path::Path;
use std::sync::{Arc, Mutex};
use std::time::Instant;

use super::clothing::{clothing_colours, shaded_colours, Palette};
use super::club::{club_csv, ClubFit};
use super::club_mesh::ClubMesh;
use super::golf_metrics::{golf_metrics, write_golf_metrics, GolfMetrics};
use super::golf_motion::{club_in_hand, load_motion, reshaped, Swing};
use super::joints::{JOINT_COUNT, TRACKING_JOINTS};
use super::marker_fit::MarkerFitOptions;
use super::puppet::{Proportions, Puppet};
use super::sequence::{SequenceOptions, SequenceSummary};
use super::sequence_dressing::{BodyMotion, DressingOptions, Wardrobe, WardrobeReport};
use super::sequence_files::{io_err, write_sequence_json, write_truth_files, SequenceError};
use super::sequence_render::{mix, SceneMesh, SequenceWriter};
use crate::body::{Mannequin, Pose};
use crate::geometry::Camera;
use crate::geometry::{SplitMix64, Vec3};
use crate::limits;

/// Tracking joints of the hips (`l_hip`, `r_hip` of [`TRACKING_JOINTS`]).
const JOINT_L_HIP: usize = 10;
const JOINT_R_HIP: usize = 13;

/// The ground truth of a frame: the joints, and the club's grip and head when held.
type TruthFrame = ([Vec3; JOINT_COUNT], Option<(Vec3, Vec3)>);

/// The broadcast cameras' roles, in camera order.
pub const CAMERA_ROLES: [&str; 4] = ["face-on", "down-the-line", "behind", "high"];

/// Settings of [`make_golf_sequence`].
#[derive(Clone, Debug)]
pub struct GolfSequenceOptions {
    /// Image size, frame rate, frames, noise, light, occluder, photos, seed (its `cameras`,
    /// 1..=4, takes the first of [`CAMERA_ROLES`]). Defaults: 4 cameras, 640×480, 50 fps, the
    /// whole swing, noise 3, light 0.1, no occluder.
    pub sequence: SequenceOptions,
    /// Shutter time, seconds (0 ..= one frame). Default 1/250 s.
    pub shutter: f64,
    /// Instants averaged over the shutter (1..=32; 1 = no blur). Default 5.
    pub blur_samples: usize,
    /// Largest relative change of each segment length and of the girth (0..=0.2). Default 0.1.
    pub reshape: f64,
    /// Fit every this many capture frames (1..=60). Default 2.
    pub fit_every: usize,
    /// The marker fit's settings. Default: stride 8, 3 rounds.
    pub fit: MarkerFitOptions,
    /// Garments sewn on the golfer and simulated through the swing
    /// ([`super::sequence_dressing`]); `None`: the clothes painted on the skin only.
    pub dressing: Option<DressingOptions>,
}

impl Default for GolfSequenceOptions {
    fn default() -> Self {
        GolfSequenceOptions {
            sequence: SequenceOptions {
                width: 640,
                height: 480,
                noise_sigma: 3.0,
                lighting_amplitude: 0.1,
                occluder_fraction: 0.0,
                ..SequenceOptions::default()
            },
            shutter: 1.0 / 250.0,
            blur_samples: 5,
            reshape: 0.1,
            fit_every: 2,
            fit: MarkerFitOptions {
                rounds: 3,
                ..MarkerFitOptions::default()
            },
            dressing: None,
        }
    }
}

impl GolfSequenceOptions {
    /// Checks the ranges given in the field docs.
    pub fn validate(&self) -> Result<(), SequenceError> {
        self.sequence.validate()?;
        let bad = |m: String| Err(SequenceError::Options(m));
        if self.sequence.cameras > CAMERA_ROLES.len() {
            return bad(format!(
                "cameras must be in 1..=4 for a golf sequence ({}), got {}",
                CAMERA_ROLES.join(", "),
                self.sequence.cameras
            ));
        }
        let frame = 1.0 / self.sequence.fps;
        if !(self.shutter.is_finite() && (0.0..=frame).contains(&self.shutter)) {
            return bad(format!(
                "shutter must be in [0, {frame}] s (one frame), got {}",
                self.shutter
            ));
        }
        if !(1..=32).contains(&self.blur_samples) {
            return bad(format!(
                "blur_samples must be in 1..=32, got {}",
                self.blur_samples
            ));
        }
        if !(self.reshape.is_finite() && (0.0..=0.2).contains(&self.reshape)) {
            return bad(format!("reshape must be in [0, 0.2], got {}", self.reshape));
        }
        if let Some(d) = &self.dressing {
            d.validate()?;
        }
        if !(1..=60).contains(&self.fit_every) {
            return bad(format!(
                "fit_every must be in 1..=60, got {}",
                self.fit_every
            ));
        }
        Ok(())
    }
}

/// What [`make_golf_sequence`] wrote and measured.
#[derive(Clone, Debug)]
pub struct GolfSequenceSummary {
    /// Folder, frames, cameras, size, wall time.
    pub sequence: SequenceSummary,
    /// The golfer's proportions (relative to the mannequin).
    pub proportions: Proportions,
    /// The marker fit's residual RMS, metres.
    pub fit_residual_rms: f64,
    /// The ground truth's golf metrics.
    pub truth: GolfMetrics,
    /// The garments' figures, when dressed.
    pub dressing: Option<WardrobeReport>,
}

/// The broadcast cameras around a golfer whose pelvis stands at `pelvis`, facing `forward`
/// (horizontal unit vector, toward the ball) with the target along `target` (horizontal unit
/// vector): face-on, down the line (behind the trail side, looking at the target), from
/// behind, and high (a crane in front toward the target). Each camera's focal length makes
/// `points` (the body and the club over the swing) fill 85 % of the image's width or height:
/// the whole swing stays in the picture. (Framing the body alone, 80 %, made the golfer twice
/// as tall in the image and the tracking 3.4 times slower and no better: 90 mm against 83.)
pub fn broadcast_cameras(
    n: usize,
    width: u32,
    height: u32,
    pelvis: Vec3,
    forward: Vec3,
    target: Vec3,
    points: &[Vec3],
) -> Result<Vec<Camera>, SequenceError> {
    let centre = Vec3::new(pelvis.x, pelvis.y, 1.0);
    let places = [
        (forward, 6.0, 1.2),
        ((-target + forward * 0.15).normalize(), 7.0, 1.5),
        ((-forward + target * 0.4).normalize(), 6.5, 1.6),
        ((forward + target).normalize(), 7.5, 4.5),
    ];
    places
        .iter()
        .take(n)
        .enumerate()
        .map(|(k, &(dir, dist, h))| {
            let eye = Vec3::new(centre.x, centre.y, 0.0) + dir * dist + Vec3::z() * h;
            let probe = Camera::looking_at_up(eye, centre, Vec3::z(), 1.0, width, height);
            let (mut sx, mut sy) = (1e-6f64, 1e-6f64);
            for p in points {
                let c = probe.to_camera_frame(p);
                if c.z > 0.1 {
                    sx = sx.max((c.x / c.z).abs());
                    sy = sy.max((c.y / c.z).abs());
                }
            }
            let focal = (0.425 * width as f64 / sx).min(0.425 * height as f64 / sy);
            let cam = Camera {
                k1: -0.02,
                ..Camera::looking_at_up(eye, centre, Vec3::z(), focal, width, height)
            };
            cam.validate_named(&format!("cam{k} ({})", CAMERA_ROLES[k]))?;
            Ok(cam)
        })
        .collect()
}

/// Makes a broadcast sequence of the golf swing in `c3d` (a GEARS capture, `.c3d`) or of
/// any motion clip (`.bvh`, no club) into `out` (created; existing files are overwritten):
/// see the [module docs](self).
pub fn make_golf_sequence(
    c3d: &Path,
    out: &Path,
    options: &GolfSequenceOptions,
) -> Result<GolfSequenceSummary, SequenceError> {
    let start = Instant::now();
    options.validate()?;
    let o = &options.sequence;
    let motion_err = |m: String| SequenceError::Motion {
        path: c3d.to_path_buf(),
        message: m,
    };
    let mannequin = Mannequin::load_makehuman(&o.makehuman)?;
    let source = load_motion(&mannequin, c3d, options.fit_every, &options.fit)?;
    let mut rng = SplitMix64::new(mix(o.seed, 6, 0));
    let proportions = reshaped(source.puppet.proportions(), options.reshape, &mut rng);
    let golfer = source
        .puppet
        .with_proportions(&proportions)
        .map_err(motion_err)?;
    let hand = mannequin
        .skeleton()
        .bone_index("wrist.L")
        .ok_or_else(|| motion_err("the mannequin has no bone wrist.L".into()))?;
    let shift = golfer.rest_heads()[hand] - source.puppet.rest_heads()[hand];
    let club = match &source.club {
        Some(c) => {
            Some(club_in_hand(&source.puppet, &source.params, c, hand, shift).map_err(motion_err)?)
        }
        None => None,
    };
    let swing = Swing {
        rate: source.rate,
        club,
        params: source.params.clone(),
        hand,
    };
    let colours = clothing_colours(&mannequin, o.seed);
    if colours.len() != golfer.rest_skin().len() {
        return Err(motion_err(
            "the puppet's skin is not the mannequin's".into(),
        ));
    }

    let frames = match o.frames {
        Some(f) => f,
        None => {
            let n = ((source.duration - o.start_time).max(0.0) * o.fps + 1e-9).floor() + 1.0;
            let what = format!("the frame count of {}", c3d.display());
            limits::check(&what, n, "max_frames", limits::get().max_frames)
                .map_err(|e| SequenceError::Options(e.to_string()))? as usize
        }
    };
    let time = |k: usize| k as f64 / o.fps;

    // the golfer at instant t: skin, joints, grip and head in the world
    let mut pose = Pose::identity(golfer.bone_count());
    let mut params = Vec::new();
    let mut club_mesh = ClubMesh::new();
    let mut at = |t: f64, skin: Option<&mut Vec<Vec3>>| {
        let club = swing.at(o.start_time + t, &mut params);
        golfer.pose_into(&params, &mut pose);
        if let Some(skin) = skin {
            golfer.skin(&pose, skin);
        }
        let joints = golfer.joints(&pose);
        let club = club.map(|(g, h)| (pose.apply(swing.hand, g), pose.apply(swing.hand, h)));
        (joints, club)
    };
    let truth: Vec<TruthFrame> = (0..frames).map(|k| at(time(k), None)).collect();

    // cameras from the address position, framing the whole swing
    let first = truth[0].0;
    let (l_hip, r_hip) = (JOINT_L_HIP, JOINT_R_HIP);
    let flat = |v: Vec3| Vec3::new(v.x, v.y, 0.0);
    let target = flat(first[l_hip] - first[r_hip])
        .try_normalize(1e-9)
        .unwrap_or_else(Vec3::x);
    let forward = target.cross(&Vec3::z());
    let points: Vec<Vec3> = truth.iter().flat_map(|(j, _)| j.iter().copied()).collect();
    let cameras = broadcast_cameras(
        o.cameras, o.width, o.height, first[0], forward, target, &points,
    )?;
    let mut writer = SequenceWriter::new(out, cameras, &points, o)?;
    writer.write_cameras_and_plates()?;
    write_ground_truth(out, &truth, &time, o.seed)?;
    let truth_club = source.club.as_ref().map(|club| ClubFit {
        rate: o.fps,
        head_markers: Vec::new(),
        shaft_markers: Vec::new(),
        head: truth.iter().map(|x| x.1.map(|c| c.1)).collect(),
        grip: truth.iter().map(|x| x.1.map(|c| c.0)).collect(),
        length: club.length,
        grip_rms: club.grip_rms,
    });
    let joints: Vec<[Vec3; JOINT_COUNT]> = truth.iter().map(|x| x.0).collect();
    let metrics = golf_metrics(&joints, o.fps, truth_club.as_ref());
    write_golf_metrics(out, "truth_metrics", &metrics)
        .map_err(|e| SequenceError::Options(e.to_string()))?;

    // the garments, sewn at rest and carried into the swing
    let mut wardrobe = match &options.dressing {
        None => None,
        Some(d) => Some(dress_golfer(&mannequin, &golfer, &swing, o, options, d)?),
    };

    // the frames: the shutter's instants, each the body, the club and the garments, shaded
    let body_triangles: Vec<[u32; 3]> = mannequin
        .triangles()
        .iter()
        .map(|t| t.map(|i| i as u32))
        .collect();
    if swing.club.is_none() {
        club_mesh = ClubMesh::empty();
    }
    let offset = colours.len() as u32;
    let cloth_offset = offset + club_mesh.positions.len() as u32;
    let cloth_triangles = wardrobe
        .as_ref()
        .map_or(Vec::new(), |w| w.triangles(cloth_offset));
    let cloth_colours = wardrobe.as_ref().map_or(Vec::new(), |w| w.colours());
    let triangles: Vec<[u32; 3]> = body_triangles
        .iter()
        .copied()
        .chain(club_mesh.triangles.iter().map(|t| t.map(|i| i + offset)))
        .chain(cloth_triangles)
        .collect();
    let base: Vec<[f32; 3]> = colours
        .iter()
        .chain(&club_mesh.colours)
        .chain(&cloth_colours)
        .copied()
        .collect();
    let blur = options.blur_samples;
    let mut shutter: Vec<SceneMesh> = vec![SceneMesh::default(); blur];
    let mut normals = Vec::new();
    let mut skin = Vec::new();
    for k in 0..frames {
        for (j, scene) in shutter.iter_mut().enumerate() {
            let phase = if blur > 1 {
                j as f64 / (blur - 1) as f64 - 0.5
            } else {
                0.0
            };
            let t = time(k) + phase * options.shutter;
            if let (_, Some((g, h))) = at(t, Some(&mut skin)) {
                club_mesh.place(g, h);
            }
            scene.positions.clear();
            scene.positions.extend_from_slice(&skin);
            scene.positions.extend_from_slice(&club_mesh.positions);
            if let Some(w) = wardrobe.as_mut() {
                w.positions_at(o.start_time + t, &mut scene.positions)?;
            }
            if scene.triangles.is_empty() {
                scene.triangles.clone_from(&triangles);
            }
            shaded_colours(
                &scene.positions,
                &triangles,
                &base,
                &mut normals,
                &mut scene.colours,
                o.shading,
            );
        }
        writer.write_frame(k, time(k), &shutter)?;
        if let Some(w) = wardrobe.as_mut() {
            w.check();
        }
    }
    let meta = serde_json::json!({
        "format": "emilion sequence",
        "version": 1,
        "fps": o.fps,
        "frames": frames,
        "width": o.width,
        "height": o.height,
        "cameras": writer.camera_names(),
        "motion": c3d.file_name().map(|n| n.to_string_lossy().into_owned()),
        "start_time": o.start_time,
        "joints": TRACKING_JOINTS.map(|j| j.name),
        "noise_sigma": o.noise_sigma,
        "lighting_amplitude": o.lighting_amplitude,
        "occluder_fraction": o.occluder_fraction,
        "seed": o.seed,
        "camera_details": writer.camera_details,
        "golf": {
            "roles": &CAMERA_ROLES[..o.cameras],
            "shutter": options.shutter,
            "blur_samples": options.blur_samples,
            "reshape": options.reshape,
            "fit_every": options.fit_every,
            "fit_residual_rms_mm": source.residual_rms * 1e3,
            "club_length": source.club.as_ref().map(|c| c.length),
            "proportions": proportions.to_json(),
            "dressing": wardrobe.as_ref().map(|w| &w.report),
        },
    });
    write_sequence_json(out, &meta)?;
    let seconds = start.elapsed().as_secs_f64();
    Ok(GolfSequenceSummary {
        sequence: SequenceSummary {
            dir: out.to_path_buf(),
            frames,
            cameras: o.cameras,
            width: o.width,
            height: o.height,
            seconds,
            seconds_per_frame: seconds / frames as f64,
        },
        proportions,
        fit_residual_rms: source.residual_rms,
        truth: metrics,
        dressing: wardrobe.map(|w| w.report),
    })
}

/// The golfer's garments of `dressing`, sewn on the golfer at rest and ready to follow the
/// swing from `lead_in` before the first frame.
fn dress_golfer(
    mannequin: &Mannequin,
    golfer: &Puppet,
    swing: &Swing,
    o: &SequenceOptions,
    options: &GolfSequenceOptions,
    dressing: &DressingOptions,
) -> Result<Wardrobe, SequenceError> {
    let person = mannequin.with_rest_skin(golfer.rest_skin())?;
    let start = (o.start_time - dressing.lead_in - options.shutter).max(0.0);
    let hips = |pose: &Pose| {
        let j = golfer.joints(pose);
        [j[JOINT_L_HIP], j[JOINT_R_HIP]]
    };
    let mut params = Vec::new();
    let mut pose = Pose::identity(golfer.bone_count());
    let hips_rest = hips(&pose);
    swing.at(start, &mut params);
    golfer.pose_into(&params, &mut pose);
    let hips_start = hips(&pose);
    let (g, sw) = (golfer.clone(), swing.clone());
    let scratch = Mutex::new((Vec::new(), Pose::identity(golfer.bone_count())));
    let skin_at = move |t: f64, out: &mut Vec<Vec3>| {
        let mut guard = scratch.lock().unwrap_or_else(|e| e.into_inner());
        let (params, pose) = &mut *guard;
        sw.at(t, params);
        g.pose_into(params, pose);
        g.skin(pose, out);
    };
    let motion = BodyMotion {
        skin_at: Arc::new(skin_at),
        start,
        hips_rest,
        hips_start,
    };
    Wardrobe::dress(&person, motion, &Palette::of(o.seed), dressing)
}

/// `ground_truth.csv`, `init_joints.csv` (frame 0 with 2 cm of seeded noise, as
/// [`super::sequence`] writes it) and, with a club, `club.csv`.
fn write_ground_truth(
    out: &Path,
    truth: &[TruthFrame],
    time: &dyn Fn(usize) -> f64,
    seed: u64,
) -> Result<(), SequenceError> {
    let rows: Vec<_> = truth
        .iter()
        .enumerate()
        .map(|(k, x)| (k, time(k), x.0))
        .collect();
    write_truth_files(out, &rows, &mut SplitMix64::new(mix(seed, 4, 0)))?;
    if truth.iter().any(|x| x.1.is_none()) {
        return Ok(());
    }
    let csv = club_csv(
        (truth.iter().enumerate()).filter_map(|(k, (_, c))| c.map(|(g, h)| (k, time(k), g, h))),
    );
    let path = out.join("club.csv");
    std::fs::write(&path, csv).map_err(io_err(&path))
}
