//! The puppet fitted to the GEARS driver swing (`../shared/data/motion/golf/`): the residual
//! over all valid markers, the per-marker CSV, and the BVH of the fitted motion read back.

use emilion::body::{read_c3d, Mannequin, Motion};
use emilion::geometry::files::data_dir;
use emilion::tracking::bvh_export::to_bvh_string;
use emilion::tracking::marker_fit::{fit_markers, MarkerFitOptions};
use emilion::tracking::marker_set::MarkerSet;

fn inputs() -> Option<(Mannequin, emilion::body::MarkerTrial)> {
    let c3d = data_dir().join("motion/golf/C3D_TA_Driver.c3d");
    let body = data_dir().join("bodies/makehuman");
    if !c3d.is_file() || !body.is_dir() {
        eprintln!("skipped: {} or {} is absent", c3d.display(), body.display());
        return None;
    }
    let mut trial = read_c3d(&c3d).unwrap();
    trial.up = trial.infer_up();
    Some((Mannequin::load_makehuman(&body).unwrap(), trial))
}

#[test]
fn the_driver_swing_is_fitted_within_15_mm_rms_and_its_bvh_reads_back() {
    let Some((mannequin, full)) = inputs() else {
        return;
    };
    // every third frame (218 frames at 120 Hz) keeps the test in seconds; the whole trial is
    // fitted by `scripts/golf_markers.rhai --set every=1` (docs/golf.md)
    let trial = full.every(3);
    let t0 = std::time::Instant::now();
    let options = MarkerFitOptions {
        calibration_stride: 8,
        rounds: 3,
        ..MarkerFitOptions::default()
    };
    let fit = fit_markers(&mannequin, &trial, &MarkerSet::gears(), &options).unwrap();
    eprintln!("fit in {:.1} s", t0.elapsed().as_secs_f64());
    eprintln!("{}", fit.residual_csv());
    eprintln!("{:?}", fit.puppet.proportions());
    assert_eq!(fit.params.len(), 218);
    // 28 body markers of the set (the club and unnamed points are not on the body)
    assert_eq!(fit.markers.len(), 28);
    let rms = fit.rms();
    assert!(rms <= 0.015, "residual RMS {:.2} mm", rms * 1e3);
    let csv = fit.residual_csv();
    assert_eq!(csv.lines().count(), 1 + 28 + 1);
    // RShoulderTop is missing in most frames: 42 valid samples of 218 (128 of 654)
    assert!(csv.contains("RShoulderTop,42,"));

    // BVH round trip: written, read back by the BVH reader, written again: the same channels
    let joints = fit.joints();
    let rest = fit.puppet.rest_joints();
    let text = to_bvh_string(&joints, trial.rate, Some(&rest)).unwrap();
    let motion = Motion::parse_bvh(&text, "fit.bvh").unwrap();
    assert_eq!(motion.frame_count(), 218);
    assert!((motion.frame_time() - 1.0 / 120.0).abs() < 1e-6);
    let written: Vec<Vec<f64>> = text
        .lines()
        .skip_while(|l| !l.starts_with("Frame Time"))
        .skip(1)
        .map(|l| l.split_whitespace().map(|v| v.parse().unwrap()).collect())
        .collect();
    for (f, row) in written.iter().enumerate() {
        assert_eq!(motion.frame(f), &row[..], "frame {f}");
    }
    // read back and written again (the file's own joints, rest lengths): the same channels
    let again: Vec<[emilion::geometry::Vec3; 16]> = (0..motion.frame_count())
        .map(|f| {
            let p = motion.joint_positions(f);
            std::array::from_fn(|k| {
                let name = emilion::tracking::joints::TRACKING_JOINTS[k].name;
                p[motion.joint_index(name).unwrap()]
            })
        })
        .collect();
    let text2 = to_bvh_string(&again, trial.rate, Some(&rest)).unwrap();
    let motion2 = Motion::parse_bvh(&text2, "again.bvh").unwrap();
    let mut worst = 0.0f64;
    for f in 0..motion.frame_count() {
        for (a, b) in motion.frame(f).iter().zip(motion2.frame(f)) {
            // angles near ±180° may come back wrapped
            let d = (a - b).abs();
            worst = worst.max(d.min((d - 360.0).abs()));
        }
    }
    eprintln!("write, read, write: channels differ by at most {worst}");
    assert!(worst < 1e-3, "channels differ by {worst}");
}
