//! Levenberg–Marquardt fit of the steady Masing loop to an averaged cycle (PHYSICS.md §1).
//!
//! The averaged fit of a tangential window has five parameters `(k0, ac, offset, x0, A)`
//! (`k0 = h0·ac`), `n` phase bins and at most two prior rows: a few hundred residuals. In
//! Python each solver iteration costs more in interpreter overhead than in arithmetic, and it
//! holds the interpreter lock, so two analysis threads cannot overlap their fits. Here the
//! residuals and their analytic Jacobian are the steady loop's branches in closed form — with
//! `h(y) = (k0/ac)(1 - e^{-ac y})`, `u = clip(x - x0, ±A)` and `s` half the distance from the
//! branch's turn (`(A - u)/2` on the descending first half of the bins, `(u + A)/2` on the
//! ascending second half), `F = ±(h(A) - 2 h(s)) + offset` plus the bins' curvature term
//! `±¼ k0 ac e^{-ac s} var(x)`; a bin beyond a turn (`x - x0` outside `±A`) continues the
//! branch's tangent at that turn, `∓ k0 e^{-ac s} (2 + ¼ ac² var) (s_raw - s)` (a bin mean's
//! noise puts the bins next to a turn beyond it; clipped, they biased the fitted amplitude
//! low) — the same formulas as `steps.Residuals.jacobian` and `steps._beyond_turns` in
//! Python, which the tests check against the Masing operator.
//!
//! [`fit_steady_loop`] minimises `Σ r²` in the caller's scaled variables (`z = value /
//! scale`, residuals divided by `rscale`), the bounds held by projection, and reports how it
//! stopped with the codes of SciPy's `least_squares` (1: gradient, 2: cost, 3: step, 0: the
//! evaluation budget ran out). The caller polishes and takes the covariance as before.

use nalgebra::{Matrix5, Vector5};

use crate::error::{check_finite, check_same_len, CoreError};

/// Parameters in order: `k0`, `ac`, `offset`, `x0`, `amplitude`.
pub const N_PARAMS: usize = 5;

/// The displacement channel's measurement of the turning points as extra residual rows
/// `(p - measured) / sigma · scale` (for `x0` and/or `amplitude`, in that order).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TurnPrior {
    pub x0: Option<f64>,
    pub amplitude: Option<f64>,
    pub sigma: f64,
    pub scale: f64,
}

/// An averaged cycle to fit: bin displacements `x` (monotone on each half), mean forces
/// `f`, weights `w`, the spread of the true displacement inside each bin (optional) and the
/// prior rows (optional).
#[derive(Debug, Clone, Copy)]
pub struct SteadyLoop<'a> {
    x: &'a [f64],
    f: &'a [f64],
    w: &'a [f64],
    bin_var: Option<&'a [f64]>,
    prior: Option<TurnPrior>,
}

impl<'a> SteadyLoop<'a> {
    /// Checks lengths (the same, at least 2 bins) and finiteness.
    pub fn new(
        x: &'a [f64],
        f: &'a [f64],
        w: &'a [f64],
        bin_var: Option<&'a [f64]>,
        prior: Option<TurnPrior>,
    ) -> Result<Self, CoreError> {
        check_same_len("x", x.len(), "F", f.len())?;
        check_same_len("x", x.len(), "w", w.len())?;
        if x.len() < 2 {
            return Err(CoreError::Empty { name: "x" });
        }
        check_finite("x", x)?;
        check_finite("F", f)?;
        check_finite("w", w)?;
        if let Some(v) = bin_var {
            check_same_len("x", x.len(), "bin_var", v.len())?;
            check_finite("bin_var", v)?;
        }
        if let Some(p) = prior {
            let vals = [
                p.x0.unwrap_or(0.0),
                p.amplitude.unwrap_or(0.0),
                p.sigma,
                p.scale,
            ];
            check_finite("prior", &vals)?;
            if p.sigma <= 0.0 {
                return Err(CoreError::InvalidParameter {
                    name: "prior sigma",
                    value: p.sigma,
                    reason: "must be > 0",
                });
            }
        }
        Ok(Self {
            x,
            f,
            w,
            bin_var,
            prior,
        })
    }

    /// Residual rows: one per bin and one per prior row.
    #[must_use]
    pub fn n_rows(&self) -> usize {
        let k = self.prior.map_or(0, |p| {
            [p.x0, p.amplitude].iter().filter(|v| v.is_some()).count()
        });
        self.x.len().saturating_add(k)
    }

    /// The weighted residuals `(model - data)·w` and prior rows at `p` into `r`
    /// (length [`Self::n_rows`]); with `jac`, their derivatives too, column by column
    /// (`jac[j·rows + i] = ∂r_i/∂p_j`).
    // i < n inside the loops (zipped iterators); j < 5.
    #[allow(clippy::arithmetic_side_effects)]
    pub fn evaluate(&self, p: &[f64; N_PARAMS], r: &mut [f64], mut jac: Option<&mut [f64]>) {
        let [k0, ac, offset, x0, a] = *p;
        let n = self.x.len();
        let rows = self.n_rows();
        let half = n / 2;
        let e_a = (-ac * a).exp();
        let h_a = -k0 / ac * (-ac * a).exp_m1();
        let hac_a = h_ac(k0, ac, a);
        for i in 0..n {
            let sg = if i < half { 1.0 } else { -1.0 };
            let raw = self.x[i] - x0;
            let u = raw.clamp(-a, a);
            let inside = raw > -a && raw < a;
            let du_dx0 = if inside { -1.0 } else { 0.0 };
            let du_da = if raw >= a {
                1.0
            } else if raw <= -a {
                -1.0
            } else {
                0.0
            };
            let s = 0.5 * (a - sg * u);
            let e = (-ac * s).exp();
            let h_s = -k0 / ac * (-ac * s).exp_m1();
            let mut force = sg * (h_a - 2.0 * h_s);
            let var = self.bin_var.map_or(0.0, |v| v[i]);
            let g = if self.bin_var.is_some() {
                sg * 0.25 * k0 * ac * e * var
            } else {
                0.0
            };
            force += g + offset;
            // beyond a turn: the branch's tangent there (force, slope and curvature term
            // continuous; `steps._beyond_turns`): `∓ k0 e^{-ac s} (2 + ¼ ac² var) (s_raw - s)`
            let dd = 0.5 * (a - sg * raw) - s;
            let q = 2.0 + 0.25 * ac * ac * var;
            let beyond = if inside { 0.0 } else { -sg * k0 * e * q * dd };
            let beyond_ok = dd != 0.0 && beyond.is_finite();
            if beyond_ok {
                force += beyond;
            }
            let w = self.w[i];
            r[i] = (force - self.f[i]) * w;
            if let Some(jm) = jac.as_deref_mut() {
                let ds_da = 0.5 * (1.0 - sg * du_da);
                let ds_dx0 = -0.5 * sg * du_dx0;
                let mut d_k0 = sg * (h_a - 2.0 * h_s) / k0;
                let mut d_ac = sg * (hac_a - 2.0 * h_ac(k0, ac, s));
                let mut d_a = sg * (k0 * e_a - 2.0 * k0 * e * ds_da);
                let mut d_x0 = sg * (-2.0 * k0 * e * ds_dx0);
                if self.bin_var.is_some() {
                    d_k0 += g / k0;
                    d_ac += g * (1.0 / ac - s);
                    d_a -= ac * g * ds_da;
                    d_x0 -= ac * g * ds_dx0;
                }
                if beyond_ok {
                    // s is 0 (the branch's own turn) or A (the next turn) here
                    let far = if s > 0.0 { 1.0 } else { 0.0 };
                    let parts = [
                        beyond / k0,
                        -sg * k0 * dd * e * (0.5 * ac * var - s * q),
                        -0.5 * k0 * q * e,
                        -sg * k0 * q * e * ((0.5 - far) - ac * dd * far),
                    ];
                    if parts.iter().all(|v| v.is_finite()) {
                        d_k0 += parts[0];
                        d_ac += parts[1];
                        d_x0 += parts[2];
                        d_a += parts[3];
                    }
                }
                jm[i] = d_k0 * w;
                jm[rows + i] = d_ac * w;
                jm[2 * rows + i] = w;
                jm[3 * rows + i] = d_x0 * w;
                jm[4 * rows + i] = d_a * w;
            }
        }
        if let Some(pr) = self.prior {
            let mut i = n;
            for (k, meas) in [(3_usize, pr.x0), (4, pr.amplitude)] {
                if let Some(m) = meas {
                    r[i] = (p[k] - m) / pr.sigma * pr.scale;
                    if let Some(jm) = jac.as_deref_mut() {
                        for j in 0..N_PARAMS {
                            jm[j * rows + i] = if j == k { pr.scale / pr.sigma } else { 0.0 };
                        }
                    }
                    i += 1;
                }
            }
        }
    }
}

/// `∂h(y)/∂ac` at fixed `k0`: `(k0/ac²) g(ac·y)`, `g(q) = q e^{-q} - (1 - e^{-q})`, by its
/// series below `|q| = 1e-3` where the two terms cancel (as `steps._h_ac`).
fn h_ac(k0: f64, ac: f64, y: f64) -> f64 {
    let q = ac * y;
    let g = if q.abs() < 1e-3 {
        q * q * (-0.5 + q * (1.0 / 3.0 + q * (-1.0 / 8.0 + q / 30.0)))
    } else {
        q * (-q).exp() + (-q).exp_m1()
    };
    k0 / (ac * ac) * g
}

/// The scaled problem: which parameters vary, their scales and bounds (scaled), the values
/// of the fixed ones, the residual scale and the stopping rules.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FitSetup {
    pub values: [f64; N_PARAMS],
    pub vary: [bool; N_PARAMS],
    pub scale: [f64; N_PARAMS],
    pub lower: [f64; N_PARAMS],
    pub upper: [f64; N_PARAMS],
    pub rscale: f64,
    pub ftol: f64,
    pub xtol: f64,
    pub gtol: f64,
    pub max_nfev: usize,
}

/// The end point: all parameter values, residual evaluations used, and how the solver
/// stopped (SciPy's codes: 1 gradient, 2 cost, 3 step, 0 evaluation budget).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LoopFit {
    pub values: [f64; N_PARAMS],
    pub nfev: usize,
    pub status: i32,
}

/// The normal equations `(JᵀJ, Jᵀr)` of the scaled problem.
type Normal = (Matrix5<f64>, Vector5<f64>);

struct Scaled<'a> {
    data: &'a SteadyLoop<'a>,
    setup: &'a FitSetup,
    idx: Vec<usize>,
    rows: usize,
    r: Vec<f64>,
    jac: Vec<f64>,
    nfev: usize,
}

impl Scaled<'_> {
    fn params(&self, z: &Vector5<f64>) -> [f64; N_PARAMS] {
        let mut p = self.setup.values;
        for (j, &k) in self.idx.iter().enumerate() {
            p[k] = z[j] * self.setup.scale[k];
        }
        p
    }

    /// Cost `½ Σ (r/rscale)²` at `z` (infinite when not finite); with `jac`, `JᵀJ` and `Jᵀr`
    /// of the scaled problem as well.
    // Index arithmetic: the Jacobian holds N_PARAMS columns of `rows` values, ka, kb < 5.
    #[allow(clippy::arithmetic_side_effects)]
    fn eval(&mut self, z: &Vector5<f64>, with_jac: bool) -> (f64, Option<Normal>) {
        self.nfev = self.nfev.saturating_add(1);
        let p = self.params(z);
        let jac = if with_jac {
            Some(self.jac.as_mut_slice())
        } else {
            None
        };
        self.data.evaluate(&p, &mut self.r, jac);
        let rs = self.setup.rscale;
        let mut cost = 0.0;
        for v in &mut self.r {
            *v /= rs;
            cost += *v * *v;
        }
        cost *= 0.5;
        if !cost.is_finite() {
            return (f64::INFINITY, None);
        }
        if !with_jac {
            return (cost, None);
        }
        let k = self.idx.len();
        let mut jtj = Matrix5::<f64>::identity();
        let mut g = Vector5::<f64>::zeros();
        let rows = self.rows;
        for a in 0..k {
            let ka = self.idx[a];
            let ca = &self.jac[ka * rows..(ka + 1) * rows];
            let sa = self.setup.scale[ka] / rs;
            g[a] = sa * ca.iter().zip(&self.r).map(|(u, v)| u * v).sum::<f64>();
            for b in 0..=a {
                let kb = self.idx[b];
                let cb = &self.jac[kb * rows..(kb + 1) * rows];
                let sb = self.setup.scale[kb] / rs;
                let v = sa * sb * ca.iter().zip(cb).map(|(u, v)| u * v).sum::<f64>();
                jtj[(a, b)] = v;
                jtj[(b, a)] = v;
            }
        }
        if jtj.iter().all(|v| v.is_finite()) && g.iter().all(|v| v.is_finite()) {
            (cost, Some((jtj, g)))
        } else {
            (f64::INFINITY, None)
        }
    }
}

/// Levenberg–Marquardt (Marquardt's diagonal damping, bounds by projection) from
/// `setup.values` over the varied parameters. Converged (status 2 or 3) once an accepted step
/// lowers the cost by less than `ftol` of it or is below `xtol·(xtol + |z|)` (scaled
/// variables); it then goes on while steps still lower the cost, and stops where no damped
/// step does (or the gradient's largest cosine with the residual is below `min(gtol, 1e-14)`:
/// status 1 if nothing was met before). After `max_nfev` evaluations it stops with the
/// status reached (0: not converged). Errors: bad input, or non-finite residuals at the
/// start.
// index arithmetic over k <= 5 varied parameters
#[allow(clippy::arithmetic_side_effects)]
pub fn fit_steady_loop(data: &SteadyLoop<'_>, setup: &FitSetup) -> Result<LoopFit, CoreError> {
    check_finite("values", &setup.values)?;
    check_finite("scale", &setup.scale)?;
    if !(setup.rscale.is_finite() && setup.rscale > 0.0) {
        return Err(CoreError::InvalidParameter {
            name: "rscale",
            value: setup.rscale,
            reason: "must be finite and > 0",
        });
    }
    let idx: Vec<usize> = (0..N_PARAMS).filter(|&k| setup.vary[k]).collect();
    for &k in &idx {
        let scale_ok = setup.scale[k] > 0.0;
        if !scale_ok || setup.lower[k].is_nan() || setup.upper[k].is_nan() {
            return Err(CoreError::InvalidParameter {
                name: "scale",
                value: setup.scale[k],
                reason: "a varied parameter needs a scale > 0 and bounds",
            });
        }
    }
    let k = idx.len();
    let rows = data.n_rows();
    let mut prob = Scaled {
        data,
        setup,
        idx,
        rows,
        r: vec![0.0; rows],
        jac: vec![0.0; rows.saturating_mul(N_PARAMS)],
        nfev: 0,
    };
    let mut z = Vector5::<f64>::zeros();
    let mut lo = Vector5::<f64>::zeros();
    let mut hi = Vector5::<f64>::zeros();
    for (j, &kk) in prob.idx.iter().enumerate() {
        z[j] = setup.values[kk] / setup.scale[kk];
        lo[j] = setup.lower[kk];
        hi[j] = setup.upper[kk];
    }
    let (mut cost, first) = prob.eval(&z, true);
    let Some((mut jtj, mut g)) = first else {
        return Err(CoreError::OutOfRange {
            what: "residual at the start",
            index: 0,
            value: cost,
        });
    };
    let done = |prob: &Scaled<'_>, z: &Vector5<f64>, status| LoopFit {
        values: prob.params(z),
        nfev: prob.nfev,
        status,
    };
    if k == 0 {
        return Ok(done(&prob, &z, 1));
    }
    let mut lambda = 1e-3;
    let mut status = 0;
    loop {
        // gradient test: the largest cosine between a Jacobian column and the residual
        let rnorm = (2.0 * cost).sqrt();
        let gmax = (0..k)
            .map(|j| {
                let cn = jtj[(j, j)].sqrt();
                if cn > 0.0 && rnorm > 0.0 {
                    (g[j] / (cn * rnorm)).abs()
                } else {
                    0.0
                }
            })
            .fold(0.0_f64, f64::max);
        if gmax <= setup.gtol.min(1e-14) {
            return Ok(done(&prob, &z, if status == 0 { 1 } else { status }));
        }
        // damped steps until one lowers the cost
        loop {
            if prob.nfev >= setup.max_nfev {
                return Ok(done(&prob, &z, status));
            }
            let mut m = Matrix5::<f64>::identity();
            let mut rhs = Vector5::<f64>::zeros();
            for a in 0..k {
                for b in 0..k {
                    m[(a, b)] = jtj[(a, b)];
                }
                m[(a, a)] += lambda * jtj[(a, a)].max(1e-300);
                rhs[a] = -g[a];
            }
            let Some(ch) = m.cholesky() else {
                lambda *= 10.0;
                if lambda > 1e20 {
                    return Ok(done(&prob, &z, status.max(3)));
                }
                continue;
            };
            let step = ch.solve(&rhs);
            let mut z_new = z;
            for j in 0..k {
                z_new[j] = (z[j] + step[j]).clamp(lo[j], hi[j]);
            }
            let dz = (z_new - z).norm();
            let (c_new, _) = prob.eval(&z_new, false);
            if c_new < cost {
                let small_cost = cost - c_new <= setup.ftol * cost;
                let small_step = dz <= setup.xtol * (setup.xtol + z.norm());
                let (c2, jg) = prob.eval(&z_new, true);
                let Some((j2, g2)) = jg else {
                    // a Jacobian that overflows next to an acceptable point: stop there
                    return Ok(done(&prob, &z, status.max(3)));
                };
                z = z_new;
                cost = c2;
                jtj = j2;
                g = g2;
                lambda = (lambda / 10.0).max(1e-15);
                // the tolerances met: go on while steps still lower the cost (an evaluation
                // costs microseconds here); the status says which tolerance was met first
                if status == 0 && small_cost {
                    status = 2;
                } else if status == 0 && small_step {
                    status = 3;
                }
                break;
            }
            if dz <= f64::EPSILON * (f64::EPSILON + z.norm()) {
                // no lower cost within rounding of the point: the minimum
                return Ok(done(&prob, &z, status.max(3)));
            }
            lambda *= 10.0;
            if lambda > 1e20 {
                return Ok(done(&prob, &z, status.max(3)));
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn cycle(n: usize, amp: f64) -> Vec<f64> {
        // descending first half, ascending second (the averaged bins' order)
        let h = n / 2;
        (0..n)
            .map(|i| {
                let ph = if i < h {
                    (i as f64 + 0.5) / h as f64
                } else {
                    (i - h) as f64 / (n - h) as f64
                };
                let c = (std::f64::consts::PI * ph).cos();
                if i < h {
                    amp * c
                } else {
                    -amp * c
                }
            })
            .collect()
    }

    fn model(x: &[f64], p: &[f64; 5], bv: Option<&[f64]>) -> Vec<f64> {
        let w = vec![1.0; x.len()];
        let zero = vec![0.0; x.len()];
        let d = SteadyLoop::new(x, &zero, &w, bv, None).unwrap();
        let mut r = vec![0.0; x.len()];
        d.evaluate(p, &mut r, None);
        r
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(48))]
        /// The analytic Jacobian equals central differences of the residuals.
        #[test]
        fn jacobian_equals_central_differences(
            ac in 1e3f64..3e5, amp_factor in 0.9f64..1.1, x0 in -2e-6f64..2e-6,
            n in 8usize..120, with_var in any::<bool>(), prior in any::<bool>(),
        ) {
            let n = 2 * (n / 2);
            let x = cycle(n, 15e-6);
            let f: Vec<f64> = x.iter().map(|v| 1e6 * v + 0.3).collect();
            let w: Vec<f64> = (0..n).map(|i| 1.0 + 0.01 * i as f64).collect();
            let bv: Vec<f64> = (0..n).map(|i| 1e-14 * (1.0 + (i % 5) as f64)).collect();
            let pr = prior.then_some(TurnPrior { x0: Some(1e-8), amplitude: Some(15e-6),
                                                 sigma: 2e-8, scale: 0.3 });
            let d = SteadyLoop::new(&x, &f, &w, with_var.then_some(bv.as_slice()), pr).unwrap();
            let p = [2e6, ac, 0.05, x0, 15e-6 * amp_factor];
            let rows = d.n_rows();
            let mut r = vec![0.0; rows];
            let mut jac = vec![0.0; rows * 5];
            d.evaluate(&p, &mut r, Some(&mut jac));
            for k in 0..5 {
                let h = 1e-6 * p[k].abs().max(1e-7);
                let (mut up, mut dn) = (p, p);
                up[k] += h;
                dn[k] -= h;
                let (mut ru, mut rd) = (vec![0.0; rows], vec![0.0; rows]);
                d.evaluate(&up, &mut ru, None);
                d.evaluate(&dn, &mut rd, None);
                let big = ru.iter().zip(&rd).map(|(a, b)| ((a - b) / (2.0 * h)).abs())
                    .fold(0.0_f64, f64::max).max(1e-300);
                let mut kinks = 0;
                for i in 0..rows {
                    let fd = (ru[i] - rd[i]) / (2.0 * h);
                    if (fd - jac[k * rows + i]).abs() > 1e-5 * big {
                        kinks += 1; // a bin at a turn switches branch inside the step
                    }
                }
                prop_assert!(kinks <= 2, "parameter {k}: {kinks} rows differ");
            }
        }

        /// A noise-free loop is recovered from a start 30 % off (turns beyond the outer
        /// bins: no bin clipped, a smooth minimum; ac·A from 0.3 to 3).
        #[test]
        fn recovers_a_noise_free_loop(ac in 2e4f64..2e5, n in 20usize..200, off in -0.3f64..0.3) {
            let n = 2 * (n / 2);
            let x = cycle(n, 15e-6);
            let truth = [2e6, ac, 0.4, 1e-7, 15e-6 * 1.02];
            let f = model(&x, &truth, None);
            let w = vec![1.0; n];
            let d = SteadyLoop::new(&x, &f, &w, None, None).unwrap();
            // (a start with the turns exactly on the outer bins sits on a kink of the clipped
            // model, where this solver can stop short: the caller's polish and SciPy fallback
            // handle that case)
            let start = [2e6 * (1.0 + off), ac * (1.0 - off), 0.0, 0.0, 15e-6 * 1.005];
            let scale = [start[0], start[1], 1.0, 15e-6, 15e-6];
            let setup = FitSetup {
                values: start, vary: [true; 5], scale,
                lower: [1e-9, 1e-9, f64::NEG_INFINITY, -1.0, 0.5],
                upper: [f64::INFINITY, f64::INFINITY, f64::INFINITY, 1.0, 1.5],
                rscale: 1.0, ftol: 1e-15, xtol: 1e-15, gtol: 1e-12, max_nfev: 2000,
            };
            let fit = fit_steady_loop(&d, &setup).unwrap();
            prop_assert!(fit.status > 0, "{fit:?}");
            for k in [0, 1, 4] {
                prop_assert!((fit.values[k] / truth[k] - 1.0).abs() < 1e-6, "{k}: {fit:?}");
            }
        }
    }

    /// Past a turn the force goes on along the branch's tangent: continuous in value and
    /// slope across `x0 ± A`, linear beyond (no clipping to the turn's force).
    #[test]
    fn bins_beyond_a_turn_continue_the_tangent() {
        let (k0, ac, a) = (2e6, 5e4, 15e-6);
        let p = [k0, ac, 0.0, 0.0, a];
        for bv in [None, Some(3e-14)] {
            // descending half (first bin of the 2-bin loop) around its own turn at x = +A
            let force = |x: f64| {
                let v = bv.map(|b| vec![b; 2]);
                model(&[x, -x], &p, v.as_deref())[0]
            };
            let h = 1e-10;
            let (below, at, above) = (force(a - h), force(a), force(a + h));
            let (far1, far2) = (force(a + 1e-7), force(a + 2e-7));
            let slope_in = (at - below) / h;
            let slope_out = (above - at) / h;
            assert!(
                (slope_in / slope_out - 1.0).abs() < 1e-3,
                "{slope_in} {slope_out}"
            );
            // linear beyond: equal steps
            assert!(((far2 - far1) / (far1 - at) - 1.0).abs() < 1e-9);
            assert!(
                far2 > far1 && far1 > at,
                "the force keeps rising past the turn"
            );
        }
    }

    #[test]
    fn bad_input_is_an_error() {
        let x = cycle(10, 1.0);
        let w = vec![1.0; 10];
        assert!(SteadyLoop::new(&x, &x[1..], &w, None, None).is_err());
        assert!(SteadyLoop::new(&x[..1], &x[..1], &w[..1], None, None).is_err());
        let mut bad = x.clone();
        bad[3] = f64::NAN;
        assert!(SteadyLoop::new(&x, &bad, &w, None, None).is_err());
        let pr = TurnPrior {
            x0: Some(0.0),
            amplitude: None,
            sigma: 0.0,
            scale: 1.0,
        };
        assert!(SteadyLoop::new(&x, &x, &w, None, Some(pr)).is_err());
        let d = SteadyLoop::new(&x, &x, &w, None, None).unwrap();
        let setup = FitSetup {
            values: [1.0, 1.0, 0.0, 0.0, 1.0],
            vary: [true; 5],
            scale: [1.0; 5],
            lower: [f64::NEG_INFINITY; 5],
            upper: [f64::INFINITY; 5],
            rscale: 0.0,
            ftol: 1e-10,
            xtol: 1e-10,
            gtol: 1e-10,
            max_nfev: 10,
        };
        assert!(fit_steady_loop(&d, &setup).is_err());
        // an overflowing start: an error, not a NaN fit
        let over = FitSetup {
            values: [1.0, -1e6, 0.0, 0.0, 1.0],
            rscale: 1.0,
            ..setup
        };
        assert!(fit_steady_loop(&d, &over).is_err());
    }
}
