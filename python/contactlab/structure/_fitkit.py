"""What the single- and multi-DOF identifications share: the joint built from fitted values,
derivatives of measured displacements, the initial-state switch and the multi-start loop."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..errors import ContactLabError
from ..fitting import Parameter, least_squares_fit
from .joints import iwan_uniform
from .model import Structure

#: elements of the uniform Iwan joint that ``joint="iwan"`` fits (slip forces spread evenly)
IWAN_ELEMENTS = 20


def add_fitted_joint(
    s: Structure, joint: str, v: dict[str, float], dof: int, dof2: int | None
) -> None:
    """Add the joint of fitted values ``v`` (names as in :mod:`.identify`) to ``s``."""
    if joint == "bouc_wen":
        s.add_joint("bouc_wen", dof, dof2, alpha=v["alpha"], beta=1.0, gamma=v["gamma"],
                    delta=v["delta"], nu=v["nu"])  # fmt: skip
    elif joint == "masing":
        s.add_joint("masing", dof, dof2, h0=v["h0"], ac=v["ac"], scale=v.get("scale", 2.0))
    elif joint == "jenkins":
        s.add_joint("jenkins", dof, dof2, k=v["kj"], fs=v["fs"])
    elif joint == "iwan":
        s.add_joint("iwan", dof, dof2, **iwan_uniform(v["kj"], v["fs"], IWAN_ELEMENTS))
    elif joint == "kelvin_voigt":
        s.add_joint("kelvin_voigt", dof, dof2, k=v["kj"], c=v["cj"])
    elif joint == "normal":
        s.add_joint("normal", dof, dof2, coeffs=[v["a1"], v["a2"], v["a3"]])


def hold_state(
    ps: list[Parameter], estimate: bool, prefixes: tuple[str, ...] = ("x0", "v0")
) -> list[Parameter]:
    """Hold the initial-state parameters at their start unless they are estimated."""
    if not estimate:
        for p in ps:
            if p.name.startswith(prefixes):
                p.vary = False
    return ps


def derivatives(t: np.ndarray, y: np.ndarray, periodic: bool) -> tuple[np.ndarray, np.ndarray]:
    """Velocity and acceleration of a sampled displacement (FFT for whole periods, else a
    Savitzky-Golay cubic or second-order differences)."""
    if periodic:
        n = y.size
        dt = float(t[1] - t[0])
        w = 2j * np.pi * np.fft.rfftfreq(n, dt)
        Y = np.fft.rfft(y)
        return np.fft.irfft(w * Y, n), np.fft.irfft(w * w * Y, n)
    dt = np.diff(t)
    win = 15
    if y.size > 2 * win and np.ptp(dt) <= 1e-6 * dt.mean():
        # Savitzky-Golay (cubic, 15 samples): second differences of raw samples amplify the
        # measurement noise by 1/dt², which biases the regression towards zero stiffness.
        from scipy.signal import savgol_filter

        h = float(dt.mean())
        return (
            savgol_filter(y, win, 3, deriv=1, delta=h),
            savgol_filter(y, win, 3, deriv=2, delta=h),
        )
    v = np.gradient(y, t, edge_order=2)
    return v, np.gradient(v, t, edge_order=2)


def column_derivatives(
    t: np.ndarray, y: np.ndarray, periodic: bool
) -> tuple[np.ndarray, np.ndarray]:
    """:func:`derivatives` of each column of ``y`` (samples × channels)."""
    vs, acc = zip(*(derivatives(t, y[:, i], periodic) for i in range(y.shape[1])), strict=True)
    return np.stack(vs, axis=1), np.stack(acc, axis=1)


def best_start(
    plan: list[tuple[dict[str, Any], list[Parameter]]],
    residual: Any,
    records: list[dict[str, Any]],
    max_nfev: int = 25,
) -> list[Parameter] | None:
    """Fit every start of ``plan`` (``(description, parameters)``) briefly and return the
    parameters of the best one (as a new start: values fitted, bounds kept), None when every
    start failed; each start's short RMS error (or error) is appended to ``records``."""
    best_cost = math.inf
    best: list[Parameter] | None = None
    for st, ps in plan:
        try:
            fr = least_squares_fit(residual, ps, max_nfev=max_nfev, ftol=1e-5, xtol=1e-5,
                                   gtol=1e-8)  # fmt: skip
        except ContactLabError as exc:
            records.append({"start": st, "cost": None, "error": str(exc)})
            continue
        cost = float(np.sqrt(fr.chisqr / max(fr.ndata, 1)))
        records.append({"start": st, "rms_short": cost})
        if cost < best_cost:
            best_cost = cost
            best = [Parameter(p.name, fr.params[p.name].value, vary=p.vary, min=p.min,
                              max=p.max, unit=p.unit, scale=p.scale) for p in ps]  # fmt: skip
    return best
