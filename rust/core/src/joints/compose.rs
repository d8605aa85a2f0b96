//! Composition: a linear spring-dashpot ([`KelvinVoigt`]), laws in parallel with a stiffness
//! and a viscous term ([`Parallel`]), and laws in series ([`Series`], the force balance solved
//! at every sample by a bracketed root search on the split of the displacement).

use super::{check_nonneg, illinois, AnyLaw, AnyState, Law};
use crate::error::CoreError;

/// `F = k (x - x0) + c ẋ`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KelvinVoigt {
    pub k: f64,
    pub c: f64,
}

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KvState {
    pub x0: f64,
    pub xp: f64,
}

impl KelvinVoigt {
    pub fn new(k: f64, c: f64) -> Result<Self, CoreError> {
        check_nonneg("k", k)?;
        check_nonneg("c", c)?;
        Ok(Self { k, c })
    }
}

impl Law for KelvinVoigt {
    type State = KvState;
    fn start(&self, x0: f64) -> KvState {
        KvState { x0, xp: x0 }
    }
    #[inline]
    fn step(&self, st: &mut KvState, dt: Option<f64>, x: f64) -> f64 {
        let v = match dt {
            None => 0.0,
            Some(dt) => (x - st.xp) / dt,
        };
        st.xp = x;
        self.k * (x - st.x0) + self.c * v
    }
}

/// `F = Σ F_i(x) + k (x - x0) + c ẋ`.
#[derive(Debug, Clone, PartialEq)]
pub struct Parallel {
    pub laws: Vec<AnyLaw>,
    pub k: f64,
    pub c: f64,
}

#[derive(Debug, Clone, PartialEq)]
pub struct ParallelState {
    pub x0: f64,
    pub xp: f64,
    pub states: Vec<AnyState>,
}

impl Parallel {
    pub fn new(laws: Vec<AnyLaw>, k: f64, c: f64) -> Result<Self, CoreError> {
        check_nonneg("k", k)?;
        check_nonneg("c", c)?;
        Ok(Self { laws, k, c })
    }
}

impl Law for Parallel {
    type State = ParallelState;
    fn start(&self, x0: f64) -> ParallelState {
        ParallelState {
            x0,
            xp: x0,
            states: self.laws.iter().map(|l| l.start(x0)).collect(),
        }
    }
    fn step(&self, st: &mut ParallelState, dt: Option<f64>, x: f64) -> f64 {
        let v = match dt {
            None => 0.0,
            Some(dt) => (x - st.xp) / dt,
        };
        st.xp = x;
        let mut f = self.k * (x - st.x0) + self.c * v;
        for (law, s) in self.laws.iter().zip(st.states.iter_mut()) {
            f += law.step(s, dt, x);
        }
        f
    }
}

/// Two laws in series: `x = x_a + x_b`, `F_a(x_a) = F_b(x_b)`; more are chained to the right.
#[derive(Debug, Clone, PartialEq)]
pub struct Series {
    pub a: AnyLaw,
    pub b: AnyLaw,
}

#[derive(Debug, Clone, PartialEq)]
pub struct SeriesState {
    pub xp: f64,
    pub xa: f64,
    pub sa: AnyState,
    pub sb: AnyState,
    pub f: f64,
}

impl Series {
    /// `a` in series with `b` in series with … (right fold, as the reference builds it).
    pub fn chain(laws: Vec<AnyLaw>) -> Result<AnyLaw, CoreError> {
        if laws.len() < 2 {
            return Err(CoreError::InvalidLaw {
                kind: "series".to_string(),
                reason: format!("takes two or more laws, got {}", laws.len()),
            });
        }
        let mut it = laws.into_iter().rev();
        let mut out = it.next().ok_or(CoreError::Empty { name: "series" })?;
        for a in it {
            out = AnyLaw::Series(Box::new(Self { a, b: out }));
        }
        Ok(out)
    }
}

/// Widen `[lo, hi]` until `phi(lo) <= 0 <= phi(hi)` (`phi` non-decreasing); `None` when no
/// sign change is found (the reference's `bracket`).
pub(crate) fn bracket(
    phi: &mut dyn FnMut(f64) -> f64,
    mut lo: f64,
    mut hi: f64,
    width: f64,
) -> Option<(f64, f64, f64, f64)> {
    let mut flo = phi(lo);
    let mut fhi = phi(hi);
    let mut w = width;
    for _ in 0..200 {
        if flo <= 0.0 && 0.0 <= fhi {
            return Some((lo, flo, hi, fhi));
        }
        if flo > 0.0 {
            lo -= w;
            flo = phi(lo);
        }
        if fhi < 0.0 {
            hi += w;
            fhi = phi(hi);
        }
        w *= 2.0;
    }
    None
}

impl Law for Series {
    type State = SeriesState;
    fn start(&self, x0: f64) -> SeriesState {
        SeriesState {
            xp: x0,
            xa: 0.0,
            sa: self.a.start(0.0),
            sb: self.b.start(x0),
            f: 0.0,
        }
    }
    fn step(&self, st: &mut SeriesState, dt: Option<f64>, x: f64) -> f64 {
        let dx = x - st.xp;
        let xa0 = st.xa;
        let (a, b) = (&self.a, &self.b);
        let (sa0, sb0) = (&st.sa, &st.sb);
        let mut phi = |xa: f64| -> f64 {
            let (mut sa, mut sb) = (sa0.clone(), sb0.clone());
            a.step(&mut sa, dt, xa) - b.step(&mut sb, dt, x - xa)
        };
        let lo = xa0 + dx.min(0.0);
        let hi = xa0 + dx.max(0.0);
        let width = dx
            .abs()
            .max(f64::EPSILON * (x.abs() + xa0.abs()))
            .max(1e-300);
        let Some((lo, flo, hi, fhi)) = bracket(&mut phi, lo, hi, width) else {
            return f64::NAN;
        };
        let ftol = 1e-14 * st.f.abs().max(flo.abs()).max(fhi.abs());
        let xa = illinois(&mut phi, lo, flo, hi, fhi, ftol);
        let (mut sa, mut sb) = (st.sa.clone(), st.sb.clone());
        let _ = a.step(&mut sa, dt, xa);
        let fb = b.step(&mut sb, dt, x - xa);
        st.xp = x;
        st.xa = xa;
        st.sa = sa;
        st.sb = sb;
        st.f = fb;
        fb
    }
}
