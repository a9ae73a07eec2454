//! The tracker without help: the automatic start (the person found and posed from the first
//! frame's images alone, `init=auto`), the clear error when nobody is there, and the search
//! again after a loss (a cut in the sequence). Sequences are made by
//! `scripts/make_sequence.rhai` and tracked by `scripts/track_body.rhai`; errors are measured
//! against the ground truth the sequence was made from.

use std::path::{Path, PathBuf};

use emilion::script::run_file;
use emilion::tracking::background_model::changing_pixels;
use emilion::tracking::cost::{FrameViews, Robust};
use emilion::tracking::pyramid::Level;
use emilion::tracking::sequence_files::{read_joints_csv, Sequence};
use emilion::tracking::tracker::TrackerOptions;
use emilion::tracking::visual_hull::{search_box, visual_hull, MIN_PERSON_VOLUME};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn temp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("emilion_recover_{name}_{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

fn sets(pairs: &[(&str, &str)]) -> Vec<(String, String)> {
    pairs
        .iter()
        .map(|(k, v)| (k.to_string(), v.to_string()))
        .collect()
}

fn clip(name: &str) -> Option<PathBuf> {
    let p = root().join("../shared/data/motion/cmu_bvh").join(name);
    if p.is_file() {
        Some(p)
    } else {
        eprintln!("skipped: {} is absent", p.display());
        None
    }
}

fn make(motion: &Path, out: &Path, frames: usize) {
    run_file(
        &root().join("scripts/make_sequence.rhai"),
        &sets(&[
            ("motion", motion.to_str().unwrap()),
            ("out", out.to_str().unwrap()),
            ("frames", &frames.to_string()),
        ]),
    )
    .unwrap_or_else(|e| panic!("make_sequence.rhai: {e}"));
}

fn track(seq: &Path, out: &Path, extra: &[(&str, &str)]) -> Result<(), String> {
    let mut opts = vec![
        ("seq", seq.to_str().unwrap()),
        ("out", out.to_str().unwrap()),
        ("overlay_every", "0"),
    ];
    opts.extend_from_slice(extra);
    run_file(&root().join("scripts/track_body.rhai"), &sets(&opts))
        .map(|_| ())
        .map_err(|e| e.to_string())
}

/// Per-frame MPJPE (mm) of the tracked joints against the sequence's ground truth.
fn errors(seq: &Path, out: &Path) -> Vec<f64> {
    let s = Sequence::open(seq).unwrap();
    let truth = s.ground_truth.unwrap();
    read_joints_csv(&out.join("tracked_joints.csv"))
        .unwrap()
        .into_iter()
        .map(|(k, _, j)| {
            let t = &truth[k];
            1000.0 * j.iter().zip(t).map(|(a, b)| (a - b).norm()).sum::<f64>() / j.len() as f64
        })
        .collect()
}

/// How far the tracked pelvis of the first frame is from the true one (m).
fn first_pelvis_offset(seq: &Path, out: &Path) -> emilion::geometry::Vec3 {
    let s = Sequence::open(seq).unwrap();
    let truth = &s.ground_truth.unwrap()[0];
    let tracked = &read_joints_csv(&out.join("tracked_joints.csv")).unwrap()[0].2;
    tracked[0] - truth[0]
}

/// The sequence is made 40 frames long, as measured in docs/body-tracking.md: the pixels
/// the sequence never changes are unknown to the hull and the cost, and with 4 frames made
/// too much of the floor was (pelvis off by (−110, −112, +58) mm, MPJPE 284 and 288 mm).
/// Ignored: 32 s of CPU (150 s wall on the shared machine) for the start alone, over the
/// suite's budget. Run with
/// `cargo test --release --test tracking_recovery -- --ignored automatic_start`.
/// The fast check that the person is found is
/// `the_visual_hull_stands_where_the_walker_does`.
#[test]
#[ignore]
fn automatic_start_finds_the_walker_without_init_joints() {
    let Some(motion) = clip("002_01.bvh") else {
        return;
    };
    let dir = temp("auto");
    let (seq, out) = (dir.join("seq"), dir.join("track"));
    make(&motion, &seq, 40);
    // the automatic start must not read it
    std::fs::remove_file(seq.join("init_joints.csv")).unwrap();
    track(&seq, &out, &[("init", "auto"), ("frames", "2")]).unwrap();
    let e = errors(&seq, &out);
    println!("MPJPE per frame after the automatic start (mm): {e:.1?}");
    assert_eq!(e.len(), 2);
    // the person is found: the pelvis stands where the true one does
    let d = first_pelvis_offset(&seq, &out);
    println!("pelvis off by {:.0?} mm", d * 1000.0);
    assert!(
        d.xy().norm() <= 0.12 && d.z.abs() <= 0.06,
        "pelvis off by {d:?} m"
    );
    // the pose is only roughly right yet (measured 167 mm, the target is 40 mm)
    assert!(e.iter().all(|&x| x <= 200.0), "{e:.1?}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// Regression: on the dressed boxer (CMU punch 002_05 filmed by `golf_sequence.rhai`, shirt
/// and trousers simulated) the rest pose's silhouette fit was best with the puppet sunk 0.28 m
/// into the floor (its spread arms then cover the clothed trunk), and the automatic start
/// kept that height or wandered off: on 100 frames at 3 cm edges the pelvis 0.22 m low,
/// 253 mm at frame 0 and 297 mm over the clip; on this test's sequence (4 cm edges) the
/// pelvis 0.17 m off sideways, 263.5 mm. The start now also refines the pose standing on the
/// hull's lowest point: 34 mm at frame 0 and 42.9 mm over the clip (docs/golf.md); here
/// 74.5 mm, the pelvis 48 mm high.
#[test]
fn the_dressed_boxer_is_started_on_the_floor_not_sunk_into_it_regression() {
    let Some(motion) = clip("002_05.bvh") else {
        return;
    };
    let dir = temp("boxer");
    let (made, out) = (dir.join("made"), dir.join("track"));
    run_file(
        &root().join("scripts/golf_sequence.rhai"),
        &sets(&[
            ("motion", motion.to_str().unwrap()),
            ("out", made.to_str().unwrap()),
            // 100 frames: with 25 the floor around the feet never changes, and the old start
            // happened to stand (119 mm)
            ("frames", "100"),
            ("edge", "0.04"),
        ]),
    )
    .unwrap_or_else(|e| panic!("golf_sequence.rhai: {e}"));
    let seq = made.join("golf_sequence");
    std::fs::remove_file(seq.join("init_joints.csv")).unwrap();
    track(&seq, &out, &[("init", "auto"), ("frames", "1")]).unwrap();
    let e = errors(&seq, &out);
    let d = first_pelvis_offset(&seq, &out);
    println!("frame 0: {e:.1?} mm, pelvis off by {:.0?} mm", d * 1000.0);
    assert!(
        d.xy().norm() <= 0.12 && d.z.abs() <= 0.06,
        "pelvis off by {d:?} m"
    );
    assert!(e[0] <= 150.0, "frame 0: {:.1} mm", e[0]);
    let _ = std::fs::remove_dir_all(&dir);
}

/// The first step of the automatic start alone (seconds): the visual hull of the walk's
/// first frame (carved as `Tracker::find_person` does: level 1, 5 cm cells, pixels the
/// sequence never changes unknown) stands over the true pelvis, with a person's volume.
#[test]
fn the_visual_hull_stands_where_the_walker_does() {
    let Some(motion) = clip("002_01.bvh") else {
        return;
    };
    let dir = temp("hull");
    let seq = dir.join("seq");
    make(&motion, &seq, 10);
    let s = Sequence::open(&seq).unwrap();
    let plates: Vec<Level> = s
        .background_plates()
        .unwrap()
        .expect("make_sequence writes clean plates")
        .iter()
        .map(Level::from_image)
        .collect();
    let o = TrackerOptions::default();
    let robust = Robust {
        sigma: o.robust_sigma,
    };
    let levels = o.layers.iter().max().copied().unwrap_or(0) + 1;
    let mut views = FrameViews::new(&s.cameras, &plates, levels, robust);
    views.set_active(&changing_pixels(&s, &plates, o.background_frames, robust, 0.2).unwrap());
    views.set_frame(&s.frame_images(0).unwrap());
    let (lo, hi) = search_box(&views);
    let hull = visual_hull(&views, 1, lo, hi, 0.05).largest_component();
    let (centre, volume) = (hull.centroid().unwrap(), hull.volume());
    let pelvis = s.ground_truth.as_ref().unwrap()[0][0];
    let d = centre - pelvis;
    println!(
        "hull: {volume:.3} m³, centre off the pelvis by {:.0?} mm",
        d * 1000.0
    );
    assert!(
        d.xy().norm() <= 0.12,
        "hull centre off the pelvis by {d:?} m"
    );
    // a person: more than the start's minimum, less than a car
    assert!((MIN_PERSON_VOLUME..2.0).contains(&volume), "{volume} m³");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn empty_frames_are_a_clear_no_person_error() {
    let Some(motion) = clip("002_01.bvh") else {
        return;
    };
    let dir = temp("empty");
    let seq = dir.join("seq");
    make(&motion, &seq, 1);
    // every frame is the empty scene (the clean plate)
    for c in 0..4 {
        std::fs::copy(
            seq.join(format!("backgrounds/cam{c}.png")),
            seq.join(format!("images/cam{c}/0000.png")),
        )
        .unwrap();
    }
    let e = track(&seq, &dir.join("track"), &[("init", "auto")]).unwrap_err();
    assert!(
        e.contains("no person found") && e.contains("frame 0") && e.contains("seq"),
        "{e}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// A cut: the dance clip 005_06's frames 0–5 (facing the first camera), then its frames
/// 60–71, where the dancer has turned a quarter turn (−80°). The track, started from
/// `init_joints.csv`, is lost at the cut; the loss is noticed and the body found again.
/// Ignored: not yet seen to pass (one run took over 15 minutes on the shared machine and was
/// not finished); run with `cargo test --release --test tracking_recovery -- --ignored`.
#[test]
#[ignore]
fn a_cut_to_a_quarter_turn_is_noticed_and_the_body_found_again() {
    let Some(motion) = clip("005_06.bvh") else {
        return;
    };
    let dir = temp("cut");
    let (made, seq, out) = (dir.join("made"), dir.join("seq"), dir.join("track"));
    make(&motion, &made, 72);
    let picks: Vec<usize> = (0..6).chain(60..72).collect();
    cut_sequence(&made, &seq, &picks);
    track(&seq, &out, &[("recover", "true")]).unwrap();
    let status = std::fs::read_to_string(out.join("track_status.csv")).unwrap();
    let states: Vec<&str> = status
        .lines()
        .skip(1)
        .map(|l| l.split(',').nth(1).unwrap())
        .collect();
    let e = errors(&seq, &out);
    println!("states: {states:?}\nMPJPE per frame (mm): {e:.0?}");
    // noticed within half a second (25 frames at 50 fps) of the cut, found again
    let first_lost = states.iter().position(|s| *s != "tracked");
    assert!(first_lost.is_some_and(|k| k >= 6), "{states:?}");
    assert!(states.contains(&"recovered"), "{states:?}");
    let tail = &e[e.len() - 4..];
    assert!(
        tail.iter().all(|&x| x <= 80.0),
        "last frames (mm): {tail:.0?}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// Copies the frames `picks` of sequence `from` into a new sequence `to` (renumbered from 0),
/// with their ground truth, cameras and clean plates.
fn cut_sequence(from: &Path, to: &Path, picks: &[usize]) {
    for sub in ["cameras", "backgrounds"] {
        std::fs::create_dir_all(to.join(sub)).unwrap();
        for f in std::fs::read_dir(from.join(sub)).unwrap() {
            let f = f.unwrap();
            std::fs::copy(f.path(), to.join(sub).join(f.file_name())).unwrap();
        }
    }
    let mut json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(from.join("sequence.json")).unwrap())
            .unwrap();
    json["frames"] = picks.len().into();
    std::fs::write(to.join("sequence.json"), json.to_string()).unwrap();
    std::fs::copy(from.join("init_joints.csv"), to.join("init_joints.csv")).unwrap();
    let gt = std::fs::read_to_string(from.join("ground_truth.csv")).unwrap();
    let mut lines = gt.lines();
    let mut out = format!("{}\n", lines.next().unwrap());
    let rows: Vec<&str> = lines.collect();
    for (k, &p) in picks.iter().enumerate() {
        let rest = rows[p]
            .split_once(',')
            .unwrap()
            .1
            .split_once(',')
            .unwrap()
            .1;
        out.push_str(&format!("{k},{},{rest}\n", k as f64 / 50.0));
        for c in 0..4 {
            let d = to.join(format!("images/cam{c}"));
            std::fs::create_dir_all(&d).unwrap();
            std::fs::copy(
                from.join(format!("images/cam{c}/{p:04}.png")),
                d.join(format!("{k:04}.png")),
            )
            .unwrap();
        }
    }
    std::fs::write(to.join("ground_truth.csv"), out).unwrap();
}
