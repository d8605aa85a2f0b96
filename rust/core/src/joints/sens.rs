//! Forward sensitivities of a law's force to its parameters, `∂F_n/∂θ_j`, carried along the
//! history in the same pass as the force (the Jacobian a least-squares fit needs, at the cost
//! of about one evaluation instead of one per parameter).
//!
//! Each supported law differentiates its own step exactly (the step's closed form, with the
//! branch taken held fixed: at a stick-slip switch the one-sided derivative of the branch the
//! kernel took). Parameters are in the order of the Python class's `param_names` (a
//! composite's own parameters, then each child's, depth first). Supported: Jenkins,
//! Maxwell-slip, Dahl, LuGre, Kelvin-Voigt and parallel compositions of them; the others
//! (series, backlash, Iwan stacks, Bouc-Wen, generalised Maxwell-slip) return `None` from
//! [`AnyLaw::sens_len`] and are differentiated by finite differences by the caller.

use super::compose::{KelvinVoigt, Parallel};
use super::dahl::Dahl;
use super::jenkins::Jenkins;
use super::lugre::LuGre;
use super::maxwell::MaxwellSlip;
use super::{check_time, sign, AnyLaw, AnyState, Law};
use crate::error::{check_finite, check_same_len, CoreError};

impl AnyLaw {
    /// Number of parameters (own and children's).
    pub fn n_params(&self) -> usize {
        match self {
            Self::Jenkins(_) | Self::KelvinVoigt(_) => 2,
            Self::MaxwellSlip(l) => l.k.len().saturating_mul(2),
            Self::Gms(l) => l.k.len().saturating_mul(2).saturating_add(6),
            Self::Segalman(_) => 4,
            Self::MasingExp(_) | Self::Dahl(_) => 3,
            Self::LuGre(_) => 7,
            Self::BoucWen(_) => 5,
            Self::Parallel(l) => l
                .laws
                .iter()
                .map(Self::n_params)
                .fold(2usize, usize::saturating_add),
            Self::Series(l) => l.a.n_params().saturating_add(l.b.n_params()),
            Self::Backlash(l) => l.law.n_params().saturating_add(1),
        }
    }

    /// Length of the state's sensitivity vector, `None` when the law has no forward
    /// sensitivities here.
    pub fn sens_len(&self) -> Option<usize> {
        match self {
            Self::Jenkins(_) => Some(2),
            Self::MaxwellSlip(l) => Some(l.k.len().saturating_mul(2)),
            Self::Dahl(_) => Some(3),
            Self::LuGre(_) => Some(7),
            Self::KelvinVoigt(_) => Some(0),
            Self::Parallel(l) => l
                .laws
                .iter()
                .map(Self::sens_len)
                .try_fold(0usize, |a, b| b.map(|b| a.saturating_add(b))),
            _ => None,
        }
    }

    /// One step of the force and its gradient `g` (length [`Self::n_params`]); `ds` is the
    /// state's sensitivity (length [`Self::sens_len`], zero at the start).
    fn step_sens(
        &self,
        st: &mut AnyState,
        ds: &mut [f64],
        dt: Option<f64>,
        x: f64,
        g: &mut [f64],
    ) -> f64 {
        match (self, st) {
            (Self::Jenkins(l), AnyState::Jenkins(s)) => jenkins_sens(l, &mut s.z, ds, x, g),
            (Self::MaxwellSlip(l), AnyState::MaxwellSlip(s)) => maxwell_sens(l, s, ds, x, g),
            (Self::Dahl(l), AnyState::Dahl(s)) => dahl_sens(l, s, ds, x, g),
            (Self::LuGre(l), AnyState::LuGre(s)) => lugre_sens(l, s, ds, dt, x, g),
            (Self::KelvinVoigt(l), AnyState::KelvinVoigt(s)) => kv_sens(l, s, dt, x, g),
            (Self::Parallel(l), AnyState::Parallel(s)) => parallel_sens(l, s, ds, dt, x, g),
            _ => f64::NAN,
        }
    }
}

fn jenkins_sens(l: &Jenkins, z: &mut f64, dz: &mut [f64], x: f64, g: &mut [f64]) -> f64 {
    let (k, fs) = (l.k, l.fs);
    let f = k * (x - *z);
    if f > fs || f < -fs {
        let s = if f > fs { 1.0 } else { -1.0 };
        // z = x - s fs / k
        *z = x - s * fs / k;
        dz[0] = s * fs / (k * k);
        dz[1] = -s / k;
        g[0] = 0.0;
        g[1] = s;
        s * fs
    } else {
        g[0] = (x - *z) - k * dz[0];
        g[1] = -k * dz[1];
        f
    }
}

fn maxwell_sens(
    l: &MaxwellSlip,
    s: &mut super::maxwell::MaxwellState,
    ds: &mut [f64],
    x: f64,
    g: &mut [f64],
) -> f64 {
    let (gk, gf) = g.split_at_mut(l.k.len());
    let mut total = 0.0;
    let mut ge = [0.0; 2];
    let elements = l.k.iter().zip(&l.fs).zip(s.z.iter_mut());
    let outs = ds.chunks_exact_mut(2).zip(gk.iter_mut().zip(gf.iter_mut()));
    for (((&k, &fs), z), (dz, (gk, gf))) in elements.zip(outs) {
        total += jenkins_sens(&Jenkins { k, fs }, z, dz, x, &mut ge);
        *gk = ge[0];
        *gf = ge[1];
    }
    total
}

/// Dahl: the step's closed form `y_n = (y^m - m a u)^{1/m}`, `m = 1 - α`, `a = σ0/Fc`,
/// `y = 1 - s F/Fc` (the limit `y e^{-a u}` at `α = 1`), differentiated in `(σ0, Fc, α)`.
fn dahl_sens(
    l: &Dahl,
    st: &mut super::dahl::DahlState,
    df: &mut [f64],
    x: f64,
    g: &mut [f64],
) -> f64 {
    let dx = x - st.xp;
    if dx != 0.0 {
        let f = st.f;
        let fc = l.fc;
        let s = sign(dx);
        let u = dx.abs();
        let a = l.sigma0 / fc;
        let m = 1.0 - l.alpha;
        let y = 1.0 - s * f / fc;
        // dy/dθ, da/dθ, dm/dθ for θ = (σ0, Fc, α)
        let dy = [
            -s * df[0] / fc,
            -s * (df[1] / fc - f / (fc * fc)),
            -s * df[2] / fc,
        ];
        let da = [1.0 / fc, -l.sigma0 / (fc * fc), 0.0];
        let dm = [0.0, 0.0, -1.0];
        let mut dyn_ = [0.0; 3];
        let mut yn = y;
        if l.alpha == 1.0 {
            let e = (-a * u).exp();
            yn = y * e;
            let lnd = if y > 0.0 {
                let ly = y.ln();
                0.5 * (ly * ly - (ly - a * u) * (ly - a * u))
            } else {
                0.0
            };
            for j in 0..3 {
                dyn_[j] = dy[j] * e - yn * u * da[j] + yn * lnd * dm[j];
            }
        } else if y > 0.0 {
            let ym = y.powf(m);
            let w = ym - m * a * u;
            if w > 0.0 {
                yn = w.powf(1.0 / m);
                let ly = y.ln();
                for j in 0..3 {
                    let dw = m * ym / y * dy[j] + (ym * ly - a * u) * dm[j] - m * u * da[j];
                    dyn_[j] = yn * (dw / (m * w) - w.ln() * dm[j] / (m * m));
                }
            } else {
                yn = 0.0;
            }
        }
        let dfc = [0.0, 1.0, 0.0];
        if l.alpha == 1.0 || y > 0.0 {
            for j in 0..3 {
                df[j] = s * dfc[j] * (1.0 - yn) - s * fc * dyn_[j];
            }
        }
        let _ = l.step(st, None, x);
    }
    g[..3].copy_from_slice(&df[..3]);
    st.f
}

/// LuGre: `z_n = z_ss + (z - z_ss) e`, `z_ss = s g/σ0`, `e = exp(-σ0 |Δx|/g)`, and
/// `F = σ0 z + σ1 (v - σ0 |v| z/g) + σ2 v`, differentiated in
/// `(σ0, σ1, σ2, Fc, Fs, vs, δ)` (the Stribeck curve `g` in the last four).
fn lugre_sens(
    l: &LuGre,
    st: &mut super::lugre::LuGreState,
    dz: &mut [f64],
    dt: Option<f64>,
    x: f64,
    g: &mut [f64],
) -> f64 {
    let dx = x - st.xp;
    let (v, gv, dg) = match dt {
        None => (0.0, l.fs, [0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0]),
        Some(dt) => {
            let v = dx / dt;
            let (gv, dg) = stribeck_sens(l, v);
            (v, gv, dg)
        }
    };
    let s0 = l.sigma0;
    let z = st.z;
    if dx != 0.0 {
        let s = sign(dx);
        let u = dx.abs();
        let zss = s * gv / s0;
        let e = (-s0 * u / gv).exp();
        for j in 0..7 {
            let ds0 = if j == 0 { 1.0 } else { 0.0 };
            let dzss = s * dg[j] / s0 - zss * ds0 / s0;
            let de = e * (-u * ds0 / gv + s0 * u * dg[j] / (gv * gv));
            dz[j] = dzss * (1.0 - e) + dz[j] * e + (z - zss) * de;
        }
    }
    let f = l.step(st, dt, x);
    let z = st.z;
    let av = v.abs();
    let zdot = v - s0 * av * z / gv;
    for j in 0..7 {
        let ds0 = if j == 0 { 1.0 } else { 0.0 };
        let dzdot = -av * ((z * ds0 + s0 * dz[j]) / gv - s0 * z * dg[j] / (gv * gv));
        g[j] = s0 * dz[j] + z * ds0 + l.sigma1 * dzdot;
    }
    g[1] += zdot;
    g[2] += v;
    f
}

/// The Stribeck curve `g(v)` of [`super::lugre::stribeck`] and its derivatives in the LuGre
/// parameters (zero in σ0, σ1, σ2).
fn stribeck_sens(l: &LuGre, v: f64) -> (f64, [f64; 7]) {
    let r = v.abs() / l.vs;
    let p = if l.delta == 2.0 {
        r * r
    } else {
        r.powf(l.delta)
    };
    let mut dg = [0.0; 7];
    if p > 48.0 {
        dg[3] = 1.0;
        return (l.fc, dg);
    }
    let e = (-p).exp();
    let span = l.fs - l.fc;
    dg[3] = 1.0 - e;
    dg[4] = e;
    dg[5] = span * e * l.delta * p / l.vs;
    dg[6] = if r > 0.0 { -span * e * p * r.ln() } else { 0.0 };
    (l.fc + span * e, dg)
}

fn kv_sens(
    l: &KelvinVoigt,
    s: &mut super::compose::KvState,
    dt: Option<f64>,
    x: f64,
    g: &mut [f64],
) -> f64 {
    let v = match dt {
        None => 0.0,
        Some(dt) => (x - s.xp) / dt,
    };
    g[0] = x - s.x0;
    g[1] = v;
    l.step(s, dt, x)
}

fn parallel_sens(
    l: &Parallel,
    st: &mut super::compose::ParallelState,
    ds: &mut [f64],
    dt: Option<f64>,
    x: f64,
    g: &mut [f64],
) -> f64 {
    let v = match dt {
        None => 0.0,
        Some(dt) => (x - st.xp) / dt,
    };
    st.xp = x;
    let mut f = l.k * (x - st.x0) + l.c * v;
    g[0] = x - st.x0;
    g[1] = v;
    let (_, mut g_rest) = g.split_at_mut(2);
    let mut ds_rest = ds;
    for (law, s) in l.laws.iter().zip(st.states.iter_mut()) {
        let (gl, gr) = g_rest.split_at_mut(law.n_params());
        let (dl, dr) = ds_rest.split_at_mut(law.sens_len().unwrap_or(0));
        f += law.step_sens(s, dl, dt, x, gl);
        g_rest = gr;
        ds_rest = dr;
    }
    f
}

/// Forces of a whole history from the relaxed state at `x0` and their sensitivities:
/// `(F, J)` with `J` row-major `(x.len(), law.n_params())`. Errors as [`super::force`], and
/// `InvalidLaw` for a law without forward sensitivities.
pub fn force_sens(
    law: &AnyLaw,
    t: Option<&[f64]>,
    x: &[f64],
    x0: f64,
) -> Result<(Vec<f64>, Vec<f64>), CoreError> {
    let ns = law.sens_len().ok_or_else(|| CoreError::InvalidLaw {
        kind: "sensitivities".to_string(),
        reason: "this law has no forward sensitivities (use finite differences)".to_string(),
    })?;
    check_finite("x0", &[x0])?;
    check_finite("x", x)?;
    if let Some(t) = t {
        check_same_len("t", t.len(), "x", x.len())?;
        check_time(t, None)?;
    } else if law.rate_dependent() {
        return Err(CoreError::InvalidState {
            reason: "the law is rate-dependent: pass the sample times t",
        });
    }
    let np = law.n_params();
    let mut st = law.start(x0);
    let mut ds = vec![0.0; ns];
    let mut f = vec![0.0; x.len()];
    let mut jac = vec![0.0; x.len().saturating_mul(np)];
    let mut tp: Option<f64> = None;
    for (i, (fi, gi)) in f
        .iter_mut()
        .zip(jac.chunks_exact_mut(np.max(1)))
        .enumerate()
    {
        let dt = match (t, tp) {
            (Some(t), Some(p)) => Some(t[i] - p),
            _ => None,
        };
        tp = t.map(|t| t[i]);
        *fi = law.step_sens(&mut st, &mut ds, dt, x[i], gi);
    }
    if let Some(index) = f.iter().position(|v| !v.is_finite()) {
        return Err(CoreError::OutOfRange {
            what: "force",
            index,
            value: f[index],
        });
    }
    Ok((f, jac))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::joints::force;

    fn signal(n: usize) -> (Vec<f64>, Vec<f64>) {
        let t: Vec<f64> = (0..n).map(|i| i as f64 * 1e-3).collect();
        let x = t
            .iter()
            .map(|&t| {
                1e-3 * (6.0 * t).sin() * (1.0 + 0.5 * (1.3 * t).sin()) + 2e-4 * (41.0 * t).sin()
            })
            .collect();
        (t, x)
    }

    /// The forward sensitivities equal central differences of the force (an independent
    /// route: the plain kernel run at perturbed parameters).
    fn check(kind: &str, p: &[f64], children: &dyn Fn() -> Vec<AnyLaw>) {
        let (t, x) = signal(3000);
        let law = AnyLaw::build(kind, p, children()).unwrap();
        let (f, jac) = force_sens(&law, Some(&t), &x, 0.0).unwrap();
        let f0 = force(&law, Some(&t), &x, 0.0).unwrap();
        assert_eq!(f, f0, "{kind}: the force of the sensitivity pass");
        let np = law.n_params();
        assert_eq!(
            np,
            p.len() + children().iter().map(AnyLaw::n_params).sum::<usize>()
        );
        let scale = f.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        // own parameters only (children's are checked on their own)
        for j in 0..p.len() {
            // Dahl's exponent: the kernel's power form loses digits as α -> 1 (w^{1/m},
            // m = 1 - α), so its differences take a wider step
            let rel = if kind == "dahl" && j == 2 { 1e-4 } else { 1e-6 };
            let h = rel * p[j].abs().max(1e-3);
            let (mut pp, mut pm) = (p.to_vec(), p.to_vec());
            pp[j] += h;
            pm[j] -= h;
            let fp = force(
                &AnyLaw::build(kind, &pp, children()).unwrap(),
                Some(&t),
                &x,
                0.0,
            )
            .unwrap();
            let fm = force(
                &AnyLaw::build(kind, &pm, children()).unwrap(),
                Some(&t),
                &x,
                0.0,
            )
            .unwrap();
            let mut worst = 0.0f64;
            let mut norm = 0.0f64;
            for i in 0..x.len() {
                let fd = (fp[i] - fm[i]) / (2.0 * h);
                worst = worst.max((fd - jac[i * np + j]).abs());
                norm = norm.max(fd.abs());
            }
            assert!(
                worst <= 1e-5 * norm.max(scale / p[j].abs().max(1e-3)),
                "{kind} parameter {j}: |FD - forward| = {worst:e} of {norm:e}"
            );
        }
    }

    #[test]
    fn sensitivities_equal_central_differences() {
        let none = || Vec::new();
        check("jenkins", &[1e4, 3.0], &none);
        check("maxwell_slip", &[1e4, 2e4, 5e3, 1.0, 4.0, 2.0], &none);
        check("dahl", &[3e4, 5.0, 1.0], &none);
        check("dahl", &[3e4, 5.0, 0.6], &none);
        check("dahl", &[3e4, 5.0, 1.7], &none);
        check("lugre", &[1e5, 30.0, 2.0, 4.0, 5.0, 2e-3, 2.0], &none);
        check("lugre", &[1e5, 30.0, 2.0, 4.0, 5.0, 2e-3, 1.3], &none);
        check("kelvin_voigt", &[1e3, 2.0], &none);
        let kids = || {
            vec![
                AnyLaw::build("lugre", &[1e5, 30.0, 2.0, 4.0, 5.0, 2e-3, 2.0], vec![]).unwrap(),
                AnyLaw::build("jenkins", &[1e4, 3.0], vec![]).unwrap(),
            ]
        };
        check("parallel", &[2e3, 1.5], &kids);
        // the children's columns of a parallel law are their own sensitivities
        let (t, x) = signal(500);
        let par = AnyLaw::build("parallel", &[2e3, 1.5], kids()).unwrap();
        let (_, jp) = force_sens(&par, Some(&t), &x, 0.0).unwrap();
        let (_, jl) = force_sens(&kids()[0], Some(&t), &x, 0.0).unwrap();
        for i in 0..x.len() {
            for j in 0..7 {
                assert_eq!(jp[i * 11 + 2 + j], jl[i * 7 + j]);
            }
        }
    }

    #[test]
    fn unsupported_laws_and_bad_input_are_errors() {
        let (t, x) = signal(10);
        let bw = AnyLaw::build("bouc_wen", &[1e4, 1e3, 0.5, 0.5, 1.0], vec![]).unwrap();
        assert!(bw.sens_len().is_none());
        assert!(force_sens(&bw, Some(&t), &x, 0.0).is_err());
        let lg = AnyLaw::build("lugre", &[1e5, 30.0, 2.0, 4.0, 5.0, 2e-3, 2.0], vec![]).unwrap();
        assert!(force_sens(&lg, None, &x, 0.0).is_err());
        let mut bad = x.clone();
        bad[3] = f64::NAN;
        assert!(force_sens(&lg, Some(&t), &bad, 0.0).is_err());
    }
}
