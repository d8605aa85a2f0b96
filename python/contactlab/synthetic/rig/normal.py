"""The rig's normal joint: ramped tone blocks of pressure from the static preload on a
Kelvin-Voigt joint with the normal effects, solved for δ, seen through a pressure cell.

Part of the rig simulator :mod:`contactlab.synthetic.rig`.
"""

from __future__ import annotations

import math

import numpy as np
from scipy import integrate, signal

from contactlab.errors import InputError

from .chain import _filter


def _normal(ti, eff, f, k, psi, p0, pa, frequencies, cycles, ramp_cycles, cell, dt):
    """The normal joint on the internal grid: ``(pressure at the cell, δ, base truth)``."""
    # tone blocks, each an integer number of cycles starting at phase 0 (continuous p)
    edges = [0.0]
    for r in frequencies:
        edges.append(edges[-1] + cycles / (f * r))
    edges_a = np.array(edges)
    rates = np.array([f * r for r in frequencies])
    w_ref = 2 * math.pi * f
    c = psi * k / (2 * math.pi * w_ref)
    eta = eff.get("hysteretic_damping", {}).get("eta", 0.0)
    a2 = eff.get("stiffness_nonlinearity", {}).get("a2", 0.0)
    a3 = eff.get("stiffness_nonlinearity", {}).get("a3", 0.0)
    asym = eff.get("asymmetric_branches", {}).get("a", 0.0)
    tr = ramp_cycles / f

    def block(tt: float) -> int:
        return int(min(np.searchsorted(edges_a, tt, side="right") - 1, len(rates) - 1))

    def pdyn(tt: float) -> float:
        b = block(tt)
        r = 1.0 if tr <= 0 else 0.5 - 0.5 * math.cos(math.pi * min(tt / tr, 1.0))
        return pa * r * math.sin(2 * math.pi * rates[b] * (tt - edges_a[b]))

    def rhs(tt: float, y: np.ndarray) -> np.ndarray:
        dlt = y[0]
        b = block(tt)
        ce = c + eta * k / (2 * math.pi * rates[b])
        R = pdyn(tt) - (k + a2 * dlt + a3 * dlt**2) * dlt
        return np.array([R / (ce * (1 + asym * math.copysign(1.0, R)))])

    t_end = float(ti[-1])
    p_dyn = _pdyn_vec(ti, edges_a, rates, pa, tr)
    if a2 == 0.0 and a3 == 0.0 and asym == 0.0:
        delta = _kelvin_voigt_blocks(ti, p_dyn, k, c, eta, edges_a, rates)
    else:
        sol = integrate.solve_ivp(
            rhs,
            (0.0, t_end),
            [0.0],
            method="Radau",
            dense_output=True,
            rtol=1e-8,
            atol=1e-9 * pa / k,
            max_step=1 / (40 * max(rates)),
        )
        if not sol.success:
            raise InputError(
                f"rig_recording: the normal joint's integration failed ({sol.message})"
            )
        delta = sol.sol(ti)[0]

    if "creep_drift" in eff:
        pc = eff["creep_drift"]
        tc = pc["tau_c"] if np.isfinite(pc["tau_c"]) else 0.25 * t_end
        delta = delta + pc["D"] * -np.expm1(-ti / tc)
    # pressure channel: the cell sees the applied pressure (dynamic part, offset p0 added)
    p_meas = p0 + _filter(cell, dt, p_dyn)
    meta = {
        "k": k,
        "psi": psi,
        "c": c,
        "p0": p0,
        "pa": pa,
        "f": f,
        "frequencies": list(frequencies),
        "displacement_amplitude": float(np.max(np.abs(delta))) or pa / k,
        "force_amplitude": pa,
    }
    return p_meas, delta, meta


def _kelvin_voigt_blocks(ti, p, k, c, eta, edges, rates):
    """k δ + c_b δ' = p exactly for piecewise-linear p, c_b = c + η k / ω_b in each block."""
    h = float(ti[1] - ti[0])
    delta = np.zeros_like(p)
    blk = np.clip(np.searchsorted(edges, ti, side="right") - 1, 0, len(rates) - 1)
    start = 0
    for b in range(len(rates)):
        idx = np.flatnonzero(blk == b)
        if idx.size == 0:
            continue
        stop = int(idx[-1]) + 1
        cb = c + eta * k / (2 * math.pi * rates[b])
        tau = cb / k
        E = math.exp(-h / tau)
        g = tau * (1 - E) / h
        bb = np.array([(1 - g) / k, (g - E) / k])
        aa = np.array([1.0, -E])
        i0 = max(start - 1, 0)
        zi = signal.lfiltic(bb, aa, y=[delta[i0]], x=[p[i0]])
        delta[i0 + 1 : stop], _ = signal.lfilter(bb, aa, p[i0 + 1 : stop], zi=zi)
        start = stop
    return delta


def _pdyn_vec(ti, edges_a, rates, pa, tr):
    b = np.clip(np.searchsorted(edges_a, ti, side="right") - 1, 0, len(rates) - 1)
    r = np.ones_like(ti) if tr <= 0 else 0.5 - 0.5 * np.cos(math.pi * np.clip(ti / tr, 0, 1))
    return pa * r * np.sin(2 * math.pi * rates[b] * (ti - edges_a[b]))
