//! The period means of [`super::fold_window`] (those of
//! [`crate::fold::period_means_pair`], bit for bit) advanced as the fold's cycles
//! complete: the cumulative trapezoid integrals of F and x run over each completed cycle's
//! samples while they are still in cache (after the cycle's loop area), instead of a pass
//! of their own over the whole window afterwards. The integrals are one sequential chain of
//! additions, paused and resumed anywhere with the same numbers; an edge is recorded once
//! the sample after it has been reached.

use crate::fold::trapezoids_until;

/// The running state of the period means over `(t, f, x)` with `edges`.
pub(super) struct PeriodMeans {
    j: usize,
    cf: f64,
    cx: f64,
    /// the next edge to record
    k: usize,
    ce_f: Vec<f64>,
    ce_x: Vec<f64>,
}

impl PeriodMeans {
    pub(super) fn new(n_edges: usize) -> Self {
        PeriodMeans {
            j: 0,
            cf: 0.0,
            cx: 0.0,
            k: 0,
            ce_f: Vec::with_capacity(n_edges),
            ce_x: Vec::with_capacity(n_edges),
        }
    }

    /// Record the edges below `t[limit]` (their interpolation reads at most sample `limit`)
    /// and carry the integrals to sample `limit` (`None`: every edge, to the end, as
    /// `period_means_pair` does).
    // Index arithmetic: j + 1 < n where read; limit < n (the caller's).
    #[allow(clippy::arithmetic_side_effects)]
    pub(super) fn advance(
        &mut self,
        (t, f, x): (&[f64], &[f64], &[f64]),
        edges: &[f64],
        limit: Option<usize>,
    ) {
        let n = t.len();
        let Some(&t0) = t.first() else {
            return;
        };
        if self.k >= edges.len() {
            // every edge recorded: the integrals are read nowhere after (no chain to carry;
            // a fold without edges runs none)
            return;
        }
        let below = limit.map_or(f64::INFINITY, |l| t[l]);
        while self.k < edges.len() && edges[self.k] < below {
            let e = edges[self.k];
            self.k += 1;
            if e <= t0 {
                self.ce_f.push(0.0);
                self.ce_x.push(0.0);
                continue;
            }
            (self.j, self.cf, self.cx) = trapezoids_until(t, (f, x), self.j, e, (self.cf, self.cx));
            let (j, cf, cx) = (self.j, self.cf, self.cx);
            if j + 1 >= n || e == t[j] {
                self.ce_f.push(cf);
                self.ce_x.push(cx);
            } else {
                let dt = t[j + 1] - t[j];
                let c1f = cf + 0.5 * (f[j + 1] + f[j]) * dt;
                let c1x = cx + 0.5 * (x[j + 1] + x[j]) * dt;
                self.ce_f.push((c1f - cf) / dt * (e - t[j]) + cf);
                self.ce_x.push((c1x - cx) / dt * (e - t[j]) + cx);
            }
        }
        if let Some(l) = limit {
            // the chain on to sample l (t strictly increasing: j stops at l)
            (self.j, self.cf, self.cx) =
                trapezoids_until(t, (f, x), self.j, t[l], (self.cf, self.cx));
        }
    }

    /// Every edge recorded (see [`PeriodMeans::advance`]): the means of F and x per period.
    // Index arithmetic: none (windows of two).
    pub(super) fn finish(
        mut self,
        tfx: (&[f64], &[f64], &[f64]),
        edges: &[f64],
    ) -> (Vec<f64>, Vec<f64>) {
        self.advance(tfx, edges, None);
        let means = |ce: &[f64]| -> Vec<f64> {
            ce.windows(2)
                .zip(edges.windows(2))
                .map(|(c, e)| (c[1] - c[0]) / (e[1] - e[0]))
                .collect()
        };
        (means(&self.ce_f), means(&self.ce_x))
    }
}
