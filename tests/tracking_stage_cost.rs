//! The cost of a stage by difference (the still part of the puppet rendered once,
//! `tracking::stage_cost`) against the full render of every candidate (`cost::pose_cost`):
//! the same number, whatever the workspace rendered before.

use std::path::PathBuf;

use emilion::body::Mannequin;
use emilion::geometry::{SplitMix64, Vec3};
use emilion::tracking::cost::{pose_cost, Appearance, CostWorkspace, FrameViews, Robust};
use emilion::tracking::puppet::{PartGroup, Puppet};
use emilion::tracking::puppet_mesh::{TrackingMesh, DEFAULT_CELL};
use emilion::tracking::pyramid::Level;
use emilion::tracking::sequence::ring_cameras;
use emilion::tracking::stage_cost::{moving_bones, StageBase};

fn noise(w: u32, h: u32, rng: &mut SplitMix64) -> image::RgbImage {
    image::RgbImage::from_fn(w, h, |_, _| {
        image::Rgb([0, 1, 2].map(|_| (rng.uniform() * 255.0) as u8))
    })
}

#[test]
fn a_stage_costed_by_difference_matches_the_full_render() {
    let data = PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../shared/data"));
    let mannequin = Mannequin::load_makehuman(&data.join("bodies/makehuman")).unwrap();
    let puppet = Puppet::new(&mannequin).unwrap();
    let mesh = TrackingMesh::build(&mannequin, &puppet, DEFAULT_CELL);
    let (w, h) = (160, 120);
    let cameras = ring_cameras(4, w, h, Vec3::new(0.0, 0.0, 0.9)).unwrap();
    let mut rng = SplitMix64::new(7);
    let plates: Vec<Level> = (0..4)
        .map(|_| Level::from_image(&noise(w, h, &mut rng)))
        .collect();
    let mut views = FrameViews::new(&cameras, &plates, 2, Robust { sigma: 40.0 });
    let images: Vec<_> = (0..4).map(|_| noise(w, h, &mut rng)).collect();
    views.set_frame(&images);
    // some pixels never change (a static occluder): they do not count
    let masks: Vec<Vec<bool>> = (0..4)
        .map(|_| (0..w * h).map(|_| rng.uniform() > 0.2).collect())
        .collect();
    views.set_active(&masks);
    let colours: Vec<[f32; 3]> = (0..mesh.rest.len())
        .map(|_| [0, 1, 2].map(|_| (rng.uniform() * 255.0) as f32))
        .collect();
    let infos = puppet.params();
    let rest = puppet.rest_params();
    for (coloured, lbs) in [(true, false), (false, false), (true, true)] {
        let app = Appearance {
            puppet: &puppet,
            mesh: &mesh,
            colours: coloured.then_some(colours.as_slice()),
            lbs,
        };
        let mut ws = CostWorkspace::new(&views, mannequin.skeleton().len(), mesh.rest.len());
        let mut base = StageBase::default();
        for group in [PartGroup::LeftArm, PartGroup::RightLeg, PartGroup::Head] {
            let dofs: Vec<usize> = (0..infos.len())
                .filter(|&k| infos[k].group == group)
                .collect();
            let moving = moving_bones(&puppet, &rest, &dofs);
            let fraction = base.rebuild(&app, &views, &rest, &moving, &[0, 1], &mut ws);
            assert!(fraction > 0.0 && fraction < 0.3, "{group:?}: {fraction}");
            let mut worst = 0.0f64;
            for trial in 0..12 {
                let mut p = rest.clone();
                for &k in &dofs {
                    p[k] += (rng.uniform() - 0.5) * 1.2;
                }
                puppet.clamp(&mut p);
                let level = trial % 2;
                let by_difference = base.cost(&app, &views, level, &p, &mut ws).unwrap();
                // every third trial renders the whole puppet in between, in the same workspace
                if trial % 3 == 0 {
                    let _ = pose_cost(&app, &views, 1 - level, &rest, &mut ws);
                }
                let full = pose_cost(&app, &views, level, &p, &mut ws);
                let again = base.cost(&app, &views, level, &p, &mut ws).unwrap();
                assert_eq!(by_difference, again, "{group:?} trial {trial}");
                let scale = (1u64 << (2 * level)) as f64 / 1000.0;
                // one pixel costs `scale`; the full render sums in f32
                let err = (by_difference - full).abs();
                assert!(
                    err < 1e-5 * full.abs().max(1.0) + 1e-3 * scale,
                    "{group:?} level {level} (colours {coloured}, lbs {lbs}): by difference \
                     {by_difference}, full {full}"
                );
                worst = worst.max(err / scale);
            }
            println!("{group:?} (colours {coloured}, lbs {lbs}): {fraction:.3} of the triangles move, worst difference {worst:.2e} pixels");
        }
    }
}
