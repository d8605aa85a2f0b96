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
    hold_state,
    noise_model_covariance,
)
from .model import SimulationResult, Structure
from .starts import _linear_starts, _params, _start_plan, equation_error, linear_grid_start

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


@with_single_blas_thread
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
            t,
            u,
            y,
            joint,
            excitation,
            structure=structure,
            masks=masks,
            joint_dofs=joint_dofs,
            input_dof=input_dof,
            mass=mass,
            substeps=substeps,
            interpolation=interpolation,
            periodic=periodic,
            multistart=multistart,
            start_samples=start_samples,
            max_nfev=max_nfev,
            estimate_initial_state=estimate_initial_state,
        )
        model = IdentifiedModel(**fields)
    else:
        model = _identify_sdof(
            t,
            u,
            y,
            joint,
            excitation,
            mass=mass,
            substeps=substeps,
            interpolation=interpolation,
            periodic=periodic,
            multistart=multistart,
            start_samples=start_samples,
            max_nfev=max_nfev,
            estimate_initial_state=estimate_initial_state,
            progress=progress,
        )
    model.elapsed = time.perf_counter() - t0
    return model


def _identify_sdof(
    t: Any,
    u: Any,
    y: Any,
    joint: str,
    excitation: str,
    *,
    mass: float | None,
    substeps: int,
    interpolation: str,
    periodic: bool | None,
    multistart: bool,
    start_samples: int,
    max_nfev: int,
    estimate_initial_state: bool,
    progress: Callable[[str], None] | None,
) -> IdentifiedModel:
    """:func:`identify` of a single-DOF record: starts, fit, and the noise-model errors."""
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
    fit = least_squares_fit(
        residual_on(t.size), best_ps, max_nfev=max_nfev, ftol=1e-7, xtol=1e-7, gtol=1e-10
    )
    # the residuals of an output-error fit are correlated in time (input noise filtered by
    # the structure): the white-noise covariance understated the errors several-fold
    v = fit.values
    r_fit = residual_on(t.size)(v)
    fit, noise = noise_model_covariance(
        fit, lambda du: residual_on(t.size, substeps, u + du)(v) - r_fit, u
    )
    return IdentifiedModel(
        structure=build_structure(joint, v, excitation),
        joint=joint,
        excitation=excitation,
        fit=fit,
        x0=float(v["x0"]),
        v0=float(v["v0"]),
        substeps=int(substeps),
        interpolation=interpolation,
        rms=float(np.sqrt(fit.chisqr / max(fit.ndata, 1))),
        starts=records,
        noise=noise,
    )


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
