//! Time per stage of the facade analysis of a one-megapixel photo: a photo (by default a
//! labelled street photo of `../shared/data`) resized to about 1 MP, analysed five times;
//! prints one JSON line per run and the median.
//! `cargo run --release --example facade_timing -- [PHOTO]`

use std::path::PathBuf;

use emilion::facade::analysis::{analyze, Options};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let photo = std::env::args().nth(1).map(PathBuf::from).unwrap_or_else(|| {
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(
            "../shared/data/facades/labelmefacade/images/static_outdoor_street_city_cambridge_uk__IMG_8741.jpg",
        )
    });
    let img = image::open(&photo)?.to_rgb8();
    let s = (1e6 / (img.width() as f64 * img.height() as f64)).sqrt();
    let (w, h) = (
        (img.width() as f64 * s).round() as u32,
        (img.height() as f64 * s).round() as u32,
    );
    let big = image::imageops::resize(&img, w, h, image::imageops::FilterType::Triangle);
    let path = std::env::temp_dir().join(format!("facade_timing_{}.png", std::process::id()));
    big.save(&path)?;
    let mut totals = Vec::new();
    for run in 0..5 {
        let a = analyze(&path, &Options::default())?;
        let stages: Vec<String> = a
            .seconds
            .iter()
            .map(|(k, v)| format!("\"{k}\":{v:.4}"))
            .collect();
        println!(
            "{{\"run\":{run},\"megapixels\":{:.3},\"total_s\":{:.4},{},\"problem\":{:?}}}",
            (w * h) as f64 / 1e6,
            a.total_seconds(),
            stages.join(","),
            a.problem().unwrap_or_default()
        );
        totals.push(a.total_seconds());
    }
    totals.sort_by(f64::total_cmp);
    println!("{{\"median_total_s\":{:.4}}}", totals[totals.len() / 2]);
    let _ = std::fs::remove_file(&path);
    Ok(())
}
