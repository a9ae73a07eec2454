//! The club tracker (`tracking::club_track`) against the capture's own club: a broadcast
//! sequence of the GEARS driver swing's downswing and impact (four cameras, 640×480, 50 fps,
//! the shutter's motion blur), the club found from the images with the truth's joints as the
//! tracked body, compared with the club the markers give (`club.csv`, which the tracker does
//! not read).

use emilion::geometry::files::data_dir;
use emilion::geometry::Vec3;
use emilion::tracking::club::frame_speeds;
use emilion::tracking::club_track::{track_club, ClubTrackOptions};
use emilion::tracking::golf_sequence::{make_golf_sequence, GolfSequenceOptions};
use emilion::tracking::sequence::SequenceOptions;
use emilion::tracking::sequence_files::Sequence;

#[test]
fn the_club_is_found_through_the_downswing_and_impact_as_the_markers_place_it() {
    let c3d = data_dir().join("motion/golf/C3D_TA_Driver.c3d");
    if !c3d.is_file() {
        eprintln!("skipped: {} is absent", c3d.display());
        return;
    }
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("club_track_downswing");
    let _ = std::fs::remove_dir_all(&dir);
    // from the top of the backswing (1.08 s) through impact (about 1.31 s)
    let o = GolfSequenceOptions {
        sequence: SequenceOptions {
            frames: Some(14),
            start_time: 1.06,
            ..GolfSequenceOptions::default().sequence
        },
        fit_every: 6,
        ..GolfSequenceOptions::default()
    };
    make_golf_sequence(&c3d, &dir, &o).unwrap();
    let seq = Sequence::open(&dir).unwrap();
    let joints = seq.ground_truth.clone().unwrap();
    let club = track_club(&seq, &joints, 0, &ClubTrackOptions::default()).unwrap();
    let text = std::fs::read_to_string(dir.join("club.csv")).unwrap();
    let truth: Vec<(Vec3, Vec3)> = text
        .lines()
        .skip(1)
        .map(|l| {
            let v: Vec<f64> = l.split(',').map(|s| s.parse().unwrap()).collect();
            (Vec3::new(v[2], v[3], v[4]), Vec3::new(v[5], v[6], v[7]))
        })
        .collect();
    let errors: Vec<f64> = (club.head.iter().zip(&truth))
        .map(|(h, t)| (h - t.1).norm())
        .collect();
    let mean = errors.iter().sum::<f64>() / errors.len() as f64;
    let worst = errors.iter().copied().fold(0.0, f64::max);
    let peak = |p: Vec<Option<Vec3>>| {
        (frame_speeds(&p, seq.fps).into_iter())
            .filter(|v| v.is_finite())
            .fold(0.0, f64::max)
    };
    let tracked_peak = peak(club.head.iter().map(|h| Some(*h)).collect());
    let truth_peak = peak(truth.iter().map(|t| Some(t.1)).collect());
    eprintln!(
        "club head: mean {:.0} mm, worst {:.0} mm off the markers' club; shaft {:.3} m (truth \
         1.097); peak {tracked_peak:.1} m/s (truth {truth_peak:.1}); {:.2} s/frame; per frame \
         {:?}",
        mean * 1e3,
        worst * 1e3,
        club.length,
        club.seconds / club.head.len() as f64,
        errors.iter().map(|e| (e * 1e3).round()).collect::<Vec<_>>()
    );
    assert!(mean < 0.08, "mean head error {mean} m");
    assert!(worst < 0.25, "worst head error {worst} m");
    assert!((club.length - 1.097).abs() < 0.1, "shaft {}", club.length);
    assert!(
        (tracked_peak - truth_peak).abs() < 0.1 * truth_peak,
        "peak {tracked_peak} against {truth_peak}"
    );
}
