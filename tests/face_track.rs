//! Face sequences and the face tracker: the synthetic sequence's files and determinism, tracking
//! against its ground truth (head pose and FAP values), the script's last line, and bad inputs.
#![cfg(feature = "scripting")]

use std::path::{Path, PathBuf};

use emilion::face::sequence::make_face_sequence;
use emilion::face::sequence_files::FaceSequence;
use emilion::face::sequence_options::FaceSequenceOptions;
use emilion::face::track_run::{track_face_sequence, write_face_track_outputs};
use emilion::face::tracker::FaceTrackerOptions;

fn temp(name: &str) -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("face_track")
        .join(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn sequence(name: &str, frames: usize) -> PathBuf {
    let dir = temp(name);
    let o = FaceSequenceOptions {
        frames,
        ..Default::default()
    };
    make_face_sequence(&dir, &o).unwrap();
    dir
}

#[test]
fn sequence_files_are_complete_and_deterministic() {
    let a = sequence("seq_a", 3);
    let b = sequence("seq_b", 3);
    let seq = FaceSequence::open(&a).unwrap();
    assert_eq!(seq.cameras.len(), 3);
    assert_eq!(seq.info.frames, 3);
    assert_eq!((seq.info.width, seq.info.height), (640, 480));
    let truth = seq.truth.as_ref().unwrap();
    assert_eq!(truth.len(), 3);
    // init.csv is frame 0 of the ground truth; all expressions start neutral
    assert!(seq.init.pose.angle_to(&truth[0].pose) < 1e-9);
    assert!(
        seq.init.faps.iter().all(|v| v.abs() < 1e-9),
        "{:?}",
        seq.init.faps
    );
    for k in 0..3 {
        for c in 0..3 {
            let p = format!("images/cam{c}/{k:04}.png");
            assert_eq!(
                std::fs::read(a.join(&p)).unwrap(),
                std::fs::read(b.join(&p)).unwrap(),
                "{p} differs between two runs with the same seed"
            );
        }
    }
    let imgs = seq.frame_images(0).unwrap();
    assert_eq!(imgs.len(), 3);
    assert!(a.join("model.obj").exists() && a.join("truth/texture.png").exists());
}

#[test]
fn tracking_recovers_pose_and_expression() {
    let dir = sequence("track", 30);
    let seq = FaceSequence::open(&dir).unwrap();
    let r = track_face_sequence(&seq, &FaceTrackerOptions::default(), None, |_, _| {}).unwrap();
    let pe = r.mean_pose_err_deg().unwrap();
    let pmax = r.max_pose_err_deg().unwrap();
    let fe = r.fap_err.clone().unwrap();
    println!(
        "30 frames: rotation error mean {pe:.3}°, worst frame {pmax:.3}°; FAP errors (% of range) {:?}; {:.1} fps",
        fe.iter().map(|e| (e * 1000.0).round() / 10.0).collect::<Vec<_>>(),
        r.fps()
    );
    assert!(
        pe <= 2.0 && pmax <= 4.0,
        "rotation error {pe}° (worst {pmax}°)"
    );
    for (f, e) in seq.info.faps.iter().zip(&fe) {
        assert!(
            *e <= 0.10,
            "FAP {f}: mean error {:.1} % of its range",
            e * 100.0
        );
    }
    let t = r.translation_err.as_ref().unwrap();
    assert!(t.iter().all(|&e| e < 0.005), "translation error above 5 mm");
    // same inputs, bit-identical outputs
    let r2 = track_face_sequence(&seq, &FaceTrackerOptions::default(), Some(6), |_, _| {}).unwrap();
    for k in 0..6 {
        assert_eq!(r.rows[k], r2.rows[k], "frame {k} differs between two runs");
    }
    let out = temp("track_out");
    let files = write_face_track_outputs(&seq, &r, &out, 10).unwrap();
    for f in [
        "tracked.csv",
        "errors.csv",
        "summary.json",
        "overlay/0000.png",
    ] {
        assert!(files.contains(&out.join(f)), "{f} not written");
    }
}

#[test]
fn tracking_a_wrong_start_costs_more_than_the_truth() {
    // the photometric cost has its minimum at the true pose and expression
    let dir = sequence("cost", 2);
    let seq = FaceSequence::open(&dir).unwrap();
    let truth = seq.truth.clone().unwrap();
    let mut tr = emilion::face::tracker::FaceTracker::new(
        &seq.model,
        &seq.cameras,
        &seq.info.faps,
        seq.init.pose,
        &seq.init.faps,
        &FaceTrackerOptions::default(),
    )
    .unwrap();
    tr.track(&seq.frame_images(0).unwrap()).unwrap();
    tr.track(&seq.frame_images(1).unwrap()).unwrap();
    let at_truth = tr.cost_at(&truth[1].pose, &truth[1].faps, 0);
    let turned = truth[1].pose.perturbed(
        &nalgebra::Vector3::new(0.0, 2f64.to_radians(), 0.0),
        &nalgebra::Vector3::zeros(),
    );
    assert!(tr.cost_at(&turned, &truth[1].faps, 0) > at_truth * 1.2);
    for j in 0..seq.info.faps.len() {
        let (lo, hi) = seq.info.fap_ranges[j];
        let mut f = truth[1].faps.clone();
        f[j] = if f[j] - lo > hi - f[j] { lo } else { hi };
        let c = tr.cost_at(&truth[1].pose, &f, 0);
        assert!(
            c > at_truth,
            "FAP {} at {}: cost {c} not above {at_truth}",
            seq.info.faps[j],
            f[j]
        );
    }
}

#[test]
fn face_track_script_prints_the_summary_line() {
    let out = temp("script");
    let seq = sequence("script_seq", 4);
    let exe = env!("CARGO_BIN_EXE_emilion");
    let o = std::process::Command::new(exe)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .args(["run", "scripts/face_track.rhai", "--set"])
        .arg(format!("seq={}", seq.display()))
        .arg("--set")
        .arg(format!("out={}", out.display()))
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(
        o.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let last = stdout.lines().last().unwrap();
    assert!(
        last.starts_with("pose_err_deg=") && last.contains(" fap_err=") && last.contains(" fps="),
        "{last}"
    );
    let pe: f64 = last["pose_err_deg=".len()..]
        .split(' ')
        .next()
        .unwrap()
        .parse()
        .unwrap();
    assert!(pe < 2.0, "{last}");
    // make_face_sequence.rhai writes a sequence that opens
    let s2 = temp("script_make");
    let o = std::process::Command::new(exe)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .args([
            "run",
            "scripts/make_face_sequence.rhai",
            "--set",
            "frames=2",
            "--set",
        ])
        .arg(format!("out={}", s2.display()))
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(FaceSequence::open(&s2).unwrap().info.frames, 2);
}

#[test]
fn bad_sequences_give_clear_errors() {
    let dir = sequence("bad", 2);
    // a missing frame
    std::fs::remove_file(dir.join("images/cam1/0001.png")).unwrap();
    let seq = FaceSequence::open(&dir).unwrap();
    let e = track_face_sequence(&seq, &FaceTrackerOptions::default(), None, |_, _| {})
        .unwrap_err()
        .to_string();
    assert!(e.contains("cam1") && e.contains("0001.png"), "{e}");
    // a frame of the wrong size
    image::RgbImage::new(320, 240)
        .save(dir.join("images/cam1/0001.png"))
        .unwrap();
    let e = seq.frame_images(1).unwrap_err().to_string();
    assert!(e.contains("0001.png") && e.contains("320×240"), "{e}");
    // an unknown column in init.csv
    let init = std::fs::read_to_string(dir.join("init.csv")).unwrap();
    std::fs::write(dir.join("init.csv"), init.replacen("fap_3", "smile", 1)).unwrap();
    let e = FaceSequence::open(&dir).unwrap_err().to_string();
    assert!(e.contains("init.csv:1") && e.contains("smile"), "{e}");
    // a missing camera file
    std::fs::write(dir.join("init.csv"), init).unwrap();
    std::fs::remove_file(dir.join("cameras/cam2.json")).unwrap();
    let e = FaceSequence::open(&dir).unwrap_err().to_string();
    assert!(e.contains("cam2.json"), "{e}");
    // bad options
    let e = make_face_sequence(
        &temp("bad_opts"),
        &FaceSequenceOptions {
            cameras: 0,
            ..Default::default()
        },
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("cameras"), "{e}");
    let e = make_face_sequence(
        &temp("bad_faps"),
        &FaceSequenceOptions {
            faps: vec![99],
            ..Default::default()
        },
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("FAP 99"), "{e}");
    let o = FaceTrackerOptions {
        robust_sigma: f64::NAN,
        ..Default::default()
    };
    let seq = FaceSequence::open(&sequence("bad2", 1)).unwrap();
    let e = track_face_sequence(&seq, &o, None, |_, _| {})
        .unwrap_err()
        .to_string();
    assert!(e.contains("robust_sigma"), "{e}");
}
