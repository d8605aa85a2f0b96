"""Hysteresis-loop analysis of a normal-contact recording (Konowalski 2009, eqs. 1-7).

From sampled dynamic pressure p(t) and normal contact displacement δ(t):

1. estimate the excitation frequency (windowed FFT peak, refined by the phase drift of the
   fundamental between the two halves of the record), cut the record into whole cycles that
   start where the fundamental of p crosses its mean upwards (folded from the earliest whole
   bin before it, so that every whole cycle the record holds is used), drop the start-up
   cycles, remove each channel's linear drift over the cycles (folded, it is a sawtooth in
   every cycle) and average the rest on a common phase grid (cycle-to-cycle scatter
   reported); a time axis uniform to the rounding of printed times is not resampled; each channel
   of the averaged cycle keeps the harmonics that stand above the noise the cycle-to-cycle
   scatter gives them (the extremes of a noisy curve overshoot: 1 % noise on δ made ψ of
   5-cycle windows 4 % low);
2. split loading (dp/dt > 0) from unloading with a Savitzky-Golay derivative of the averaged
   cycle and fit each branch with a polynomial p(δ) (degree 4 by default, eq. 1); the centre
   curve is their mean (Table 2 satisfies this to the printed digits);
3. shift δ so the centre curve passes through the origin (δ = 0 at p = 0, the static
   equilibrium under p0) and compute E_d (loop area, ∮ p dδ from the samples), E_pu / E_pd
   (strain energy under the centre curve to the extreme displacement on the loading / relief
   side), ψ by eq. 3 (E_d / E_pu) and eq. 7 (2 E_d / (E_pd + E_pu)), k_tan (eq. 4, slope of the
   centre curve at p = 0), k_sec (eq. 5, 2 pa / Δδ) and k_s(δ) (eq. 6).

All quantities are SI (Pa, m, J/m², Pa/m); :meth:`LoopResult.table2` shows the paper's units.
PHYSICS.md §2 warns that the paper's printed ψ = 0.0887 and k_tan = 1.206 MPa/µm do not
follow from its Table 2 loop; nothing here assumes them.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .. import _core
from .._arrays import as_1d, positive
from .._options import takes_options
from .._physical import check_channel
from ..errors import ContactLabWarning, InputError
from . import paper as _paper
from ._spectral import (  # the loop energy's spectral estimate and its error
    _band_limited,
    _energy_std,
    _harmonics_kept,
)

_UNITS = {
    "E_d": "J/m^2",
    "E_d_poly": "J/m^2",
    "E_pu": "J/m^2",
    "E_pd": "J/m^2",
    "psi": "1",
    "psi_kv": "1",
    "k_tan": "Pa/m",
    "k_sec": "Pa/m",
    "k_s_delta": "Pa/m; ascending powers of delta in m (a1, a2, a3, a4)",
    "poly_load": "Pa; ascending powers of delta in m",
    "poly_unload": "Pa; ascending powers of delta in m",
    "poly_centre": "Pa; ascending powers of delta in m",
    "delta_max": "m",
    "delta_min": "m",
    "delta_offset": "m",
    "cycle_scatter": "m",
    "cycle_scatter_rel": "1",
    "E_d_cycle_std": "J/m^2",
    "p0": "Pa",
    "pa": "Pa",
    "pa_nominal": "Pa",
    "omega": "rad/s",
    "frequency": "Hz",
}


@dataclass
class LoopResult:
    """Result of :func:`analyze_loop`. SI units throughout (see :attr:`units`)."""

    E_d: float
    E_d_poly: float
    E_pu: float
    E_pd: float
    psi: float
    psi_kv: float
    k_tan: float
    k_sec: float
    k_s_delta: list[float]
    poly_load: list[float]
    poly_unload: list[float]
    poly_centre: list[float]
    delta_max: float
    delta_min: float
    delta_offset: float
    p0: float
    pa: float
    omega: float
    frequency: float
    n_cycles: int
    n_discarded: int
    samples_per_cycle: float
    cycle_scatter: float
    cycle_scatter_rel: float
    #: scatter of the cycles' contributions to E_d (√n times its standard error, from the
    #: noise of each harmonic of both channels pooled over neighbouring harmonics, or the
    #: jackknife over the cycles when that reads clearly more), so that
    #: ``E_d_cycle_std / sqrt(n_cycles)`` is E_d's standard error
    E_d_cycle_std: float
    degree: int
    resampled: bool
    #: Averaged cycle: phase time (s from the cycle start), dynamic pressure, displacement
    #: (shifted by ``delta_offset``), its cycle-to-cycle standard deviation, loading mask.
    cycle_t: np.ndarray = field(repr=False)
    cycle_p: np.ndarray = field(repr=False)
    cycle_delta: np.ndarray = field(repr=False)
    cycle_delta_std: np.ndarray = field(repr=False)
    loading: np.ndarray = field(repr=False)
    units: dict[str, str] = field(default_factory=lambda: dict(_UNITS), repr=False)
    #: where p0 came from: "given" (argument, CLI, file-name tag or manifest) or "mean of p"
    p0_source: str = "mean of p"
    #: the nominal dynamic amplitude given (NaN when none); ``pa`` is always measured
    pa_nominal: float = float("nan")

    _SCALARS = (
        "E_d",
        "E_d_poly",
        "E_pu",
        "E_pd",
        "psi",
        "psi_kv",
        "k_tan",
        "k_sec",
        "delta_max",
        "delta_min",
        "delta_offset",
        "p0",
        "pa",
        "omega",
        "frequency",
        "samples_per_cycle",
        "cycle_scatter",
        "cycle_scatter_rel",
        "E_d_cycle_std",
    )

    def to_dict(self, arrays: bool = False) -> dict[str, Any]:
        """JSON-ready dict of the results (SI); ``arrays=True`` adds the averaged cycle."""
        d: dict[str, Any] = {k: float(getattr(self, k)) for k in self._SCALARS}
        for k in ("k_s_delta", "poly_load", "poly_unload", "poly_centre"):
            d[k] = [float(v) for v in getattr(self, k)]
        d["n_cycles"] = int(self.n_cycles)
        d["n_discarded"] = int(self.n_discarded)
        d["degree"] = int(self.degree)
        d["resampled"] = bool(self.resampled)
        d["p0_source"] = self.p0_source
        if np.isfinite(self.pa_nominal):
            d["pa_nominal"] = float(self.pa_nominal)
        d["units"] = dict(self.units)
        if arrays:
            for k in ("cycle_t", "cycle_p", "cycle_delta", "cycle_delta_std"):
                d[k] = getattr(self, k).tolist()
            d["loading"] = self.loading.astype(bool).tolist()
        return d

    def table2(self) -> dict[str, list[float]]:
        """Loop polynomials in the paper's units (p in MPa, δ in µm), like its Table 2."""
        return {
            "load": _paper.loop_poly_to_display(self.poly_load).tolist(),
            "centre": _paper.loop_poly_to_display(self.poly_centre).tolist(),
            "unload": _paper.loop_poly_to_display(self.poly_unload).tolist(),
        }

    def report(self) -> str:
        """Human-readable summary in the paper's units."""
        t2 = self.table2()
        head = "".join(f"{'a' + str(i):>11}" for i in range(self.degree + 1))
        lines = [
            f"Loop analysis: p0 = {self.p0 / 1e6:.4g} MPa, pa = {self.pa / 1e6:.4g} MPa, "
            f"ω = {self.omega:.6g} rad/s ({self.frequency:.6g} Hz)",
            f"cycles averaged: {self.n_cycles} (discarded {self.n_discarded}), "
            f"{self.samples_per_cycle:.6g} samples/cycle, scatter of δ "
            f"{self.cycle_scatter * 1e6:.3g} µm ({100 * self.cycle_scatter_rel:.2g} % of Δδ)",
            f"{'curve':<8}{head}",
        ]
        for name in ("load", "centre", "unload"):
            lines.append(f"{name:<8}" + "".join(f"{v:11.5f}" for v in t2[name]))
        lines += [
            f"E_d = {self.E_d:.5g} J/m² (from the curves: {self.E_d_poly:.5g}), "
            f"E_pu = {self.E_pu:.5g}, E_pd = {self.E_pd:.5g} J/m²",
            f"ψ (eq. 7) = {self.psi:.5g}, ψ_KV (eq. 3) = {self.psi_kv:.5g}",
            f"k_tan = {self.k_tan / 1e12:.5g} MPa/µm, k_sec = {self.k_sec / 1e12:.5g} MPa/µm",
            f"δ_max = {self.delta_max * 1e6:.5g} µm, δ_min = {self.delta_min * 1e6:.5g} µm",
        ]
        return "\n".join(lines)


# --- helpers -------------------------------------------------------------------------------


def _time_vector(t: Any, n: int) -> np.ndarray:
    if np.ndim(t) == 0:
        fs = positive(t, "sampling rate")
        return np.arange(n) / fs
    tv = as_1d(t, "t")
    if tv.size != n:
        raise InputError(f"t has {tv.size} samples but p has {n}")
    d = np.diff(tv)
    if np.any(d <= 0):
        i = int(np.argmax(d <= 0)) + 1
        raise InputError(
            f"t must be strictly increasing, but t[{i}] = {tv[i]} does not exceed "
            f"t[{i - 1}] = {tv[i - 1]}"
        )
    return tv


def _estimate_omega(x: np.ndarray, dt: float) -> float:
    """Angular frequency of the dominant sinusoid in ``x`` (uniform sampling ``dt``)."""
    n = x.size
    y = x - x.mean()
    if not np.any(y):
        raise InputError("p is constant: no periodic excitation to analyse")
    spec = np.abs(np.fft.rfft(y * np.hanning(n)))
    spec[0] = 0.0
    k = int(np.argmax(spec))
    if k == 0 or spec[k] <= 0:
        raise InputError("p shows no periodic excitation")
    kf = float(k)
    if 1 <= k < spec.size - 1:
        a, b, c = np.log(spec[k - 1 : k + 2] + 1e-300)
        den = a - 2 * b + c
        if den < 0:
            kf = k + 0.5 * (a - c) / den
    w = 2 * np.pi * kf / (n * dt)
    # Refine with the phase drift of the fundamental between the two halves (Hann-windowed
    # sums, so the image at -ω leaks little into the phase).
    h = n // 2
    tt = np.arange(n) * dt
    win = np.hanning(h)
    for _ in range(3):
        za = np.sum(win * y[:h] * np.exp(-1j * w * tt[:h]))
        zb = np.sum(win * y[h : 2 * h] * np.exp(-1j * w * tt[h : 2 * h]))
        if za == 0 or zb == 0:
            break
        dphi = float(np.angle(zb / za))
        w_new = w + dphi / (h * dt)
        if not np.isfinite(w_new) or w_new <= 0:
            break
        w = w_new
    return float(w)


def _periodic_extreme(y: np.ndarray, largest: bool) -> float:
    """Extreme of a periodic sampled curve, refined by a parabola through three samples."""
    i = int(np.argmax(y) if largest else np.argmin(y))
    n = y.size
    a, b, c = y[(i - 1) % n], y[i], y[(i + 1) % n]
    den = a - 2 * b + c
    if den == 0 or (largest and den > 0) or (not largest and den < 0):
        return float(b)
    off = 0.5 * (a - c) / den
    if abs(off) > 1:
        return float(b)
    return float(b - 0.25 * (a - c) * off)


def _loop_energy(p: np.ndarray, d: np.ndarray) -> np.ndarray:
    """∮ p dδ over one period of each row (periodic samples), by Parseval: exact for the
    trigonometric interpolants of the samples (no polygon error)."""
    n = p.shape[-1]
    P = np.fft.rfft(p, axis=-1) / n
    D = np.fft.rfft(d, axis=-1) / n
    kmax = (n - 1) // 2  # drop the Nyquist term of even n (no defined derivative)
    k = np.arange(1, kmax + 1)
    prod = np.conj(P[..., 1 : kmax + 1]) * D[..., 1 : kmax + 1]
    return -4 * np.pi * np.sum(k * prod.imag, axis=-1)


def _detrended(X: np.ndarray, roll: int) -> np.ndarray:
    """The folded cycles (rows) of a channel with its linear trend over them removed: the
    slope from the cycle means (a periodic signal has the same mean over every whole
    cycle), the ramp subtracted at each sample's place in the record. ``roll``: bins the
    rows were rolled back by (their first ``roll`` bins were recorded last)."""
    n, bins = X.shape
    if n < 2:
        return X
    c = np.arange(n, dtype=float)
    means = X.mean(axis=1)
    slope = float(np.polyfit(c, means, 1)[0])  # per cycle
    if not (np.isfinite(slope) and slope != 0.0):
        return X
    j = np.arange(bins)
    place = ((j + roll) % bins) / bins  # the bin's place in its cycle as recorded
    ramp = slope * (c[:, None] + (place[None, :] - (bins - 1) / (2 * bins)) - c.mean())
    return X - ramp


def _poly_shift(c: np.ndarray, s: float) -> np.ndarray:
    """Coefficients of ``q(x) = c(x + s)`` (ascending)."""
    out = np.zeros_like(c)
    # Horner with the polynomial (x + s).
    for a in c[::-1]:
        out = np.concatenate(([0.0], out[:-1])) + s * out
        out[0] += a
    return out


def _polyval(c: Any, x: Any) -> Any:
    return np.polynomial.polynomial.polyval(x, np.asarray(c, dtype=float))


def _savgol_derivative_periodic(x: np.ndarray) -> np.ndarray:
    """Savitzky-Golay first derivative (quadratic fit, window ~n/32) of a periodic signal,
    in samples⁻¹: ``Σ k x[i+k] / Σ k²``. Antisymmetric, so for a sampled sine its sign is
    that of the cosine at every sample."""
    n = x.size
    half = max(2, n // 64)
    ks = np.arange(1, half + 1)
    out = np.zeros_like(x)
    for k in ks:
        out += k * (np.roll(x, -k) - np.roll(x, k))
    return out / (2 * np.sum(ks.astype(float) ** 2))


# --- the steps of analyze_loop ---------------------------------------------------------------


def _check_inputs(t: Any, p: Any, delta: Any, degree: Any) -> tuple[np.ndarray, ...]:
    """Step 1: arrays, time vector and degree checked; returns ``(t, p, delta)``."""
    pv = as_1d(p, "p")
    dv = as_1d(delta, "delta")
    if dv.size != pv.size:
        raise InputError(f"p has {pv.size} samples but delta has {dv.size}")
    n = pv.size
    if n < 8:
        raise InputError(f"a recording of {n} samples is too short to hold two cycles")
    tv = _time_vector(t, n)
    if isinstance(degree, bool) or not isinstance(degree, (int, np.integer)) or degree < 1:
        raise InputError(f"degree must be an integer >= 1, got {degree!r}")
    check_channel("p", pv, "Pa", "pressure")
    if not np.ptp(dv) > 0:
        raise InputError(
            f"delta is constant ({float(dv[0]):g} m): the displacement sensor recorded no motion, "
            "so there is no loop to analyse"
        )
    check_channel("delta", dv, "m", "displacement")
    return tv, pv, dv


#: a time axis whose samples lie within this fraction of their own value (plus 1e-6 of a
#: step) of a uniform grid is uniform, its jitter the rounding of times printed to 9 or
#: more significant digits (half a unit of the 9th digit is at most 5e-9 of the value)
_PRINTED_TIME = 5e-9


def _uniform(
    tv: np.ndarray, pv: np.ndarray, dv: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray, float, bool]:
    """Step 2: resample onto a uniform grid (median step) when the sampling is not uniform.

    Uniform also means every sample on the straight line through the first and last (whose
    slope is then the step) within the rounding of a printed time (:data:`_PRINTED_TIME`):
    a time axis written to 10 significant digits (CSV) jitters by up to 1e-5 of a step at
    250 s (1000 samples a cycle of 2π s), which the test on the steps alone (each within
    1e-6 of the median step) took for irregular sampling: the record was interpolated onto
    the median of the rounded steps (0.00628319 s for 0.0062831853 s) and lost its last
    sample, and with it, in a 5-cycle track window, a whole cycle."""
    n = tv.size
    dt_line = float(tv[-1] - tv[0]) / (n - 1)
    off = np.abs(tv - (tv[0] + dt_line * np.arange(n)))
    # never beyond 1 % of a step (times far from 0, as clock readings, round coarsely)
    tol = 1e-6 * dt_line + np.minimum(_PRINTED_TIME * np.abs(tv), 1e-2 * dt_line)
    if dt_line > 0 and bool(np.all(off <= tol)):
        return tv, pv, dv, dt_line, False
    dts = np.diff(tv)
    dt = float(np.median(dts))
    resampled = bool(np.max(np.abs(dts - dt)) > 1e-6 * dt)
    if resampled:
        tu = tv[0] + dt * np.arange(int(np.floor((tv[-1] - tv[0]) / dt)) + 1)
        pv = np.interp(tu, tv, pv)
        dv = np.interp(tu, tv, dv)
        tv = tu
    return tv, pv, dv, dt, resampled


@dataclass(frozen=True)
class _Cycles:
    """Where the whole cycles are: ω, samples per period, first cycle start (samples), bins,
    cycles analysed and discarded."""

    omega: float
    period: float
    start: float
    bins: int
    n_used: int
    discard: int
    #: the folded cycles start this many bins before the fundamental's upward crossing
    #: (rolled back after averaging), so that as many whole cycles fit as the record holds
    roll: int = 0


#: the cycles may drift off the sample grid by this fraction of a cycle over the record and
#: still be folded on it (a phase error of at most 0.0063 rad; the loop changes by its square)
_SNAP_CYCLE = 1e-3


def _discard_count(discard_cycles: Any, n_whole: int) -> int:
    if discard_cycles is None:
        return 1 if n_whole >= 3 else 0
    try:
        discard = int(discard_cycles)
        whole = not isinstance(discard_cycles, bool) and discard == discard_cycles
    except (TypeError, ValueError, OverflowError):
        whole = False
    if not whole:
        raise InputError(f"discard_cycles must be a whole number, got {discard_cycles!r}")
    if discard < 0:
        raise InputError(f"discard_cycles must be >= 0, got {discard}")
    return discard


def _cycles(
    tv: np.ndarray,
    pv: np.ndarray,
    dt: float,
    omega: float | None,
    n_bins: int | None,
    discard_cycles: Any,
) -> _Cycles:
    """Step 3: the excitation frequency and the whole cycles, starting where the fundamental
    of p crosses its mean upwards (the start-up cycles dropped)."""
    n = pv.size
    w = _estimate_omega(pv, dt) if omega is None else positive(omega, "omega")
    period = 2 * np.pi / (w * dt)  # samples per cycle
    if period < 8:
        raise InputError(
            f"only {period:.3g} samples per cycle at ω = {w:.6g} rad/s; at least 8 are needed"
        )
    # Phase of the fundamental: p ≈ mean + A sin(ω t + θ); cycles start where ω t + θ ≡ 0.
    z = np.sum((pv - pv.mean()) * np.exp(-1j * w * (tv - tv[0])))
    theta = float(np.angle(z)) + np.pi / 2
    s0 = ((-theta) % (2 * np.pi)) / (2 * np.pi) * period  # samples from the first sample
    bins = round(period) if n_bins is None else int(n_bins)
    if bins < 8:
        raise InputError(f"n_bins must be >= 8, got {bins}")

    def first_fold(s0: float, period: float) -> tuple[float, int, int]:
        # The folded cycles may start any whole number of bins before the crossing (the
        # averaged cycle is rolled back): the earliest such start fits the most whole
        # cycles. Starting at the crossing itself lost one whenever a record cut at p's
        # upward crossings began a few samples before its fundamental's (every 5-cycle
        # track window: 3 cycles analysed, not 4).
        step = period / bins
        roll = int(np.floor(s0 / step + 1e-9))
        first = max(s0 - roll * step, 0.0)
        n_whole = int(np.floor((n - 1 - first + step) / period + 1e-9))
        return first, roll % bins, n_whole

    first, roll, n_whole = first_fold(s0, period)
    if n_whole < 2:
        raise InputError(
            f"the recording holds fewer than two whole cycles ({max(n_whole, 0)} at "
            f"ω = {w:.6g} rad/s, {period:.4g} samples per cycle)"
        )
    # Snap to the sample grid when the period is an integer number of samples, so that
    # folding needs no interpolation: when the cycles drift off the estimated period by less
    # than 0.05 samples or :data:`_SNAP_CYCLE` of a cycle over the record. ω from 5 cycles
    # with 1 % noise on p is known to ~1e-4 (0.05 samples in 500): at 0.05 samples alone
    # a window of 5 whole cycles folded 4 when the estimate came out long.
    drift_tol = max(0.05, _SNAP_CYCLE * period)
    if n_bins is None and abs(period - round(period)) * n_whole < drift_tol:
        period = float(round(period))
        s0 = float(round(s0)) % period
        first, roll, n_whole = first_fold(s0, period)
    discard = _discard_count(discard_cycles, n_whole)
    n_used = n_whole - discard
    if n_used < 1:
        raise InputError(f"discarding {discard} of {n_whole} whole cycles leaves none to analyse")
    return _Cycles(float(w), float(period), first + discard * period, bins, n_used, discard, roll)


def dynamic_only(p: np.ndarray) -> bool:
    """True when a pressure channel holds only the dynamic part (piezo sensors: its mean is
    within half the dynamic amplitude of zero), so the static pressure p0 must be given."""
    a = float(np.max(np.abs(p))) if p.size else 0.0
    if not (a > 0 and np.isfinite(a)):
        return False
    # on p / max|p|: the mean and the range of values near 1e308 overflowed (found by
    # fuzz/diagnose); the comparison is scale-free, so the answer is the same
    q = p / a
    half_range = 0.5 * float(np.ptp(q))
    return bool(abs(float(np.mean(q))) < 0.5 * half_range)


def _pressure_levels(
    pdyn: np.ndarray, p_mean: float, p0: float | None, pa_nominal: float | None = None
) -> tuple[float, float]:
    """Step 5: ``(p0, pa)``; the joint must stay closed (pa ≤ p0). A given nominal ``pa``
    is compared with the measured amplitude (a warning beyond 10 %)."""
    if p0 is None and abs(p_mean) < 0.5 * 0.5 * float(np.ptp(pdyn)):
        raise InputError(
            f"the pressure channel holds only the dynamic pressure (mean {p_mean:.3g} Pa, "
            f"amplitude {0.5 * float(np.ptp(pdyn)):.3g} Pa): give the static pressure p0 "
            "(analyze_loop(p0=...), --p0 0.5MPa, a file-name tag such as p0-0.5MPa, or the "
            "manifest's p0 column)"
        )
    p0_val = p_mean if p0 is None else float(p0)
    if not np.isfinite(p0_val):
        raise InputError(f"p0 must be finite, got {p0}")
    pa = 0.5 * (_periodic_extreme(pdyn, True) - _periodic_extreme(pdyn, False))
    if not pa > 0:
        raise InputError("the dynamic pressure has no amplitude: p is constant over every cycle")
    if pa > p0_val:
        raise InputError(
            f"pa = {pa:.6g} Pa exceeds p0 = {p0_val:.6g} Pa: the joint would separate "
            "(if p holds only the dynamic pressure, give p0: analyze_loop(p0=...) or --p0)"
        )
    if pa_nominal is not None and abs(pa - pa_nominal) > 0.1 * abs(pa_nominal):
        warnings.warn(
            f"the measured dynamic amplitude pa = {pa:.4g} Pa differs from the nominal "
            f"{pa_nominal:.4g} Pa by {100 * (pa / pa_nominal - 1):+.0f}%",
            ContactLabWarning,
            stacklevel=4,  # helper, analyze_loop, its options wrapper, the caller
        )
    return p0_val, pa


@dataclass(frozen=True)
class _Branches:
    load: np.ndarray  # ascending coefficients of p(δ), δ zeroed
    unload: np.ndarray
    centre: np.ndarray
    shift: float  # δ offset removed
    loading: np.ndarray  # mask of the averaged cycle's loading samples (dp/dt > 0)


def _branches(pdyn: np.ndarray, dm: np.ndarray, degree: int, zero_delta: bool) -> _Branches:
    """Step 6: loading (dp/dt > 0) and unloading polynomials p(δ) of eq. 1, the centre curve
    their mean, and δ shifted so the centre curve passes through the origin."""
    dp = _savgol_derivative_periodic(pdyn)
    load = dp >= 0
    unload = dp <= 0
    if load.sum() < degree + 1 or unload.sum() < degree + 1:
        raise InputError(
            f"a branch of the loop has fewer than degree + 1 = {degree + 1} points; "
            "lower degree or sample more densely"
        )
    m = float(dm.mean())
    u = dm - m
    c_load = np.asarray(_core.poly_fit(u[load], pdyn[load], degree))
    c_unload = np.asarray(_core.poly_fit(u[unload], pdyn[unload], degree))
    c_centre = 0.5 * (c_load + c_unload)
    u_lo, u_hi = float(u.min()), float(u.max())
    r = -m  # undo the centring: keep δ as recorded
    if zero_delta:
        roots = np.asarray(_core.poly_roots_in(c_centre, u_lo, u_hi))
        if roots.size == 0:
            warnings.warn(
                "the centre curve does not cross p = 0 inside the loop; δ is left as recorded",
                ContactLabWarning,
                stacklevel=4,  # helper, analyze_loop, its options wrapper, the caller
            )
        else:
            r = float(roots[np.argmin(np.abs(roots))])
    c_load = _poly_shift(c_load, r)
    c_unload = _poly_shift(c_unload, r)
    return _Branches(c_load, c_unload, 0.5 * (c_load + c_unload), m + r, dp > 0)


@dataclass(frozen=True)
class _Energies:
    E_d: float
    E_d_poly: float
    E_pu: float
    E_pd: float
    d_max: float
    d_min: float


def _energies(pdyn: np.ndarray, dz: np.ndarray, br: _Branches) -> _Energies:
    """Step 7: E_d (loop area from the samples), E_d from the curves, E_pu / E_pd (strain
    energy under the centre curve to the extremes)."""
    d_max = _periodic_extreme(dz, True)
    d_min = _periodic_extreme(dz, False)
    E_d = float(_loop_energy(pdyn, dz))
    ic = np.polynomial.polynomial.polyint(br.centre)
    E_pu = float(_polyval(ic, d_max) - _polyval(ic, 0.0))
    E_pd = float(_polyval(ic, d_min) - _polyval(ic, 0.0))
    diff_int = np.polynomial.polynomial.polyint(br.load - br.unload)
    E_d_poly = float(_polyval(diff_int, d_max) - _polyval(diff_int, d_min))
    if E_pu <= 0 or E_pd <= 0:
        raise InputError(
            "the centre curve does not store positive strain energy on both sides of the "
            "equilibrium; is delta's sign consistent with p (compression positive)?"
        )
    if E_d <= 0:
        warnings.warn(
            f"the loop area is not positive (E_d = {E_d:.3g} J/m²): loading and unloading "
            "may be swapped or the loop is dominated by noise",
            ContactLabWarning,
            stacklevel=4,  # helper, analyze_loop, its options wrapper, the caller
        )
    return _Energies(E_d, E_d_poly, E_pu, E_pd, d_max, d_min)


def _stiffness(
    br: _Branches, dz: np.ndarray, en: _Energies, pa: float, zero_delta: bool
) -> tuple[float, float, np.ndarray]:
    """Step 8: k_tan (eq. 4, slope of the centre curve at p = 0), k_sec (eq. 5) and the
    coefficients of k_s(δ) (eq. 6), warning when k_s is not positive over the loop."""
    p_zero_at = 0.0
    if not zero_delta:
        rr = np.asarray(_core.poly_roots_in(br.centre, float(dz.min()), float(dz.max())))
        if rr.size:
            p_zero_at = float(rr[np.argmin(np.abs(rr))])
    k_tan = float(_polyval(np.polynomial.polynomial.polyder(br.centre), p_zero_at))
    k_sec = 2 * pa / (en.d_max - en.d_min)
    k_s = br.centre[1:].copy()
    kmin, kat = _core.poly_min_on(np.ascontiguousarray(k_s), en.d_min, en.d_max)
    if kmin <= 0:
        warnings.warn(
            f"k_s(δ) is not positive over the loop's range (k_s = {kmin:.3g} Pa/m at "
            f"δ = {kat:.3g} m); a nonlinear model built on it is invalid there",
            ContactLabWarning,
            stacklevel=4,  # helper, analyze_loop, its options wrapper, the caller
        )
    return k_tan, k_sec, k_s


# --- main entry point ----------------------------------------------------------------------


def _folded(v: np.ndarray, cyc: _Cycles) -> np.ndarray:
    """Step 4: the whole cycles of one channel folded onto the phase grid, ``(cycles, bins)``,
    each starting at the fundamental's upward crossing (as the averaged cycle reports), with
    a slow drift removed (step 4a)."""
    n_used, bins = cyc.n_used, cyc.bins
    V = np.asarray(_core.fold_cycles(v, cyc.start, cyc.period, n_used, bins)).reshape(n_used, bins)
    V = np.roll(V, -cyc.roll, axis=1)
    # step 4a: a slow drift of either channel (sensor offsets creeping) is no part of the
    # closed loop; folded, it is a sawtooth in every cycle: 2e-10 m/s on δ (0.2 % of its
    # range a cycle) made ψ 0.15 % high, E_d 0.09 %
    return _detrended(V, cyc.roll)


def _averaged_cycle(
    P: np.ndarray, D: np.ndarray, p_mean: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
    """Step 4b: the averaged cycle ``(p − p_mean, δ)`` band-limited to its harmonics above
    the noise, the cycle-to-cycle scatter of δ per bin and the standard deviation of E_d.

    The harmonics kept are those above the noise estimated from the cycle-to-cycle scatter.
    The loop's extremes, curves and area are taken from them: the largest of the noisy
    samples near a turning point overshoots it (by ~1 % of the range of δ at 1 % noise on 4
    cycles of 1000 samples, which made ψ 4 % low), and the noise of the two channels at the
    harmonics the loop does not hold only scatters E_d.
    """
    n_used, bins = P.shape
    Ps = np.fft.rfft(P, axis=1) / bins
    Ds = np.fft.rfft(D, axis=1) / bins
    kp, kd = _harmonics_kept(Ps, bins), _harmonics_kept(Ds, bins)
    ps = _band_limited(Ps.mean(axis=0), kp, bins) - p_mean
    ds = _band_limited(Ds.mean(axis=0), kd, bins)
    if n_used > 1:
        dstd = D.std(axis=0, ddof=1)
        e_std = _energy_std(Ps, Ds, min(kp, kd))
    else:
        dstd = np.zeros(bins)
        e_std = 0.0
    return ps, ds, dstd, e_std


@takes_options
def analyze_loop(
    t: Any,
    p: Any,
    delta: Any,
    *,
    degree: int = 4,
    omega: float | None = None,
    discard_cycles: int | None = None,
    p0: float | None = None,
    pa: float | None = None,
    zero_delta: bool = True,
    n_bins: int | None = None,
) -> LoopResult:
    """Analyse the hysteresis loop of a normal-contact recording (Konowalski 2009, eqs. 1-7).

    Parameters
    ----------
    t : array_like or float
        Sample times in s (strictly increasing), or the sampling rate in Hz.
    p : array_like
        Contact pressure in Pa: the total pressure p0 + p_dyn(t) (then ``p0`` defaults to its
        mean) or the dynamic part only (then pass ``p0``). Only p minus its cycle mean enters
        the loop.
    delta : array_like
        Normal contact displacement in m (zeroed at the static state under p0).
    degree : int, default 4
        Degree of the loading/unloading/centre polynomials p(δ) (eq. 1 uses 4).
    omega : float, optional
        Angular excitation frequency in rad/s; estimated from ``p`` when omitted.
    discard_cycles : int, optional
        Whole cycles dropped at the start (start-up transient). Default: 1 when the record
        holds at least 3 whole cycles, else 0.
    p0 : float, optional
        Mean (static) pressure in Pa; default: the mean of ``p`` over the analysed cycles.
        Required when ``p`` holds only the dynamic pressure (piezo sensors: mean ≈ 0).
    pa : float, optional
        Nominal dynamic amplitude in Pa: reported as ``pa_nominal`` and compared with the
        measured ``pa`` (a warning when they differ by more than 10 %).
    zero_delta : bool, default True
        Shift δ so the centre curve passes through the origin (δ = 0 at p = 0); the shift is
        reported as ``delta_offset``.
    n_bins : int, optional
        Phase points per averaged cycle (default: samples per period, rounded).

    Returns
    -------
    LoopResult

    Raises
    ------
    InputError
        Mismatched lengths, NaN/inf (index named), non-increasing time, fewer than two whole
        cycles, pa > p0 (the joint would separate), a branch too short for ``degree``.

    Examples
    --------
    >>> from contactlab.normal import analyze_loop
    >>> from contactlab.synthetic.normal import synthetic_recording
    >>> t, p, d = synthetic_recording(model="table2", n_cycles=4, noise=None)
    >>> res = analyze_loop(t, p, d)
    >>> [round(a, 3) for a in res.table2()["unload"]]
    [-0.015, 1.32, 1.705, 3.562, 4.176]
    """
    tv, pv, dv = _check_inputs(t, p, delta, degree)
    degree = int(degree)
    tv, pv, dv, dt, resampled = _uniform(tv, pv, dv)
    cyc = _cycles(tv, pv, dt, omega, n_bins, discard_cycles)
    n_used, bins = cyc.n_used, cyc.bins
    P, D = _folded(pv, cyc), _folded(dv, cyc)
    pm = P.mean(axis=0)
    dm = D.mean(axis=0)
    p_mean = float(pm.mean())
    pdyn = pm - p_mean
    if pa is not None and not (np.isfinite(pa) and pa > 0):
        raise InputError(f"pa must be a finite pressure > 0, got {pa!r}")
    ps, ds, dstd, e_std = _averaged_cycle(P, D, p_mean)
    p0_val, pa_meas = _pressure_levels(ps, p_mean, p0, pa)
    br = _branches(ps, ds, degree, zero_delta)
    dz = dm - br.shift
    en = _energies(ps, ds - br.shift, br)
    k_tan, k_sec, k_s = _stiffness(br, ds - br.shift, en, pa_meas, zero_delta)
    w = cyc.omega
    scatter = float(np.sqrt(np.mean(dstd**2)))
    return LoopResult(
        E_d=en.E_d,
        E_d_poly=en.E_d_poly,
        E_pu=en.E_pu,
        E_pd=en.E_pd,
        psi=2 * en.E_d / (en.E_pd + en.E_pu),
        psi_kv=en.E_d / en.E_pu,
        k_tan=k_tan,
        k_sec=k_sec,
        k_s_delta=k_s.tolist(),
        poly_load=br.load.tolist(),
        poly_unload=br.unload.tolist(),
        poly_centre=br.centre.tolist(),
        delta_max=en.d_max,
        delta_min=en.d_min,
        delta_offset=float(br.shift),
        p0=p0_val,
        pa=pa_meas,
        omega=w,
        frequency=w / (2 * np.pi),
        n_cycles=n_used,
        n_discarded=cyc.discard,
        samples_per_cycle=float(cyc.period),
        cycle_scatter=scatter,
        cycle_scatter_rel=float(scatter / (en.d_max - en.d_min)),
        E_d_cycle_std=e_std,
        degree=degree,
        resampled=resampled,
        cycle_t=np.arange(bins) * (2 * np.pi / w / bins),
        cycle_p=pdyn,
        cycle_delta=dz,
        cycle_delta_std=dstd,
        loading=br.loading,
        p0_source="mean of p" if p0 is None else "given",
        pa_nominal=float("nan") if pa is None else float(pa),
    )
