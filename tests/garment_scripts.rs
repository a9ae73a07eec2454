//! The garment script end to end on a short run: the A-shirt pattern is read, meshed,
//! pre-positioned and put in a sewing simulation that steps, renders and writes its glTF.
//! (Sewing to a closed seam is not reached yet: see the README's garment section.)
#![cfg(feature = "scripting")]

use std::path::{Path, PathBuf};

use emilion::script::run_file;

#[test]
fn aaron_script_dresses_the_mannequin_and_writes_its_outputs() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let out = Path::new(env!("CARGO_TARGET_TMPDIR")).join("garment");
    let _ = std::fs::remove_dir_all(&out);
    std::fs::create_dir_all(&out).unwrap();
    let sets = vec![
        ("out".to_string(), out.display().to_string()),
        ("seconds".to_string(), "0.05".to_string()),
        ("edge".to_string(), "0.03".to_string()),
    ];
    if let Err(e) = run_file(&root.join("scripts/aaron.rhai"), &sets) {
        panic!("scripts/aaron.rhai failed:\n{e}");
    }
    for f in [
        "front.png",
        "side.png",
        "back.png",
        "garment.glb",
        "pattern.png",
        "pattern.svg",
    ] {
        let p = out.join("aaron").join(f);
        assert!(
            std::fs::metadata(&p).map(|m| m.len() > 0).unwrap_or(false),
            "{} missing",
            p.display()
        );
    }
}
