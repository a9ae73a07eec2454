//! Diagnostics of the tracker on a sequence made from a BVH clip: that the puppet reproduces
//! the ground truth, the cost at the true pose against perturbed poses (per parameter and
//! pyramid level), searches started from the true pose and from perturbed ones, the start
//! (pre-positioning) per joint, and with a third argument, tracking from the true first pose.
//! `cargo run --release --example track_diag -- SEQ_DIR CLIP.bvh [truth]`
//!
//! Limb mode (`LIMB_FRAMES=24,30`, `LIMB=lowerarm01.L`): the texture learnt at the true first
//! pose, then per listed frame the cost at the truth against the truth with that bone's
//! flexion changed, with the left arm's six angles set to `ARM=f,t,s,f,t,s` (upper arm, forearm),
//! and where a search from the truth ends; with `LIMB_TRACK=N`, tracking from the true first
//! pose for N frames, printing the arm's angles against the truth.

use std::path::Path;

use emilion::body::retarget::{Animation, RetargetOptions};
use emilion::body::{Mannequin, Motion};
use emilion::tracking::background_model::sequence_backgrounds;
use emilion::tracking::cost::{pose_cost, Appearance, CostWorkspace, FrameViews, Robust};
use emilion::tracking::joints::mpjpe;
use emilion::tracking::puppet::Puppet;
use emilion::tracking::puppet_mesh::TrackingMesh;
use emilion::tracking::sequence_files::Sequence;
use emilion::tracking::texture::learn_colours;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    if args.len() < 3 {
        return Err("usage: track_diag SEQ_DIR CLIP.bvh [truth]".into());
    }
    let seq = Sequence::open(&args[1])?;
    let mannequin = Mannequin::load_makehuman(Path::new("../shared/data/bodies/makehuman"))?;
    let motion = Motion::load_bvh(Path::new(&args[2]))?;
    let anim = Animation::new(mannequin.clone(), motion, RetargetOptions::default())?;
    let puppet = Puppet::new(&mannequin)?;
    let mesh = TrackingMesh::build(&mannequin, &puppet, 0.03);
    println!(
        "mesh: {} vertices, {} triangles",
        mesh.rest.len(),
        mesh.triangles.len()
    );
    let backgrounds = backgrounds_for(&seq, &args)?;
    let mut views = FrameViews::new(&seq.cameras, &backgrounds, 3, Robust { sigma: 40.0 });
    let mut ws = CostWorkspace::new(&views, mannequin.skeleton().len(), mesh.rest.len());
    let gt_params: Vec<Vec<f64>> = (0..seq.frames)
        .map(|k| puppet.params_from_pose(&anim.pose_at(k as f64 / seq.fps)))
        .collect();
    if let Ok(list) = std::env::var("LIMB_FRAMES") {
        let frames: Vec<usize> = list.split(',').filter_map(|s| s.parse().ok()).collect();
        let joint = std::env::var("LIMB").unwrap_or_else(|_| "lowerarm01.L".into());
        return limb_costs(&seq, &mannequin, &gt_params, &frames, &joint);
    }
    // representation check
    let gt = seq.ground_truth.as_ref().ok_or("no ground truth")?;
    let mut worst: f64 = 0.0;
    for (k, p) in gt_params.iter().enumerate() {
        puppet.pose_into(p, &mut ws.pose);
        worst = worst.max(mpjpe(&puppet.joints(&ws.pose), &gt[k]));
    }
    println!(
        "puppet vs ground truth joints: worst frame {:.3} mm",
        worst * 1000.0
    );
    views.set_frame(&seq.frame_images(0)?);
    let app0 = Appearance {
        puppet: &puppet,
        mesh: &mesh,
        colours: None,
        lbs: false,
    };
    ws.pose_mesh(&app0, &gt_params[0]);
    let vv: Vec<_> = views
        .views
        .iter()
        .map(|v| (&v[0].camera, &v[0].image, Some(v[0].active.as_slice())))
        .collect();
    let (colours, seen) = learn_colours(&mesh, &ws.skinned, &vv);
    println!(
        "texture: {seen} of {} vertices seen; gains {:?}",
        mesh.rest.len(),
        views.gains
    );
    let app = Appearance {
        colours: Some(&colours),
        ..app0
    };
    for &k in &[0usize, 5, 10, 15] {
        if k >= seq.frames {
            break;
        }
        views.set_frame(&seq.frame_images(k)?);
        for level in 0..3 {
            let c0 = pose_cost(&app, &views, level, &gt_params[k], &mut ws);
            let s0 = pose_cost(&app0, &views, level, &gt_params[k], &mut ws);
            let mut line = format!(
                "frame {k} level {level}: cost {c0:.3} (silhouette {s0:.3}); +0.15 rad / 3 cm on"
            );
            for (i, info) in puppet.params().iter().enumerate() {
                if i % 3 != 0 && i >= 6 {
                    continue;
                }
                let mut p = gt_params[k].clone();
                p[i] += if i < 3 { 0.03 } else { 0.15 };
                let c = pose_cost(&app, &views, level, &p, &mut ws);
                line += &format!(" {}:{:+.3}", info.name, c - c0);
            }
            println!("{line}");
        }
    }
    if let Some(init) = &seq.init_joints {
        let fit = puppet.fit_to_joints(init, &puppet.rest_params());
        puppet.pose_into(&fit, &mut ws.pose);
        println!(
            "fit to the init joints: {:.1} mm from the truth",
            1000.0 * mpjpe(&puppet.joints(&ws.pose), &gt[0])
        );
        let backgrounds = backgrounds_for(&seq, &args)?;
        let mut t = emilion::tracking::tracker::Tracker::new(
            &mannequin,
            &seq.cameras,
            &backgrounds,
            Default::default(),
        )?;
        let p = t.start(&seq.frame_images(0)?, init)?;
        println!(
            "after the start: {:.1} mm",
            1000.0 * mpjpe(&t.joints(&p), &gt[0])
        );
        let names = emilion::tracking::joints::TRACKING_JOINTS;
        let fj = puppet.joints(&ws.pose);
        let sj = t.joints(&p);
        for k in 0..16 {
            println!(
                "  {:10} init {:5.1} fit {:5.1} start {:5.1} mm",
                names[k].name,
                1000.0 * (init[k] - gt[0][k]).norm(),
                1000.0 * (fj[k] - gt[0][k]).norm(),
                1000.0 * (sj[k] - gt[0][k]).norm()
            );
        }
    }
    if args.len() > 3 {
        track_from_truth(&seq, &mannequin, &gt_params, 20, Default::default())?;
    }
    Ok(())
}

/// Tracks `frames` frames from the true first pose; prints per-frame errors (mm).
pub fn track_from_truth(
    seq: &Sequence,
    mannequin: &Mannequin,
    gt_params: &[Vec<f64>],
    frames: usize,
    options: emilion::tracking::tracker::TrackerOptions,
) -> Result<(), Box<dyn std::error::Error>> {
    let backgrounds = backgrounds_for(seq, &std::env::args().collect::<Vec<_>>())?;
    let mut t =
        emilion::tracking::tracker::Tracker::new(mannequin, &seq.cameras, &backgrounds, options)?;
    let gt = seq.ground_truth.as_ref().ok_or("no ground truth")?;
    t.start_at(&seq.frame_images(0)?, &gt_params[0])?;
    let mut rng = emilion::geometry::SplitMix64::new(5);
    for k in [1usize, 5, 10] {
        t.set_frame(&seq.frame_images(k)?)?;
        for noise in [0.02, 0.05, 0.1] {
            let mut p0 = gt_params[k].clone();
            for (i, v) in p0.iter_mut().enumerate() {
                *v += if i < 3 { noise * 0.3 } else { noise } * rng.normal();
            }
            let e0 = 1000.0 * mpjpe(&t.joints(&p0), &gt[k]);
            let (p1, _) = t.search(&p0, 1.0);
            let (p2, _) = t.search(&p1, 0.35);
            let (p3, _) = t.search(&p2, 0.15);
            let (p4, _) = t.search(&p3, 0.07);
            println!(
                "frame {k}: from {e0:.1} mm off: passes {:.1} {:.1} {:.1} {:.1} mm",
                1000.0 * mpjpe(&t.joints(&p1), &gt[k]),
                1000.0 * mpjpe(&t.joints(&p2), &gt[k]),
                1000.0 * mpjpe(&t.joints(&p3), &gt[k]),
                1000.0 * mpjpe(&t.joints(&p4), &gt[k])
            );
        }
        for scale in [0.0, 0.3, 1.0] {
            let (p, c) = t.search(&gt_params[k], scale);
            println!("frame {k}: search from the true pose (spread ×{scale}) ends {:.1} mm away, cost {c:.3}", 1000.0 * mpjpe(&t.joints(&p), &gt[k]));
        }
    }
    t.start_at(&seq.frame_images(0)?, &gt_params[0])?;
    let t0 = std::time::Instant::now();
    let mut line = String::from("from truth:");
    for (k, truth) in gt.iter().enumerate().take(frames.min(seq.frames)).skip(1) {
        let (p, _) = t.track(&seq.frame_images(k)?)?;
        line += &format!(" {:.0}", 1000.0 * mpjpe(&t.joints(&p), truth));
    }
    println!(
        "{line}  ({:.2} s/frame)",
        t0.elapsed().as_secs_f64() / frames as f64
    );
    Ok(())
}

/// The sequence's clean plates, or the median of its frames.
fn backgrounds_for(
    seq: &Sequence,
    _args: &[String],
) -> Result<Vec<emilion::tracking::pyramid::Level>, Box<dyn std::error::Error>> {
    if let Some(plates) = seq.background_plates()? {
        return Ok(plates
            .iter()
            .map(emilion::tracking::pyramid::Level::from_image)
            .collect());
    }
    Ok(sequence_backgrounds(seq, seq.frames, 25)?)
}

/// For each of `frames`: the image cost at the true pose against the true pose with bone
/// `bone`'s flexion set to 0 (straightened) and to ±0.5 rad from the truth, then where a
/// search started from the truth ends (joint errors), the texture learnt at the true pose of
/// frame 0.
fn limb_costs(
    seq: &Sequence,
    mannequin: &Mannequin,
    gt_params: &[Vec<f64>],
    frames: &[usize],
    bone: &str,
) -> Result<(), Box<dyn std::error::Error>> {
    let backgrounds = backgrounds_for(seq, &[])?;
    let mut t = emilion::tracking::tracker::Tracker::new(
        mannequin,
        &seq.cameras,
        &backgrounds,
        Default::default(),
    )?;
    let gt = seq.ground_truth.as_ref().ok_or("no ground truth")?;
    t.start_at(&seq.frame_images(0)?, &gt_params[0])?;
    let infos = t.puppet().params().to_vec();
    let flex = infos
        .iter()
        .position(|i| i.name == format!("{bone}.flex"))
        .ok_or("no such bone")?;
    let names = emilion::tracking::joints::TRACKING_JOINTS;
    if let Ok(n) = std::env::var("LIMB_TRACK") {
        // track from the true first pose, printing the limb's parameters against the truth
        let n: usize = n.parse()?;
        let dofs: Vec<usize> = (0..infos.len())
            .filter(|&i| {
                infos[i]
                    .name
                    .starts_with(bone.split('.').next().unwrap_or(bone))
                    || infos[i].name.starts_with(&format!(
                        "upperarm01.{}",
                        bone.rsplit('.').next().unwrap_or("L")
                    ))
            })
            .collect();
        let label: Vec<&str> = dofs.iter().map(|&i| infos[i].name.as_str()).collect();
        println!("{label:?}");
        for k in 1..n.min(seq.frames) {
            let (p, _) = t.track(&seq.frame_images(k)?)?;
            let j = t.joints(&p);
            let wrist = 1000.0 * (j[6] - gt[k][6]).norm();
            let tr: Vec<String> = dofs.iter().map(|&i| format!("{:+.2}", p[i])).collect();
            let gv: Vec<String> = dofs
                .iter()
                .map(|&i| format!("{:+.2}", gt_params[k][i]))
                .collect();
            println!(
                "{k}: l_wrist {wrist:.0} mm; tracked {} truth {}",
                tr.join(" "),
                gv.join(" ")
            );
        }
        return Ok(());
    }
    for &k in frames {
        t.set_frame(&seq.frame_images(k)?)?;
        let truth = &gt_params[k];
        let (_, c0) = t.search(truth, 0.0);
        let mut line = format!(
            "frame {k}: {bone}.flex {:.2}, cost at truth {c0:.4};",
            truth[flex]
        );
        for (label, value) in [
            ("straight", 0.0),
            ("-0.5", truth[flex] - 0.5),
            ("+0.5", truth[flex] + 0.5),
        ] {
            let mut p = truth.clone();
            p[flex] = value;
            let (_, c) = t.search(&p, 0.0);
            line += &format!(" {label} {:+.4}", c - c0);
        }
        if let Ok(arm) = std::env::var("ARM") {
            // the truth with the left arm's six angles replaced
            let vals: Vec<f64> = arm.split(',').filter_map(|s| s.parse().ok()).collect();
            let mut p = truth.clone();
            let first = infos
                .iter()
                .position(|i| i.name == "upperarm01.L.flex")
                .ok_or("no upper arm")?;
            for (o, v) in vals.iter().enumerate() {
                p[first + o] = *v;
            }
            let (_, c) = t.search(&p, 0.0);
            line += &format!(" given arm {:+.4}", c - c0);
        }
        let (p, c) = t.search(truth, 0.5);
        let j = t.joints(&p);
        line += &format!(
            "; search from truth: cost {:+.4}, flex {:.2},",
            c - c0,
            p[flex]
        );
        for (i, n) in names.iter().enumerate() {
            let e = 1000.0 * (j[i] - gt[k][i]).norm();
            if e > 40.0 {
                line += &format!(" {} {e:.0}", n.name);
            }
        }
        println!("{line}");
    }
    Ok(())
}
