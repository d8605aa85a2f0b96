"""Model against measurement, as Konowalski (2009) Figs. 9-12 show it.

:func:`compare` drives each model with the measured pressure and reports, over the whole
cycles after the start-up, the RMS and peak errors of δ and δ' and the error of the loop area
(energy dissipated per cycle). The measured velocity comes from a Savitzky-Golay derivative
(default) or a band-limited spectral derivative, never a plain difference, because the
displacement sensor's noise would dominate it.

The paper's four views (Figs. 9-12) are drawn by :mod:`contactlab.report.normal`.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .._arrays import as_1d
from .._moved import forward
from ..errors import InputError


def measured_velocity(
    t: np.ndarray,
    delta: np.ndarray,
    *,
    method: str = "savgol",
    window: int | None = None,
    omega: float | None = None,
    harmonics: int = 10,
) -> np.ndarray:
    """Noise-robust dδ/dt of a uniformly sampled displacement.

    ``method="savgol"``: Savitzky-Golay (cubic) derivative over ``window`` samples (default:
    about 1/8 of a period when ``omega`` is known, else 15). ``method="spectral"``: FFT
    derivative keeping the first ``harmonics`` harmonics of ``omega``.
    """
    from .._filters import savgol_filter

    n = delta.size
    dt = float(np.median(np.diff(t)))
    if method == "savgol":
        if window is None:
            spc = 2 * np.pi / (omega * dt) if omega else 240.0
            window = max(7, int(spc / 8) | 1)
        window = int(window)
        if window % 2 == 0:
            window += 1
        if window > n:
            window = n if n % 2 else n - 1
        if window < 5:
            raise InputError("too few samples for a Savitzky-Golay derivative")
        return savgol_filter(delta, window, 3, deriv=1, delta=dt, mode="interp")
    if method == "spectral":
        if not omega:
            raise InputError("the spectral derivative needs omega")
        f = np.fft.rfftfreq(n, dt) * 2 * np.pi
        D = np.fft.rfft(delta - delta.mean())
        D[f > harmonics * omega * (1 + 1e-9)] = 0
        return np.fft.irfft(1j * f * D, n)
    raise InputError(f"method must be 'savgol' or 'spectral', got {method!r}")


def _loop_area_per_cycle(p: np.ndarray, d: np.ndarray, n_cycles: float) -> float:
    """∮ p dδ per cycle over whole cycles of samples (closed polygon: last joins first)."""
    return float(np.sum(0.5 * (p + np.roll(p, -1)) * (np.roll(d, -1) - d)) / n_cycles)


@dataclass
class Comparison:
    """Result of :func:`compare`: signals over the compared window and error metrics.

    ``metrics[name]`` holds, in SI: ``rms_delta``, ``peak_delta`` (m), ``rms_velocity``,
    ``peak_velocity`` (m/s), the same divided by the measured peak-to-peak value
    (``*_rel``), ``loop_area_model``, ``loop_area_measured`` (J/m² per cycle) and
    ``loop_area_error`` (relative).
    """

    t: np.ndarray
    p: np.ndarray
    delta: np.ndarray
    velocity: np.ndarray
    models: dict[str, dict[str, np.ndarray]]
    metrics: dict[str, dict[str, float]]
    omega: float
    n_cycles: float
    info: dict[str, Any] = field(default_factory=dict)

    def to_dict(self) -> dict[str, Any]:
        return {
            "metrics": {k: dict(v) for k, v in self.metrics.items()},
            "omega": self.omega,
            "n_cycles": self.n_cycles,
            **self.info,
        }

    def table(self) -> str:
        """Error metrics per model (µm, µm/s, % of the measured loop area)."""
        w = max(12, *(len(n) + 2 for n in self.metrics))
        head = (
            f"{'model':<{w}}{'RMS δ [µm]':>12}{'peak δ':>10}{'RMS δ′ [µm/s]':>15}"
            f"{'peak δ′':>10}{'ΔE_d':>9}"
        )
        rows = [head]
        for name, m in self.metrics.items():
            rows.append(
                f"{name:<{w}}{m['rms_delta'] * 1e6:12.4g}{m['peak_delta'] * 1e6:10.4g}"
                f"{m['rms_velocity'] * 1e6:15.4g}{m['peak_velocity'] * 1e6:10.4g}"
                f"{100 * m['loop_area_error']:8.3g}%"
            )
        return "\n".join(rows)


def _models(model: Any) -> dict[str, Any]:
    if isinstance(model, Mapping):
        out = dict(model)
    elif isinstance(model, (list, tuple)):
        out = {}
        for m in model:
            name = type(m).__name__
            out[name if name not in out else f"{name}{len(out)}"] = m
    else:
        out = {type(model).__name__: model}
    if not out:
        raise InputError("no model given")
    for name, m in out.items():
        if not hasattr(m, "simulate") or not hasattr(m, "omega"):
            raise InputError(f"model {name!r} has no simulate() / omega")
    return out


def compare(
    t: Any,
    p: Any,
    delta: Any,
    model: Any,
    *,
    p0: float | None = None,
    discard_cycles: int = 1,
    velocity: str = "savgol",
    window: int | None = None,
    rtol: float = 1e-8,
) -> Comparison:
    """Drive ``model`` (one model, a list, or a ``{name: model}`` dict) with the measured
    pressure and compare its δ(t), δ'(t) and loop with the measurement.

    Parameters
    ----------
    t, p, delta : array_like
        Measurement: times (s, uniform), pressure (Pa, total or dynamic), displacement (m).
    p0 : float, optional
        Static pressure to subtract from ``p``; default: the model's ``p0`` if set, else the
        mean of ``p``.
    discard_cycles : int
        Whole cycles (of the first model's ω) left out of the metrics at the start.
    velocity : {"savgol", "spectral"}
        How the measured δ' is obtained (see :func:`measured_velocity`).

    Examples
    --------
    >>> from contactlab.normal import KelvinVoigt, compare
    >>> from contactlab.synthetic.normal import synthetic_recording
    >>> t, p, d = synthetic_recording(model="linear", n_cycles=6, seed=0)
    >>> c = compare(t, p, d, KelvinVoigt(1.206e12, 0.0887, 1.0))
    >>> c.metrics["KelvinVoigt"]["rms_delta_rel"] < 0.01
    True
    """
    tv = as_1d(t, "t")
    pv = as_1d(p, "p")
    dv = as_1d(delta, "delta")
    if not tv.size == pv.size == dv.size:
        raise InputError(f"t, p and delta have {tv.size}, {pv.size} and {dv.size} samples")
    if tv.size < 16:
        raise InputError("too few samples to compare")
    models = _models(model)
    first = next(iter(models.values()))
    omega = float(first.omega)
    period = 2 * np.pi / omega
    span = tv[-1] - tv[0]
    if span + float(np.median(np.diff(tv))) < 2 * period * (1 - 1e-6):
        raise InputError(f"the recording spans {span / period:.3g} cycles; at least two are needed")
    if int(discard_cycles) != discard_cycles or discard_cycles < 0:
        raise InputError(f"discard_cycles must be a whole number >= 0, got {discard_cycles!r}")
    dt = float(np.median(np.diff(tv)))
    t_start = tv[0] + int(discard_cycles) * period
    # A cycle of samples ends one sample before the next cycle starts.
    n_cyc = int(np.floor((tv[-1] + dt - t_start) / period + 1e-6))
    if n_cyc < 1:
        raise InputError("no whole cycle is left after discard_cycles")
    eps = 1e-6 * dt
    win = (tv >= t_start - eps) & (tv < t_start + n_cyc * period - eps)
    v_meas = measured_velocity(tv, dv, method=velocity, window=window, omega=omega)

    sims: dict[str, dict[str, np.ndarray]] = {}
    metrics: dict[str, dict[str, float]] = {}
    dpp = float(np.ptp(dv[win]))
    vpp = float(np.ptp(v_meas[win]))
    base_default = float(np.mean(pv[win])) if p0 is None else float(p0)
    for name, m in models.items():
        base = base_default if (p0 is not None or getattr(m, "p0", None) is None) else m.p0
        res = m.simulate(tv, pv, p0=base, rtol=rtol)
        if not res.success:
            raise InputError(f"model {name!r} could not be simulated: {res.message}")
        d_m, v_m = res.delta, res.velocity
        sims[name] = {"delta": d_m, "velocity": v_m}
        ed = d_m[win] - dv[win]
        ev = v_m[win] - v_meas[win]
        pd = pv[win] - base
        a_meas = _loop_area_per_cycle(pd, dv[win], n_cyc)
        a_mod = _loop_area_per_cycle(pd, d_m[win], n_cyc)
        metrics[name] = {
            "rms_delta": float(np.sqrt(np.mean(ed**2))),
            "peak_delta": float(np.max(np.abs(ed))),
            "rms_velocity": float(np.sqrt(np.mean(ev**2))),
            "peak_velocity": float(np.max(np.abs(ev))),
            "rms_delta_rel": float(np.sqrt(np.mean(ed**2)) / dpp) if dpp else float("nan"),
            "peak_delta_rel": float(np.max(np.abs(ed)) / dpp) if dpp else float("nan"),
            "rms_velocity_rel": float(np.sqrt(np.mean(ev**2)) / vpp) if vpp else float("nan"),
            "peak_velocity_rel": float(np.max(np.abs(ev)) / vpp) if vpp else float("nan"),
            "loop_area_model": a_mod,
            "loop_area_measured": a_meas,
            "loop_area_error": (a_mod - a_meas) / a_meas if a_meas else float("nan"),
        }
    return Comparison(
        t=tv,
        p=pv - base_default,
        delta=dv,
        velocity=v_meas,
        models=sims,
        metrics=metrics,
        omega=omega,
        n_cycles=float(n_cyc),
        info={"t_start": float(t_start), "t_end": float(t_start + n_cyc * period)},
    )


# --- plots -----------------------------------------------------------------------------------


# moved to the report layer (issue 32): the old names warn and forward
__getattr__ = forward(
    __name__,
    {
        "plot_comparison": "contactlab.report.normal",
        "plot_displacement": "contactlab.report.normal",
        "plot_loops": "contactlab.report.normal",
        "plot_phase_portrait": "contactlab.report.normal",
        "plot_velocity": "contactlab.report.normal",
    },
)
