"""The result of a tangential analysis (:class:`TangentialAnalysis`): the fit, the derived
quantities of *Experimental investigation of tangential contact stiffness and equivalent
damping* (energy per cycle, eq. 17 damping, eqs. 18-19 stiffness) with their errors, the
identifiability verdict, and its JSON form (SI values plus a ``units`` map).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..fitting import FitResult, json_number
from ..masing import Masing
from .preprocess import AveragedLoop, CycleScatter

#: SI units of every reported quantity
UNITS = {
    "h0": "N",
    "ac": "1/m",
    "h0_ac": "N/m",
    "offset": "N",
    "x0": "m",
    "amplitude": "m",
    "delay": "s",  # a known channel delay corrected (contactlab.tangential.lag)
    "channel_delay": "s",  # the delay estimated from the loop
    "energy_per_cycle": "J",
    "energy_per_cycle_numeric": "J",
    "equivalent_damping": "N/m",
    "equivalent_damping_numeric": "N/m",
    "k_local0": "N/m",
    "k_local_amplitude": "N/m",
    "k_global": "N/m",
    "h0_lower_bound": "N",
    "ac_upper_bound": "1/m",
    "peak_force": "N",
    "force_drift": "N/s",
    "displacement_drift": "m/s",
    "loop_area_recorded": "J",
    "h0_plateau": "N",
    "ac_lower_bound": "1/m",
    "k_local0_lower_bound": "N/m",
}
_STICK_UNITS = {
    "stick_duration": "s",
    "breakaway_force": "N",
    "breakaway_force_stderr": "N",
    "velocity_threshold": "m/s",
    "smooth_turn_dwell": "s",
}


@dataclass
class TangentialAnalysis:
    """Result of :func:`analyze_tangential`.

    Attributes
    ----------
    fit : FitResult
        Parameters ``h0``, ``ac``, ``offset`` (and ``x0`` when fitted) with standard errors,
        covariance and correlations, χ², AIC/BIC.
    model : Masing
        The best-fit model (when ``identifiable`` is False it reproduces the loop at this
        amplitude but its ``h0`` and ``ac`` are not individually meaningful).
    amplitude, amplitude_stderr : float
        Displacement amplitude (half the averaged loop's x range) and its error from the
        cycle-to-cycle scatter.
    loop : AveragedLoop or None
        The period-averaged loop (None when the recording has fewer than 2 cycles and the fit
        was on the signal).
    scatter : CycleScatter or None
        Per-cycle amplitude, force range, energy and period.
    identifiable : bool
        Whether ``h0`` and ``ac`` are separately determined.
    identifiability : dict
        The evidence: relative errors, correlation, ``ac·A``, Jacobian condition, message.
    derived : dict
        ``name -> (value, stderr)`` for the derived quantities (see :data:`UNITS`).
    warnings : list of str
        Everything a user should know (also issued as :class:`ContactLabWarning`).
    x, F, F_model, weights : ndarray
        The data the fit saw (averaged bins or the signal's samples), the model at the optimum
        and the residual weights.
    """

    fit: FitResult
    model: Masing
    amplitude: float
    amplitude_stderr: float
    loop: AveragedLoop | None
    scatter: CycleScatter | None
    identifiable: bool
    identifiability: dict[str, Any]
    derived: dict[str, tuple[float, float]]
    warnings: list[str]
    on: str
    history: str
    x: np.ndarray
    F: np.ndarray
    F_model: np.ndarray
    weights: np.ndarray
    t: np.ndarray | None = None
    source: str = "<arrays>"
    meta: dict[str, Any] = field(default_factory=dict)
    regime: dict[str, Any] = field(default_factory=dict)

    @property
    def residual(self) -> np.ndarray:
        """Data minus model (N), unweighted."""
        return self.F - self.F_model

    def value(self, name: str) -> float:
        return self.to_dict()[name]

    def to_dict(self) -> dict[str, Any]:
        """JSON-safe summary: SI values, ``*_stderr``, a ``units`` map and the fit.

        When ``h0`` and ``ac`` are not identifiable their values are None (not arbitrary
        numbers); ``h0_ac`` (always present) carries what the data determine.
        """
        p = self.fit.params
        ident = self.identifiable
        ev = self.identifiability
        h0, h0_se = p["h0"].value, p["h0"].stderr
        if ev.get("h0_source") == "plateau" and "h0_plateau" in self.derived:
            h0, h0_se = self.derived["h0_plateau"]
        ih0 = bool(ev.get("h0", ident))
        iac = bool(ev.get("ac", ident))
        out: dict[str, Any] = {
            "source": self.source,
            "on": self.on,
            "history": self.history,
            "h0": json_number(h0) if ih0 else None,
            "h0_stderr": json_number(h0_se) if ih0 else None,
            "ac": json_number(p["ac"].value) if iac else None,
            "ac_stderr": json_number(p["ac"].stderr) if iac else None,
            "offset": json_number(p["offset"].value),
            "offset_stderr": json_number(p["offset"].stderr),
        }
        if "x0" in p:
            out["x0"] = json_number(p["x0"].value)
            out["x0_stderr"] = json_number(p["x0"].stderr)
        out["force_sign"] = int(self.meta.get("force_sign", 1))
        out["orientation_reason"] = str(self.meta.get("orientation_reason", ""))
        la = self.meta.get("loop_area_recorded")
        if la is not None:
            out["loop_area_recorded"] = json_number(la[0])
            out["loop_area_recorded_stderr"] = json_number(la[1])
        out["amplitude"] = json_number(self.amplitude)
        out["amplitude_stderr"] = json_number(self.amplitude_stderr)
        for k, (v, e) in self.derived.items():
            out[k] = json_number(v)
            out[f"{k}_stderr"] = json_number(e)
        out["identifiable"] = {
            k: (json_number(v) if isinstance(v, float) else v)
            for k, v in self.identifiability.items()
        }
        for k, v in self.regime.items():
            if k == "stick_slip":
                out[k] = dict({kk: json_number(vv) for kk, vv in v.items()}, units=_STICK_UNITS)
            else:
                out[k] = v if isinstance(v, str) else json_number(v)
        out["n_cycles"] = None if self.scatter is None else self.scatter.n_cycles
        out["warnings"] = list(self.warnings)
        out["fit"] = self.fit.to_dict()
        out["units"] = {k: u for k, u in UNITS.items() if k in out}
        for k in list(out["units"]):
            if f"{k}_stderr" in out:
                out["units"][f"{k}_stderr"] = UNITS[k]
        return out

    def _error_text(self, key: str, value: float, stderr: float) -> str:
        """``+/- e unit`` of a derived quantity, or why it has no meaningful error: a bound
        has none, a NaN error is no error, and a channel delay whose error exceeds half the
        loop's period is not identifiable (a delay is only defined within a period)."""
        unit = UNITS.get(key, "")
        if key.endswith(("_lower_bound", "_upper_bound")):
            return f"{unit} (a one-sided bound: no standard error)"
        if not np.isfinite(stderr):
            return f"{unit} (not identifiable: no finite standard error)"
        if key == "channel_delay" and self.scatter is not None:
            period = float(np.median(self.scatter.period))
            if np.isfinite(period) and stderr > 0.5 * period:
                return (
                    f"s (not identifiable: its standard error, {stderr:.3g} s, exceeds half "
                    f"the period, {0.5 * period:.3g} s)"
                )
        return f"+/- {stderr:.3g} {unit}"

    def report(self) -> str:
        """Human-readable summary: fit report, identifiability and derived quantities."""
        lines = [f"Tangential analysis of {self.source} (fit on {self.on}, {self.history})"]
        lines.append(self.fit.report())
        lines.append("[[Identifiability]]")
        lines.append(f"    {self.identifiability['message']}")
        if self.regime:
            lines.append("[[Regime]]")
            lines.append(f"    {self.regime.get('regime_reason', '')}")
        lines.append("[[Derived quantities]]")
        lines.append(
            f"    amplitude = {self.amplitude:.6g} "
            f"{self._error_text('amplitude', self.amplitude, self.amplitude_stderr)}"
        )
        for k, (v, e) in self.derived.items():
            lines.append(f"    {k} = {v:.6g} {self._error_text(k, v, e)}".rstrip())
        if self.warnings:
            lines.append("[[Warnings]]")
            lines += [f"    {w}" for w in self.warnings]
        return "\n".join(lines)
