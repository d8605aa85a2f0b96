//! In-place dense LU with partial pivoting on preallocated storage: the Newton loop factors a
//! small matrix every iteration, and allocation-free factoring keeps SDOF steps at tens of ns.

/// The matrix handed to [`Lu::factor`] is singular (a zero or non-finite pivot) or misshapen.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Singular;

/// LU factors of an `n × n` row-major matrix.
#[derive(Debug, Clone)]
pub struct Lu {
    n: usize,
    factors: Vec<f64>,
    piv: Vec<usize>,
}

impl Lu {
    pub fn new(n: usize) -> Self {
        Self {
            n,
            factors: vec![0.0; n * n],
            piv: vec![0; n],
        }
    }

    /// Factor `a` (`n × n`, row-major). `Err(Singular)` when a pivot is zero or not finite.
    pub fn factor(&mut self, a: &[f64], n: usize) -> Result<(), Singular> {
        if n != self.n || a.len() != n * n {
            return Err(Singular);
        }
        self.factors.copy_from_slice(a);
        if n == 1 {
            let p = self.factors[0];
            return if p != 0.0 && p.is_finite() {
                Ok(())
            } else {
                Err(Singular)
            };
        }
        let lu = &mut self.factors;
        for k in 0..n {
            let mut p = k;
            let mut best = lu[k * n + k].abs();
            for r in k + 1..n {
                let v = lu[r * n + k].abs();
                if v > best {
                    best = v;
                    p = r;
                }
            }
            if !(best > 0.0 && best.is_finite()) {
                return Err(Singular);
            }
            self.piv[k] = p;
            if p != k {
                for c in 0..n {
                    lu.swap(k * n + c, p * n + c);
                }
            }
            let inv = 1.0 / lu[k * n + k];
            for r in k + 1..n {
                let l = lu[r * n + k] * inv;
                lu[r * n + k] = l;
                if l != 0.0 {
                    for c in k + 1..n {
                        lu[r * n + c] -= l * lu[k * n + c];
                    }
                }
            }
        }
        Ok(())
    }

    /// Solve in place with the last factorisation.
    pub fn solve(&self, b: &mut [f64]) {
        let n = self.n;
        if n == 1 {
            b[0] /= self.factors[0];
            return;
        }
        for k in 0..n {
            b.swap(k, self.piv[k]);
        }
        for r in 0..n {
            let s: f64 = (0..r).map(|c| self.factors[r * n + c] * b[c]).sum();
            b[r] -= s;
        }
        for r in (0..n).rev() {
            let s: f64 = (r + 1..n).map(|c| self.factors[r * n + c] * b[c]).sum();
            b[r] = (b[r] - s) / self.factors[r * n + r];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn solves_a_pivoting_system() {
        let a = [0.0, 2.0, 1.0, 1.0, 1.0, 0.0, 3.0, 0.0, 1.0];
        let x = [1.0, -2.0, 0.5];
        let mut b: Vec<f64> = (0..3)
            .map(|r| (0..3).map(|c| a[r * 3 + c] * x[c]).sum())
            .collect();
        let mut lu = Lu::new(3);
        assert!(lu.factor(&a, 3).is_ok());
        lu.solve(&mut b);
        for (p, q) in b.iter().zip(&x) {
            assert!((p - q).abs() < 1e-14);
        }
    }

    #[test]
    fn singular_is_an_error() {
        let mut lu = Lu::new(2);
        assert!(lu.factor(&[1.0, 2.0, 2.0, 4.0], 2).is_err());
    }
}
