//! Diagnostics of the face tracker on a synthetic sequence: per-frame pose and FAP errors.
//! `cargo run --release --example face_track_diag -- OUT_DIR [frames] [rigid]`

use emilion::face::sequence::make_face_sequence;
use emilion::face::sequence_files::FaceSequence;
use emilion::face::sequence_options::FaceSequenceOptions;
use emilion::face::tracker::{FaceTracker, FaceTrackerOptions};
use std::path::Path;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let out = Path::new(args.get(1).map(String::as_str).unwrap_or("/tmp/face_diag"));
    let frames: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(20);
    let rigid = args.get(3).is_some_and(|s| s == "rigid");
    let mut o = FaceSequenceOptions {
        frames,
        ..Default::default()
    };
    if rigid {
        o.faps.clear();
    }
    let t = std::time::Instant::now();
    make_face_sequence(out, &o).unwrap();
    eprintln!("sequence {:.2} s", t.elapsed().as_secs_f64());
    let seq = FaceSequence::open(out).unwrap();
    let truth = seq.truth.clone().unwrap();
    let mut tr = FaceTracker::new(
        &seq.model,
        &seq.cameras,
        &seq.info.faps,
        seq.init.pose,
        &seq.init.faps,
        &FaceTrackerOptions::default(),
    )
    .unwrap();
    eprintln!("samples {}", tr.sample_count());
    let t = std::time::Instant::now();
    let mut sum = 0.0;
    for (k, truth_k) in truth.iter().enumerate().take(seq.info.frames) {
        let imgs = seq.frame_images(k).unwrap();
        let r = tr.track(&imgs).unwrap();
        let e = r.pose.angle_to(&truth_k.pose).to_degrees();
        let te = (r.pose.translation - truth_k.pose.translation).norm() * 1000.0;
        let fe: Vec<String> = r
            .faps
            .iter()
            .zip(&truth_k.faps)
            .zip(&seq.info.fap_ranges)
            .map(|((a, b), (lo, hi))| format!("{:.0}", 100.0 * (a - b).abs() / (hi - lo)))
            .collect();
        sum += e;
        if let Ok(j) = std::env::var("PROFILE") {
            let j: usize = j.parse().unwrap();
            let (lo, hi) = seq.info.fap_ranges[j];
            let mut f = truth_k.faps.clone();
            let mut line = String::new();
            for s in 0..=8 {
                f[j] = lo + (hi - lo) * s as f64 / 8.0;
                line.push_str(&format!(
                    " {:.0}:{:.1}",
                    f[j],
                    tr.cost_at(&truth_k.pose, &f, 0)
                ));
            }
            println!("    profile fap {j} true {:.0}:{line}", truth_k.faps[j]);
        }
        if std::env::var("FAPDUMP").is_ok() {
            println!(
                "    est {:?}\n    tru {:?}",
                r.faps.iter().map(|v| v.round()).collect::<Vec<_>>(),
                truth_k.faps.iter().map(|v| v.round()).collect::<Vec<_>>()
            );
        }
        println!(
            "{k:3} rot {e:.2}° t {te:.1} mm cost {:.3} faps% {}",
            r.cost,
            fe.join(" ")
        );
    }
    let dt = t.elapsed().as_secs_f64();
    println!(
        "mean rot {:.2}°, {:.1} fps, seen {:.2}",
        sum / seq.info.frames as f64,
        seq.info.frames as f64 / dt,
        tr.seen_fraction()
    );
}
