//! Taylor-series steps for the contact ODE over one forcing segment (issue 33).
//!
//! Inside a sample interval the driving pressure is one cubic (see [`super::forcing`]), so the
//! solution of `δ' = r (p / k_s − δ)` is analytic there and its Taylor series in the normalised
//! time `v ∈ [0, 1]` of a (sub-)step is found exactly by the recurrences of automatic
//! differentiation (Jorba & Zou 2005):
//!
//! - `K = k_s(δ(v))`: Horner's rule on series, `H_m = a_m + δ·H_{m+1}` (k_s of δ), or on the
//!   cubic `p(v)` itself (k_s of p, no dependence on δ), or a constant;
//! - `u = p / K`: `u_n = (p_n − Σ_{j=1..n} K_j u_{n−j}) / K_0`;
//! - `δ_{n+1} = R (u_n − δ_n) / (n + 1)`, `R = r` times the step length.
//!
//! For the δ law the recurrences are rearranged so that each new term needs one multiply and
//! one subtraction after the previous one ([`Taylor::step_delta`]: every coefficient of order
//! `n` is linear in `δ_n`, the rest comes from older terms and is computed meanwhile); the
//! series is the same up to rounding, 1.4x faster (the plain recurrences are kept for the
//! other laws and as the test's reference).
//!
//! A noisy record changes nothing here: its cubic's coefficients are larger, the series is
//! the same. The order grows until the last two terms are below the tolerance
//! `atol + rtol |δ_0|` (at least [`MIN_ORDER`], past the cubic's own terms); beyond the order
//! `n > R` the terms shrink at least as fast as `R / (n + 1)`, so what is left out is smaller
//! than the last term kept. A step whose series does not converge by [`NP`] − 1 terms fails
//! and the caller splits the interval. Work per step: about `L n²/2` multiply-adds for an
//! order `n` and `L` stiffness coefficients; no allocation.

/// Length of the series buffers (orders 0 ..= NP − 1).
pub(crate) const NP: usize = 32;
/// Most stiffness coefficients handled (more: the caller uses RODAS4).
pub(crate) const LMAX: usize = 8;
/// Lowest order accepted: past the cubic forcing's own terms (`δ_4` is the last one it
/// drives directly), so that two vanishing terms are not taken for convergence.
pub(crate) const MIN_ORDER: usize = 6;

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Kind {
    Constant,
    Delta,
    Pressure,
}

/// Series buffers and the law's coefficients (built once per solve).
#[derive(Debug, Clone)]
pub(crate) struct Taylor {
    kind: Kind,
    a: [f64; LMAX],
    len: usize,
    inv: [f64; NP],
    d: [f64; NP],
    u: [f64; NP],
    k: [f64; NP],
    h: [[f64; NP]; LMAX],
}

impl Taylor {
    /// The recurrences for `stiffness`, or `None` if it has more than [`LMAX`] coefficients.
    pub(crate) fn new(stiffness: &super::model::Stiffness) -> Option<Self> {
        use super::model::Stiffness;
        let (kind, c): (Kind, &[f64]) = match stiffness {
            Stiffness::Constant(k) => (Kind::Constant, std::slice::from_ref(k)),
            Stiffness::Delta(c) => (Kind::Delta, c.as_slice()),
            Stiffness::Pressure(c) => (Kind::Pressure, c.as_slice()),
        };
        if c.is_empty() || c.len() > LMAX {
            return None;
        }
        let mut a = [0.0; LMAX];
        a[..c.len()].copy_from_slice(c);
        let mut inv = [0.0; NP];
        for (n, v) in inv.iter_mut().enumerate().skip(1) {
            *v = 1.0 / n as f64;
        }
        Some(Self {
            kind,
            a,
            len: c.len(),
            inv,
            d: [0.0; NP],
            u: [0.0; NP],
            k: [0.0; NP],
            h: [[0.0; NP]; LMAX],
        })
    }

    /// `δ_1` of the last step's series (`dδ/dv` at its start).
    #[inline]
    pub(crate) fn first_term(&self) -> f64 {
        self.d[1]
    }

    /// One step: `e` the forcing cubic in the step's normalised time `v ∈ [0, 1]`
    /// (`p = e0 + e1 v + e2 v² + e3 v³`), `rs` the rate `r` times the step length, `y0` the
    /// state at `v = 0`, `tol` the absolute tolerance. Returns `δ(1)` and the order used, or
    /// `None` if the series did not converge, `k_s(δ_0) ≤ 0` or a value is not finite.
    // Index arithmetic on fixed-size buffers: every index is < NP or < LMAX by the loop
    // bounds (n + 1 < NP is checked before it is used; len ≤ LMAX by `new`).
    #[inline]
    pub(crate) fn step(
        &mut self,
        e: &[f64; 4],
        rs: f64,
        y0: f64,
        tol: f64,
    ) -> Option<(f64, usize)> {
        // The number of Horner levels as a constant, so that their loop unrolls.
        match (self.kind, self.len) {
            (Kind::Delta, 2) => self.step_delta::<2>(e, rs, y0, tol),
            (Kind::Delta, 3) => self.step_delta::<3>(e, rs, y0, tol),
            (Kind::Delta, 4) => self.step_delta::<4>(e, rs, y0, tol),
            (Kind::Delta, 5) => self.step_delta::<5>(e, rs, y0, tol),
            (Kind::Delta, 6) => self.step_delta::<6>(e, rs, y0, tol),
            (Kind::Delta, 7) => self.step_delta::<7>(e, rs, y0, tol),
            (Kind::Delta, 8) => self.step_delta::<8>(e, rs, y0, tol),
            _ => self.step_impl::<1>(e, rs, y0, tol),
        }
    }

    /// [`Self::step`] for `L` stiffness coefficients (δ law; any `L` for the others).
    // Index arithmetic on fixed-size buffers: every index is < NP or < LMAX by the loop
    // bounds (n + 1 < NP is checked before it is used; L ≤ LMAX by `step`).
    #[allow(clippy::arithmetic_side_effects)]
    #[inline(always)]
    fn step_impl<const L: usize>(
        &mut self,
        e: &[f64; 4],
        rs: f64,
        y0: f64,
        tol: f64,
    ) -> Option<(f64, usize)> {
        self.prepare(e);
        let len = self.len;
        let a = self.a;
        let d = &mut self.d;
        let u = &mut self.u;
        let k = &mut self.k;
        let h = &mut self.h;
        d[0] = y0;
        let mut inv_k0 = 0.0;
        let mut u0k = 0.0; // u_0 / K_0
                           // K is known in advance (constant / pressure law): its last nonzero order.
        let kdeg = match self.kind {
            Kind::Constant => 0,
            Kind::Pressure => (3 * (len - 1)).min(NP - 1),
            Kind::Delta => NP - 1,
        };
        for n in 0..NP - 1 {
            if self.kind == Kind::Delta {
                // Horner levels h[m] = a[m] + δ·h[m+1], top level the constant a[L-1].
                if L == 1 {
                    k[n] = if n == 0 { a[0] } else { 0.0 };
                } else {
                    let top = L - 2;
                    h[top][n] = a[L - 1] * d[n] + if n == 0 { a[top] } else { 0.0 };
                    for m in (0..top).rev() {
                        let (lo, hi) = h.split_at_mut(m + 1);
                        let (cur, up) = (&mut lo[m], &hi[0]);
                        // Older terms first: the ones with the newest coefficients
                        // (d[n], up[n]) end the chain.
                        let mut s = 0.0;
                        for j in 1..n {
                            s += d[j] * up[n - j];
                        }
                        if n > 0 {
                            s += d[n] * up[0];
                        }
                        s += d[0] * up[n];
                        cur[n] = s + if n == 0 { a[m] } else { 0.0 };
                    }
                    k[n] = h[0][n];
                }
            }
            if n == 0 {
                let k0 = k[0];
                if !(k0 > 0.0 && k0.is_finite()) {
                    return None;
                }
                inv_k0 = 1.0 / k0;
                u0k = e[0] * inv_k0 * inv_k0;
            }
            // u_n = (e_n − Σ_{j<n} K_j u_{n−j}) / K_0 − K_n u_0 / K_0: the older terms first,
            // so that the chain from K_n to δ_{n+1} is two multiply-adds.
            let mut s = 0.0;
            let hi = if n <= kdeg { n } else { kdeg + 1 };
            for j in 1..hi {
                s += k[j] * u[n - j];
            }
            let en = if n < 4 { e[n] } else { 0.0 };
            let mut un = (en - s) * inv_k0;
            if n >= 1 && n <= kdeg {
                un -= k[n] * u0k;
            }
            u[n] = un;
            let cn = rs * self.inv[n + 1];
            d[n + 1] = cn * un - cn * d[n];
            let order = n + 1;
            if order >= MIN_ORDER && d[n].abs() + d[n + 1].abs() <= tol {
                let mut y = 0.0;
                for &c in d[..=order].iter().rev() {
                    y += c;
                }
                return if y.is_finite() {
                    Some((y, order))
                } else {
                    None
                };
            }
        }
        None
    }

    /// [`Self::step`] for the δ law with `L >= 2` coefficients, the recurrences arranged so
    /// that the chain from one term to the next is one multiply and one subtraction.
    ///
    /// Each Horner level's `n`-th coefficient is linear in the newest term `δ_n`:
    /// `H_{m,n} = P_{m,n} + D_m δ_n` with `D_m = ∂H_m/∂δ` at `δ_0` (`D_{L-2} = a_{L-1}`,
    /// `D_m = H_{m+1,0} + δ_0 D_{m+1}`, so `D_0 = k_s'(δ_0)`) and `P_{m,n} = Σ_{j=1}^{n-1}
    /// δ_j H_{m+1,n-j} + δ_0 P_{m+1,n}` from the older terms only. With `Q_n = (e_n −
    /// Σ_{j=1}^{n-1} K_j u_{n-j}) / K_0` (older terms) the step's recurrence
    /// `δ_{n+1} = c_n (u_n − δ_n)`, `u_n = Q_n − K_n u_0 / K_0`, becomes
    /// `δ_{n+1} = c_n (Q_n − P_{0,n} u_0/K_0) − c_n (1 + D_0 u_0/K_0) δ_n`: the older terms'
    /// part is computed while the previous term is still on its way. The same series as
    /// [`Self::step_impl`] up to rounding.
    // Index arithmetic on fixed-size buffers: every index is < NP or < LMAX by the loop
    // bounds (n + 1 < NP is checked before it is used; 2 <= L ≤ LMAX by `step`).
    #[allow(clippy::arithmetic_side_effects)]
    #[inline(always)]
    fn step_delta<const L: usize>(
        &mut self,
        e: &[f64; 4],
        rs: f64,
        y0: f64,
        tol: f64,
    ) -> Option<(f64, usize)> {
        let a = self.a;
        let d = &mut self.d;
        let u = &mut self.u;
        let k = &mut self.k;
        let h = &mut self.h;
        let top = L - 2;
        // Order 0: the Horner levels at δ_0 and their derivatives.
        d[0] = y0;
        h[top][0] = a[top] + a[L - 1] * y0;
        for m in (0..top).rev() {
            h[m][0] = a[m] + y0 * h[m + 1][0];
        }
        let mut dm = [0.0; LMAX];
        dm[top] = a[L - 1];
        for m in (0..top).rev() {
            dm[m] = h[m + 1][0] + y0 * dm[m + 1];
        }
        let k0 = h[0][0];
        k[0] = k0;
        if !(k0 > 0.0 && k0.is_finite()) {
            return None;
        }
        let inv_k0 = 1.0 / k0;
        let u0 = e[0] * inv_k0;
        let u0k = u0 * inv_k0;
        u[0] = u0;
        let b = 1.0 + dm[0] * u0k;
        let c0 = rs * self.inv[1];
        d[1] = c0 * u0 - c0 * y0;
        let mut pm = [0.0; LMAX];
        for n in 1..NP - 1 {
            // The older terms' parts of the levels' n-th coefficients, top down.
            pm[top] = 0.0;
            for m in (0..top).rev() {
                let up = &h[m + 1];
                let mut s = 0.0;
                for j in 1..n {
                    s += d[j] * up[n - j];
                }
                pm[m] = s + y0 * pm[m + 1];
            }
            let mut s = 0.0;
            for j in 1..n {
                s += k[j] * u[n - j];
            }
            let en = if n < 4 { e[n] } else { 0.0 };
            let q = (en - s) * inv_k0;
            let cn = rs * self.inv[n + 1];
            let dn = d[n];
            d[n + 1] = cn * (q - pm[0] * u0k) - (cn * b) * dn;
            // The n-th coefficients, for the orders after.
            for m in 0..=top {
                h[m][n] = pm[m] + dm[m] * dn;
            }
            let kn = h[0][n];
            k[n] = kn;
            u[n] = q - kn * u0k;
            let order = n + 1;
            if order >= MIN_ORDER && dn.abs() + d[n + 1].abs() <= tol {
                let mut y = 0.0;
                for &c in d[..=order].iter().rev() {
                    y += c;
                }
                return if y.is_finite() {
                    Some((y, order))
                } else {
                    None
                };
            }
        }
        None
    }

    /// The δ-independent part of the recurrences: `K = k_s(p(v))` for the pressure law, the
    /// constant for Kelvin-Voigt.
    // Index arithmetic on fixed-size buffers (indices < NP by the loop bounds).
    #[allow(clippy::arithmetic_side_effects)]
    #[inline]
    fn prepare(&mut self, e: &[f64; 4]) {
        match self.kind {
            Kind::Delta => {}
            Kind::Constant => {
                self.k[0] = self.a[0];
            }
            Kind::Pressure => {
                // Horner on series: K = a[len-1]; K = a[m] + p·K, degree growing by 3.
                let len = self.len;
                let k = &mut self.k;
                k.fill(0.0);
                k[0] = self.a[len - 1];
                let mut deg = 0usize;
                let mut tmp = [0.0; NP];
                for m in (0..len - 1).rev() {
                    let nd = (deg + 3).min(NP - 1);
                    tmp[..=nd].fill(0.0);
                    for (i, &ki) in k[..=deg].iter().enumerate() {
                        for (j, &ej) in e.iter().enumerate() {
                            if i + j <= nd {
                                tmp[i + j] += ki * ej;
                            }
                        }
                    }
                    tmp[0] += self.a[m];
                    k[..=nd].copy_from_slice(&tmp[..=nd]);
                    deg = nd;
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::model::Stiffness;
    use super::*;

    /// Plain RK4 with many steps on `δ' = R (p(v)/k(v, δ) − δ)` over `v ∈ [0, 1]`.
    fn rk4(e: &[f64; 4], rs: f64, y0: f64, k: impl Fn(f64, f64) -> f64) -> f64 {
        let p = |v: f64| e[0] + v * (e[1] + v * (e[2] + v * e[3]));
        let f = |v: f64, y: f64| rs * (p(v) / k(p(v), y) - y);
        let n = 20_000;
        let hh = 1.0 / n as f64;
        let mut y = y0;
        for i in 0..n {
            let v = i as f64 * hh;
            let k1 = f(v, y);
            let k2 = f(v + 0.5 * hh, y + 0.5 * hh * k1);
            let k3 = f(v + 0.5 * hh, y + 0.5 * hh * k2);
            let k4 = f(v + hh, y + hh * k3);
            y += hh / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
        }
        y
    }

    type KFn = Box<dyn Fn(f64, f64) -> f64>;

    #[test]
    fn matches_fine_rk4_for_every_law() {
        let e = [0.3, 0.01, -0.005, 0.002];
        let cases: Vec<(Stiffness, KFn)> = vec![
            (Stiffness::Constant(1.3), Box::new(|_, _| 1.3)),
            (
                Stiffness::Delta(vec![1.3, 1.6, 2.9, 2.9]),
                Box::new(|_, d| 1.3 + d * (1.6 + d * (2.9 + d * 2.9))),
            ),
            (
                Stiffness::Pressure(vec![1.2, 0.4, -0.3, 0.2]),
                Box::new(|p, _| 1.2 + p * (0.4 + p * (-0.3 + p * 0.2))),
            ),
        ];
        for (st, k) in cases {
            let mut t = Taylor::new(&st).unwrap();
            for rs in [0.1, 1.0, 1.7] {
                let Some((y, order)) = t.step(&e, rs, 0.17, 1e-14) else {
                    panic!("{st:?} rs {rs}: {:?}", &t.d)
                };
                let yr = rk4(&e, rs, 0.17, &k);
                assert!((y - yr).abs() < 1e-12, "{st:?} rs {rs}: {y} vs {yr}");
                assert!((MIN_ORDER..NP).contains(&order));
            }
        }
    }

    /// The rearranged δ-law recurrences (`step_delta`) against the plain ones (`step_impl`,
    /// Horner on series term by term) for every supported number of coefficients.
    #[test]
    fn the_linearised_recurrences_give_the_plain_series() {
        let mut state = 0x2545_F491_4F6C_DD1D_u64;
        let mut uni = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / 9_007_199_254_740_992.0
        };
        let (mut worst, mut converged) = (0.0_f64, 0);
        for len in 2..=LMAX {
            for _ in 0..200 {
                let c: Vec<f64> = (0..len)
                    .map(|i| if i == 0 { 1.0 + uni() } else { 0.5 * uni() })
                    .collect();
                let e = [
                    uni(),
                    0.2 * (uni() - 0.5),
                    0.1 * (uni() - 0.5),
                    0.05 * uni(),
                ];
                // near the quasi-static state δ = p / k_s, as in a solve
                let (rs, y0) = (0.05 + 2.0 * uni(), e[0] / c[0] * (0.8 + 0.4 * uni()));
                let mut t = Taylor::new(&Stiffness::Delta(c)).unwrap();
                let tol = 1e-13 + 1e-11 * y0;
                let fast = t.step(&e, rs, y0, tol);
                let plain = match len {
                    2 => t.step_impl::<2>(&e, rs, y0, tol),
                    3 => t.step_impl::<3>(&e, rs, y0, tol),
                    4 => t.step_impl::<4>(&e, rs, y0, tol),
                    5 => t.step_impl::<5>(&e, rs, y0, tol),
                    6 => t.step_impl::<6>(&e, rs, y0, tol),
                    7 => t.step_impl::<7>(&e, rs, y0, tol),
                    _ => t.step_impl::<8>(&e, rs, y0, tol),
                };
                let (Some((yf, of)), Some((yp, op))) = (fast, plain) else {
                    // neither converged within the buffers (a large rate for this law)
                    assert!(
                        fast.is_none() && plain.is_none(),
                        "{len} {e:?}: {fast:?} {plain:?}"
                    );
                    continue;
                };
                converged += 1;
                assert!(of.abs_diff(op) <= 1, "len {len}: orders {of} vs {op}");
                worst = worst.max((yf - yp).abs() / yp.abs().max(1e-3));
            }
        }
        assert!(worst < 1e-13, "worst relative difference {worst:e}");
        assert!(converged > 1000, "{converged} of 1400 converged");
    }

    #[test]
    fn fails_rather_than_returning_an_unconverged_sum() {
        let mut t = Taylor::new(&Stiffness::Constant(1.0)).unwrap();
        // R = 60 in one step: the free decay's terms 60^n/n! are far from converged at NP.
        assert!(t.step(&[1.0, 0.0, 0.0, 0.0], 60.0, 0.0, 1e-12).is_none());
        let mut t = Taylor::new(&Stiffness::Delta(vec![1.0, 10.0])).unwrap();
        assert!(t.step(&[0.0; 4], 1.0, -0.2, 1e-12).is_none()); // k_s(δ0) < 0
    }
}
