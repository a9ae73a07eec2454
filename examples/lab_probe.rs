use emilion::kes::{lab, read_fabric, wang};
use std::path::Path;
fn main() {
    let args: Vec<String> = std::env::args().collect();
    let spec = if args[1].ends_with(".json") && args.get(2).map(|s| s == "wang").unwrap_or(false) {
        wang::import_wang(Path::new(&args[1])).unwrap()
    } else {
        read_fabric(Path::new(&args[1])).unwrap()
    };
    let mut opts = lab::LabOptions::default();
    if args.iter().any(|a| a == "coarse") { opts.meshes.truncate(1); }
    let t = std::time::Instant::now();
    let r = lab::run_fabric(&spec, &opts).unwrap();
    println!("{} fit rounds {} in {:?}", r.name, r.fit_rounds, t.elapsed());
    for p in &r.params { println!("{:14} {:6} {:5} {:12} meas {:10.4} sim {:10.4} err {:+.2}%", p.test, p.mesh, p.param, p.unit, p.measured, p.simulated, p.error_pct); }
    for c in &r.curves { println!("{:14} {:6} rms {:.2}%", c.test, c.mesh, c.rms_pct); }
    println!("bending length {:?}", r.bending_length);
    lab::write_fabric_outputs(&r, Path::new("out/labprobe")).unwrap();
}
