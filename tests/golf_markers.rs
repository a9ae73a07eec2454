//! The GEARS driver swing's club and golf metrics against the data's own figures: the lead
//! wrist marker's peak speed from frame differences (9.75 m/s per the data README), the club
//! head found as the faster cluster (~50 m/s), and `scripts/golf_markers.rhai` end to end.

use emilion::body::read_c3d;
use emilion::geometry::files::data_dir;
use emilion::geometry::Vec3;
use emilion::tracking::club::{fit_club, GEARS_CLUB};
use emilion::tracking::golf_metrics::{fit_plane, golf_metrics, marker_joints};

fn trial() -> Option<emilion::body::MarkerTrial> {
    let c3d = data_dir().join("motion/golf/C3D_TA_Driver.c3d");
    if !c3d.is_file() {
        eprintln!("skipped: {} is absent", c3d.display());
        return None;
    }
    let mut t = read_c3d(&c3d).unwrap();
    t.up = t.infer_up();
    Some(t)
}

#[test]
fn lead_wrist_peak_is_9_75_mps_and_the_club_head_is_the_fast_cluster() {
    let Some(trial) = trial() else { return };
    let (a, b, wrist) = GEARS_CLUB;
    // given in either order, the head is found from the data
    let club = fit_club(&trial, &b, &a, wrist).unwrap();
    assert_eq!(trial.labels[club.head_markers[0]], "Marker_2:2:1");
    let (frame, head) = club.head_peak().unwrap();
    eprintln!(
        "club head peak {head:.2} m/s at frame {frame}; shaft {:.3} m; grip spread {:.1} mm",
        club.length,
        club.grip_rms * 1e3
    );
    assert!((45.0..60.0).contains(&head), "{head}");
    // a driver is 1.1–1.2 m long; the head centroid sits a few cm from the shaft's end
    assert!((0.9..1.3).contains(&club.length), "{}", club.length);
    let m = golf_metrics(&marker_joints(&trial).unwrap(), trial.rate, Some(&club));
    let w = m.lead_wrist_peak();
    assert!((w - 9.75).abs() < 0.005, "lead wrist peak {w}");
    let x = m.x_factor_peak();
    let plane = m.plane.unwrap();
    eprintln!(
        "X-factor peak {x:.1} deg; swing plane {:.1} deg (rms {:.0} mm)",
        plane.inclination_deg,
        plane.rms * 1e3
    );
    assert!(x.is_finite() && x < 90.0, "{x}");
    assert!((20.0..80.0).contains(&plane.inclination_deg));
}

#[test]
fn a_plane_through_a_tilted_circle_has_its_tilt() {
    // a circle of radius 1 in a plane tilted 60° about x: inclination 60°, rms 0
    let t = 60f64.to_radians();
    let pts: Vec<Vec3> = (0..36)
        .map(|k| {
            let a = k as f64 * 10f64.to_radians();
            Vec3::new(a.cos(), a.sin() * t.cos(), a.sin() * t.sin())
        })
        .collect();
    let p = fit_plane(&pts).unwrap();
    assert!(
        (p.inclination_deg - 60.0).abs() < 1e-9,
        "{}",
        p.inclination_deg
    );
    assert!(p.rms < 1e-6, "{}", p.rms);
    assert!(fit_plane(&pts[..2]).is_none());
}

#[cfg(feature = "scripting")]
#[test]
fn golf_markers_script_writes_its_files_and_last_line() {
    if trial().is_none() {
        return;
    }
    let out = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("golf_markers_script");
    let _ = std::fs::remove_dir_all(&out);
    std::fs::create_dir_all(&out).unwrap();
    let root = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let sets = vec![("out".to_string(), out.display().to_string())];
    emilion::script::run_file(&root.join("scripts/golf_markers.rhai"), &sets).unwrap();
    for f in [
        "fit.bvh",
        "residuals.csv",
        "posed.obj",
        "markers_metrics.csv",
        "markers_metrics_rotation.png",
        "markers_metrics_speed.svg",
        "fitted_metrics.csv",
    ] {
        let p = out.join("golf_markers").join(f);
        assert!(
            std::fs::metadata(&p).map_or(0, |m| m.len()) > 0,
            "{}",
            p.display()
        );
    }
}
