"""A delay between the force and displacement channels: corrected when it is known, estimated
from the averaged loop when it is not.

Masing hysteresis (PHYSICS.md §1) is rate-independent: the force turns exactly when the
displacement does. A delay between the channels (different anti-alias filters, a
conditioning amplifier, an acquisition skew) makes the recorded force turn later than the
displacement; viscous damping ``c·ẋ`` makes it turn earlier (the force leads). Either one
biases ``h0``, ``ac`` and the energy without a misfit that shows: at 1 % noise a delay of
1.1 ms on a 1 Hz loop (x low-passed at 200 Hz, F at 100 Hz, causal Butterworth) moved
``h0`` +2.4 %, ``ac`` -3.6 % and ``E`` -4.4 %, with residuals 1.05× the noise, because the
delay is nearly degenerate with ``h0`` and ``ac`` at that noise.

- :func:`shift_force` corrects a known delay (``delay=`` of
  :func:`~contactlab.tangential.analyze_tangential`, ``--delay`` on the command line): the
  force is read ``delay`` later by 4-point (cubic Lagrange) interpolation between samples, and
  the samples the shift leaves without force data are dropped.
- :func:`estimate` measures the delay on the averaged loop: the Masing fit augmented by a
  time shift ``τ`` of the modelled force, ``F_model(t - τ) ≈ F_model - τ dF_model/dt``,
  solved to first order at the fit (one Gauss-Newton step of the augmented least squares:
  ``τ`` is the part of the residual along ``dF_model/dt`` that the fit's own parameters
  cannot absorb, its error the residual scale over that part's norm). Because the branch
  shape after the turn is the Masing branch itself, the estimate holds in gross sliding too,
  where a parabola in time around the turn does not (a turn-time prototype read -1.1 ms on a
  loop without delay at ``ac·A = 10``). Its linear response also says what correcting it does
  to ``h0`` and ``E``.

A delay is named in a warning only when it is significant (``|τ| > 4σ``) and its effect on
``h0`` or ``E`` exceeds their standard errors, and only where the Masing model describes the
loop (pre-sliding and transition, residuals within twice the noise): on a plateau (gross
sliding, stick-slip) ``h0`` comes from the plateau, which a delay does not move, and a loop
the model misses would read its misfit as a delay. The estimate itself (``channel_delay``,
``channel_delay_stderr``, s) is reported everywhere the averaged fit runs.

Measured on fresh seeds (1 Hz, 1 kHz, 100 cycles, 1 % noise on both channels, 8 seeds each):
true 1.1 ms reads 1.07 ± 0.13 ms (pre-sliding, ac·A 0.8) and 1.08 ± 0.08 ms (transition, 2);
no delay 0.00 ± 0.11 and -0.03 ± 0.08 ms (0 warnings); viscous damping (2 % of the force)
-2.2 ms in pre-sliding (named as a lead), +0.5 ± 0.25 ms (not significant) in transition.
NOT reliable, hence never warned about: gross sliding (ac·A 10: 1.1 ms reads 0.18 ± 0.04 ms),
and a noise-free displacement channel (1.1 ms reads 0.06 ms); with a noise-free force the
stated error is 3-5x too small (x-only noise: 1.07 ± 0.05 ms against a stated 0.013), so a
loop whose bins' noise comes mostly from the displacement (:data:`MAX_X_SHARE`) is not
warned about either.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import InputError

#: ``|τ| / σ_τ`` above which an estimated delay can be named in a warning
SIGNIFICANCE = 4.0
#: the displacement noise's share of the bins' force noise above which the estimate is not
#: warned about (:func:`displacement_noise_share`). 1 % noise on x, no delay, 20 fresh seeds
#: each, pre-sliding: with 1 % on F (share 0.52) the delay's scatter is 0.13 ms against a
#: stated 0.105; 0.6 % (0.75): 0.061 / 0.077; 0.4 % (0.86): 0.052 / 0.054; 0.25 % (0.93):
#: 0.050 / 0.036; none on F (1.0): 0.055 / 0.014, and 9 of 20 records were warned
MAX_X_SHARE = 0.9
#: the averaged fit's residuals over the noise above which the estimate is not warned about
#: (the model misses the loop; :func:`~contactlab.tangential.quantities.misfit_ratio`)
MAX_MISFIT = 2.0


def shift_force(
    t: np.ndarray | None, x: np.ndarray, F: np.ndarray, delay: float
) -> tuple[np.ndarray | None, np.ndarray, np.ndarray, int]:
    """``(t, x, F, dropped)`` with the force read ``delay`` seconds later (``delay > 0``: the
    recorded force lags the displacement), ``dropped`` the samples at the end (or, for a
    negative delay, at the start) the shift leaves without force data.

    Uniform sampling: 4-point cubic Lagrange interpolation between samples (exact for a whole
    number of samples); otherwise linear interpolation in ``t``.
    """
    delay = check_delay(delay)
    if t is None:
        raise InputError("delay= needs the time axis (t) to shift the force by seconds")
    n = x.size
    if delay == 0.0:
        return t, x, F, 0
    dt = (float(t[-1]) - float(t[0])) / (n - 1) if n > 1 else math.nan
    _check_period(t, x, delay)
    uniform = n > 1 and bool(np.all(np.abs(np.diff(t) - dt) <= 1e-6 * dt))
    if not uniform:
        ts = t + delay
        ok = (ts >= t[0]) & (ts <= t[-1])
        Fs = np.interp(ts[ok], t, F)
        return t[ok], x[ok], Fs, int(n - ok.sum())
    s = delay / dt
    k = math.floor(s)
    f = s - k
    if f < 1e-9 or f > 1 - 1e-9:  # a whole number of samples
        k = round(s)
        lo, hi = max(0, -k), min(n, n - k)
        Fs = F[lo + k : hi + k].copy()
    else:
        # F(i + k + f) from samples i+k-1 .. i+k+2
        w = (
            -f * (f - 1) * (f - 2) / 6,
            (f + 1) * (f - 1) * (f - 2) / 2,
            -(f + 1) * f * (f - 2) / 2,
            (f + 1) * f * (f - 1) / 6,
        )
        lo, hi = max(0, 1 - k), min(n, n - k - 2)
        if hi <= lo:
            raise InputError(f"delay {delay:g} s leaves no samples of the record")
        Fs = w[0] * F[lo + k - 1 : hi + k - 1]
        for j in (1, 2, 3):
            Fs += w[j] * F[lo + k - 1 + j : hi + k - 1 + j]
    if hi <= lo:
        raise InputError(f"delay {delay:g} s leaves no samples of the record")
    xs = np.ascontiguousarray(x[lo:hi])
    return np.ascontiguousarray(t[lo:hi]), xs, np.ascontiguousarray(Fs), int(n - (hi - lo))


def check_delay(delay: Any) -> float:
    """``delay`` as a float, refused when it is not a finite number of seconds."""
    try:
        d = float(delay)
    except (TypeError, ValueError):
        raise InputError(f"delay must be a number of seconds, got {delay!r}") from None
    if not math.isfinite(d):
        raise InputError(f"delay must be a finite number of seconds, got {delay!r}")
    return d


def _check_period(t: np.ndarray, x: np.ndarray, delay: float) -> None:
    """Refuse a delay of a quarter period or more (the force would be matched to the wrong
    stroke: no channel delay is that large, it is a wrong unit or a wrong sign convention)."""
    from .preprocess import find_reversals

    try:
        rev = find_reversals(x, t)
        pt = np.asarray(rev.peak_times, dtype=float)
    except InputError:
        pt = np.empty(0)
    if pt.size >= 2:
        period, what = float(np.median(np.diff(pt))), "the drive's period"
    else:
        period, what = float(t[-1] - t[0]), "the record's duration"
    if abs(delay) >= 0.25 * period:
        raise InputError(
            f"delay {1e3 * delay:.4g} ms is a quarter or more of {what} ({1e3 * period:.4g} "
            "ms): a channel delay is a small fraction of a period (seconds expected: "
            "--delay 1.1ms, delay=1.1e-3)"
        )


@dataclass(frozen=True)
class DelayEstimate:
    """The force's delay behind the displacement on the averaged loop (s; negative: the force
    leads, as viscous damping makes it) and what correcting it changes."""

    tau: float
    stderr: float
    period: float
    h0: tuple[float, float]  # (fitted, corrected for τ)
    energy: tuple[float, float]

    @property
    def degrees(self) -> float:
        return 360.0 * self.tau / self.period if self.period > 0 else math.nan

    @property
    def significant(self) -> bool:
        return bool(
            math.isfinite(self.tau)
            and self.stderr > 0
            and abs(self.tau) > SIGNIFICANCE * self.stderr
        )


def estimate(raw: Any, res: Any, data: Any) -> DelayEstimate | None:
    """:class:`DelayEstimate` of an averaged fit (``raw``: its :class:`FitResult`, ``res``:
    its :class:`~contactlab.tangential.steps.Residuals`); None where there is no averaged
    loop with a period.

    The delayed model is the fitted Masing loop driven by a smooth displacement: the averaged
    displacement's harmonics above its noise (the fit's own path is the bins' monotone
    projection, flat over the bins next to a turn where the noise exceeds the movement, and
    that flat top mimics a delay: at 1 % displacement noise it absorbed 25 % of it). Each
    bin's force is averaged over its width (the turn's kink falls inside a bin). ``τ`` and
    the fit's parameters are refitted together by Gauss-Newton from the fit (closed-form
    derivatives; the turning-point rows of the fit kept): fixing the parameters at the fit,
    or only projecting their first-order response out, left 10-15 % of the delay in them."""
    from .steps import model_of

    loop = data.loop
    if data.on != "averaged" or loop is None or loop.n_cycles < 2 or data.start != 0:
        return None
    period = float(np.mean(loop.scatter.period))
    if not (math.isfinite(period) and period > 0):
        return None
    v = raw.values
    names = [n for n in raw.var_names if n in _PARAMS]
    if not v["ac"] > 0 or not v["k0"] > 0 or len(names) != len(raw.var_names):
        return None
    nb = loop.x.size
    pr = res.prior
    n_rows = 0 if pr is None else len(pr.names)
    if data.stop is not None or res.w.size != nb or data.xd.size != nb:
        return None
    loop_model = _DelayedLoop(loop, res.w, period)
    meas = {} if pr is None else {"x0": pr.x0, "amplitude": pr.amplitude}
    idx = {n: i for i, n in enumerate(names)}

    def system(th: np.ndarray, tau: float) -> tuple[np.ndarray, np.ndarray]:
        vv = dict(v)
        vv.update(zip(names, th, strict=True))
        r, cols = loop_model.residual(vv, tau)
        J = np.zeros((nb + n_rows, len(names) + 1))
        for n, i in idx.items():
            J[:nb, i] = cols[n]
        J[:nb, -1] = cols["tau"]
        rows = np.zeros(n_rows)
        for j, k in enumerate(pr.names if pr is not None else ()):
            rows[j] = (vv[k] - meas[k]) / pr.sigma * pr.scale  # type: ignore[union-attr]
            if k in idx:
                J[nb + j, idx[k]] = pr.scale / pr.sigma  # type: ignore[union-attr]
        return np.concatenate([r, rows]), J

    with np.errstate(all="ignore"):  # a wild step: not finite, no estimate
        return _solve(system, v, names, idx, nb, period, model_of)


def _solve(system: Any, v: dict[str, float], names: list[str], idx: dict[str, int], nb: int,
           period: float, model_of: Any) -> DelayEstimate | None:  # fmt: skip
    """The Gauss-Newton steps of :func:`estimate`."""
    th0 = np.array([v[n] for n in names])
    th, tau = th0.copy(), 0.0
    e, J = system(th, tau)
    if not (np.all(np.isfinite(e)) and np.all(np.isfinite(J))):
        return None
    # the parameters of this model without a delay (to tell what τ changes)
    th_nd = th0 + np.linalg.lstsq(J[:, :-1], -e, rcond=None)[0]
    bin_t = period / nb
    # two Gauss-Newton steps (the model is nearly linear in τ over a bin: a third moved τ by
    # under 1 % of its error on the test loops); the residual after the second is its
    # linear prediction
    for it in range(2):
        step = np.linalg.lstsq(J, -e, rcond=None)[0]
        step[-1] = float(np.clip(step[-1], -2 * bin_t, 2 * bin_t))
        th, tau = th + step[:-1], tau + float(step[-1])
        if it == 0:
            vv = dict(zip(names, th, strict=True))
            if vv.get("ac", 1.0) <= 0 or vv.get("k0", 1.0) <= 0 or vv.get("amplitude", 1.0) <= 0:
                return None
            e, J = system(th, tau)
            if not (np.all(np.isfinite(e)) and np.all(np.isfinite(J))):
                return None
        else:
            e = e + J @ step
    dof = e.size - J.shape[1]
    if not (abs(tau) < 0.1 * period and dof > 0 and np.all(np.isfinite(J))):
        return None
    try:
        cov = np.linalg.inv(J.T @ J) * (float(e @ e) / dof)
    except np.linalg.LinAlgError:
        return None
    se = math.sqrt(cov[-1, -1]) if cov[-1, -1] > 0 else math.nan
    vc = dict(v)
    for n, i in idx.items():
        vc[n] = v[n] + float(th[i] - th_nd[i])
    return DelayEstimate(
        tau, se, period, (_h0(v), _h0(vc)), (_energy(model_of, v), _energy(model_of, vc))
    )


_PARAMS = ("k0", "ac", "offset", "x0", "amplitude")


def _dh_dac(k0: float, ac: float, y: Any) -> Any:
    """``∂h(y)/∂ac`` of ``h(y) = (k0/ac)(1 - e^{-ac y})`` at fixed ``k0``: ``(k0/ac²)(q e^{-q}
    - (1 - e^{-q}))``, ``q = ac·y``, by its series below q = 1e-3 where the terms cancel."""
    q = ac * np.asarray(y, dtype=float)
    with np.errstate(over="ignore", invalid="ignore"):
        big = q * np.exp(-q) + np.expm1(-q)
    small = q * q * (-0.5 + q * (1.0 / 3.0 + q * (-1.0 / 8.0 + q / 30.0)))
    return k0 / ac**2 * np.where(np.abs(q) < 1e-3, small, big)


def _extreme(grid: np.ndarray, xg: np.ndarray, sign: float) -> float:
    """Phase of the maximum (``sign`` 1) or minimum (-1) of a periodic curve on ``grid``,
    refined by a parabola through its neighbours."""
    i = int(np.argmax(sign * xg))
    a, b, c = xg[i - 1], xg[i], xg[(i + 1) % xg.size]
    den = a - 2 * b + c
    d = 0.5 * (a - c) / den if den != 0 else 0.0
    return float(np.mod(grid[i] + d * (grid[1] - grid[0]), 1.0))


#: phases on which the displacement's turns are searched (:meth:`_DelayedLoop.x_on_grid`)
_GRID = 4096


class _DelayedLoop:
    """The steady Masing loop (:func:`~contactlab.tangential.model.steady_loop_force`'s
    branches in closed form, PHYSICS.md §1) of a force read ``τ`` late, on the averaged
    loop's bins, with its derivatives: the displacement at phase ``φ - τ/T`` from its
    significant harmonics, the branch from that phase (descending from the peak at 0 to the
    valley at 1/2), averaged over each bin's width."""

    SUB = 2  # points across a bin

    def __init__(self, loop: Any, w: np.ndarray, period: float) -> None:
        self.w, self.period, self.F = w, period, loop.F
        n = loop.x.size
        off = (np.arange(self.SUB) + 0.5) / self.SUB - 0.5
        # the bins are uniform in phase: their centres, spread across each bin
        self.sub = ((np.arange(n) + 0.5)[:, None] / n + off[None, :] / n).ravel()
        c = np.fft.rfft(loop.x) / n
        sx = loop.x_std / math.sqrt(max(loop.n_cycles, 1))
        fin = np.isfinite(sx)
        noise = float(np.mean(sx[fin])) / math.sqrt(n) if fin.any() else 0.0
        k = np.arange(c.size)
        # harmonics above 4x the noise and 1e-4 of the largest (a noise-free channel's bins
        # carry tiny harmonics of the binning itself, which ring between the bins), at least
        # 8 bins a period
        floor = max(4 * noise, 1e-4 * float(np.max(np.abs(c[1:])))) if c.size > 1 else 0.0
        keep = (np.abs(c) > floor) & (k > 0) & (k <= n // 8)
        self.c0 = float(c[0].real)
        self.k = k[keep]
        self.c = 2 * c[keep]
        # the branches switch where this displacement turns (not at the bins' nominal phases
        # 0 and 1/2, which are the turn times of the noisy samples)
        grid = np.arange(_GRID) / _GRID
        xg = self.x_on_grid()
        self.turns = (_extreme(grid, xg, 1.0), _extreme(grid, xg, -1.0))

    def x_on_grid(self) -> np.ndarray:
        """x at the phases ``j / _GRID`` (as :meth:`x_and_slope`), by one inverse FFT of the
        kept harmonics (the direct sum over 4096 phases cost 2 ms a window)."""
        X = np.zeros(_GRID // 2 + 1, dtype=complex)
        X[self.k] = self.c * np.exp(-1j * np.pi * self.k / self.F.size) * (_GRID / 2)
        return self.c0 + np.fft.irfft(X, _GRID)

    def x_and_slope(self, phase: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """x and dx/dφ at ``phase`` (bin 0 centred at 0.5/n: a bin's phase is its centre)."""
        z = np.exp(2j * np.pi * np.outer(phase - 0.5 / self.F.size, self.k))
        zc = z @ self.c
        dz = z @ (2j * np.pi * self.k * self.c)
        return self.c0 + zc.real, dz.real

    def x_and_slope_shifted(self, tau: float) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`x_and_slope` at the sub-bin phases ``sub - τ/T`` (uniform: ``(j + ½)/(SUB·n)``
        shifted), by two inverse FFTs of the kept harmonics instead of the direct sum."""
        n = self.F.size
        m = self.SUB * n
        lag = 0.5 / m - tau / self.period - 0.5 / n
        ck = self.c * np.exp(2j * np.pi * self.k * lag) * (m / 2)
        X = np.zeros(m // 2 + 1, dtype=complex)
        X[self.k] = ck
        D = np.zeros(m // 2 + 1, dtype=complex)
        D[self.k] = 2j * np.pi * self.k * ck
        return self.c0 + np.fft.irfft(X, m), np.fft.irfft(D, m)

    def residual(self, v: dict[str, float], tau: float) -> tuple[np.ndarray, dict[str, np.ndarray]]:
        k0, ac, x0, A = v["k0"], v["ac"], v["x0"], v["amplitude"]
        ph = np.mod(self.sub - tau / self.period, 1.0)
        if self.k.size and int(self.k.max()) < self.SUB * self.F.size // 2:
            x, dx = self.x_and_slope_shifted(tau)
        else:
            x, dx = self.x_and_slope(ph)
        raw = x - x0
        u = np.clip(raw, -A, A)
        inside = (raw > -A) & (raw < A)
        pk, vl = self.turns
        sg = np.where(np.mod(ph - pk, 1.0) < np.mod(vl - pk, 1.0), 1.0, -1.0)  # descending
        s = 0.5 * (A - sg * u)
        e, eA = np.exp(-ac * s), math.exp(-ac * A)
        hA = -k0 / ac * math.expm1(-ac * A)
        hs = -k0 / ac * np.expm1(-ac * s)
        f = sg * (hA - 2.0 * hs) + v["offset"]
        ds_dA = 0.5 * (1.0 - sg * np.where(raw >= A, 1.0, np.where(raw <= -A, -1.0, 0.0)))
        stiff = k0 * e * inside  # dF/du
        out = np.empty((7, x.size))
        out[0] = f
        out[1] = (f - v["offset"]) / k0
        out[2] = sg * (_dh_dac(k0, ac, A) - 2.0 * _dh_dac(k0, ac, s))
        out[3] = 1.0
        out[4] = -stiff
        out[5] = sg * (k0 * eA - 2.0 * k0 * e * ds_dA)
        out[6] = stiff * dx * (-1.0 / self.period)
        if self.SUB == 2:
            # the mean over each bin's two points as ``mean(axis=2)`` sums them (from +0.0,
            # the sum's identity), bit for bit, without its strided reduction (95 of a
            # call's ~370 µs)
            o3 = out.reshape(7, -1, 2)
            m = (0.0 + o3[:, :, 0] + o3[:, :, 1]) / 2 * self.w
        else:
            m = out.reshape(7, -1, self.SUB).mean(axis=2) * self.w
        m[0] -= self.F * self.w
        return m[0], dict(zip(("k0", "ac", "offset", "x0", "amplitude", "tau"), m[1:], strict=True))


def _h0(v: dict[str, float]) -> float:
    return v["k0"] / v["ac"] if v["ac"] > 0 else math.nan


def _energy(model_of: Any, v: dict[str, float]) -> float:
    try:
        return float(model_of(v).loop_energy(v["amplitude"]))
    except Exception:  # a corrected ac at or below 0: no model
        return math.nan


def warning(
    est: DelayEstimate | None,
    h0_stderr: float | None,
    energy_stderr: float | None,
    *,
    misfit: float,
    sliding: bool,
    applied: float | None = None,
) -> str | None:
    """The warning about a delay between the channels, or None (see the module docstring for
    when: significant, with an effect on ``h0`` or ``E`` beyond their errors, on a loop the
    model describes)."""
    if est is None or not est.significant or sliding:
        return None
    if math.isfinite(misfit) and misfit > MAX_MISFIT:
        return None
    dh = est.h0[0] - est.h0[1]  # what the delay did to the fitted h0
    de = est.energy[0] - est.energy[1]
    big_h = h0_stderr is not None and math.isfinite(dh) and abs(dh) > h0_stderr
    big_e = energy_stderr is not None and math.isfinite(de) and abs(de) > energy_stderr
    if not (big_h or big_e):
        return None
    ms, se = 1e3 * est.tau, 1e3 * est.stderr
    side = "lags behind" if est.tau > 0 else "leads"
    cause = (
        "a delay in the force channel (filters, amplifier, acquisition skew)"
        if est.tau > 0
        else "viscous (rate-dependent) damping, or a delay in the displacement channel"
    )
    fix = 1e3 * (est.tau + (applied or 0.0))
    rel_h = 100 * dh / est.h0[1] if est.h0[1] else math.nan
    rel_e = 100 * de / est.energy[1] if est.energy[1] else math.nan
    return (
        f"the force {side} the displacement by {abs(ms):.3g} ± {se:.2g} ms "
        f"({abs(est.degrees):.3g}° of the {1 / est.period:.4g} Hz drive; "
        f"{abs(est.tau / est.stderr):.1f}σ): a rate-independent friction loop turns with the "
        f"displacement, so this is {cause}. It moves h0 by {rel_h:+.2g} % and the energy per "
        f"cycle by {rel_e:+.2g} % (corrected: h0 ≈ {est.h0[1]:.4g} N, E ≈ "
        f"{est.energy[1]:.4g} J). If it is a channel delay, correct it with --delay "
        f"{fix:.3g}ms (delay={fix * 1e-3:.3g} in Python)"
    )


def annotate(
    derived: dict[str, tuple[float, float]],
    fit: Any,
    raw: Any,
    res: Any,
    data: Any,
    *,
    sliding: bool,
    misfit: float,
    applied: float | None = None,
) -> list[str]:
    """Estimate the delay of an averaged fit into ``derived["channel_delay"]`` (value,
    stderr; s) and return its warning, if any (:func:`warning`)."""
    est = estimate(raw, res, data)
    if est is None:
        return []
    derived["channel_delay"] = (est.tau, est.stderr)
    if displacement_noise_share(raw, data) > MAX_X_SHARE:
        return []  # the stated error is too small there (module docstring): not warned
    e_se = derived.get("energy_per_cycle", (math.nan, math.nan))[1]
    txt = warning(est, fit.params["h0"].stderr, e_se, misfit=misfit, sliding=sliding,
                  applied=applied)  # fmt: skip
    return [txt] if txt else []


def displacement_noise_share(raw: Any, data: Any) -> float:
    """The displacement noise's share of the averaged bins' force noise, ``mean((k σx)²) /
    (mean(σF²) + mean((k σx)²))`` (``k`` the branch slope, :func:`steps.branch_slope`;
    :func:`steps.loop_noise`); NaN without a spread to estimate it from."""
    from . import steps

    loop = getattr(data, "loop", None)
    if loop is None or loop.n_cycles < 2:
        return math.nan
    vF, vx = steps.loop_noise(loop)
    k = steps.branch_slope(raw.values, data.xpath)
    with np.errstate(over="ignore", invalid="ignore"):
        a, b = k * k * vx, np.asarray(vF, dtype=float)
    a, b = a[np.isfinite(a)], b[np.isfinite(b)]
    if not (a.size and b.size):
        return math.nan
    ex, eF = float(np.mean(a)), float(np.mean(b))
    tot = ex + eF
    return ex / tot if math.isfinite(tot) and tot > 0 else math.nan


def record(res: Any, delay: float | None, dropped: int) -> None:
    """Note a corrected delay in a result: ``delay`` (s, exact as given: stderr 0) and the
    samples dropped at the record's end (start) for want of force data."""
    if delay is None:
        return
    res.derived["delay"] = (float(delay), 0.0)
    res.derived["delay_dropped_samples"] = (float(dropped), 0.0)
    res.meta["delay"] = float(delay)
    res.meta["delay_dropped_samples"] = int(dropped)


def shifted_recording(rec: Any, delay: float) -> tuple[Any, int]:
    """``(recording, dropped)``: a tangential recording with its force read ``delay`` later
    (:func:`shift_force`), every other channel cut to the samples kept."""
    from dataclasses import replace

    t, x, F, dropped = shift_force(rec.t, rec["x"], rec["F"], delay)
    lo = int(np.searchsorted(rec.t, t[0])) if t is not None and t.size else 0
    data = {k: (x if k == "x" else F if k == "F" else np.asarray(a)[lo : lo + x.size])
            for k, a in rec.data.items()}  # fmt: skip
    meta = dict(rec.meta or {}, delay=float(delay), delay_dropped_samples=dropped)
    return replace(rec, t=t, data=data, meta=meta), dropped


def delayed_recording(recording: Any, delay: float) -> Any:
    """A tangential recording in any of the forms the workflows take, with its force read
    ``delay`` seconds later (:func:`shift_force`; ``delay > 0``: the recorded force lags the
    displacement), every other channel cut to the samples kept.

    Parameters
    ----------
    recording : contactlab.io.Recording, dict or tuple
        A Recording with channels ``x`` and ``F`` (its meta gains ``delay`` and
        ``delay_dropped_samples``, as :func:`shifted_recording` sets them), a dict with ``t``,
        ``x``, ``F`` (other keys of the time axis' length cut alike), or ``(t, x, F)``.
    delay : float
        The force channel's delay behind the displacement (s).

    Returns
    -------
    Recording, dict or tuple
        The same form as given.

    Examples
    --------
    >>> import numpy as np
    >>> t = np.arange(400) * 1e-3
    >>> x, F = np.sin(2 * np.pi * t), np.cos(2 * np.pi * t)
    >>> tt, xs, Fs = delayed_recording((t, x, F), 2e-3)
    >>> bool(np.array_equal(Fs, F[2:])), xs.size
    (True, 398)
    """
    if hasattr(recording, "t") and hasattr(recording, "data"):
        return shifted_recording(recording, delay)[0]
    if isinstance(recording, dict):
        t = recording.get("t")
        if t is None or "x" not in recording or "F" not in recording:
            raise InputError("delay= needs the channels 't', 'x' and 'F' of a tangential recording")
        ta = np.asarray(t, dtype=float)
        ts, x, F, _ = shift_force(ta, np.asarray(recording["x"], dtype=float),
                                  np.asarray(recording["F"], dtype=float), delay)  # fmt: skip
        lo = int(np.searchsorted(ta, ts[0])) if ts is not None and ts.size else 0
        out = {k: (np.asarray(v)[lo : lo + x.size] if np.ndim(v) == 1 and len(v) == ta.size
                   else v) for k, v in recording.items()}  # fmt: skip
        out.update(t=ts, x=x, F=F)
        return out
    if isinstance(recording, (tuple, list)) and len(recording) == 3:
        t, x, F = (np.asarray(a, dtype=float) for a in recording)
        ts, xs, Fs, _ = shift_force(t, x, F, delay)
        return ts, xs, Fs
    raise InputError(
        "delay= needs a contactlab.io.Recording, a dict with 't', 'x', 'F' or a tuple (t, x, F)"
    )
