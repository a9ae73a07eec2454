//! The virtual Kawabata lab from Rust, without scripting: one fabric file (ours, or a Wang
//! 2011 ARCSim material with `wang`) through every rig on a coarse and a fine mesh; prints the
//! measured and simulated KES parameters and the curve errors, writes CSV and plots.
//! `cargo run --release --example kes_lab -- kawabata/fabrics/suiting-hesc.json [coarse]`
//! `cargo run --release --example kes_lab -- ../shared/data/fabrics/wang2011/royal-target.json wang`
use emilion::kes::{lab, read_fabric, wang};
use std::path::Path;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let file = args
        .get(1)
        .map(String::as_str)
        .unwrap_or("kawabata/fabrics/suiting-hesc.json");
    let spec = if args.iter().any(|a| a == "wang") {
        wang::import_wang(Path::new(file))?
    } else {
        read_fabric(Path::new(file))?
    };
    let mut opts = lab::LabOptions::default();
    if args.iter().any(|a| a == "coarse") {
        opts.meshes.truncate(1);
    }
    let r = lab::run_fabric(&spec, &opts)?;
    println!("{}: {} fitting rounds", r.name, r.fit_rounds);
    for p in &r.params {
        println!(
            "{:14} {:6} {:5} {:12} measured {:10.4} simulated {:10.4} ({:+.2} %)",
            p.test, p.mesh, p.param, p.unit, p.measured, p.simulated, p.error_pct
        );
    }
    for c in &r.curves {
        println!(
            "{:14} {:6} curve RMS {:.2} % of range",
            c.test, c.mesh, c.rms_pct
        );
    }
    if let Some((s, t)) = r.bending_length {
        println!(
            "Peirce bending length {:.3} cm, (B/W)^(1/3) {:.3} cm",
            s * 100.0,
            t * 100.0
        );
    }
    let out = Path::new("out/kes_lab");
    let files = lab::write_fabric_outputs(&r, out)?;
    println!("wrote {} files into {}", files.len(), out.display());
    Ok(())
}
