"""The named steps of the tangential and normal loop analyses, each on its own (issue 13)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from contactlab import InputError
from contactlab.masing import Masing
from contactlab.normal import loop as nloop
from contactlab.synthetic.normal import synthetic_recording as normal_recording
from contactlab.synthetic.tangential import synthetic_recording
from contactlab.tangential import analysis, steps
from contactlab.tangential.uncertainty import reparametrize


def _clean(n_cycles: int = 5, **kw):
    return synthetic_recording(h0=20.0, ac=1e5, amplitude=10e-6, n_cycles=n_cycles, fs=2000.0,
                               noise=0.0, seed=0, **kw)  # fmt: skip


def _prepared(on: str = "averaged"):
    rec = _clean()
    det = steps.detrend(rec["x"], rec["F"], rec.t, on=on, enabled=True, n_points=None,
                        rel_threshold=0.5, min_cycles=2)  # fmt: skip
    data = steps.fit_data(det, rec.t, on=on, steady=True, rel_threshold=0.5)
    return det, data


def test_detrend_removes_a_force_drift_and_reports_it():
    rec = _clean(n_cycles=6, drift=0.05)  # N/s
    det = steps.detrend(rec["x"], rec["F"], rec.t, on="averaged", enabled=True, n_points=None,
                        rel_threshold=0.5, min_cycles=2)  # fmt: skip
    slope, se = det.force_drift
    assert slope == pytest.approx(0.05, rel=0.05)
    assert se >= 0
    off = steps.detrend(rec["x"], rec["F"], rec.t, on="averaged", enabled=False, n_points=None,
                        rel_threshold=0.5, min_cycles=2)  # fmt: skip
    assert off.drift is None and off.force_drift == (0.0, 0.0)


def test_fit_data_averaged_and_signal():
    _, avg = _prepared("averaged")
    assert avg.xd.size == avg.loop.x.size and avg.start == 0 and avg.stop is None
    assert avg.amplitude0 == pytest.approx(10e-6, rel=0.05)
    _, sig = _prepared("signal")
    assert sig.xd.size == sig.x.size and sig.start == sig.rev.first > 0
    # the monotone path has no reversal between the turns
    seg = sig.xpath[sig.rev.turns[1] : sig.rev.turns[2]]
    assert np.all(np.diff(seg) >= 0) or np.all(np.diff(seg) <= 0)


def test_residuals_vanish_at_the_truth_of_a_clean_steady_signal():
    _, data = _prepared("signal")
    res = steps.Residuals(data, data.w)
    a = float(data.x[data.sl].max() - data.x[data.sl].min()) / 2
    truth = {"k0": 20.0 * 1e5, "ac": 1e5, "offset": 0.0, "x0": 0.0, "amplitude": a}
    r = res.residual(truth)
    assert np.sqrt(np.mean(r**2)) < 1e-3 * 20.0
    # a force perturbation moves the residual by exactly -dF on the fitted stretch
    dF = np.full(data.Fd.size, 0.1)
    assert np.allclose(res.residual(truth, dF=dF) - r, -0.1)


def test_start_values_bracket_the_truth_and_refuse_bad_initial_values():
    _, data = _prepared("averaged")
    sv = steps.start_values(data, rel_threshold=0.5, fit_offset=True, fit_x0=True,
                            fit_amplitude=True, initial=None)  # fmt: skip
    names = [p.name for p in sv.params]
    assert names == ["k0", "ac", "offset", "x0", "amplitude"]
    k0 = sv.params[0].value
    assert 0.2 < k0 / 2e6 < 5
    with pytest.raises(InputError, match="initial h0, ac"):
        steps.start_values(data, rel_threshold=0.5, fit_offset=True, fit_x0=True,
                           fit_amplitude=True, initial={"h0": -1.0})  # fmt: skip


def test_identifiability_step_on_a_straight_loop():
    """Amplitude ≪ 1/ac: only h0·ac is identified, and the step says so with bounds."""
    rec = synthetic_recording(h0=40.0, ac=300.0, amplitude=10e-6, n_cycles=6, fs=2000.0,
                              noise=0.01, seed=11)  # fmt: skip
    det = steps.detrend(rec["x"], rec["F"], rec.t, on="averaged", enabled=True, n_points=None,
                        rel_threshold=0.5, min_cycles=2)  # fmt: skip
    data = steps.fit_data(det, rec.t, on="averaged", steady=True, rel_threshold=0.5)
    sv = steps.start_values(data, rel_threshold=0.5, fit_offset=True, fit_x0=True,
                            fit_amplitude=True, initial=None)  # fmt: skip
    raw, _res, _ = steps.fit(steps.Residuals(data, data.w), sv, fit_x0=True, fit_amplitude=True)
    fit = reparametrize(raw)
    ident, ev = analysis.identifiability(fit, raw, raw.values["amplitude"], 0.2)
    assert not ident and "NOT separately identifiable" in ev["message"]
    assert ev["h0_lower_bound"] > 0 and ev["ac_upper_bound"] > 300
    assert fit.params["h0"].identifiable is False


def test_amplitude_step_uses_the_fit_when_fitted():
    rec = _clean()
    res = analysis.analyze_tangential(rec, warn=False)
    assert res.amplitude == pytest.approx(10e-6, rel=1e-3)
    assert res.fit.params["amplitude"].value == res.amplitude


def test_normal_steps_cycles_levels_branches():
    t, p, d = normal_recording(model="table2", n_cycles=4, noise=None)
    tv, pv, dv = nloop._check_inputs(t, p, d, 4)
    tv, pv, dv, dt, resampled = nloop._uniform(tv, pv, dv)
    assert not resampled
    cyc = nloop._cycles(tv, pv, dt, None, None, None)
    assert cyc.discard == 1 and cyc.n_used == 3
    assert cyc.omega == pytest.approx(1.0, rel=1e-3)
    pdyn = np.sin(np.linspace(0, 2 * np.pi, 64, endpoint=False))
    p0, pa = nloop._pressure_levels(pdyn, 2.0, None)
    assert p0 == 2.0 and pa == pytest.approx(1.0, abs=1e-3)
    with pytest.raises(InputError, match="give the static pressure p0"):
        nloop._pressure_levels(pdyn, 0.0, None)
    with pytest.raises(InputError, match="whole number"):
        nloop._discard_count(1.5, 4)


def test_normal_energies_of_an_ellipse_match_the_closed_form():
    """A Kelvin-Voigt ellipse p = k δ + h δ': ∮ p dδ = π h ω Δ² for δ = Δ sin ωt."""
    n = 256
    ph = np.linspace(0, 2 * np.pi, n, endpoint=False)
    k, c, amp = 2.0, 0.3, 1.5
    dz = amp * np.sin(ph)
    pdyn = k * dz + c * amp * np.cos(ph)
    br = nloop._branches(pdyn, dz, 4, True)
    en = nloop._energies(pdyn, dz - br.shift, br)
    assert en.E_d == pytest.approx(math.pi * c * amp**2, rel=1e-9)
    assert Masing(1.0, 1.0).h0 == 1.0  # import check of the model type used above


def _closed_residual(res, v):
    """The residuals of an averaged fit from the steady loop in closed form (complex-step
    friendly in k0, ac, offset): F = ±(h(A) - 2 h(s)) + ±¼ k0 ac e^{-ac s} var(x), a bin
    beyond a turn on its branch's tangent there."""
    d = res.data
    k0, ac, x0, A = v["k0"], v["ac"], v["x0"], v["amplitude"]
    n = d.xpath.size
    sg = np.r_[np.ones(n // 2), -np.ones(n - n // 2)]
    s_raw = 0.5 * (A - sg * (d.xpath - x0))
    s = np.clip(s_raw, 0.0, A)
    F = sg * (-k0 / ac * np.expm1(-ac * A) + 2 * k0 / ac * np.expm1(-ac * s))
    F = F + sg * 0.25 * k0 * ac * np.exp(-ac * s) * d.bin_var + v["offset"]
    # beyond a turn: the tangent (force, slope) of the branch there
    F = F - sg * k0 * np.exp(-ac * s) * (2 + 0.25 * ac * ac * d.bin_var) * (s_raw - s)
    r = (F - d.Fd)[d.sl] * res.w[d.sl]
    pr = res.prior
    if pr is None:
        return r
    meas = {"x0": pr.x0, "amplitude": pr.amplitude}
    return np.r_[r, [(v[k] - meas[k]) / pr.sigma * pr.scale for k in pr.names]]


@pytest.mark.parametrize(
    ("ac", "amp_factor", "prior"),
    [(6e4, 0.999, False), (6e4, 0.97, True), (2e5, 1.02, True), (3.0, 1.0, False)],
)
def test_analytic_jacobian_equals_finite_differences(ac, amp_factor, prior):
    """Residuals.jacobian (closed-form branches, the bins' curvature term, prior rows) against
    central differences of the residuals the Masing operator gives; amplitudes below and
    above the bins' range put some bins beyond a turn (on their branch's tangent there);
    ac = 3 1/m is a nearly linear loop (ac·A ~ 5e-5), where the ac column's two terms
    cancel."""
    from contactlab.tangential.window import window_detrended

    rec = synthetic_recording(h0=2e6 / ac, ac=ac, amplitude=15e-6, n_cycles=8, fs=1500.0,
                              frequency=2.0, noise=0.02, x_noise=0.01, seed=6911)  # fmt: skip
    opts = {"n_points": None, "rel_threshold": 0.5, "min_cycles": 2, "detrend": True}
    det = window_detrended(rec["x"], rec["F"], rec.t, opts)
    data = steps.fit_data(det, rec.t, on="averaged", steady=True, rel_threshold=0.5)
    assert data.bin_var is not None
    pr = steps.PriorRows(("x0", "amplitude"), 1e-8, 15e-6, 2e-8, 0.3) if prior else None
    res = steps.Residuals(data, data.w, pr)
    v = {"k0": 2e6, "ac": ac, "offset": 0.05, "x0": 2e-9, "amplitude": 15e-6 * amp_factor}
    J = res.jacobian(v)
    # the closed form is the Masing operator's loop (to rounding)
    np.testing.assert_allclose(_closed_residual(res, v), res(v), rtol=0,
                               atol=1e-12 * np.max(np.abs(res(v))))  # fmt: skip
    for k in ("k0", "ac", "offset"):  # complex step: no cancellation, even as ac → 0
        step = 1e-30 * abs(v[k])
        cs = _closed_residual(res, dict(v, **{k: v[k] + 1j * step})).imag / step
        np.testing.assert_allclose(J[k], cs, rtol=0, atol=1e-9 * np.max(np.abs(cs)), err_msg=k)
    for k, x in v.items():
        if k in ("k0", "ac", "offset"):
            continue
        h = 1e-5 * abs(x)
        up, dn = dict(v, **{k: x + h}), dict(v, **{k: x - h})
        fd = (res(up) - res(dn)) / (2 * h)
        # no kink: a bin beyond a turn continues its branch instead of being clipped there
        np.testing.assert_allclose(J[k], fd, rtol=0, atol=1e-6 * np.max(np.abs(fd)), err_msg=k)
    with pytest.raises(InputError):
        steps.Residuals(steps.fit_data(det, rec.t, on="signal", steady=True,
                                       rel_threshold=0.5), data.w).jacobian(v)  # fmt: skip
