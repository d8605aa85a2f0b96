//! The pieces of [`super::fold_window`]'s pass over the samples: the knot segment of the
//! phase, the open cell's running sums, the next bin.

use super::{flush_cell, Bin};

/// A cycle's range of cell means before its first cell: [max x, max F, max -x, max -F]
/// (the smallest means negated, so that one rule updates the four).
pub(super) const NO_RANGE: [f64; 4] = [f64::NEG_INFINITY; 4];

/// One knot segment of the phase: `φ(t) = slope (t - k_lo) + p_lo` on `[k_lo, k_hi)`.
pub(super) struct Segment {
    pub(super) k_lo: f64,
    pub(super) k_hi: f64,
    pub(super) p_lo: f64,
    pub(super) slope: f64,
}

impl Segment {
    /// The segment from knot `j` (`j + 1` a knot).
    // Index arithmetic: j + 1 < the knots' length (the caller's).
    #[allow(clippy::arithmetic_side_effects)]
    #[inline(always)]
    pub(super) fn of(kt: &[f64], kp: &[f64], j: usize) -> Self {
        Segment {
            k_lo: kt[j],
            k_hi: kt[j + 1],
            p_lo: kp[j],
            slope: (kp[j + 1] - kp[j]) / (kt[j + 1] - kt[j]),
        }
    }

    /// The phase at `ti` inside the segment (off its first knot: [`super::fold_window`]
    /// takes `p_lo` there).
    #[inline(always)]
    pub(super) fn phase(&self, ti: f64) -> f64 {
        self.slope * (ti - self.k_lo) + self.p_lo
    }
}

/// The open cell's running sums: its bin's sample sums (x, F, φ, φ², x², t) carried from
/// the bin, and the cell's own sums of x, F, φ (kept in registers while the cell's run of
/// samples lasts: the same additions in the same order as adding into the bin sample by
/// sample).
#[derive(Default, Clone, Copy)]
pub(super) struct Cell {
    pub(super) cur: [f64; 6],
    pub(super) cx: f64,
    pub(super) cf: f64,
    pub(super) cp: f64,
}

impl Cell {
    /// The complete cell into its bin and its cycle's ranges `r`; `n` its samples.
    #[inline(always)]
    pub(super) fn flush(&self, bin: &mut Bin, r: &mut [f64; 4], n: f64) {
        flush_cell(bin, r, n, (self.cx, self.cf, self.cp), &self.cur);
    }

    #[inline(always)]
    pub(super) fn add(&mut self, xi: f64, fi: f64, frac: f64, ti: f64) {
        self.cur[0] += xi;
        self.cur[1] += fi;
        self.cur[2] += frac;
        self.cur[3] += frac * frac;
        self.cur[4] += xi * xi;
        self.cur[5] += ti;
        self.cx += xi;
        self.cf += fi;
        self.cp += frac;
    }

    /// The samples from `i` (below `stop`) that follow in the same knot segment `seg`, cycle
    /// (from `c_lo`) and bin (`g < g_hi`, `g = frac · n_bins`): added; returns the first
    /// sample not taken and its phase when computed here (else -1: `stop` or the segment's
    /// end reached). The phase of the last sample taken is [`Segment::phase`] of it (the same
    /// expression, so the same number).
    // Index arithmetic: i < stop <= the slices' length.
    #[allow(clippy::arithmetic_side_effects)]
    #[inline(always)]
    pub(super) fn run(
        &mut self,
        (t, x, f): (&[f64], &[f64], &[f64]),
        mut i: usize,
        stop: usize,
        seg: &Segment,
        (c_lo, nbf, g_hi): (f64, f64, f64),
    ) -> (usize, f64) {
        let (t, x, f) = (&t[..stop], &x[..stop], &f[..stop]);
        // the nine running sums in locals for the loop (as fields of `self` behind the
        // reference they stayed in memory: a store and a load in each sum's chain every
        // sample); the same additions in the same order
        let [mut s0, mut s1, mut s2, mut s3, mut s4, mut s5] = self.cur;
        let (mut cx, mut cf, mut cp) = (self.cx, self.cf, self.cp);
        let mut next = -1.0;
        while i < stop {
            let ti = t[i];
            if ti >= seg.k_hi {
                break;
            }
            let ph = seg.phase(ti);
            let frac = ph - c_lo;
            if frac * nbf >= g_hi {
                next = ph;
                break;
            }
            let (xi, fi) = (x[i], f[i]);
            s0 += xi;
            s1 += fi;
            s2 += frac;
            s3 += frac * frac;
            s4 += xi * xi;
            s5 += ti;
            cx += xi;
            cf += fi;
            cp += frac;
            i += 1;
        }
        self.cur = [s0, s1, s2, s3, s4, s5];
        (self.cx, self.cf, self.cp) = (cx, cf, cp);
        (i, next)
    }
}

/// The bin of `g = frac · n_bins` when the open bin `[b_hi - 1, b_hi)` (number `cb`) does
/// not hold it: `(b, b_lo, b_hi)`, the last bin open above.
// Index arithmetic: cb + 2 < nb checked; nb >= 1.
#[allow(clippy::arithmetic_side_effects)]
#[inline(always)]
pub(super) fn next_bin(g: f64, b_hi: f64, cb: usize, nb: usize) -> (usize, f64, f64) {
    if g >= b_hi && g < b_hi + 1.0 && cb + 2 < nb {
        // the next bin (not the last): b_hi = cb + 1 exactly, so floor(g) = cb + 1
        return (cb + 1, b_hi, b_hi + 1.0);
    }
    let b = (g as usize).min(nb - 1);
    let lo = b as f64;
    let hi = if b + 1 == nb { f64::INFINITY } else { lo + 1.0 };
    (b, lo, hi)
}
