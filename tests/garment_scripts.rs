//! The garment scripts end to end on short runs: the A-shirt's, the pencil skirt's and the
//! trousers' patterns
//! are read, meshed, pre-positioned and put in a sewing simulation (in fabrics from
//! `kawabata/fabrics`) that steps, renders and writes its glTF. Sewing to closed seams is
//! checked in tests/garment_sewing.rs.
#![cfg(feature = "scripting")]

use std::path::{Path, PathBuf};

use emilion::script::run_file;

/// Runs `scripts/<name>.rhai` briefly and checks that it wrote its outputs.
fn run_garment_script(name: &str) {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let out = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("garment_{name}"));
    let _ = std::fs::remove_dir_all(&out);
    std::fs::create_dir_all(&out).unwrap();
    let sets = vec![
        ("out".to_string(), out.display().to_string()),
        ("seconds".to_string(), "0.05".to_string()),
        ("edge".to_string(), "0.03".to_string()),
    ];
    if let Err(e) = run_file(&root.join(format!("scripts/{name}.rhai")), &sets) {
        panic!("scripts/{name}.rhai failed:\n{e}");
    }
    for f in [
        "front.png",
        "side.png",
        "back.png",
        "garment.glb",
        "pattern.png",
        "pattern.svg",
    ] {
        let p = out.join(name).join(f);
        assert!(
            std::fs::metadata(&p).map(|m| m.len() > 0).unwrap_or(false),
            "{} missing",
            p.display()
        );
    }
}

#[test]
fn aaron_script_dresses_the_mannequin_and_writes_its_outputs() {
    run_garment_script("aaron");
}

#[test]
fn penelope_script_dresses_the_mannequin_and_writes_its_outputs() {
    run_garment_script("penelope");
}

#[test]
fn paco_script_dresses_the_mannequin_and_writes_its_outputs() {
    run_garment_script("paco");
}
