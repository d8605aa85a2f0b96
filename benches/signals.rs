// Shared benchmark signals (included by the criterion benches; no dependencies).

/// SplitMix64: a small deterministic generator, good enough for test signals.
pub struct SplitMix(pub u64);
impl SplitMix {
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in [0, 1).
    pub fn uniform(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// Sine of amplitude `amp`, 1000 samples per period.
pub fn sine(n: usize, amp: f64) -> Vec<f64> {
    (0..n)
        .map(|i| amp * (i as f64 * std::f64::consts::TAU / 1000.0).sin())
        .collect()
}

/// Band-limited noise: white noise through a 4th-order low-pass (two cascaded biquads,
/// cut-off at 1/50 of the sample rate), scaled to RMS `amp`.
pub fn band_limited(n: usize, amp: f64, seed: u64) -> Vec<f64> {
    let mut r = SplitMix(seed);
    let w = std::f64::consts::TAU / 50.0;
    let (s, c) = w.sin_cos();
    let alpha = s / std::f64::consts::SQRT_2;
    let a0 = 1.0 + alpha;
    let b = [(1.0 - c) / 2.0 / a0, (1.0 - c) / a0, (1.0 - c) / 2.0 / a0];
    let a = [-2.0 * c / a0, (1.0 - alpha) / a0];
    let mut y = vec![0.0; n];
    let mut st = [[0.0f64; 4]; 2];
    for v in &mut y {
        let mut u = r.uniform() - 0.5;
        for z in &mut st {
            let out = b[0] * u + b[1] * z[0] + b[2] * z[1] - a[0] * z[2] - a[1] * z[3];
            z[1] = z[0];
            z[0] = u;
            z[3] = z[2];
            z[2] = out;
            u = out;
        }
        *v = u;
    }
    let rms = (y.iter().map(|v| v * v).sum::<f64>() / n as f64).sqrt();
    for v in &mut y {
        *v *= amp / rms;
    }
    y
}

/// Random walk with ±`step` increments of random sign: reverses every ~2 samples.
pub fn random_walk(n: usize, step: f64, seed: u64) -> Vec<f64> {
    let mut r = SplitMix(seed);
    let mut x = 0.0;
    (0..n)
        .map(|_| {
            x += if r.next_u64() & 1 == 0 { step } else { -step };
            x
        })
        .collect()
}
