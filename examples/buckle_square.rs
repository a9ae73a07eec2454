//! Exploration: a square cloth pushed from one border, with and without Choi–Ko.
use emilion::cloth::elements::SpringKind;
use emilion::cloth::{ClothModel, FabricParameters, Simulation, SimulationParameters, Trajectory};
fn main() {
    let n: usize = std::env::args()
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or(41);
    for ck in [false, true] {
        let mut m = ClothModel::grid(0.5, 0.5, n, n, FabricParameters::default()).unwrap();
        let mut seed: u64 = 12345;
        for p in &mut m.mesh.positions {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            p.z = 1e-4 * (((seed >> 11) as f64 / (1u64 << 53) as f64) - 0.5);
        }
        if ck {
            m.enable_choi_ko();
        }
        let params = SimulationParameters {
            dt: 1.0 / 120.0,
            gravity: [0.0, 0.0, 0.0],
            ..Default::default()
        };
        let mut sim = Simulation::new(m, params).unwrap();
        let left: Vec<usize> = (0..n).map(|i| i * n).collect();
        let right: Vec<usize> = (0..n).map(|i| i * n + n - 1).collect();
        sim.pin(&left).unwrap();
        sim.attach(
            &right,
            Trajectory::Keyframes(vec![(0.0, [0.0; 3]), (1.0, [-0.1, 0.0, 0.0])]),
        )
        .unwrap();
        let t = std::time::Instant::now();
        let steps = 180;
        sim.run_steps(steps, |_, _| Ok(())).unwrap();
        let ms = t.elapsed().as_secs_f64() * 1e3 / steps as f64;
        let law = sim.model.law.clone();
        let (mut comp, mut tot) = (0, 0);
        for s in &sim.model.springs {
            if let SpringKind::Stretch { .. } = s.kind {
                tot += 1;
                let l = (sim.state.x[s.b] - sim.state.x[s.a]).norm();
                if l < 0.99 * s.rest {
                    comp += 1;
                }
            }
        }
        let (_, _, el) = sim.energy();
        let mid = n / 2;
        let z: Vec<f64> = (0..n).map(|j| sim.state.x[mid * n + j].z).collect();
        let zmax = z.iter().fold(0.0f64, |a, b| a.max(b.abs()));
        let _ = law;
        println!("choi_ko {ck}: {ms:.2} ms/step, compressed >1%: {comp}/{tot} = {:.1}%, elastic {el:.4} J, max |z| mid row {zmax:.4}", 100.0 * comp as f64 / tot as f64);
        println!(
            "  z mid row: {:?}",
            z.iter()
                .step_by(2)
                .map(|v| (v * 1e3).round() / 1.0)
                .collect::<Vec<_>>()
        );
    }
}
