fn main() {
    let n: usize = std::env::args()
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or(128);
    let steps: u64 = std::env::args()
        .nth(2)
        .and_then(|s| s.parse().ok())
        .unwrap_or(40);
    let mut sim = emilion::scenes::hang(n).unwrap();
    for _ in 0..steps {
        let st = sim.step().unwrap();
        println!(
            "step {:4} it {:4} res {:.2e} conv {} solve {:.2} ms",
            st.step, st.cg_iterations, st.residual, st.converged, st.solve_ms
        );
    }
}
