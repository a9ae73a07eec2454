//! The learned facade parse on the shared data (read in place, skipped with a message when
//! absent): a tiny forest trained on three CMP facades beats the trivial window baselines on
//! two held-out ones; the layouts are detected and predictions written in each dataset's own
//! format; a model file of another version, truncated or not a model is a clear error; the
//! training and evaluation scripts run end to end on a few photos.

use std::path::{Path, PathBuf};

use emilion::facade::learned::dataset::{labelled_folder, read_elements, Layout};
use emilion::facade::learned::evaluate::{evaluate_folder, EvalOptions, Split};
use emilion::facade::learned::model::{Model, MODEL_VERSION};
use emilion::facade::learned::train::{train, FeatureSet, TrainOptions};

fn data(name: &str) -> Option<PathBuf> {
    let d = emilion::geometry::files::data_dir()
        .join("facades")
        .join(name);
    if d.join("labels").is_dir() {
        Some(d)
    } else {
        eprintln!("skipped: {} is absent", d.display());
        None
    }
}

fn tmp(name: &str) -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("facade_learned")
        .join(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn tiny(cmp: &Path) -> Model {
    let opts = TrainOptions {
        folders: vec![cmp.to_path_buf()],
        max_images: 3,
        samples_per_image: 2000,
        features: FeatureSet::All,
        trees: 6,
        max_depth: 12,
        min_leaf: 4,
        seed: 1,
    };
    let r = train(&opts).unwrap();
    assert_eq!((r.images, r.samples), (3, 6000));
    r.model
}

#[test]
fn a_tiny_forest_beats_the_trivial_baselines_on_a_held_out_facade() {
    let Some(cmp) = data("cmp_base") else { return };
    let model = tiny(&cmp);
    let out = tmp("tiny");
    let opts = EvalOptions {
        split: Split::Holdout,
        structure: true,
        limit: 2,
        window_boost: 1.0,
    };
    let s = evaluate_folder(&cmp, &out, &model, &opts).unwrap();
    eprintln!(
        "tiny forest on 2 held-out CMP facades: window IoU {:.3} (all-window {:.3}), F1 {:.3}, \
         pixel accuracy {:.3} (all-wall {:.3})",
        s.window_iou, s.all_window_iou, s.f1, s.pixel_accuracy, s.all_wall_accuracy
    );
    assert_eq!((s.layout, s.images), (Layout::Cmp, 2));
    assert!(s.window_iou > s.all_window_iou + 0.1, "{s:?}");
    // all-wall finds no window (F1 0); three training photos are too few to beat its pixel
    // accuracy (0.52 against 0.62 here), which the full model does (docs/facades.md)
    assert!(s.f1 > 0.05, "{s:?}");
    // predictions are CMP index PNGs of the photo's size
    let (stems, _) = labelled_folder(&cmp).unwrap();
    let pred = out.join("pred").join(format!("{}.png", stems[3]));
    let p = read_elements(&pred, Layout::Cmp).unwrap();
    let t = read_elements(
        &cmp.join("labels").join(format!("{}.png", stems[3])),
        Layout::Cmp,
    )
    .unwrap();
    assert_eq!((p.width, p.height), (t.width, t.height));
    // the model file reads back the same
    let file = out.join("m.bin");
    model.save(&file).unwrap();
    assert_eq!(Model::load(&file).unwrap(), model);
}

#[test]
fn a_model_of_another_version_truncated_or_foreign_is_a_clear_error() {
    let Some(cmp) = data("cmp_base") else { return };
    let model = tiny(&cmp);
    let out = tmp("versions");
    let file = out.join("m.bin");
    model.save(&file).unwrap();
    let bytes = std::fs::read(&file).unwrap();
    let mut old = bytes.clone();
    old[16..20].copy_from_slice(&(MODEL_VERSION + 1).to_le_bytes());
    let cases: [(&str, Vec<u8>, &str); 3] = [
        ("old.bin", old, "train it again"),
        ("cut.bin", bytes[..bytes.len() / 2].to_vec(), "truncated"),
        (
            "photo.bin",
            b"\x89PNG not a model at all".to_vec(),
            "not an emilion facade model",
        ),
    ];
    for (name, b, want) in cases {
        let p = out.join(name);
        std::fs::write(&p, b).unwrap();
        let e = Model::load(&p).unwrap_err().to_string();
        assert!(e.contains(want) && e.contains(name), "{e}");
    }
}

#[test]
fn layouts_are_detected_and_labelmefacade_predictions_are_its_colours() {
    let (Some(cmp), Some(lm)) = (data("cmp_base"), data("labelmefacade")) else {
        return;
    };
    assert_eq!(labelled_folder(&cmp).unwrap().1, Layout::Cmp);
    let (stems, layout) = labelled_folder(&lm).unwrap();
    assert_eq!((stems.len(), layout), (23, Layout::LabelMe));
    let model = tiny(&cmp);
    let out = tmp("lm");
    let opts = EvalOptions {
        split: Split::Holdout,
        structure: true,
        limit: 1,
        window_boost: 1.0,
    };
    let s = evaluate_folder(&lm, &out, &model, &opts).unwrap();
    assert_eq!(s.images, 1);
    let pred = out.join("pred").join(format!("{}.png", stems[0]));
    read_elements(&pred, Layout::LabelMe).unwrap();
    // a CMP label map read as LabelMeFacade colours fails naming the file
    let e = read_elements(&cmp.join("labels").join("cmp_b0001.png"), Layout::LabelMe);
    assert!(e.is_err());
}

#[test]
fn the_training_and_evaluation_scripts_run_on_a_few_photos() {
    let Some(cmp) = data("cmp_base") else { return };
    let out = tmp("scripts");
    let bin = env!("CARGO_BIN_EXE_emilion");
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let model = out.join("model");
    let o = std::process::Command::new(bin)
        .arg("run")
        .arg(root.join("scripts/facade_train.rhai"))
        .args(["--set", &format!("out={}", model.display())])
        .args(["--set", &format!("folders={}", cmp.display())])
        .args([
            "--set",
            "max_images=2",
            "--set",
            "samples=500",
            "--set",
            "trees=3",
        ])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let o = std::process::Command::new(bin)
        .arg("run")
        .arg(root.join("scripts/facades_eval.rhai"))
        .args(["--set", &format!("dir={}", cmp.display())])
        .args(["--set", &format!("out={}", out.display())])
        .args(["--set", "method=learned"])
        .args(["--set", &format!("model={}", model.display())])
        .args(["--set", "limit=1"])
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let last = stdout.lines().last().unwrap_or("");
    assert!(
        last.starts_with("window_iou=") && last.contains(" f1=") && last.ends_with(" images=1"),
        "{stdout}"
    );
    let csv = std::fs::read_to_string(out.join("facades_learned.csv")).unwrap();
    assert!(csv.starts_with("image,window_iou,f1") && csv.contains("baseline_all_wall"));
    // training on the 23 evaluation photos is refused
    let o = std::process::Command::new(bin)
        .arg("run")
        .arg(root.join("scripts/facade_train.rhai"))
        .args(["--set", &format!("out={}", out.join("bad").display())])
        .args([
            "--set",
            &format!("folders={}", cmp.with_file_name("labelmefacade").display()),
        ])
        .output()
        .unwrap();
    assert!(!o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("never trained on"));
}
