"""Identification of a single-DOF structure with a joint from its input and response.

Output-error least squares (:func:`contactlab.fitting.least_squares_fit`): the model
``m x'' + c x' + k x + F_joint = u`` (``excitation="force"``) or
``m x'' + c (x' − y') + k (x − y) + F_joint = 0`` with the measured base motion ``y``
(``excitation="base"``) is simulated by the Rust core and its displacement compared with the
measured one. Fitted: ``m`` (unless given), ``c``, ``k``, the joint's parameters and the
initial state ``x0``, ``v0``; standard errors, correlations and identifiability come from the
fit. The output-error surface of a hysteretic joint has local minima (e.g. Bouc-Wen's γ, δ
signs, a slip force above or below the excitation's reach), so several starts are fitted on a
short stretch of the record and the best is refined on the whole of it.

Starting values come from an equation-error fit of the linear model to the record
(derivatives by finite differences), which also gives the force the joint must supply
(``u − m x'' − c x' − k x``), the route that reconstructs the joint force from the equation
of motion.

Bouc-Wen: only the products ``β γ`` and ``β δ`` enter the law, so ``β`` is held at 1 and
``γ``, ``δ`` carry the products (units 1/m^ν).
"""

from __future__ import annotations

import json
import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from .._arrays import as_1d
from .._blas import with_single_blas_thread
from .._io_atomic import write_text
from .._physical import MAX_MAGNITUDE, check_channel
from ..errors import ContactLabError, InputError
from ..fitting import FitResult, Parameter, least_squares_fit
from .fitkit import (
    IWAN_ELEMENTS,
    add_fitted_joint,
    best_start,
    derivatives,
    hold_state,
    noise_model_covariance,
)
from .model import SimulationResult, Structure

JOINTS = ("masing", "jenkins", "iwan", "bouc_wen", "kelvin_voigt", "normal", "linear")
__all__ = [
    "IWAN_ELEMENTS",
    "JOINTS",
    "IdentifiedModel",
    "equation_error",
    "identify",
    "linear_grid_start",
]


@dataclass
class IdentifiedModel:
    """An identified SDOF structure with a joint; simulate it for new inputs.

    Attributes
    ----------
    structure : Structure
        The fitted structure (``M``, ``C``, ``K`` and the joint, dof 0 to ground).
    joint : str
    excitation : {"force", "base"}
    fit : FitResult
        Parameters with standard errors, correlations, identifiability.
    x0, v0 : float, or list of float (one per DOF)
        Estimated initial displacement and velocity of the record.
    substeps : int
        Integration steps per sample used in the fit (and by :meth:`simulate`).
    interpolation : str
        Input interpolation between samples used in the fit.
    rms : float
        RMS output error on the fitted record [m].
    starts : list of dict
        Each start's initial values and training cost (multi-start).
    elapsed : float
        Wall time of the identification [s].
    input_dof : int or None
        Several DOFs, force excitation: the DOF the (1-D) input force acts on.
    joint_dofs : tuple or None
        Several DOFs: ``(i, j)`` the joint acts between (``j = None``: the ground).
    pattern : Pattern or None
        Several DOFs: which entries of ``M``, ``C``, ``K`` were fitted (chain or masks).
    noise : dict or None
        The noise levels the standard errors allow for, estimated from the residual
        spectrum: ``input_noise`` (σ of white noise on ``u``), ``output_noise`` (one σ per
        displacement channel [m]) and ``probes`` (see
        :func:`contactlab.structure._fitkit.noise_model_covariance`).
    """

    structure: Structure
    joint: str
    excitation: str
    fit: FitResult
    x0: float | list[float] = 0.0
    v0: float | list[float] = 0.0
    substeps: int = 4
    interpolation: str = "linear"
    rms: float = math.nan
    starts: list[dict[str, Any]] = field(default_factory=list)
    elapsed: float = math.nan
    input_dof: int | None = None
    joint_dofs: tuple[int, int | None] | None = None
    pattern: Any = None
    noise: dict[str, Any] | None = None

    def simulate(
        self,
        t: Any,
        force: Any = None,
        base: Any = None,
        *,
        periodic: bool = False,
        x0: Any = None,
        v0: Any = None,
        interpolation: str | None = None,
    ) -> SimulationResult:
        """Response of the identified model to a new input (from rest unless ``x0``/``v0``).

        ``force`` for a force-excited model, ``base`` (displacement) for a base-excited one.
        Returns a :class:`SimulationResult` whose ``.x`` is the displacement at ``t``.
        """
        if self.excitation == "force" and force is None:
            raise InputError("this model is force-excited: pass force=")
        if self.excitation == "base" and base is None:
            raise InputError("this model is base-excited: pass base=")
        n = self.structure.n
        if force is not None and n > 1 and np.ndim(force) == 1:
            # a multi-DOF model's input is the force at input_dof
            f1 = as_1d(force, "force")
            force = np.zeros((f1.size, n))
            force[:, self.input_dof if self.input_dof is not None else n - 1] = f1
        return self.structure.simulate(
            t,
            force=force,
            base=base,
            x0=x0,
            v0=v0,
            periodic=periodic,
            substeps=self.substeps,
            interpolation=interpolation or self.interpolation,
        )

    def to_dict(self) -> dict[str, Any]:
        d = self._to_dict()
        if self.structure.n > 1:
            d["n_dofs"] = self.structure.n
            d["input_dof"] = self.input_dof
            d["joint_dofs"] = list(self.joint_dofs) if self.joint_dofs else None
            d["pattern"] = self.pattern.to_dict() if self.pattern is not None else None
        return d

    def _to_dict(self) -> dict[str, Any]:
        return {
            "kind": "contactlab.structure.IdentifiedModel",
            "joint": self.joint,
            "excitation": self.excitation,
            "structure": self.structure.to_dict(),
            "x0": self.x0,
            "v0": self.v0,
            "substeps": self.substeps,
            "interpolation": self.interpolation,
            "rms": _num(self.rms),
            "elapsed": _num(self.elapsed),
            "fit": self.fit.to_dict(),
            "starts": self.starts,
            "noise": self.noise,
            "units": {
                "x0": "m",
                "v0": "m/s",
                "rms": "m",
                "elapsed": "s",
                "noise.output_noise": "m",
                "noise.input_noise": "N" if self.excitation == "force" else "m",
            },
        }

    def save(self, path: str | Path) -> None:
        """Write the model as JSON (atomically); :meth:`load` reads it back."""
        write_text(path, json.dumps(self.to_dict(), indent=2))

    @classmethod
    def load(cls, path: str | Path) -> IdentifiedModel:
        from .model import load_json

        d = load_json(path, "model JSON (`contactlab identify --json`)")
        return cls.from_dict(d)

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> IdentifiedModel:
        try:
            s = Structure.from_dict(d["structure"])
            fd = d["fit"]
            params = (
                {
                    p["name"]: Parameter(
                        name=p["name"],
                        value=float(p["value"]),
                        stderr=p.get("stderr"),
                        vary=bool(p.get("vary", True)),
                        identifiable=p.get("identifiable"),
                        note=p.get("note", ""),
                        unit=p.get("unit", ""),
                    )
                    for p in fd["params"].values()
                }
                if isinstance(fd.get("params"), dict)
                else {}
            )
            fit = FitResult(
                params=params,
                var_names=list(fd.get("var_names", [])),
                covar=None,
                correl=None,
                chisqr=float(fd.get("chisqr") or math.nan),
                redchi=float(fd.get("redchi") or math.nan),
                aic=float(fd.get("aic") or math.nan),
                bic=float(fd.get("bic") or math.nan),
                ndata=int(fd.get("ndata", 0)),
                nvarys=int(fd.get("nvarys", 0)),
                success=bool(fd.get("success", True)),
                status=int(fd.get("status", 0)),
                message=str(fd.get("message", "")),
                nfev=int(fd.get("nfev", 0)),
                residual=np.zeros(0),
            )
            extra: dict[str, Any] = {}
            if s.n > 1:
                from .identify_mdof import pattern_from_dict

                jd = d.get("joint_dofs") or [0, None]
                extra = {
                    "input_dof": None if d.get("input_dof") is None else int(d["input_dof"]),
                    "joint_dofs": (int(jd[0]), None if jd[1] is None else int(jd[1])),
                    "pattern": pattern_from_dict(d["pattern"]) if d.get("pattern") else None,
                }

            def state(key: str) -> float | list[float]:
                v = d.get(key, 0.0)
                return [float(a) for a in v] if isinstance(v, list) else float(v)

            return cls(
                structure=s,
                joint=str(d["joint"]),
                excitation=str(d["excitation"]),
                fit=fit,
                x0=state("x0"),
                v0=state("v0"),
                substeps=int(d.get("substeps", 1)),
                interpolation=str(d.get("interpolation", "linear")),
                rms=float(d.get("rms") or math.nan),
                starts=list(d.get("starts", [])),
                elapsed=float(d.get("elapsed") or math.nan),
                noise=d.get("noise") if isinstance(d.get("noise"), dict) else None,
                **extra,
            )
        except (KeyError, TypeError, ValueError) as exc:
            raise InputError(f"not an identified-structure model: {exc}") from None

    def report(self) -> str:
        lines = [
            f"joint: {self.joint}   excitation: {self.excitation}   "
            f"RMS output error: {self.rms:.4g} m   time: {self.elapsed:.1f} s",
            self.fit.report(),
        ]
        return "\n".join(lines)


def _num(v: float) -> float | None:
    return float(v) if v is not None and math.isfinite(v) else None


# ------------------------------------------------------------------ building models
def build_structure(joint: str, v: dict[str, float], excitation: str) -> Structure:
    """The SDOF structure of parameter values ``v`` (names as in the fit)."""
    s = Structure(v["m"], v["c"], v["k"])
    add_fitted_joint(s, joint, v, 0, None)
    return s


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
                    r = Structure(m, c, k).simulate(t, base=u, x0=x0)
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
                    r = Structure(m1, 2 * z * m1 * w, k1).simulate(t, force=u)
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


@with_single_blas_thread
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


def identify(
    t: Any,
    u: Any,
    y: Any,
    joint: str = "bouc_wen",
    excitation: str = "force",
    *,
    mass: float | None = None,
    substeps: int = 4,
    interpolation: str = "auto",
    periodic: bool | None = None,
    multistart: bool = True,
    start_samples: int = 4096,
    max_nfev: int = 200,
    estimate_initial_state: bool = True,
    structure: Any = "chain",
    masks: dict[str, Any] | None = None,
    joint_dofs: Any = (0, None),
    input_dof: int | None = None,
    progress: Callable[[str], None] | None = None,
) -> IdentifiedModel:
    """Identify ``m``, ``c``, ``k`` and a joint from input ``u`` and response ``y``.

    With ``y`` of shape ``(n_samples, n_dofs)`` (the displacement of every mass; more than
    one column), a structure of several DOFs is identified
    (:mod:`contactlab.structure.identify_mdof`): ``structure="chain"`` (masses ``m{i}``,
    springs ``k{i}``, dashpots ``c{i}`` between DOF ``i−1`` and ``i``, element 0 to the
    ground or base) or ``masks={"M": ..., "C": ..., "K": ...}`` (symmetric boolean masks of
    free entries, parameters ``K[i,j]``), the joint between ``joint_dofs=(i, j)`` (``j`` None:
    the ground), the force ``u`` acting at ``input_dof`` (default the last DOF) or the base
    motion ``u`` under every DOF (``mass=`` the masses, needed then). Initial state
    parameters ``x0_{i}``, ``v0_{i}``.

    Parameters
    ----------
    t : array_like
        Sample times [s] (uniform for ``interpolation="fourier"``).
    u : array_like
        Input: force [N] (``excitation="force"``) or base displacement [m] (``"base"``).
    y : array_like
        Measured displacement of the mass [m].
    joint : str
        ``"masing"``, ``"jenkins"``, ``"iwan"`` (uniform slip-force density, 20 elements),
        ``"bouc_wen"``, ``"kelvin_voigt"``, ``"normal"`` (cubic ``k_s(d)`` force law) or
        ``"linear"`` (no joint).
    mass : float, optional
        Known mass [kg] (held fixed; required for base excitation).
    substeps : int
        Integration steps per sample interval.
    interpolation : {"auto", "linear", "fourier"}
        Input between samples; ``auto``: ``fourier`` when the record is periodic.
    periodic : bool, optional
        Whether the record holds whole periods of a periodic input (derivatives by FFT for
        the starting values); default: ``interpolation == "fourier"``.
    multistart : bool
        Fit every start on the first ``start_samples`` samples and refine the best.
    estimate_initial_state : bool
        Fit ``x0`` and ``v0`` (else the record starts from rest).
    progress : callable, optional
        Called with the stage (``"starts"``, ``"fit"``, ``"errors"``) after every simulation
        of a single-DOF identification (a progress bar counts them).

    Returns
    -------
    IdentifiedModel
    """
    t0 = time.perf_counter()
    joint = _checked_kind(joint, excitation)
    if np.ndim(y) == 2 and np.shape(y)[1] > 1:
        from .identify_mdof import identify_mdof

        fields = identify_mdof(
            t, u, y, joint, excitation, structure=structure, masks=masks,
            joint_dofs=joint_dofs, input_dof=input_dof, mass=mass, substeps=substeps,
            interpolation=interpolation, periodic=periodic, multistart=multistart,
            start_samples=start_samples, max_nfev=max_nfev,
            estimate_initial_state=estimate_initial_state,
        )  # fmt: skip
        model = IdentifiedModel(**fields)
        model.elapsed = time.perf_counter() - t0
        return model
    t, u, y = _checked_sdof_record(t, u, y, excitation, mass)
    if interpolation == "auto":
        interpolation = "fourier" if periodic else "linear"
    if periodic is None:
        periodic = interpolation == "fourier"
    lin, lins = _linear_starts(t, u, y, excitation, mass, bool(periodic))

    residual_on = _SdofResidual(joint, excitation, t, u, y, interpolation, substeps, progress)

    records: list[dict[str, Any]] = []
    n_s = min(int(start_samples), t.size)
    plan = _start_plan(joint, lin, lins, y, mass, t, lambda: residual_on(n_s, 2))
    est = estimate_initial_state
    best_ps = hold_state(_params(joint, plan[0][1], y, mass, plan[0][2]), est)
    if multistart and len(plan) > 1:
        tried = [(st, hold_state(_params(joint, li, y, mass, st0), est)) for st, li, st0 in plan]
        best_ps = best_start(tried, residual_on(n_s, 2), records) or best_ps
    fit = least_squares_fit(residual_on(t.size), best_ps, max_nfev=max_nfev, ftol=1e-7,
                            xtol=1e-7, gtol=1e-10)  # fmt: skip
    # the residuals of an output-error fit are correlated in time (input noise filtered by
    # the structure): the white-noise covariance understated the errors several-fold
    v = fit.values
    r_fit = residual_on(t.size)(v)
    fit, noise = noise_model_covariance(
        fit, lambda du: residual_on(t.size, substeps, u + du)(v) - r_fit, u
    )
    model = IdentifiedModel(
        structure=build_structure(joint, v, excitation), joint=joint, excitation=excitation,
        fit=fit, x0=float(v["x0"]), v0=float(v["v0"]), substeps=int(substeps),
        interpolation=interpolation, rms=float(np.sqrt(fit.chisqr / max(fit.ndata, 1))),
        starts=records, noise=noise,
    )  # fmt: skip
    model.elapsed = time.perf_counter() - t0
    return model


def _checked_sdof_record(
    t: Any, u: Any, y: Any, excitation: str, mass: float | None
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """One DOF's record as checked arrays: same lengths, enough samples, physical magnitudes,
    increasing time, the mass given under base excitation."""
    if np.ndim(y) == 2 and np.shape(y)[1] == 1:
        y = np.asarray(y)[:, 0]
    t = as_1d(t, "t")
    u = as_1d(u, "u")
    y = as_1d(y, "y")
    if not (t.size == u.size == y.size):
        raise InputError(f"t, u and y differ in length ({t.size}, {u.size}, {y.size})")
    if t.size < 20:
        raise InputError(f"{t.size} samples are too few to identify a structure")
    # magnitudes a fit can square (found by fuzzing: 1e300 channels overflowed in np.std
    # and the derivative filters); the input may be zero or constant (free decay, a step)
    check_channel("y", y, "m", "displacement")
    big = float(np.max(np.abs(u)))
    if big > MAX_MAGNITUDE:
        raise InputError(
            f"u reaches {big:.3g} {'N' if excitation == 'force' else 'm'}: beyond any "
            "physical input; a unit mix-up or a corrupt file?"
        )
    if np.any(np.diff(t) <= 0):
        raise InputError("t must be strictly increasing")
    if excitation == "base" and mass is None:
        raise InputError("base excitation needs the mass: pass mass=... (kg)")
    return t, u, y


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


class _SdofResidual:
    """``residual_on(n, sub, u_in)``: the output-error residual of the first ``n`` samples
    (simulated with ``sub`` substeps, the input ``u_in`` if given) as a function of the
    fitted values. ``progress`` (optional) is called with the stage after each simulation."""

    def __init__(
        self,
        joint: str,
        excitation: str,
        t: np.ndarray,
        u: np.ndarray,
        y: np.ndarray,
        interpolation: str,
        substeps: int,
        progress: Callable[[str], None] | None = None,
    ) -> None:
        self.joint, self.excitation, self.t, self.u, self.y = joint, excitation, t, u, y
        self.interpolation, self.substeps = interpolation, substeps
        self.progress = progress

    def __call__(self, n: int, sub: int | None = None, u_in: np.ndarray | None = None) -> Any:
        sub = self.substeps if sub is None else sub
        t, u, y, joint, excitation = self.t, self.u, self.y, self.joint, self.excitation
        tt, uu, yy = t[:n], (u[:n] if u_in is None else u_in), y[:n]
        interp = self.interpolation if n == t.size else "linear"
        progress = self.progress
        full = n == t.size and sub == self.substeps
        stage = "errors" if u_in is not None else "fit" if full else "starts"

        def res(v: dict[str, float]) -> np.ndarray:
            if progress is not None:
                progress(stage)
            try:
                s = build_structure(joint, v, excitation)
                kw = {"force": uu} if excitation == "force" else {"base": uu}
                r = s.simulate(
                    tt, x0=[v["x0"]], v0=[v["v0"]], substeps=sub, interpolation=interp, **kw
                )
            except ContactLabError:
                return np.full(n, 1e3 * float(np.max(np.abs(yy))) + 1.0)
            x = r.x
            if x.size < n:  # failed run: penalise the rest
                x = np.concatenate([x, np.full(n - x.size, 10 * np.max(np.abs(yy)) + 1.0)])
            return x - yy

        return res


def _checked_kind(joint: str, excitation: str) -> str:
    """The joint's name in canonical spelling; a typed error for an unknown joint or
    excitation."""
    joint = str(joint).lower().replace("-", "_")
    if joint not in JOINTS:
        raise InputError(f"joint must be one of {', '.join(JOINTS)}; got {joint!r}")
    if excitation not in ("force", "base"):
        raise InputError(f"excitation must be 'force' or 'base', got {excitation!r}")
    return joint
