//! Writes expression pictures of the generic face: `cargo run --release --example face_preview -- OUT`
fn main() {
    let out = std::env::args()
        .nth(1)
        .unwrap_or("/tmp/face_preview".into());
    std::fs::create_dir_all(&out).unwrap();
    for (name, v) in [
        ("neutral", 0.0),
        ("smile", 1.0),
        ("surprise", 1.0),
        ("anger", 1.0),
        ("sadness", 1.0),
        ("fap_3", 800.0),
        ("fap_19", 1024.0),
    ] {
        let vals = if v == 0.0 {
            vec![]
        } else {
            vec![(name.to_string(), v)]
        };
        let img = emilion::face::preview::expression_image(&vals, 400, 0.0).unwrap();
        img.save(format!("{out}/{name}.png")).unwrap();
    }
}
