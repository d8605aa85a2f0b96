"""Starting values of a structure identification (:func:`contactlab.structure.identify`).

The equation-error fit of the linear model to the record (:func:`equation_error`, derivatives
by finite differences), which also gives the force the joint must supply; where its stiffness
comes out at or below zero (a short or slow record), the linear model of a grid of natural
frequencies and damping ratios that best matches the output (:func:`linear_grid_start`); and
the joint's starts on them (a plan of ``(start, linear model, joint start)``).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np

from ..errors import ContactLabError, InputError
from ..fitting import Parameter
from .fitkit import derivatives
from .model import Structure

__all__ = ["equation_error", "linear_grid_start"]


def equation_error(
    t: np.ndarray,
    u: np.ndarray,
    y: np.ndarray,
    excitation: str = "force",
    mass: float | None = None,
    *,
    periodic: bool = False,
) -> dict[str, Any]:
    """Linear equation-error fit and the reconstructed joint force.

    ``force``: ``u ≈ m x'' + c x' + k x``; ``base`` (``u`` = base displacement, ``y`` = mass
    displacement): ``−m x'' ≈ c (x' − u') + k (x − u)``, ``m`` required. Returns ``m``, ``c``,
    ``k`` and ``joint_force = rhs − m x'' − c x' − k x`` (what the joint must supply if the
    linear part were exactly this).
    """
    xd, xdd = derivatives(t, y, periodic)
    if excitation == "force":
        cols = [xdd, xd, y]
        rhs = u.copy()
        if mass is not None:
            rhs = rhs - mass * xdd
            cols = [xd, y]
        A = np.stack(cols, axis=1)
        coef, *_ = np.linalg.lstsq(A, rhs, rcond=None)
        m, c, k = coef if mass is None else (mass, coef[0], coef[1])
        jf = u - m * xdd - c * xd - k * y
    else:
        if mass is None:
            raise InputError("base excitation needs the mass (mass=...) for the equation error")
        ud, _ = derivatives(t, u, periodic)
        A = np.stack([xd - ud, y - u], axis=1)
        coef, *_ = np.linalg.lstsq(A, -mass * xdd, rcond=None)
        m, (c, k) = mass, coef
        jf = -m * xdd - c * (xd - ud) - k * (y - u)
    # The same with a Coulomb term fs·sign(x') (joint to ground): starting values for the
    # friction joints (a linear fit lets the stiffness absorb the friction force).
    sgn = np.sign(xd)
    if excitation == "force":
        rhs_c, cols_c = u - m * xdd, [xd, y, sgn]
    else:
        ud, _ = derivatives(t, u, periodic)
        rhs_c, cols_c = -m * xdd, [xd - ud, y - u, sgn]
    cc, *_ = np.linalg.lstsq(np.stack(cols_c, axis=1), rhs_c, rcond=None)
    return {
        "m": float(m),
        "c": float(c),
        "k": float(k),
        "joint_force": jf,
        "coulomb": {"c": float(cc[0]), "k": float(cc[1]), "fs": float(cc[2])},
    }


def linear_grid_start(
    t: np.ndarray,
    u: np.ndarray,
    y: np.ndarray,
    excitation: str,
    mass: float | None,
    *,
    n_freq: int = 24,
    zetas: tuple[float, ...] = (0.01, 0.05, 0.2, 0.7),
    keep: int = 3,
) -> list[dict[str, Any]]:
    """The linear SDOF model (``m``, ``c``, ``k``) of least output error over a grid of
    natural frequencies (geometric, from one cycle per record to a sixth of the sampling
    rate) and damping ratios: starting values when the equation error fails.

    Base excitation: the response depends on ``k/m`` and ``c/m`` only (``m`` given).
    Force excitation: the response of the unit-stiffness model is scaled by its least-squares
    factor ``1/k`` (``m = k/ω²``; with a given mass, ``k = m ω²``). Returns the best ``keep``
    models at distinct frequencies (at least a factor 1.5 apart), best first, each with
    ``grid_f`` [Hz] and ``grid_rms`` (its output error) [m]; empty when none has a positive
    scale.
    """
    dt = float(np.median(np.diff(t)))
    f_lo = 1.0 / max(float(t[-1] - t[0]), dt)
    f_hi = 1.0 / (6.0 * dt)
    if not f_hi > f_lo:
        return []
    found: list[tuple[float, float, float, float, float]] = []  # rms, f, m, c, k
    x0 = [float(y[0])] if excitation == "base" else None
    for f in np.geomspace(f_lo, f_hi, n_freq):
        w = 2 * np.pi * f
        for z in zetas:
            if excitation == "base":
                m = float(mass)  # type: ignore[arg-type]
                k, c = m * w * w, 2 * z * m * w
                try:
                    r = Structure(m, c, k).simulate(t, base=u, x0=x0, substeps=1)
                except ContactLabError:
                    continue
                if r.x.size < t.size:
                    continue
                e = r.x - y
            else:
                # unit stiffness (or the given mass), then the best scale
                m1 = 1.0 / (w * w) if mass is None else float(mass)
                k1 = 1.0 if mass is None else m1 * w * w
                try:
                    r = Structure(m1, 2 * z * m1 * w, k1).simulate(t, force=u, substeps=1)
                except ContactLabError:
                    continue
                g = r.x
                if g.size < t.size or not np.all(np.isfinite(g)):
                    continue
                gg = float(g @ g)
                scale = float(g @ y) / gg if gg > 0 else 0.0
                if not scale > 0:
                    continue
                if mass is None:
                    k = 1.0 / scale
                    m, c = k / (w * w), 2 * z * k / w
                else:
                    scale = 1.0  # the mass fixes the scale
                    m, c, k = m1, 2 * z * m1 * w, k1
                e = scale * g - y
            rms = float(np.sqrt(np.mean(e * e)))
            if math.isfinite(rms):
                found.append((rms, float(f), m, c, k))
    out: list[dict[str, Any]] = []
    for rms, f, m, c, k in sorted(found):
        if all(max(f / o["grid_f"], o["grid_f"] / f) >= 1.5 for o in out):
            out.append({"m": m, "c": c, "k": k, "grid_f": f, "grid_rms": rms})
        if len(out) == keep:
            break
    return out


def _joint_grid_plan(
    joint: str,
    lin: dict[str, Any],
    y: np.ndarray,
    mass: float | None,
    t: np.ndarray,
    res: Any,
    keep: int = 10,
) -> list[tuple[dict[str, Any], dict[str, Any], dict[str, float]]]:
    """The ``keep`` best starts of a friction joint on a grid of total stiffness (natural
    frequency), joint share and slip force, each judged by one simulation (``res``)."""
    dt = float(np.median(np.diff(t)))
    m = float(mass) if mass is not None else float(lin["m"])
    scored = []
    for f in np.geomspace(1.0 / max(float(t[-1] - t[0]), dt), 1.0 / (6.0 * dt), 12):
        k = m * (2 * np.pi * f) ** 2
        li = {**lin, "m": m, "k": k, "c": 0.02 * math.sqrt(k * m)}
        for kf in (0.5, 0.85):
            for ff in (0.01, 0.03, 0.1, 0.3, 1.0, 3.0):
                st0 = {"f_frac": ff, "k_frac": kf}
                v = {p.name: p.value for p in _params(joint, li, y, mass, st0)}
                v["x0"] = float(y[0])
                e = res(v)
                rms = float(np.sqrt(np.mean(e * e)))
                if math.isfinite(rms):
                    scored.append((rms, float(f), kf, ff, li, st0))
    scored.sort(key=lambda a: a[0])
    return [
        ({"f_frac": ff, "k_frac": kf, "grid_f": f, "grid_rms": rms}, li, st0)
        for rms, f, kf, ff, li, st0 in scored[:keep]
    ]


def _params(
    joint: str, lin: dict[str, Any], y: np.ndarray, mass: float | None, start: dict[str, float]
) -> list[Parameter]:
    m, c, k = lin["m"], max(lin["c"], 1e-9 * abs(lin["k"]) + 1e-12), abs(lin["k"])
    yr = max(float(np.std(y)), 1e-300)
    ftyp = max(k * yr, 1e-300)
    frac = start.get("k_frac", 0.5)
    ps = [
        Parameter("m", m if mass is None else mass, vary=mass is None, min=0.0, unit="kg"),
        Parameter("c", c, min=0.0, unit="N s/m", scale=max(c, 1e-3 * k * yr)),
    ]
    kl = Parameter("k", k * (1 - frac), min=0.0, unit="N/m", scale=k)
    if joint in ("linear",):
        kl.value = k
        ps.append(kl)
    elif joint == "kelvin_voigt":
        # the joint is the linear spring-damper: the structure's own k, c would duplicate it
        ps[1] = Parameter("c", 0.0, vary=False, unit="N s/m")
        ps += [
            Parameter("k", 0.0, vary=False, unit="N/m"),
            Parameter("kj", k, min=0.0, unit="N/m"),
            Parameter("cj", c, min=0.0, unit="N s/m"),
        ]
    elif joint == "normal":
        ps.append(Parameter("k", 0.0, vary=False, unit="N/m"))
        ps += [
            Parameter("a1", k, min=0.0, unit="N/m"),
            Parameter("a2", start.get("a2", 0.0), unit="N/m^2", scale=k / yr),
            Parameter("a3", start.get("a3", 0.0), unit="N/m^3", scale=k / yr**2),
        ]
    else:
        ps.append(kl)
        kj = k * frac
        if joint == "bouc_wen":
            ps += [
                Parameter("alpha", kj, min=1e-9 * kj, unit="N/m"),
                Parameter("gamma", start["gamma"] / yr, unit="1/m", scale=1 / yr),
                Parameter("delta", start["delta"] / yr, unit="1/m", scale=1 / yr),
                Parameter("nu", 1.0, min=0.25, max=4.0, vary=start.get("fit_nu", True), unit=""),
            ]
        elif joint in ("masing", "jenkins", "iwan"):
            cf = lin["coulomb"]
            fsc = start["f_frac"] * ftyp
            if start.get("coulomb") and cf["fs"] > 0 and cf["k"] > 0:
                # k and c from the Coulomb-augmented regression, joint stiffer than k
                kl.value = cf["k"]
                ps[1].value = max(cf["c"], ps[1].value * 1e-3)
                kj, fsc = start["kj_frac"] * cf["k"], start["f_frac"] * cf["fs"]
            if joint == "masing":
                ps += [
                    Parameter("h0", fsc, min=0.0, unit="N"),
                    Parameter("ac", kj / fsc, min=0.0, unit="1/m"),
                ]
            else:
                ps += [
                    Parameter("kj", kj, min=0.0, unit="N/m"),
                    Parameter("fs", fsc, min=0.0, unit="N"),
                ]
    ps += [
        Parameter("x0", 0.0, unit="m", scale=yr),
        Parameter("v0", 0.0, unit="m/s", scale=yr * 2 * np.pi * 10),
    ]
    return ps


def _starts(joint: str) -> list[dict[str, float]]:
    if joint == "bouc_wen":
        return [
            {"gamma": g, "delta": d, "k_frac": f}
            for (g, d) in ((0.5, -0.5), (0.5, 0.5), (-0.25, 0.5))
            for f in (0.5,)
        ]
    if joint in ("masing", "jenkins", "iwan"):
        return [{"f_frac": f, "k_frac": kf} for f in (0.1, 0.3, 1.0) for kf in (0.3, 0.7)] + [
            {"coulomb": 1.0, "f_frac": f, "kj_frac": kf, "k_frac": 0.5}
            for f in (0.7, 1.4)
            for kf in (3.0, 30.0)
        ]
    if joint == "normal":
        return [{"a2": 0.0, "a3": 0.0}]
    return [{}]


def _start_plan(
    joint: str,
    lin: Any,
    lins: list[dict[str, Any]],
    y: np.ndarray,
    mass: float | None,
    t: np.ndarray,
    short_residual: Callable[[], Any],
) -> list[tuple[dict[str, Any], dict[str, Any], dict[str, Any]]]:
    """The starts of a single-DOF identification: ``(start, linear model, joint start)``
    for every joint start on every linear model of the grid of frequencies
    (``short_residual()`` makes the residual on the first samples, used only there)."""
    starts = _starts(joint)
    plan = [
        (st0 if len(lins) == 1 else {**st0, "grid_f": li["grid_f"]}, li, st0)
        for li in lins
        for st0 in starts
    ]
    if len(lins) > 1 and joint in ("masing", "jenkins", "iwan"):
        # the linear grid cannot hold the mass against a joint to the fixed ground (what a
        # frame rubbing on a wall does on a short record): explore the joint's stiffness
        # share and slip force on the grid of frequencies, one simulation each (first), as
        # well as the usual starts on the linear grid's models
        plan = _joint_grid_plan(joint, lin, y, mass, t, short_residual()) + plan
    return plan


def _linear_starts(
    t: np.ndarray,
    u: np.ndarray,
    y: np.ndarray,
    excitation: str,
    mass: float | None,
    periodic: bool,
) -> tuple[dict[str, Any], list[dict[str, Any]]]:
    """The equation-error linear model and the linear models that seed the joint's starts."""
    lin = equation_error(t, u, y, excitation, mass, periodic=periodic)
    lins = [lin]
    if not (lin["k"] > 0 and lin["m"] > 0):
        # a short or slow record (a few hundred samples, the mass following the base) can
        # leave the regression's stiffness at or below zero: start from the linear model of
        # a grid of natural frequencies and damping ratios that best matches the output
        grid = linear_grid_start(t, u, y, excitation, mass)
        if not grid:
            raise InputError(
                "the equation-error fit gives a non-positive mass or stiffness "
                f"(m = {lin['m']:.4g}, k = {lin['k']:.4g}), and no linear model on a grid of "
                "natural frequencies follows the response; is the response in metres and "
                "the input the right channel?"
            )
        # the best few grid models (distinct frequencies) each seed the joint's starts
        # with light viscous damping: the grid's damping ratio stands in for the joint's
        # dissipation, which the joint's parameters are to take over
        lins = [{**lin, **g, "c": 0.02 * math.sqrt(g["k"] * g["m"])} for g in grid]
        lin = lins[0]
    return lin, lins
