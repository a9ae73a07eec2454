//! Synthetic multi-camera sequences: made by `make_sequence`, read back by `Sequence::open`,
//! checked against the animation they come from (ground truth, visibility of the body and
//! joints, occluder coverage), their error messages, and bit-for-bit determinism.

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use emilion::body::{Animation, Mannequin, Motion, RetargetOptions};
use emilion::geometry::Camera;
use emilion::tracking::joints::{JointSet, JOINT_COUNT};
use emilion::tracking::sequence::{make_sequence, SequenceOptions};
use emilion::tracking::sequence_files::Sequence;
use image::RgbImage;

const FRAMES: usize = 3;

fn data() -> PathBuf {
    std::env::var_os("EMILION_DATA").map_or_else(
        || PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../shared/data")),
        Into::into,
    )
}

fn motion() -> PathBuf {
    data().join("motion/cmu_bvh/002_05.bvh")
}

fn options() -> SequenceOptions {
    SequenceOptions {
        frames: Some(FRAMES),
        backgrounds: data().join("facades/labelmefacade/images"),
        makehuman: data().join("bodies/makehuman"),
        seed: 11,
        ..SequenceOptions::default()
    }
}

/// A fresh, empty folder under the system temp dir.
fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("emilion_seq_{}_{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// The 3-frame sequence of the punch clip made once for the tests that only read it.
fn base() -> &'static Path {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let dir = scratch("base");
        let s = make_sequence(&motion(), &dir, &options()).unwrap();
        assert_eq!(
            (s.frames, s.cameras, s.width, s.height),
            (FRAMES, 4, 320, 240)
        );
        eprintln!(
            "3 frames × 4 cameras in {:.2} s ({:.3} s per frame)",
            s.seconds, s.seconds_per_frame
        );
        dir
    })
}

fn animation() -> Animation {
    let m = Mannequin::load_makehuman(&data().join("bodies/makehuman")).unwrap();
    Animation::new(
        m,
        Motion::load_bvh(&motion()).unwrap(),
        RetargetOptions::default(),
    )
    .unwrap()
}

fn copy_dir(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for e in std::fs::read_dir(from).unwrap() {
        let p = e.unwrap().path();
        let q = to.join(p.file_name().unwrap());
        if p.is_dir() {
            copy_dir(&p, &q);
        } else {
            std::fs::copy(&p, &q).unwrap();
        }
    }
}

#[test]
fn sequence_reads_back_with_exact_ground_truth() {
    let seq = Sequence::open(base()).unwrap();
    assert_eq!(seq.frames, FRAMES);
    assert_eq!(seq.fps, 50.0);
    assert_eq!((seq.width, seq.height), (320, 240));
    assert_eq!(seq.camera_names, ["cam0", "cam1", "cam2", "cam3"]);
    for (c, cam) in seq.cameras.iter().enumerate() {
        let text = std::fs::read_to_string(base().join(format!("cameras/cam{c}.json"))).unwrap();
        let again = Camera::from_json(&text).unwrap();
        assert_eq!(&again, cam);
        assert_eq!(again.to_json().unwrap().trim(), text.trim());
        assert_eq!((cam.width, cam.height), (320, 240));
        assert!(cam.k1 < 0.0 && cam.k1 > -0.1);
    }
    // distinct viewpoints on a ring around the body
    for a in 0..4 {
        for b in a + 1..4 {
            assert!((seq.cameras[a].center() - seq.cameras[b].center()).norm() > 2.0);
        }
    }
    for k in 0..FRAMES {
        let images = seq.frame_images(k).unwrap();
        assert_eq!(images.len(), 4);
        assert!(images.iter().all(|i| i.dimensions() == (320, 240)));
    }
    let err = seq.frame_images(FRAMES).unwrap_err().to_string();
    assert!(
        err.contains("out of range") && err.contains(&FRAMES.to_string()),
        "{err}"
    );

    let anim = animation();
    let joints = JointSet::new(anim.mannequin()).unwrap();
    let truth = seq.ground_truth.as_ref().expect("ground_truth.csv");
    assert_eq!(truth.len(), FRAMES);
    for (k, row) in truth.iter().enumerate() {
        let expected = joints.positions(&anim.pose_at(k as f64 / 50.0));
        assert_eq!(row, &expected, "frame {k}");
    }
    // the joints move between frames (the clip is playing)
    assert!((truth[2][6] - truth[0][6]).norm() > 1e-4);
    let init = seq.init_joints.expect("init_joints.csv");
    let d: Vec<f64> = (0..JOINT_COUNT)
        .map(|j| (init[j] - truth[0][j]).norm())
        .collect();
    assert!(d.iter().all(|&e| e > 0.0 && e < 0.12), "{d:?}");
    let mean = d.iter().sum::<f64>() / JOINT_COUNT as f64;
    assert!(mean > 0.015 && mean < 0.06, "mean init error {mean}");
}

#[test]
fn every_camera_sees_every_joint() {
    let seq = Sequence::open(base()).unwrap();
    for (k, joints) in seq.ground_truth.as_ref().unwrap().iter().enumerate() {
        for (c, cam) in seq.cameras.iter().enumerate() {
            for (j, p) in joints.iter().enumerate() {
                let uv = cam.project(p).expect("in front of the camera");
                assert!(
                    uv[0] > 5.0 && uv[0] < 314.0 && uv[1] > 5.0 && uv[1] < 234.0,
                    "frame {k} cam{c} joint {j} at {uv:?}"
                );
            }
        }
    }
    // and the body fills a sensible part of the height
    let cam = &seq.cameras[0];
    let j = &seq.ground_truth.as_ref().unwrap()[0];
    let ys: Vec<f64> = j.iter().map(|p| cam.project(p).unwrap()[1]).collect();
    let span =
        ys.iter().cloned().fold(f64::MIN, f64::max) - ys.iter().cloned().fold(f64::MAX, f64::min);
    assert!(
        span > 0.4 * 240.0 && span < 0.8 * 240.0,
        "joint span {span} px"
    );
}

/// One noise-free frame of `opts`, in a fresh folder; returns its images.
fn one_frame(name: &str, opts: SequenceOptions) -> (Sequence, Vec<RgbImage>) {
    let dir = scratch(name);
    let opts = SequenceOptions {
        frames: Some(1),
        noise_sigma: 0.0,
        ..opts
    };
    make_sequence(&motion(), &dir, &opts).unwrap();
    let seq = Sequence::open(&dir).unwrap();
    let images = seq.frame_images(0).unwrap();
    let _ = std::fs::remove_dir_all(&dir);
    (seq, images)
}

fn differing(a: &RgbImage, b: &RgbImage) -> Vec<bool> {
    a.pixels().zip(b.pixels()).map(|(p, q)| p != q).collect()
}

#[test]
fn body_is_visible_and_occluder_covers_a_tenth() {
    let body = one_frame(
        "body",
        SequenceOptions {
            occluder_fraction: 0.0,
            ..options()
        },
    );
    let empty = one_frame(
        "empty",
        SequenceOptions {
            occluder_fraction: 0.0,
            body: false,
            ..options()
        },
    );
    let occl = one_frame(
        "occluded",
        SequenceOptions {
            body: false,
            ..options()
        },
    );
    let joints = body.0.ground_truth.as_ref().unwrap()[0];
    for c in 0..4 {
        let cam = &body.0.cameras[c];
        // the body: pixels that differ from the empty scene, around every joint
        let diff = differing(&body.1[c], &empty.1[c]);
        let n = diff.iter().filter(|&&d| d).count() as f64 / diff.len() as f64;
        assert!(n > 0.02 && n < 0.3, "cam{c}: body covers {n} of the image");
        let on_body = joints
            .iter()
            .filter(|p| {
                let uv = cam.project(p).unwrap();
                let (x, y) = (uv[0].round() as i64, uv[1].round() as i64);
                (-1..=1).any(|dy| (-1..=1).any(|dx| diff[((y + dy) * 320 + x + dx) as usize]))
            })
            .count();
        assert!(
            on_body >= 14,
            "cam{c}: only {on_body} joints land on the body"
        );
        // the occluder: pixels that differ from the scene without it
        let diff = differing(&occl.1[c], &empty.1[c]);
        let n = diff.iter().filter(|&&d| d).count() as f64 / diff.len() as f64;
        assert!(
            (n - 0.10).abs() <= 0.01,
            "cam{c}: occluder covers {n} of the image"
        );
        // it hides some joints, not all of them
        let hidden = joints
            .iter()
            .filter(|p| {
                let uv = cam.project(p).unwrap();
                diff[(uv[1].round() as usize) * 320 + uv[0].round() as usize]
            })
            .count();
        assert!(
            hidden < JOINT_COUNT,
            "cam{c}: the occluder hides every joint"
        );
    }
}

#[test]
fn errors_name_the_file() {
    let dir = scratch("errors");
    copy_dir(base(), &dir);
    // image of the wrong size
    image::RgbImage::new(10, 8)
        .save(dir.join("images/cam1/0001.png"))
        .unwrap();
    let seq = Sequence::open(&dir).unwrap();
    assert!(seq.frame_images(0).is_ok());
    let err = seq.frame_images(1).unwrap_err().to_string();
    assert!(
        err.contains("cam1")
            && err.contains("0001.png")
            && err.contains("10×8")
            && err.contains("320×240"),
        "{err}"
    );
    // missing image
    std::fs::remove_file(dir.join("images/cam3/0002.png")).unwrap();
    let err = seq.frame_images(2).unwrap_err().to_string();
    assert!(err.contains("0002.png") && err.contains("missing"), "{err}");
    // unknown joint column
    let gt = dir.join("ground_truth.csv");
    let text = std::fs::read_to_string(&gt).unwrap();
    std::fs::write(&gt, text.replacen("l_knee_x", "l_kneecap_x", 1)).unwrap();
    let err = Sequence::open(&dir).unwrap_err().to_string();
    assert!(
        err.contains("ground_truth.csv") && err.contains("l_kneecap_x"),
        "{err}"
    );
    // malformed number: the line is named
    let mut lines: Vec<String> = text.lines().map(String::from).collect();
    lines[2] = lines[2].replacen(',', ",oops", 2);
    std::fs::write(&gt, lines.join("\n")).unwrap();
    let err = Sequence::open(&dir).unwrap_err().to_string();
    assert!(err.contains("ground_truth.csv:3"), "{err}");
    std::fs::write(&gt, &text).unwrap();
    assert!(Sequence::open(&dir).is_ok());
    // missing camera file
    std::fs::remove_file(dir.join("cameras/cam2.json")).unwrap();
    let err = Sequence::open(&dir).unwrap_err().to_string();
    assert!(
        err.contains("cam2.json") && err.contains("missing"),
        "{err}"
    );
    // malformed camera file
    std::fs::write(dir.join("cameras/cam2.json"), "{\"intrinsics\": 3}").unwrap();
    let err = Sequence::open(&dir).unwrap_err().to_string();
    assert!(err.contains("cam2.json"), "{err}");
    // no sequence.json
    std::fs::remove_file(dir.join("sequence.json")).unwrap();
    let err = Sequence::open(&dir).unwrap_err().to_string();
    assert!(err.contains("sequence.json"), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
    // bad options and a missing clip
    let bad = SequenceOptions {
        cameras: 0,
        ..options()
    };
    let err = make_sequence(&motion(), &scratch("bad"), &bad)
        .unwrap_err()
        .to_string();
    assert!(err.contains("cameras"), "{err}");
    let err = make_sequence(Path::new("no/such/clip.bvh"), &scratch("bad"), &options())
        .unwrap_err()
        .to_string();
    assert!(err.contains("clip.bvh"), "{err}");
}

#[test]
fn same_seed_same_bytes() {
    let dir = scratch("again");
    make_sequence(&motion(), &dir, &options()).unwrap();
    for file in [
        "sequence.json",
        "ground_truth.csv",
        "init_joints.csv",
        "cameras/cam3.json",
    ] {
        assert_eq!(
            std::fs::read(base().join(file)).unwrap(),
            std::fs::read(dir.join(file)).unwrap(),
            "{file}"
        );
    }
    for c in 0..4 {
        for k in 0..FRAMES {
            let f = format!("images/cam{c}/{k:04}.png");
            assert!(
                std::fs::read(base().join(&f)).unwrap() == std::fs::read(dir.join(&f)).unwrap(),
                "{f}"
            );
        }
    }
    // another seed: other noise, photos and clothes
    let other = one_frame(
        "seed",
        SequenceOptions {
            seed: 12,
            ..options()
        },
    );
    let first = image::open(base().join("images/cam0/0000.png"))
        .unwrap()
        .into_rgb8();
    assert!(first != other.1[0]);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn rasterizer_speed_and_rigid_skinning() {
    use emilion::render::raster::{draw_triangles, project_vertices, RasterTarget};
    use emilion::tracking::clothing::{clothing_colours, shaded_colours};
    let seq = Sequence::open(base()).unwrap();
    let anim = animation();
    let m = anim.mannequin();
    let mut skin = Vec::new();
    m.skin(&anim.pose_at(0.0), &mut skin);
    let tris: Vec<[u32; 3]> = m.triangles().iter().map(|t| t.map(|i| i as u32)).collect();
    let (mut normals, mut colours) = (Vec::new(), Vec::new());
    shaded_colours(
        &skin,
        &tris,
        &clothing_colours(m, 1),
        &mut normals,
        &mut colours,
        true,
    );
    let mut target = RasterTarget::new(320, 240);
    let mut projected = Vec::new();
    let n = 200;
    let start = std::time::Instant::now();
    for _ in 0..n {
        target.clear();
        project_vertices(&seq.cameras[0], &skin, &mut projected);
        draw_triangles(&mut target, &projected, &colours, &tris);
    }
    let each = start.elapsed().as_secs_f64() / n as f64;
    eprintln!(
        "project + draw {} triangles at 320×240: {:.3} ms",
        tris.len(),
        each * 1e3
    );
    let covered = target.depth.iter().filter(|d| d.is_finite()).count();
    assert!(covered > 1500 && covered < 20_000, "{covered} pixels");
    let (x0, y0, x1, y1) = target.touched().unwrap();
    assert!(x1 - x0 < 200 && y1 - y0 < 200 && x0 > 0 && y0 > 0);

    // rigid skinning by dominant bone renders too, a little differently
    let lbs = one_frame("lbs", options());
    let rigid = one_frame(
        "rigid",
        SequenceOptions {
            lbs: false,
            ..options()
        },
    );
    for c in 0..4 {
        let d = differing(&lbs.1[c], &rigid.1[c])
            .iter()
            .filter(|&&d| d)
            .count();
        assert!(d > 0 && d < 320 * 240 / 10, "cam{c}: {d} pixels differ");
    }
}

#[cfg(feature = "scripting")]
#[test]
fn script_makes_a_sequence() {
    let out = scratch("script");
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let sets = [
        ("motion", motion().display().to_string()),
        ("out", out.display().to_string()),
        ("frames", "2".to_string()),
    ]
    .map(|(k, v)| (k.to_string(), v));
    emilion::script::run_file(&root.join("scripts/make_sequence.rhai"), &sets).unwrap();
    let seq = Sequence::open(&out).unwrap();
    assert_eq!((seq.frames, seq.cameras.len()), (2, 4));
    assert!(seq.frame_images(1).is_ok());
    let _ = std::fs::remove_dir_all(&out);
}

#[test]
fn frames_in_other_photo_formats_are_read() {
    let dir = scratch("formats");
    copy_dir(base(), &dir);
    let want = Sequence::open(base()).unwrap().frame_images(1).unwrap();
    // camera 0's frame 1 as a hand-written PPM, camera 2's as a BMP (both lossless)
    let png = dir.join("images/cam0/0001.png");
    let img = image::open(&png).unwrap().into_rgb8();
    let mut ppm = format!("P6\n{} {}\n255\n", img.width(), img.height()).into_bytes();
    ppm.extend_from_slice(img.as_raw());
    std::fs::write(dir.join("images/cam0/0001.ppm"), ppm).unwrap();
    std::fs::remove_file(&png).unwrap();
    let png = dir.join("images/cam2/0001.png");
    image::open(&png)
        .unwrap()
        .save(dir.join("images/cam2/0001.BMP"))
        .unwrap();
    std::fs::remove_file(&png).unwrap();
    let seq = Sequence::open(&dir).unwrap();
    assert!(seq.image_path(0, 1).ends_with("0001.ppm"));
    assert_eq!(seq.frame_images(1).unwrap(), want);
    // an undecodable frame is named
    std::fs::write(dir.join("images/cam0/0001.ppm"), b"P6 broken").unwrap();
    let err = seq.frame_images(1).unwrap_err().to_string();
    assert!(
        err.contains("0001.ppm") && err.contains("cannot be decoded as an image"),
        "{err}"
    );
}
