//! Small seeded pseudo-random generators for everything that must be reproducible bit for
//! bit: [`SplitMix64`] for cloth perturbations, random choices in the buckling models,
//! synthetic noise and annealing moves; [`Lcg64`], the 64-bit linear congruential generator
//! the facade pictures and tests draw their noise from. The same seed gives the same sequence
//! on every machine.

/// SplitMix64 state. Cheap to copy; one per thread or per task for deterministic results.
#[derive(Clone, Copy, Debug)]
pub struct SplitMix64 {
    state: u64,
}

impl SplitMix64 {
    /// A generator started from `seed`.
    pub fn new(seed: u64) -> SplitMix64 {
        SplitMix64 { state: seed }
    }

    /// The generator's state: `SplitMix64::new(g.state())` continues exactly where `g` is
    /// (what a checkpoint saves).
    pub fn state(&self) -> u64 {
        self.state
    }

    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.state = self.state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1), 53 bits.
    pub fn uniform(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Uniform in [lo, hi).
    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.uniform()
    }

    /// Standard normal (Box–Muller; one of the pair is drawn per call).
    pub fn normal(&mut self) -> f64 {
        let u1 = 1.0 - self.uniform(); // (0, 1]
        let u2 = self.uniform();
        (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
    }

    /// A random index below `n` (`n` > 0).
    pub fn below(&mut self, n: usize) -> usize {
        ((self.uniform() * n as f64) as usize).min(n.saturating_sub(1))
    }

    /// A random bit.
    pub fn bit(&mut self) -> bool {
        self.next_u64() & 1 == 1
    }
}

/// Knuth's MMIX linear congruential generator: `s ← s · 6364136223846793005 +
/// 1442695040888963407` (mod 2⁶⁴). Its high bits are the random ones; callers take the bits
/// they need from [`Lcg64::next_u64`].
#[derive(Clone, Copy, Debug)]
pub struct Lcg64 {
    state: u64,
}

impl Lcg64 {
    /// A generator started from `seed`.
    pub fn new(seed: u64) -> Lcg64 {
        Lcg64 { state: seed }
    }

    /// Steps the generator and returns its new state.
    pub fn next_u64(&mut self) -> u64 {
        self.state = self
            .state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        self.state
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uniform_mean_and_normal_variance() {
        let mut r = SplitMix64::new(7);
        let n = 200_000;
        let (mut s, mut s2) = (0.0, 0.0);
        let mut u = 0.0;
        for _ in 0..n {
            u += r.uniform();
            let x = r.normal();
            s += x;
            s2 += x * x;
        }
        assert!((u / n as f64 - 0.5).abs() < 0.005);
        assert!((s / n as f64).abs() < 0.01);
        assert!((s2 / n as f64 - 1.0).abs() < 0.02);
    }

    #[test]
    fn lcg_steps_as_mmix() {
        let mut r = Lcg64::new(1);
        assert_eq!(
            r.next_u64(),
            6364136223846793005u64.wrapping_add(1442695040888963407)
        );
        let (mut a, mut b) = (Lcg64::new(9), Lcg64::new(9));
        for _ in 0..100 {
            assert_eq!(a.next_u64(), b.next_u64());
        }
    }

    #[test]
    fn same_seed_same_sequence() {
        let (mut a, mut b) = (SplitMix64::new(3), SplitMix64::new(3));
        for _ in 0..100 {
            assert_eq!(a.next_u64(), b.next_u64());
        }
    }
}
