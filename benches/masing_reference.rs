// The reference for the Masing kernel benchmark: a plain std-Rust loop of the same rules as
// `contactlab_core::masing` (PHYSICS.md §1), written the obvious way — a stack of sample
// indices into `x`/`out`, libm `exp`/`exp_m1` per sample, no blocking. Shared by the
// benchmark (speed ratio) and the core's tests (agreement to 1e-12). It can stop and resume
// (`Reference::run` over consecutive ranges) so that the benchmark can time it piece by piece.

/// `h0 (1 - exp(-ac |u|))` with the sign of `u`; `exp_m1` below ln 2 keeps small `u` accurate.
#[inline]
pub fn virgin(h0: f64, ac: f64, u: f64) -> f64 {
    let z = ac * u.abs();
    let g = if z < std::f64::consts::LN_2 {
        -(-z).exp_m1()
    } else {
        1.0 - (-z).exp()
    };
    (h0 * g).copysign(u)
}

/// The loop's memory between ranges: last input and force, direction, and the stack of
/// reversal sample indices (reused, so its allocation is not timed).
#[derive(Default)]
pub struct Reference {
    xp: f64,
    hp: f64,
    dir: i8,
    pub stack: Vec<usize>,
}

impl Reference {
    /// Back to the origin (keeps the stack's allocation).
    pub fn reset(&mut self) {
        self.stack.clear();
        (self.xp, self.hp, self.dir) = (0.0, 0.0, 0);
    }

    /// Masing forces of `x[range]` into `out[range]`, continuing from the previous range
    /// (which must end where this one starts).
    pub fn run(
        &mut self,
        h0: f64,
        ac: f64,
        lam: f64,
        x: &[f64],
        out: &mut [f64],
        range: std::ops::Range<usize>,
    ) {
        // Locals in registers, as in a one-shot loop.
        let (mut xp, mut hp, mut dir) = (self.xp, self.hp, self.dir);
        let stack = &mut self.stack;
        for i in range {
            let xi = x[i];
            if xi != xp {
                let d: i8 = if xi > xp { 1 } else { -1 };
                if dir != 0 && d != dir {
                    stack.push(i - 1);
                }
                dir = d;
                // Wipe out every loop the step closes.
                loop {
                    let target = match stack.len() {
                        0 => break,
                        1 => -x[stack[0]],
                        n => x[stack[n - 2]],
                    };
                    if (xi - target) * f64::from(d) >= 0.0 {
                        let keep = if stack.len() == 1 { 0 } else { stack.len() - 2 };
                        stack.truncate(keep);
                    } else {
                        break;
                    }
                }
                hp = match stack.last() {
                    Some(&r) => out[r] + lam * virgin(h0, ac, (xi - x[r]) / lam),
                    None => virgin(h0, ac, xi),
                };
                xp = xi;
            }
            out[i] = hp;
        }
        (self.xp, self.hp, self.dir) = (xp, hp, dir);
    }
}

/// Masing forces of `x` from the origin into `out` (reused between calls); `stack` is the
/// caller's scratch stack of reversal sample indices.
#[allow(dead_code)] // the core's tests use it; the benchmark runs `Reference` piece by piece
pub fn reference_force(
    h0: f64,
    ac: f64,
    lam: f64,
    x: &[f64],
    out: &mut [f64],
    stack: &mut Vec<usize>,
) {
    let mut r = Reference {
        stack: std::mem::take(stack),
        ..Reference::default()
    };
    r.reset();
    r.run(h0, ac, lam, x, out, 0..x.len());
    *stack = r.stack;
}
