//! The input scan of a block: the continuation bits that mark the first pass's turning
//! points ([`continuation_bits`], [`next_clear`]) and the scan kernel [`Scan`] with the
//! finiteness check folded in.

use super::{all_finite, BLOCK};
use crate::simd::Kernel;

/// Continuation bits of a block of input.
pub(super) type Cont = [u64; BLOCK / 64];

/// Bit `p` (word `p / 64`) set when step `p` of `x` moves strictly in the direction of step
/// `p - 1`: `x[p] - x[p-1]` and `x[p-1] - x[p-2]` both positive or both negative. Bits 0 and
/// 1 (no earlier step in the block) and bits past `x.len()` are clear.
#[inline(always)]
fn continuation_bits(x: &[f64]) -> Cont {
    let mut flags = [0_u8; BLOCK];
    let m = x.len().min(BLOCK);
    if m >= 3 {
        let (a, b, c) = (&x[..m.wrapping_sub(2)], &x[1..m.wrapping_sub(1)], &x[2..m]);
        for (((f, &x0), &x1), &x2) in flags[2..m].iter_mut().zip(a).zip(b).zip(c) {
            let (d0, d1) = (x1 - x0, x2 - x1);
            *f = u8::from((d0 > 0.0 && d1 > 0.0) || (d0 < 0.0 && d1 < 0.0));
        }
    }
    let mut bits = [0_u64; BLOCK / 64];
    for (w, fl) in bits.iter_mut().zip(flags.chunks_exact(64)) {
        *w = fl
            .iter()
            .enumerate()
            .fold(0_u64, |acc, (j, &f)| acc | (u64::from(f) << j));
    }
    bits
}

/// The first position `>= p` whose bit in `bits` is clear (`BLOCK` if none).
#[inline(always)]
pub(super) fn next_clear(bits: &Cont, p: usize) -> usize {
    let mut w = p / 64;
    if w >= bits.len() {
        return BLOCK;
    }
    let mut v = !bits[w] >> (p % 64);
    if v != 0 {
        return p.wrapping_add(v.trailing_zeros() as usize);
    }
    loop {
        w = w.wrapping_add(1);
        if w >= bits.len() {
            return BLOCK;
        }
        v = !bits[w];
        if v != 0 {
            return (w << 6).wrapping_add(v.trailing_zeros() as usize);
        }
    }
}

/// The input scan of a block, as a [`Kernel`]: whether every value is finite and, when so,
/// the continuation bits (the first pass's turning points).
/// (The bits only when the second field says so; else all clear.)
pub(super) struct Scan<'a>(pub(super) &'a [f64], pub(super) bool);

impl Kernel for Scan<'_> {
    type Output = Option<Cont>;
    #[inline(always)]
    fn run_at(self) -> Option<Cont> {
        let (x, bits) = (self.0, self.1);
        all_finite(x).then(|| {
            if bits {
                continuation_bits(x)
            } else {
                [0; BLOCK / 64]
            }
        })
    }
}
