//! Facade evaluation against the labelled street photos of `../shared/data/facades/
//! labelmefacade` (non-commercial terms: read in place, never copied): the label maps read
//! into canonical classes reproduce the dataset's known statistics, a perfect parse scores
//! perfectly, and `scripts/facades_eval.rhai` prints its summary line.

use std::path::{Path, PathBuf};
use std::process::Command;

use emilion::facade::instances::window_instances;
use emilion::facade::report::labelled_images;
use emilion::facade::{Class, FacadeError, FacadeScore, LabelMap, Rect};

fn data() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data/facades/labelmefacade")
}

fn truth(name: &str) -> LabelMap {
    LabelMap::read_labelmefacade(&data().join("labels").join(format!("{name}.png"))).unwrap()
}

#[test]
fn all_wall_scores_the_known_baseline_and_every_image_has_windows() {
    let names = labelled_images(&data()).unwrap();
    assert_eq!(names.len(), 23);
    let mut pooled = emilion::facade::PixelScore::default();
    for n in &names {
        let t = truth(n);
        let s =
            FacadeScore::of(&LabelMap::filled(t.width, t.height, Class::Wall), &[], &t).unwrap();
        pooled.add(&s.pixels);
        assert_eq!(s.pixels.iou(Class::Window), 0.0);
        assert_eq!(s.windows.f1(), 0.0);
        // the subset was selected with at least 6 window components per image
        assert!(window_instances(&t).len() >= 6, "{n}");
    }
    // the protocol notes: all-wall ≈ 0.82 on the 45-image selection, ≈ 0.8 on these 23
    let acc = pooled.accuracy();
    eprintln!("all-wall pooled pixel accuracy {acc:.4}");
    assert!((0.78..0.85).contains(&acc), "{acc}");
}

#[test]
fn a_parse_equal_to_the_labels_scores_perfectly() {
    let name = "static_boston_street_april__p1010089";
    let t = truth(name);
    let windows: Vec<Rect> = window_instances(&t).iter().map(|w| w.rect).collect();
    let s = FacadeScore::of(&t, &windows, &t).unwrap();
    assert_eq!(s.pixels.accuracy(), 1.0);
    assert_eq!(s.pixels.iou(Class::Window), 1.0);
    assert_eq!(s.windows.f1(), 1.0);
    // every window shifted by half its width (IoU 1/3) no longer counts
    let shifted: Vec<Rect> = windows
        .iter()
        .map(|r| {
            let d = (r.x1 - r.x0).div_ceil(2);
            Rect {
                x0: r.x0 + d,
                x1: r.x1 + d,
                ..*r
            }
        })
        .collect();
    let s2 = FacadeScore::of(&t, &shifted, &t).unwrap();
    assert_eq!(s2.windows.true_positives, 0, "{:?}", s2.windows);
}

#[test]
fn a_label_map_with_a_foreign_colour_is_refused_by_name() {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("facade_bad_label");
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("bad.png");
    let mut img = image::RgbImage::from_pixel(4, 3, image::Rgb([128, 0, 0]));
    img.put_pixel(2, 1, image::Rgb([10, 20, 30]));
    img.save(&path).unwrap();
    match LabelMap::read_labelmefacade(&path) {
        Err(e @ FacadeError::UnknownColour { x: 2, y: 1, .. }) => {
            let text = e.to_string();
            assert!(
                text.contains("bad.png") && text.contains("(2, 1)"),
                "{text}"
            );
        }
        other => panic!("{other:?}"),
    }
    let missing = LabelMap::read_labelmefacade(&dir.join("none.png")).unwrap_err();
    assert!(missing.to_string().contains("none.png"));
}

#[test]
fn eval_script_prints_the_summary_line_and_writes_its_tables() {
    let out = Path::new(env!("CARGO_TARGET_TMPDIR")).join("facades_eval");
    let _ = std::fs::remove_dir_all(&out);
    let run = |extra: &[&str]| {
        let mut c = Command::new(env!("CARGO_BIN_EXE_emilion"));
        c.arg("run")
            .arg(Path::new(env!("CARGO_MANIFEST_DIR")).join("scripts/facades_eval.rhai"))
            .arg("--set")
            .arg(format!("dir={}", data().display()))
            .arg("--set")
            .arg(format!("out={}", out.display()));
        for e in extra {
            c.arg("--set").arg(e);
        }
        c.output().unwrap()
    };
    let o = run(&["method=all_wall"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let stdout = String::from_utf8_lossy(&o.stdout);
    let last = stdout.lines().last().unwrap_or("");
    assert_eq!(last, "window_iou=0.0 f1=0.0 images=23", "{stdout}");
    assert!(out.join("facades.csv").exists() && out.join("facades.md").exists());
    let csv = std::fs::read_to_string(out.join("facades.csv")).unwrap();
    assert_eq!(csv.lines().count(), 24);
    // the grammar pipeline on the held-out half (parameters were chosen on the other half)
    let o = run(&["method=grammar", "half=test"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let stdout = String::from_utf8_lossy(&o.stdout);
    eprintln!("{stdout}");
    let last = stdout.lines().last().unwrap_or("");
    let field = |k: &str| -> f64 {
        last.split_whitespace()
            .find_map(|w| w.strip_prefix(k))
            .and_then(|v| v.parse().ok())
            .unwrap_or(f64::NAN)
    };
    assert_eq!(field("images="), 11.0, "{last}");
    // well above labelling every pixel window (0.095 window IoU on these photos) and above the
    // floors × tiles lattice alone (0.083, F1 0.05), which the windows found one by one
    // replaced; still far below the goal (see the README)
    assert!(field("window_iou=") > 0.2 && field("f1=") > 0.15, "{last}");
    // an unknown method is a script error at its line
    let bad = run(&["method=mueller"]);
    assert!(!bad.status.success());
    let script = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/scripts/facades_eval.rhai"
    ))
    .unwrap();
    let line = 1 + script
        .lines()
        .position(|l| l.contains("throw `unknown method"))
        .unwrap();
    let err = String::from_utf8_lossy(&bad.stderr);
    assert!(err.contains(&format!("facades_eval.rhai:{line}")), "{err}");
}
