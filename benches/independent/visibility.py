"""An independent visibility criterion for a hidden effect (eval-only).

For a record, the noise-free effect signal is compared with the base model refitted to it
(nonlinear least squares of the base parameters under the effective variance
sigma_y^2 + (dy/dx)^2 sigma_x^2). Two noncentralities (in units of the noise variance):

* ``lam_detect``: the weighted residual norm left after the base refit (what any test that
  knows the base model could see);
* ``lam_identify``: the smallest residual norm after also projecting off the linearised
  direction of any *other* candidate effect (what a test must see to name this effect rather
  than a look-alike).

An effect is called visible when ``lam_identify >= THRESHOLD``: 95 % power of a chi-square
test with one degree of freedom at a false-alarm rate of 3 % shared by 15 candidates
(z = 3.09), doubled because the diagnosis judges on held-out cycles (half the data).
"""

from __future__ import annotations

import math

import numpy as np
from generator import (
    masing_series,
    series_compliance_force,
    virgin_function,
)
from scipy.optimize import least_squares

THRESHOLD = 2.0 * (3.09 + 1.645) ** 2  # 44.8


def _weights_tangential(x, F, sigma_x, sigma_y, h0, ac):
    dx = np.gradient(x)
    dF = np.gradient(F)
    with np.errstate(divide="ignore", invalid="ignore"):
        slope = np.where(np.abs(dx) > 0, dF / dx, h0 * ac)
    slope = np.clip(np.nan_to_num(slope, nan=h0 * ac), 0.0, h0 * ac)
    return 1.0 / (sigma_y**2 + (slope * sigma_x) ** 2)


def _proj_resid(r, J, w):
    """Weighted residual norm of r after least-squares projection off the columns of J."""
    sw = np.sqrt(w)
    Jw = J * sw[:, None]
    rw = r * sw
    scale = np.linalg.norm(Jw, axis=0)
    scale[scale == 0] = 1.0
    coef, *_ = np.linalg.lstsq(Jw / scale, rw, rcond=None)
    rr = rw - (Jw / scale) @ coef
    return float(rr @ rr)


def tangential_directions(ideal, h0, ac, A, f):
    """Linearised directions of every tangential candidate at its null (sample grid)."""
    t, x, v, a = ideal["t"], ideal["x_true"], ideal["v"], ideal["a"]
    fv = virgin_function("exponential", h0, ac)
    M = masing_series(x, fv)
    w = 2 * np.pi * f
    eps_x = 1e-3 * A
    tm = 0.5 * (t[0] + t[-1])
    s_travel = None
    from generator import last_turning_travel

    s_travel = last_turning_travel(x)
    d_c = 0.1 * A
    xi = np.clip((x - 0.5 * (x.max() + x.min())) / max(0.5 * np.ptp(x), 1e-30), -1, 1)
    dMdt = np.gradient(M, t)
    dirs = {
        "viscous_damping": v[:, None],
        "inertia": a[:, None],
        "parallel_stiffness": x[:, None],
        "series_compliance": (
            (series_compliance_force(x, fv, h0 * ac / 1e-3) - M) / 1e-3 * (1.0 / (h0 * ac))
        )[:, None],
        "force_offset": np.ones_like(t)[:, None],
        "force_drift": t[:, None],
        "displacement_offset": ((masing_series(x - eps_x, fv) - M) / eps_x)[:, None],
        "channel_delay": (-dMdt)[:, None],
        "asymmetry": np.abs(M)[:, None],
        "non_masing_scaling": ((masing_series(x, fv, lam=2.0 - 1e-3) - M) / 1e-3)[:, None],
        "parameter_drift": ((t - tm) * M)[:, None],
        "stribeck": (np.exp(-((v / (0.5 * A * w)) ** 2)) * M)[:, None],
        "position_friction": np.column_stack(
            [
                M * g
                for g in (
                    np.cos(np.pi * xi),
                    np.sin(np.pi * xi),
                    np.cos(2 * np.pi * xi),
                    np.sin(2 * np.pi * xi),
                    xi,
                )
            ]
        ),
        "stick_slip": (h0 * np.sign(v) * (s_travel / d_c) * np.exp(1.0 - s_travel / d_c))[:, None],
        "normal_load": np.column_stack([M * np.cos(2 * w * t), M * np.sin(2 * w * t)]),
    }
    return dirs


def tangential_visibility(ideal, truth, effect, dirs=None):
    """(lam_detect, lam_identify, nearest look-alike) for a tangential record's ideal signals."""
    h0, ac = truth["h0"], truth["ac"]
    x_rep, F = ideal["x_rep"], ideal["F"]
    sx, sy = truth["sigma_x"], truth["sigma_y"]
    fv0 = virgin_function("exponential", h0, ac)
    w = _weights_tangential(x_rep, masing_series(x_rep, fv0), sx, sy, h0, ac)
    sw = np.sqrt(w)

    def resid(p):
        fv = virgin_function("exponential", h0 * math.exp(p[0]), ac * math.exp(p[1]))
        return (F - masing_series(x_rep, fv)) * sw

    sol = least_squares(resid, [0.0, 0.0], x_scale=[0.01, 0.01], diff_step=1e-4, max_nfev=40)
    r = sol.fun / sw
    lam_detect = float(sol.fun @ sol.fun)
    Jb = sol.jac / sw[:, None]
    if dirs is None:
        dirs = tangential_directions(ideal, h0, ac, truth["A"], truth["f"])
    best = (math.inf, None)
    for name, D in dirs.items():
        if name == effect:
            continue
        lam = _proj_resid(r, np.column_stack([Jb, D]), w)
        if lam < best[0]:
            best = (lam, name)
    return (
        lam_detect,
        best[0],
        best[1],
        {"h0": h0 * math.exp(sol.x[0]), "ac": ac * math.exp(sol.x[1])},
    )


# --------------------------------------------------------------------------- normal
def kv_from_rest(t, t_pre, pa, k, c, w):
    """Closed-form Kelvin-Voigt delta for p - p0 = pa sin(w (t - t_pre)), t >= t_pre, from rest."""
    tp = np.clip(t - t_pre, 0.0, None)
    mag = pa / math.hypot(k, c * w)
    phi = math.atan2(c * w, k)
    d = mag * np.sin(w * tp - phi) + mag * math.sin(phi) * np.exp(-k * tp / c)
    return np.where(t >= t_pre, d, 0.0)


def normal_directions(ideal, truth):
    from generator import normal_delta

    t = ideal["t"]
    p0, pa, k, psi, f = truth["p0"], truth["pa"], truth["k"], truth["psi"], truth["f"]
    w = 2 * np.pi * f
    t_pre = truth["t_pre"]
    c = psi * k / (2 * np.pi * w)
    d0 = kv_from_rest(t, t_pre, pa, k, c, w)
    D = pa / k
    e = 1e-3
    d_nl, _ = normal_delta(
        "stiffness_nonlinearity", {"a1": k, "a2": e * k / D, "a3": 0.0}, t, pa, p0, k, psi, w, t_pre
    )
    d_as, _ = normal_delta("asymmetric_branches", {"a": e}, t, pa, p0, k, psi, w, t_pre)
    T = t[-1] - t[0]
    return {
        "stiffness_nonlinearity": ((d_nl - d0) / e)[:, None],
        "creep_drift": (1.0 - np.exp(-t / (0.2 * T)))[:, None],
        "channel_delay": (-np.gradient(d0, t))[:, None],
        "asymmetric_branches": ((d_as - d0) / e)[:, None],
    }


def normal_visibility(ideal, truth, effect, dirs=None):
    """(lam_detect, lam_identify, nearest look-alike) for a normal record's ideal signals."""
    t = ideal["t"]
    pa, k, psi, f = truth["pa"], truth["k"], truth["psi"], truth["f"]
    w = 2 * np.pi * f
    t_pre = truth["t_pre"]
    sx, sy = truth["sigma_x"], truth["sigma_y"]
    wts = np.full(len(t), 1.0 / (sy**2 + (sx / k) ** 2))
    sw = np.sqrt(wts)
    d = ideal["delta"]

    def resid(p):
        kk = k * math.exp(p[0])
        cc = psi * math.exp(p[1]) * kk / (2 * np.pi * w)
        return (d - kv_from_rest(t, t_pre, pa, kk, cc, w)) * sw

    sol = least_squares(resid, [0.0, 0.0], x_scale=[0.01, 0.01], diff_step=1e-5, max_nfev=60)
    r = sol.fun / sw
    lam_detect = float(sol.fun @ sol.fun)
    Jb = sol.jac / sw[:, None]
    if dirs is None:
        dirs = normal_directions(ideal, truth)
    best = (math.inf, None)
    for name, D in dirs.items():
        if name == effect:
            continue
        lam = _proj_resid(r, np.column_stack([Jb, D]), wts)
        if lam < best[0]:
            best = (lam, name)
    return (
        lam_detect,
        best[0],
        best[1],
        {"k": k * math.exp(sol.x[0]), "psi": psi * math.exp(sol.x[1])},
    )
