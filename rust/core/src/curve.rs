//! Virgin (initial loading) curves for the Masing operator.
//!
//! A curve is an odd, non-decreasing function `f` with `f(0) = 0`. The operator only calls
//! [`Backbone::eval`]; the energy and stiffness helpers use the rest of the trait. Adding a
//! curve means implementing this trait; the operator does not change.

use crate::error::{check_finite, check_positive, CoreError};

/// An odd, monotone non-decreasing virgin curve with `f(0) = 0`.
pub trait Backbone {
    /// `f(u)`, odd in `u`.
    fn eval(&self, u: f64) -> f64;
    /// `f'(u)`, even in `u`.
    fn slope(&self, u: f64) -> f64;
    /// `∫_0^u f(s) ds` for `u >= 0`.
    fn integral(&self, u: f64) -> f64;
    /// Area between the curve and its chord on `[0, u]`, `u >= 0`:
    /// `∫_0^u f - u f(u) / 2`. A closed Masing loop of range `R` with branch scale `λ`
    /// dissipates `2 λ² B(R/λ)` (PHYSICS.md §1). Override where the default cancels badly.
    fn chord_area(&self, u: f64) -> f64 {
        let u = u.abs();
        self.integral(u) - 0.5 * u * self.eval(u)
    }
}

/// `2^(j/64)` for `j = 0..64` as bit patterns of a head (the nearest double) and a tail (the
/// nearest double to the rest), computed to 80 digits.
const EXP2_64THS: [[u64; 2]; 64] = [
    [0x3FF0000000000000, 0x0000000000000000],
    [0x3FF02C9A3E778061, 0xBC719083535B085D],
    [0x3FF059B0D3158574, 0x3C8D73E2A475B465],
    [0x3FF0874518759BC8, 0x3C6186BE4BB284FF],
    [0x3FF0B5586CF9890F, 0x3C98A62E4ADC610B],
    [0x3FF0E3EC32D3D1A2, 0x3C403A1727C57B53],
    [0x3FF11301D0125B51, 0xBC96C51039449B3A],
    [0x3FF1429AAEA92DE0, 0xBC932FBF9AF1369E],
    [0x3FF172B83C7D517B, 0xBC819041B9D78A76],
    [0x3FF1A35BEB6FCB75, 0x3C8E5B4C7B4968E4],
    [0x3FF1D4873168B9AA, 0x3C9E016E00A2643C],
    [0x3FF2063B88628CD6, 0x3C8DC775814A8495],
    [0x3FF2387A6E756238, 0x3C99B07EB6C70573],
    [0x3FF26B4565E27CDD, 0x3C82BD339940E9D9],
    [0x3FF29E9DF51FDEE1, 0x3C8612E8AFAD1255],
    [0x3FF2D285A6E4030B, 0x3C90024754DB41D5],
    [0x3FF306FE0A31B715, 0x3C86F46AD23182E4],
    [0x3FF33C08B26416FF, 0x3C932721843659A6],
    [0x3FF371A7373AA9CB, 0xBC963AEABF42EAE2],
    [0x3FF3A7DB34E59FF7, 0xBC75E436D661F5E3],
    [0x3FF3DEA64C123422, 0x3C8ADA0911F09EBC],
    [0x3FF4160A21F72E2A, 0xBC5EF3691C309278],
    [0x3FF44E086061892D, 0x3C489B7A04EF80D0],
    [0x3FF486A2B5C13CD0, 0x3C73C1A3B69062F0],
    [0x3FF4BFDAD5362A27, 0x3C7D4397AFEC42E2],
    [0x3FF4F9B2769D2CA7, 0xBC94B309D25957E3],
    [0x3FF5342B569D4F82, 0xBC807ABE1DB13CAD],
    [0x3FF56F4736B527DA, 0x3C99BB2C011D93AD],
    [0x3FF5AB07DD485429, 0x3C96324C054647AD],
    [0x3FF5E76F15AD2148, 0x3C9BA6F93080E65E],
    [0x3FF6247EB03A5585, 0xBC9383C17E40B497],
    [0x3FF6623882552225, 0xBC9BB60987591C34],
    [0x3FF6A09E667F3BCD, 0xBC9BDD3413B26456],
    [0x3FF6DFB23C651A2F, 0xBC6BBE3A683C88AB],
    [0x3FF71F75E8EC5F74, 0xBC816E4786887A99],
    [0x3FF75FEB564267C9, 0xBC90245957316DD3],
    [0x3FF7A11473EB0187, 0xBC841577EE04992F],
    [0x3FF7E2F336CF4E62, 0x3C705D02BA15797E],
    [0x3FF82589994CCE13, 0xBC9D4C1DD41532D8],
    [0x3FF868D99B4492ED, 0xBC9FC6F89BD4F6BA],
    [0x3FF8ACE5422AA0DB, 0x3C96E9F156864B27],
    [0x3FF8F1AE99157736, 0x3C85CC13A2E3976C],
    [0x3FF93737B0CDC5E5, 0xBC675FC781B57EBC],
    [0x3FF97D829FDE4E50, 0xBC9D185B7C1B85D1],
    [0x3FF9C49182A3F090, 0x3C7C7C46B071F2BE],
    [0x3FFA0C667B5DE565, 0xBC9359495D1CD533],
    [0x3FFA5503B23E255D, 0xBC9D2F6EDB8D41E1],
    [0x3FFA9E6B5579FDBF, 0x3C90FAC90EF7FD31],
    [0x3FFAE89F995AD3AD, 0x3C97A1CD345DCC81],
    [0x3FFB33A2B84F15FB, 0xBC62805E3084D708],
    [0x3FFB7F76F2FB5E47, 0xBC75584F7E54AC3B],
    [0x3FFBCC1E904BC1D2, 0x3C823DD07A2D9E84],
    [0x3FFC199BDD85529C, 0x3C811065895048DD],
    [0x3FFC67F12E57D14B, 0x3C92884DFF483CAD],
    [0x3FFCB720DCEF9069, 0x3C7503CBD1E949DB],
    [0x3FFD072D4A07897C, 0xBC9CBC3743797A9C],
    [0x3FFD5818DCFBA487, 0x3C82ED02D75B3707],
    [0x3FFDA9E603DB3285, 0x3C9C2300696DB532],
    [0x3FFDFC97337B9B5F, 0xBC91A5CD4F184B5C],
    [0x3FFE502EE78B3FF6, 0x3C839E8980A9CC8F],
    [0x3FFEA4AFA2A490DA, 0xBC9E9C23179C2893],
    [0x3FFEFA1BEE615A27, 0x3C9DC7F486A4B6B0],
    [0x3FFF50765B6E4540, 0x3C99D3E12DD8A18B],
    [0x3FFFA7C1819E90D8, 0x3C874853F3A5931E],
];

/// `1 - exp(-z)` for `z >= 0`, to about an ulp relative for every `z` (small `z` included),
/// written without branches or library calls so that loops over it vectorise (SSE2 on a
/// generic x86-64 build). The scalar and vectorised code paths run the same IEEE operations,
/// so a value computed once per sample and once at a reversal is bit-identical.
///
/// `-z = (64 k + j) ln2/64 + r` with `0 <= j < 64`, `|r| <= ln2/128` (Cody–Waite in two
/// parts, round-to-nearest by the 1.5·2⁵² trick, no `round()` call), so `e^{-z} = 2^k ·
/// 2^{j/64} · e^r`; `2^{j/64} = T + t` from a table (head and tail), `p = expm1(r)` by its
/// Taylor polynomial to degree 6 (remainder below `|r|^7/7! < 3e-20`; Estrin's scheme), then
/// `1 - e^{-z} = (1 - s) - (s_t + s p)` with `s = 2^k T`, `s_t = 2^k t`. For `k = j = 0`
/// that is `-p` (no cancellation); for `k = -1` `s` is in `(1/2, 1)` and `1 - s` exact
/// (Sterbenz), the result at least `1 - 2^{-1/128} ≈ 0.0054` against errors of order `1e-19`
/// in the bracket; below, the result exceeds 1/2. Checked against libm over the whole range
/// in `tests/masing_kernel.rs`.
#[inline(always)]
pub fn one_minus_exp_neg(z: f64) -> f64 {
    // 64 / ln 2, and ln 2 / 64 split so that kf · LN2_64_HI is exact for |kf| < 2^20.
    const INV_LN2_64: f64 = 64.0 * std::f64::consts::LOG2_E;
    const LN2_64_HI: f64 = f64::from_bits(0x3F86_2E42_FEE0_0000); // fdlibm's ln2_hi / 64
    const LN2_64_LO: f64 = f64::from_bits(0x3D8A_39EF_3579_3C76); // fdlibm's ln2_lo / 64
    const SHIFTER: f64 = 6_755_399_441_055_744.0; // 1.5 · 2^52
    // The exponent bias times 64 folded into the shifter: the low bits of `t` are then
    // `64 (k + 1023) + j >= 0`, a biased exponent and a table index by two shifts and a mask.
    const BIAS: f64 = 65_472.0; // 1023 · 64
    // Beyond 708 exp(-z) < 2^-1021: 1 - exp(-z) rounds to 1, and 2^k stays a normal number.
    let z = if z < 708.0 { z } else { 708.0 };
    let t = -z * INV_LN2_64 + (SHIFTER + BIAS);
    let kf = t - (SHIFTER + BIAS);
    let m = t.to_bits().wrapping_sub(SHIFTER.to_bits()); // 64 (k + 1023) + j, in 102..=65472
    let r = (-z - kf * LN2_64_HI) - kf * LN2_64_LO;
    let [head, tail] = EXP2_64THS[(m & 63) as usize];
    let two_k = f64::from_bits((m >> 6) << 52);
    let s = f64::from_bits(head) * two_k;
    let st = f64::from_bits(tail) * two_k;
    let r2 = r * r;
    let q = ((1.0 + r * 0.5) + (1.0 / 6.0 + r * (1.0 / 24.0)) * r2)
        + (1.0 / 120.0 + r * (1.0 / 720.0)) * (r2 * r2);
    let p = r * q;
    (1.0 - s) - (st + s * p)
}

/// The paper's exponential virgin curve `f(u) = h0 (1 - exp(-ac u))`, odd-extended.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Exponential {
    /// Saturation force h0 (break-away friction force).
    pub h0: f64,
    /// Curvature ac (1/length).
    pub ac: f64,
}

impl Exponential {
    pub fn new(h0: f64, ac: f64) -> Result<Self, CoreError> {
        check_positive("h0", h0)?;
        check_positive("ac", ac)?;
        // the initial stiffness h0·ac must be a number too (fuzzing: 4e201 · 4e204 = inf)
        crate::error::check_output("h0*ac", &[h0 * ac])?;
        Ok(Self { h0, ac })
    }

    /// Energy dissipated by a symmetric Masing cycle (λ = 2) of amplitude `a` (PHYSICS.md §1).
    pub fn loop_energy(&self, a: f64) -> f64 {
        8.0 * self.chord_area(a)
    }
}

/// `S(z) = [z - (1 - e^-z) - z (1 - e^-z) / 2] / z³` for `0 <= z < 2`: the chord area of
/// `1 - e^-u` on `[0, z]` divided by `z³`, by its series `Σ_{m>=3} (-1)^{m+1} (m - 2) z^(m-3) /
/// (2 m!)` (no cancellation; `S(0) = 1/12`). Dividing out `z³` keeps the chord area finite
/// when `z` is so small that `z³` underflows (ac → 0 with h0·ac fixed, where fits of nearly
/// linear loops go).
fn exp_chord_area_unit_over_z3(z: f64) -> f64 {
    debug_assert!((0.0..2.0).contains(&z));
    let mut term = 1.0 / 6.0; // z^(m-3) / m! at m = 3
    let mut sum = 0.0;
    let mut m = 3.0_f64;
    loop {
        let t = term * (m - 2.0) * 0.5;
        let signed = if (m as i64) % 2 == 0 { t } else { -t };
        sum -= signed;
        if t < 1e-18 * sum.abs() || m > 60.0 {
            break;
        }
        m += 1.0;
        term *= z / m;
    }
    sum
}

impl Backbone for Exponential {
    #[inline(always)]
    fn eval(&self, u: f64) -> f64 {
        (self.h0 * one_minus_exp_neg(self.ac * u.abs())).copysign(u)
    }
    fn slope(&self, u: f64) -> f64 {
        self.h0 * self.ac * (-self.ac * u.abs()).exp()
    }
    fn integral(&self, u: f64) -> f64 {
        let u = u.abs();
        self.h0 * (u - one_minus_exp_neg(self.ac * u) / self.ac)
    }
    fn chord_area(&self, u: f64) -> f64 {
        let u = u.abs();
        let z = self.ac * u;
        if z < 2.0 {
            // (h0/ac) z³ S(z) written as (h0 ac) z u² S(z): h0/ac and z³ over/underflow when
            // ac is tiny and h0 huge (h0 ac finite), which gave NaN or 0 instead of E.
            (self.h0 * self.ac) * z * u * u * exp_chord_area_unit_over_z3(z)
        } else {
            // (h0/ac)(z - g - z g/2) with z = ac·u expanded: z itself overflows for ac·u beyond
            // the range (inf - inf was NaN, found by AFL++) while the area h0 u (1 - g/2) does not.
            let g = one_minus_exp_neg(z);
            self.h0 * (u * (1.0 - 0.5 * g) - g / self.ac)
        }
    }
}

/// A measured backbone: points `(u_i, f_i)` with `u_0 = 0`, `f_0 = 0`, `u` strictly increasing
/// and `f` non-decreasing, interpolated by a monotone piecewise cubic (Fritsch–Carlson / PCHIP),
/// odd-extended, and continued linearly with the end slope beyond the last point.
#[derive(Debug, Clone, PartialEq)]
pub struct Tabulated {
    u: Vec<f64>,
    f: Vec<f64>,
    d: Vec<f64>,
    /// Cumulative integral at each knot.
    cum: Vec<f64>,
}

// Knot-table index arithmetic: a table holds n >= 2 knots (checked in `Tabulated::new`) and
// every index stays in 0..n, so nothing over- or underflows.
#[allow(clippy::arithmetic_side_effects)]
impl Tabulated {
    pub fn new(u: &[f64], f: &[f64]) -> Result<Self, CoreError> {
        crate::error::check_same_len("x_points", u.len(), "f_points", f.len())?;
        if u.len() < 2 {
            return Err(CoreError::InvalidBackbone {
                index: u.len(),
                reason: "need at least two points (the origin and one more)",
            });
        }
        check_finite("x_points", u)?;
        check_finite("f_points", f)?;
        if u[0] != 0.0 || f[0] != 0.0 {
            return Err(CoreError::InvalidBackbone {
                index: 0,
                reason: "the backbone must start at the origin (x = 0, f = 0)",
            });
        }
        for i in 1..u.len() {
            if u[i] <= u[i - 1] {
                return Err(CoreError::InvalidBackbone {
                    index: i,
                    reason: "x_points must be strictly increasing",
                });
            }
            if f[i] < f[i - 1] {
                return Err(CoreError::InvalidBackbone {
                    index: i,
                    reason: "f_points must be non-decreasing (monotone backbone)",
                });
            }
        }
        if f[f.len() - 1] <= 0.0 {
            return Err(CoreError::InvalidBackbone {
                index: f.len() - 1,
                reason: "the backbone must rise above zero",
            });
        }
        let d = pchip_slopes(u, f);
        let mut cum = vec![0.0; u.len()];
        for i in 1..u.len() {
            let h = u[i] - u[i - 1];
            // Exact integral of the Hermite cubic over one interval.
            cum[i] = cum[i - 1] + h * (f[i - 1] + f[i]) / 2.0 + h * h * (d[i - 1] - d[i]) / 12.0;
        }
        crate::error::check_output("backbone slope", &d)?;
        crate::error::check_output("backbone integral", &cum)?;
        Ok(Self {
            u: u.to_vec(),
            f: f.to_vec(),
            d,
            cum,
        })
    }

    /// The knots `(u, f)`.
    pub fn points(&self) -> (&[f64], &[f64]) {
        (&self.u, &self.f)
    }

    /// Interval index `i` with `u[i] <= s < u[i+1]`, or `None` beyond the last knot.
    #[inline]
    fn interval(&self, s: f64) -> Option<usize> {
        let n = self.u.len();
        if s >= self.u[n - 1] {
            return None;
        }
        // partition_point: first index with u > s; s >= 0 = u[0] so it is >= 1.
        // NaN (or s < 0 from a direct caller) finds no knot: None, as beyond the table, rather
        // than an index underflow (found by AFL++ on the public `Backbone` methods).
        self.u.partition_point(|&v| v <= s).checked_sub(1)
    }

    fn eval_pos(&self, s: f64) -> f64 {
        let n = self.u.len();
        match self.interval(s) {
            None => self.f[n - 1] + self.d[n - 1] * (s - self.u[n - 1]),
            Some(i) => {
                let h = self.u[i + 1] - self.u[i];
                let t = (s - self.u[i]) / h;
                let (t2, t3) = (t * t, t * t * t);
                let h00 = 2.0 * t3 - 3.0 * t2 + 1.0;
                let h10 = t3 - 2.0 * t2 + t;
                let h01 = -2.0 * t3 + 3.0 * t2;
                let h11 = t3 - t2;
                h00 * self.f[i]
                    + h10 * h * self.d[i]
                    + h01 * self.f[i + 1]
                    + h11 * h * self.d[i + 1]
            }
        }
    }
}

/// Fritsch–Carlson monotone slopes (the scheme of scipy's `PchipInterpolator`).
// Index arithmetic on n = x.len() >= 2 knots (n >= 3 past the early return).
#[allow(clippy::arithmetic_side_effects)]
fn pchip_slopes(x: &[f64], y: &[f64]) -> Vec<f64> {
    let n = x.len();
    let h: Vec<f64> = x.windows(2).map(|w| w[1] - w[0]).collect();
    let delta: Vec<f64> = (0..n - 1).map(|i| (y[i + 1] - y[i]) / h[i]).collect();
    let mut d = vec![0.0; n];
    if n == 2 {
        d[0] = delta[0];
        d[1] = delta[0];
        return d;
    }
    for k in 1..n - 1 {
        if delta[k - 1] * delta[k] <= 0.0 {
            d[k] = 0.0;
        } else {
            let w1 = 2.0 * h[k] + h[k - 1];
            let w2 = h[k] + 2.0 * h[k - 1];
            d[k] = (w1 + w2) / (w1 / delta[k - 1] + w2 / delta[k]);
        }
    }
    d[0] = pchip_end(h[0], h[1], delta[0], delta[1]);
    d[n - 1] = pchip_end(h[n - 2], h[n - 3], delta[n - 2], delta[n - 3]);
    d
}

fn pchip_end(h0: f64, h1: f64, m0: f64, m1: f64) -> f64 {
    let d = ((2.0 * h0 + h1) * m0 - h0 * m1) / (h0 + h1);
    if d.signum() != m0.signum() || m0 == 0.0 {
        0.0
    } else if m0.signum() != m1.signum() && d.abs() > 3.0 * m0.abs() {
        3.0 * m0
    } else {
        d
    }
}

// Knot-table index arithmetic: a table holds n >= 2 knots (checked in `Tabulated::new`) and
// every index stays in 0..n, so nothing over- or underflows.
#[allow(clippy::arithmetic_side_effects)]
impl Backbone for Tabulated {
    #[inline]
    fn eval(&self, u: f64) -> f64 {
        self.eval_pos(u.abs()).copysign(u)
    }
    fn slope(&self, u: f64) -> f64 {
        let s = u.abs();
        let n = self.u.len();
        match self.interval(s) {
            None => self.d[n - 1],
            Some(i) => {
                let h = self.u[i + 1] - self.u[i];
                let t = (s - self.u[i]) / h;
                let t2 = t * t;
                let dh00 = (6.0 * t2 - 6.0 * t) / h;
                let dh10 = 3.0 * t2 - 4.0 * t + 1.0;
                let dh01 = (-6.0 * t2 + 6.0 * t) / h;
                let dh11 = 3.0 * t2 - 2.0 * t;
                dh00 * self.f[i] + dh10 * self.d[i] + dh01 * self.f[i + 1] + dh11 * self.d[i + 1]
            }
        }
    }
    fn chord_area(&self, u: f64) -> f64 {
        let s = u.abs();
        let n = self.u.len();
        if self.interval(s).is_some() {
            return self.integral(s) - 0.5 * s * self.eval_pos(s);
        }
        // Beyond the last knot f is linear, f = fe + d r (r = s - ue): the r² terms of ∫f and
        // of s f / 2 cancel, leaving cum_e - ue fe / 2 + r (fe - ue d) / 2. Written so the
        // area stays finite where r² overflows (inf - inf was NaN, found by AFL++).
        let (ue, fe, de) = (self.u[n - 1], self.f[n - 1], self.d[n - 1]);
        let r = s - ue;
        self.cum[n - 1] - 0.5 * ue * fe + 0.5 * r * (fe - ue * de)
    }
    fn integral(&self, u: f64) -> f64 {
        let s = u.abs();
        let n = self.u.len();
        match self.interval(s) {
            None => {
                let r = s - self.u[n - 1];
                self.cum[n - 1] + self.f[n - 1] * r + 0.5 * self.d[n - 1] * r * r
            }
            Some(i) => {
                let h = self.u[i + 1] - self.u[i];
                let t = (s - self.u[i]) / h;
                let (t2, t3, t4) = (t * t, t * t * t, t * t * t * t);
                // Antiderivatives of the Hermite basis functions on [0, t].
                let i00 = t4 / 2.0 - t3 + t;
                let i10 = t4 / 4.0 - 2.0 * t3 / 3.0 + t2 / 2.0;
                let i01 = -t4 / 2.0 + t3;
                let i11 = t4 / 4.0 - t3 / 3.0;
                self.cum[i]
                    + h * (i00 * self.f[i]
                        + i10 * h * self.d[i]
                        + i01 * self.f[i + 1]
                        + i11 * h * self.d[i + 1])
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn simpson(f: impl Fn(f64) -> f64, a: f64, b: f64, n: usize) -> f64 {
        let h = (b - a) / n as f64;
        let mut s = f(a) + f(b);
        for i in 1..n {
            let w = if i % 2 == 1 { 4.0 } else { 2.0 };
            s += w * f(a + h * i as f64);
        }
        s * h / 3.0
    }

    #[test]
    fn exponential_energy_matches_physics_formula_and_limits() {
        let c = Exponential::new(3.0, 2.0).unwrap();
        for &a in &[0.05, 0.3, 1.0, 2.5, 10.0] {
            let hm = c.eval(a);
            let printed = 8.0 * (c.h0 * (a - (1.0 - (-c.ac * a).exp()) / c.ac) - a * hm / 2.0);
            let e = c.loop_energy(a);
            assert!(
                (e - printed).abs() <= 1e-9 * printed.abs(),
                "{a}: {e} vs {printed}"
            );
        }
        // Small amplitude: cubic law (2/3) h0 ac^2 A^3.
        let a = 1e-6;
        let cubic = 2.0 / 3.0 * c.h0 * c.ac * c.ac * a * a * a;
        assert!((c.loop_energy(a) / cubic - 1.0).abs() < 1e-5);
        // Large amplitude: 4 h0 A - 8 h0 / ac.
        let a = 50.0;
        let big = 4.0 * c.h0 * a - 8.0 * c.h0 / c.ac;
        assert!((c.loop_energy(a) / big - 1.0).abs() < 1e-12);
    }

    #[test]
    fn chord_area_series_and_direct_agree_at_switch() {
        let z = 2.0 - 1e-12;
        let below = z * z * z * exp_chord_area_unit_over_z3(z);
        let g = one_minus_exp_neg(2.0);
        let direct = 2.0 - g - g;
        assert!((below - direct).abs() < 1e-12);
        let c = Exponential::new(3.0, 5.0).unwrap();
        let (lo, hi) = (c.chord_area(0.4 - 1e-13), c.chord_area(0.4 + 1e-13));
        assert!((lo / hi - 1.0).abs() < 1e-11);
    }

    #[test]
    fn chord_area_when_ac_u_overflows_and_tabulated_nan_input() {
        // found by AFL++ (fuzz/afl): ac·u = inf made (z - g - z g/2) inf - inf = NaN; the area
        // of the chord above the curve tends to h0 u / 2 - h0/ac (here h0 u / 2 = 1e300)
        let c = Exponential::new(2.0, 7.6e221).unwrap();
        let a = c.chord_area(1e300);
        assert!((a / 1e300 - 1.0).abs() < 1e-15, "{a}");
        // the expanded form agrees with the definition ∫h - u h(u)/2 where z is finite
        let c = Exponential::new(3.0, 5.0).unwrap();
        for u in [0.5, 2.0, 40.0] {
            let direct = c.integral(u) - 0.5 * u * c.eval(u);
            assert!((c.chord_area(u) / direct - 1.0).abs() < 1e-13, "{u}");
        }
        // a NaN abscissa is NaN out, not an index underflow (a panic)
        let t = Tabulated::new(&[0.0, 2.0], &[0.0, 1e-300]).unwrap();
        assert!(t.eval(f64::NAN).is_nan());
        assert!(t.chord_area(f64::NAN).is_nan()); // through slope and integral: no panic
                                                  // beyond the last knot: r² overflowed in ∫f and in s f / 2 (inf - inf, AFL++); the
                                                  // true area (1/2)(fe - ue d) r + ... is ~ -1e-300 · 1.8e308 / 2 here, finite
        let a = t.chord_area(f64::MAX);
        assert!(a.is_finite() && a.abs() < 1e9, "{a}");
        // the rearranged form is the definition ∫f - s f(s)/2 where nothing overflows
        let t = Tabulated::new(&[0.0, 1.0, 2.0], &[0.0, 1.0, 1.5]).unwrap();
        for s in [0.5, 1.5, 2.0, 3.0, 40.0] {
            let direct = t.integral(s) - 0.5 * s * t.eval(s);
            assert!(
                (t.chord_area(s) - direct).abs() < 1e-12 * direct.abs().max(1.0),
                "{s}"
            );
        }
    }

    #[test]
    fn loop_energy_stays_finite_when_ac_is_tiny_and_h0_huge() {
        // h0 ac = 1e6 N/m fixed while ac -> 0: E -> (2/3) h0 ac² A³ = (2/3) (h0 ac) (ac A) A².
        // h0/ac and (ac A)³ over/underflowed here (NaN for h0 >= 1e155, 0 near 1e150).
        let a = 2.5e-7;
        for e in [0, 50, 100, 150, 160, 200, 250, 300] {
            let ac = 10f64.powi(-e) * 1.0;
            let c = Exponential::new(1e6 / ac, ac).unwrap();
            let want = 2.0 / 3.0 * (c.h0 * c.ac) * (c.ac * a) * a * a;
            let got = c.loop_energy(a);
            assert!(
                got.is_finite() && (got / want - 1.0).abs() < 1e-6,
                "{e}: {got} vs {want}"
            );
        }
    }

    #[test]
    fn tabulated_integral_matches_quadrature_and_is_monotone() {
        let u = [0.0, 0.1, 0.3, 0.7, 1.5];
        let f = [0.0, 0.8, 1.5, 1.9, 2.0];
        let t = Tabulated::new(&u, &f).unwrap();
        for &s in &[0.05, 0.3, 0.55, 1.2, 1.5, 2.0] {
            let q = simpson(|v| t.eval(v), 0.0, s, 20_000);
            assert!((t.integral(s) - q).abs() < 1e-9, "{s}");
        }
        let mut prev = t.eval(0.0);
        for i in 1..2000 {
            let v = t.eval(i as f64 * 1e-3);
            assert!(v >= prev);
            prev = v;
        }
        for (i, &ui) in u.iter().enumerate() {
            assert!((t.eval(ui) - f[i]).abs() < 1e-15);
            assert!((t.eval(-ui) + f[i]).abs() < 1e-15);
        }
    }

    #[test]
    fn tabulated_rejects_bad_tables() {
        assert!(matches!(
            Tabulated::new(&[0.1, 0.2], &[0.0, 1.0]),
            Err(CoreError::InvalidBackbone { index: 0, .. })
        ));
        assert!(matches!(
            Tabulated::new(&[0.0, 0.2, 0.1], &[0.0, 1.0, 2.0]),
            Err(CoreError::InvalidBackbone { index: 2, .. })
        ));
        assert!(matches!(
            Tabulated::new(&[0.0, 0.1, 0.2], &[0.0, 1.0, 0.5]),
            Err(CoreError::InvalidBackbone { index: 2, .. })
        ));
        assert!(Tabulated::new(&[0.0, f64::NAN], &[0.0, 1.0]).is_err());
    }
}
