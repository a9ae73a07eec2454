//! Times the solver kernels (assembly, block product, line factorisation and sweeps) on the
//! benchmark scene after 20 steps: `cargo run --release --example solver_kernels -- 256`.
use emilion::cloth::solver::assembly::{Assembly, AssemblyInputs};
use emilion::cloth::solver::line_solver::{LineDir, LineSolver};
use emilion::geometry::Vec3;
use std::time::Instant;
fn main() {
    let n: usize = std::env::args()
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or(256);
    let mut sim = emilion::scenes::hang(n).unwrap();
    sim.run_steps(20, |_, _| Ok(())).unwrap();
    let model = &sim.model;
    let mut asm = Assembly::new(model);
    let mut ls = LineSolver::new(&mut asm.a, n, n);
    let inp = AssemblyInputs {
        dt: 1.0 / 120.0,
        gravity: Vec3::new(0.0, 0.0, -9.81),
        matrix: true,
    };
    let reps = 20;
    rayon::scope(|_| {
        let t = Instant::now();
        for _ in 0..reps {
            asm.assemble(model, &sim.state.x, &sim.state.v, inp);
        }
        println!(
            "assemble {:.3} ms",
            t.elapsed().as_secs_f64() * 1e3 / reps as f64
        );
        let x = vec![Vec3::new(1.0, 2.0, 3.0); n * n];
        let mut y = vec![Vec3::zeros(); n * n];
        let t = Instant::now();
        for _ in 0..reps {
            asm.a.mul_vec(&x, &mut y);
        }
        println!(
            "spmv f64 {:.3} ms",
            t.elapsed().as_secs_f64() * 1e3 / reps as f64
        );
        let fixed = vec![false; n * n];
        let t = Instant::now();
        for _ in 0..reps {
            ls.factor(&asm.a, &fixed, None);
        }
        println!(
            "factor {:.3} ms",
            t.elapsed().as_secs_f64() * 1e3 / reps as f64
        );
        let t = Instant::now();
        for _ in 0..reps {
            ls.sweep(
                &asm.a,
                LineDir::Warp,
                &x,
                &mut y,
                &fixed,
                None,
                [0, 1, 2],
                false,
            );
        }
        println!(
            "sweep warp {:.3} ms",
            t.elapsed().as_secs_f64() * 1e3 / reps as f64
        );
        let t = Instant::now();
        for _ in 0..reps {
            ls.sweep(
                &asm.a,
                LineDir::Weft,
                &x,
                &mut y,
                &fixed,
                None,
                [0, 1, 2],
                false,
            );
        }
        println!(
            "sweep weft {:.3} ms",
            t.elapsed().as_secs_f64() * 1e3 / reps as f64
        );
    });
}
