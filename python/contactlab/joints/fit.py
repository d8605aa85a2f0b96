"""Fit a joint law to measured force-displacement histories and predict new ones.

:func:`fit` drives a law of :mod:`contactlab.joints.laws` with the measured displacement of
one or several records and adjusts its parameters (shared by all records) so that its force
matches the measured one in the least-squares sense:

    min_θ,β  Σ_records Σ_samples ( law_θ(t, x) + Σ_j β_j φ_j(t, x) − F )²

``φ_j`` are optional linear terms in parallel with the law: a force offset (``offset=True``:
a load-cell zero), a stiffness ``x``, a viscous term ``ẋ``, an inertia ``ẍ`` (``stiffness``,
``damping``, ``mass``; derivatives by second-order central differences on the record's own
time axis) and a direction-dependent gain ``a |F_law|`` (``asymmetry``: the law's force
scaled by ``1 + a`` when positive and ``1 − a`` when negative, as the capstan effect of a
self-energising band brake makes its friction differ between the two directions, while a
clearance's dead band stays at zero force, which an offset would move).

The linear coefficients are eliminated at every trial θ by linear least squares (variable
projection, G. H. Golub, V. Pereyra, SIAM J. Numer. Anal. 10 (1973)), so the nonlinear
search runs over the law's parameters only; a last joint fit of all parameters from that
optimum gives the covariance of everything.

Conventions follow :func:`contactlab.fitting.least_squares_fit`: parameters with standard
errors from ``(JᵀJ)⁻¹`` scaled by the reduced χ², correlations, and a parameter the data do
not determine (a direction of the Jacobian below its singular-value cut-off) reported as
``not identifiable: <why>`` with no standard error, never ± nan. A fit that does not
converge returns ``success=False`` with the solver's message; only malformed input raises.

Start values come from the records (:func:`loop_features`): the plateau of the force (the
Coulomb force of a sliding joint), the travel after a reversal over which the force swings
through 80 % of its range (a secant stiffness) and the typical speed, mapped onto each law's
parameters (:func:`start_law`); when the fit from there ends poorly, it is repeated from
stiffer and softer starts and the best one kept.

Each law starts relaxed (force 0, no history) at its record's first displacement; a
record's ``mask`` selects the samples compared (a run-in excluded, a training window).
"""

from __future__ import annotations

import itertools
import math
import time
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..errors import ContactLabError, InputError
from ..fitting import FitResult, Parameter, json_number
from ..reversals import excursions
from .fit_problem import (
    _STATIC,
    TERMS,
    Problem,
    _term_columns,
    thin_indices,
    turning_points,
)
from .records import JointRecord, as_records

__all__ = [
    "DEFAULT_FIXED",
    "ONE_SPEED_SPREAD",
    "TERMS",
    "JointFit",
    "LoopFeatures",
    "fit",
    "loop_features",
    "start_law",
    "thin_indices",
    "turning_points",
]


#: parameters held at their start value unless ``fixed`` says otherwise (weakly determined
#: shape exponents and redundant scales)
DEFAULT_FIXED: dict[str, tuple[str, ...]] = {
    "lugre": ("delta",),
    "gms": ("delta", "alpha0"),
    "masing": ("scale",),
    "bouc_wen": ("beta", "nu"),  # with ν held, β only scales γ and δ
    "dahl": (),
}


@dataclass(frozen=True)
class LoopFeatures:
    """Scales of a set of records that start values are made of.

    ``force_level`` [N]: half the robust range of F (1-99 %); ``force_mid`` [N]: its middle;
    ``swing_length`` [m]: median travel after a reversal for the force to swing through 80 %
    of ``2·force_level``; ``stiffness`` [N/m] = ``1.6 force_level / swing_length``;
    ``speed`` [m/s]: median |Δx/Δt| over the steps where x moves (a quantised stage that
    holds still every other sample moves at this speed, not at half of it); ``stroke`` [m]:
    half the displacement range; ``speed_spread``: the 95th over the 5th percentile of those
    speeds (near 1: the record slides at one speed).
    """

    force_level: float
    force_mid: float
    swing_length: float
    stiffness: float
    speed: float
    stroke: float
    speed_spread: float = math.inf


def loop_features(records: Sequence[JointRecord]) -> LoopFeatures:
    """Start-value scales from the records' loops (see :class:`LoopFeatures`)."""
    Fs = np.concatenate([r.require_force()[r.selected()] for r in records])
    q1, q99 = np.percentile(Fs, [1.0, 99.0])
    level = 0.5 * float(q99 - q1)
    if not level > 0:
        raise InputError("the measured force is constant: there is no loop to fit")
    mid = 0.5 * float(q99 + q1)
    swings, speeds, strokes = [], [], []
    for r in records:
        x, F = r.x, r.require_force()
        lo, hi = float(np.min(x)), float(np.max(x))
        strokes.append(0.5 * (hi - lo))
        v = np.abs(np.diff(x) / np.diff(r.t))
        speeds.append(v[v > 0])
        if not hi > lo:
            continue
        ex = excursions(x, 0.5 * (lo + hi), 0.25 * (hi - lo))
        turns = np.asarray(ex.extreme, dtype=np.int64)
        for a, b in itertools.pairwise(turns):
            seg_F = F[a : b + 1]
            target = 0.8 * 2.0 * level
            moved = np.abs(seg_F - seg_F[0])
            k = int(np.argmax(moved >= target)) if np.any(moved >= target) else -1
            if k > 0:
                swings.append(abs(float(x[a + k] - x[a])))
    stroke = max(float(np.median(strokes)), 1e-300)
    swing = float(np.median(swings)) if swings else 0.5 * stroke
    swing = min(max(swing, 1e-6 * stroke), 2.0 * stroke)
    moving = np.concatenate(speeds)
    speed, spread = stroke, math.inf
    if moving.size:
        speed = float(np.median(moving))
        p5, p95 = np.percentile(moving, [5.0, 95.0])
        spread = float(p95 / p5) if p5 > 0 else math.inf
    return LoopFeatures(level, mid, swing, 1.6 * level / swing, speed, stroke, spread)


def _leaf_start(name: str, f: LoopFeatures, stiff: float, n_elements: int) -> Any:
    from .laws import LAWS

    Fc, k0, v = f.force_level, f.stiffness * stiff, f.speed
    cls = LAWS[name]
    if name == "jenkins":
        return cls(k=k0, fs=Fc)
    if name == "iwan":
        return cls(k=2.0 * k0, fs_max=Fc)
    if name == "segalman":
        return cls(F_S=Fc, K_T=2.0 * k0, chi=-0.5, beta=0.1)
    if name == "maxwell_slip":
        n = n_elements
        phi = (np.arange(n) + 1.0) / n * 2.0 * Fc / k0  # slip displacements up to the swing
        w = np.full(n, 2.0 * k0 / n)
        fs = w * phi
        fs *= Fc / fs.sum()
        return cls(k=w, fs=fs)
    if name == "gms":
        n = n_elements
        return cls(k=np.full(n, 2.0 * k0 / n) * (np.arange(n) + 1.0) ** -0.5 * 1.5,
                   alpha=np.full(n, 1.0 / n), Fc=Fc, Fs=1.1 * Fc, vs=0.3 * v, C=20.0 * Fc,
                   delta=2.0, sigma2=0.01 * Fc / v)  # fmt: skip
    if name == "dahl":
        return cls(sigma0=2.0 * k0, Fc=Fc, alpha=1.0)
    if name == "lugre":
        return cls(sigma0=2.0 * k0, sigma1=0.01 * Fc / v, sigma2=0.01 * Fc / v, Fc=Fc,
                   Fs=1.1 * Fc, vs=0.3 * v, delta=2.0)  # fmt: skip
    if name == "bouc_wen":
        # ν = 1: saturation force α / (β (γ + δ)) = Fc with γ = δ = 1/2
        return cls(alpha=2.0 * k0, beta=2.0 * k0 / Fc, gamma=0.5, delta=0.5, nu=1.0)
    if name == "masing":
        return cls(h0=Fc, ac=2.0 * k0 / Fc, scale=2.0)
    if name == "kelvin_voigt":
        return cls(k=k0, c=0.01 * Fc / v)
    raise InputError(
        f"law {name!r} needs its parts: give an instance (e.g. Parallel(Jenkins(k, fs), k=..)) "
        "or a chain such as 'backlash:jenkins'"
    )


def start_law(law: str, records: Any, *, stiffness_factor: float = 1.0,
              n_elements: int = 4) -> Any:  # fmt: skip
    """A law named ``law`` with start values from the records' loops.

    ``law`` is a registry name (:data:`contactlab.joints.LAWS`) or a chain of them joined by
    ``:`` for laws behind a clearance, e.g. ``"backlash:lugre"`` (a dead band, its width
    started at a fifth of the swing length, in series with a LuGre law). Maxwell-slip and
    generalised Maxwell-slip get ``n_elements`` elements.
    """
    from .laws import LAWS

    recs = as_records(records)
    f = loop_features(recs)
    parts = [p.strip().lower() for p in str(law).split(":")]
    for p in parts:
        if p not in LAWS:
            raise InputError(f"unknown law {p!r}; known: {', '.join(sorted(LAWS))}")
    if parts[0] == "backlash":
        if len(parts) != 2:
            raise InputError("give the law behind the clearance: e.g. 'backlash:jenkins'")
        inner = _leaf_start(parts[1], f, 2.0 * stiffness_factor, n_elements)
        return LAWS["backlash"](0.2 * f.swing_length, inner)
    if len(parts) != 1:
        raise InputError(f"law {law!r}: only 'backlash:<law>' chains are known")
    return _leaf_start(parts[0], f, stiffness_factor, n_elements)


@dataclass
class JointFit:
    """A law fitted to records (:func:`fit`): predicts forces with :meth:`force`.

    Attributes
    ----------
    law : JointLaw
        The law with the fitted parameters.
    terms : dict
        Coefficients of the linear terms in parallel (``offset`` N, ``k_parallel`` N/m,
        ``c_parallel`` N s/m, ``mass`` kg) that were fitted.
    result : FitResult
        The least-squares result over the law's parameters and the terms: values, standard
        errors, correlations, χ², AIC/BIC, ``success`` and ``message``.
    records : list of str
        Names of the records fitted.
    n_samples : int
        Samples compared (after thinning).
    seconds : float
        Wall time of the fit.
    """

    law: Any
    terms: dict[str, float]
    result: FitResult
    records: list[str]
    n_samples: int
    seconds: float = 0.0
    thinned_every: int = 1
    starts_tried: int = 1
    name: str = ""
    notes: list[str] = field(default_factory=list)

    def __post_init__(self) -> None:
        if not self.name:
            self.name = self.law.name

    @property
    def success(self) -> bool:
        return bool(self.result.success)

    @property
    def message(self) -> str:
        return self.result.message

    @property
    def params(self) -> dict[str, Parameter]:
        """The fitted parameters (the law's, then the terms') with standard errors."""
        return self.result.params

    @property
    def correl(self) -> dict[str, dict[str, float]]:
        return self.result.correl_dict()

    def force(self, t: Any, x: Any, x0: float | None = None) -> np.ndarray:
        """Predicted force for the displacement history ``x`` at times ``t``.

        The law starts relaxed at ``x0`` (default: the first displacement), as in the fit.
        """
        from .._arrays import as_1d

        xa = as_1d(x, "x")
        ta = as_1d(t, "t")
        if ta.size != xa.size:
            raise InputError(f"t has {ta.size} samples, x has {xa.size}")
        start = float(xa[0]) if x0 is None else float(x0)
        P = np.asarray(self.law.force(ta, xa, start), dtype=float)
        F = P.copy()
        names = [n for n in _STATIC if n in self.terms]
        if names:
            F += _term_columns(names, ta, xa) @ np.array([self.terms[n] for n in names])
        if "asymmetry" in self.terms:
            F += self.terms["asymmetry"] * np.abs(P)
        return F

    def report(self) -> str:
        """A text report: the law, the fit statistics, parameters with errors, notes."""
        head = [f"[[Joint law]] {self.law!r}", f"    records: {', '.join(self.records)}",
                f"    samples compared: {self.n_samples}"
                + (f" (every {self.thinned_every}th + turning points)"
                   if self.thinned_every > 1 else "")]  # fmt: skip
        extra = [f"    {n}" for n in self.notes]
        return "\n".join(head + [self.result.report()] + (["[[Joint fit notes]]", *extra]
                                                          if extra else []))  # fmt: skip

    def to_dict(self) -> dict[str, Any]:
        """JSON-safe summary (SI values, a ``units`` map)."""
        params = {}
        for n, p in self.params.items():
            params[n] = {
                "value": json_number(p.value),
                "stderr": json_number(p.stderr),
                "identifiable": p.identifiable,
                "vary": p.vary,
                "note": p.note,
                "unit": p.unit,
            }
        r = self.result
        return {
            "law": self.law.name,
            "name": self.name,
            "law_repr": repr(self.law),
            "params": params,
            "terms": {k: json_number(v) for k, v in self.terms.items()},
            "correl": r.correl_dict() or None,
            "success": bool(r.success),
            "message": r.message,
            "chisqr": json_number(r.chisqr),
            "redchi": json_number(r.redchi),
            "aic": json_number(r.aic),
            "bic": json_number(r.bic),
            "nfev": int(r.nfev),
            "records": list(self.records),
            "n_samples": self.n_samples,
            "thinned_every": self.thinned_every,
            "seconds": json_number(self.seconds),
            "notes": list(r.notes) + list(self.notes),
            "units": {n: p.unit for n, p in self.params.items()},
        }


def _resolve_law(law: Any, recs: list[JointRecord], stiffness_factor: float,
                 n_elements: int) -> Any:  # fmt: skip
    from .laws import LAWS, JointLaw

    if isinstance(law, JointLaw):
        return law
    if isinstance(law, type) and issubclass(law, JointLaw):
        law = law.name
    if isinstance(law, str):
        return start_law(law, recs, stiffness_factor=stiffness_factor, n_elements=n_elements)
    raise InputError(f"law must be a name ({', '.join(sorted(LAWS))}), a law class or a law "
                     f"instance, got {type(law).__name__}")  # fmt: skip


#: the spread of sliding speeds (95th / 5th percentile) below which a record is taken to
#: slide at one speed: the Stribeck curve's Fs and vs are then held (see :func:`fit`)
ONE_SPEED_SPREAD = 3.0

#: the Stribeck parameters of the rate-dependent laws
_STRIBECK = {"lugre": ("Fs", "vs"), "gms": ("Fs", "vs")}


def _fixed_names(law: Any, fixed: Any, features: LoopFeatures | None = None,
                 notes: list[str] | None = None) -> set[str]:  # fmt: skip
    names = law.param_names
    if fixed is None:
        base, pre = law.name, ""
        if base == "backlash":
            base, pre = law.laws[0].name, law.laws[0].name + "."
        defaults = [pre + n for n in DEFAULT_FIXED.get(base, ())]
        if features is not None and features.speed_spread < ONE_SPEED_SPREAD and base in _STRIBECK:
            held = [pre + n for n in _STRIBECK[base]]
            defaults += held
            if notes is not None:
                notes.append(
                    f"{' and '.join(held)} held at their start values: the records slide at "
                    f"one speed (95th / 5th percentile of the moving |dx/dt|: "
                    f"{features.speed_spread:.2g}), which does not separate a Stribeck curve "
                    "from the Coulomb force (give fixed= to fit them anyway)"
                )
        return {n for n in defaults if n in names}
    out = set(fixed.keys() if isinstance(fixed, Mapping) else fixed)
    unknown = out - set(names)
    if unknown:
        raise InputError(f"fixed: unknown parameter(s) {', '.join(sorted(unknown))} of "
                         f"{law.name} ({', '.join(names)})")  # fmt: skip
    return out


def _zero_at_bound(fitted: Any, start: Any, fixed: set[str], notes: list[str]) -> Any:
    """Parameters whose closed lower bound is 0 (a damping, a viscous coefficient) that the
    search drove to it (below 1e-6 of their start value) are set to 0 and held there
    (added to ``fixed``), with a note: a boundary optimum, which the covariance fit and its
    trust check would otherwise take for an unconverged direction."""
    zero = {}
    starts = start.params
    for spec, (n, v) in zip(fitted._specs(), fitted.params.items(), strict=True):
        if n in fixed or spec.lo != 0.0 or spec.open_lo:
            continue
        if starts.get(n, 0.0) > 0 and v <= 1e-6 * starts[n]:
            zero[n] = 0.0
    if not zero:
        return fitted
    fixed.update(zero)
    notes.append(f"{', '.join(zero)} = 0 at the lower bound (held there for the covariance)")
    return fitted.with_params(zero)


def fit(
    records: Any,
    x: Any = None,
    F: Any = None,
    *,
    law: Any = "lugre",
    fixed: Iterable[str] | Mapping[str, float] | None = None,
    bounds: Mapping[str, tuple[float, float]] | None = None,
    offset: bool = False,
    stiffness: bool = False,
    damping: bool = False,
    mass: bool = False,
    asymmetry: bool = False,
    fs: float | None = None,
    max_samples: int | None = None,
    n_elements: int = 4,
    restarts: bool = True,
    max_nfev: int | None = None,
    name: str = "",
) -> JointFit:
    """Fit a joint law to one or several measured records (shared parameters).

    Parameters
    ----------
    records : array or record(s)
        Either the time axis ``t`` [s] of one record (with ``x`` and ``F`` given), or a record
        or a list of records (:func:`contactlab.joints.records.as_record`: ``(t, x, F)``
        tuples, mappings, :class:`JointRecord`, :class:`contactlab.io.Recording`), fitted
        together.
    x, F : array, optional
        Displacement [m] and force [N] of the one record whose time is ``records``.
    law : str, law class or law instance, default "lugre"
        A registry name (``"jenkins"``, ``"iwan"``, ``"segalman"``, ``"maxwell_slip"``,
        ``"gms"``, ``"dahl"``, ``"lugre"``, ``"bouc_wen"``, ``"masing"``,
        ``"kelvin_voigt"``) or ``"backlash:<name>"``, started from the loops
        (:func:`start_law`); or a law instance, whose parameters are the start values (any
        composition: ``Series``, ``Parallel``, ``Backlash``).
    fixed : names or mapping, optional
        Parameters held at their start value (a mapping also sets the value). Default: the
        law's weakly determined shape parameters (:data:`DEFAULT_FIXED`).
    bounds : mapping, optional
        ``name -> (lo, hi)`` replacing the law's own bounds.
    offset, stiffness, damping, mass, asymmetry : bool
        Fit a constant force, a parallel stiffness, a parallel viscous term, an inertia term
        in parallel with the law, a direction-dependent gain of the law's force (linear
        coefficients, see the module docstring).
    fs : float, optional
        Sampling rate of records given without a time axis.
    max_samples : int, optional
        When the records hold more samples, the law is driven with every n-th sample plus
        every turning point of the displacement (:func:`thin_indices`; exact for the
        rate-independent laws, a coarser input path for the rate-dependent ones) so that the
        fit costs about ``max_samples`` samples per evaluation. Default: all samples.
    n_elements : int
        Elements of a Maxwell-slip / generalised Maxwell-slip law named by string.
    restarts : bool
        When the first fit fails or explains less than 90 % of the force's variance, fit
        again from 4× stiffer and softer starts and keep the best.
    max_nfev : int, optional
        Evaluation budget of each solver run.
    name : str
        Label of the fitted model in comparisons (default: the law's name).

    Returns
    -------
    JointFit
        ``success=False`` (with the solver's message) when the fit did not converge.

    Examples
    --------
    >>> import numpy as np
    >>> from contactlab.joints import Jenkins, fit
    >>> t = np.linspace(0.0, 3.0, 1201)
    >>> x = 2e-3 * np.sin(2 * np.pi * t)
    >>> F = Jenkins(k=5e3, fs=4.0).force(t, x)
    >>> res = fit(t, x, F, law="jenkins")
    >>> round(res.params["k"].value), round(res.params["fs"].value, 6), res.success
    (5000, 4.0, True)
    """
    t0 = time.perf_counter()
    recs = _records(records, x, F, fs, max_samples, n_elements)
    terms = [n for n, on in (("offset", offset), ("k_parallel", stiffness),
                             ("c_parallel", damping), ("mass", mass),
                             ("asymmetry", asymmetry)) if on]  # fmt: skip
    first = _resolve_law(law, recs, 1.0, n_elements)
    held: list[str] = []
    fixed_names = _fixed_names(first, fixed, loop_features(recs), held)
    fixed_values = dict(fixed) if isinstance(fixed, Mapping) else {}
    if fixed_values:
        first = first.with_params(fixed_values)
    prob = Problem.build(recs, terms, max_samples, fixed_names, bounds, max_nfev)
    errors: list[str] = []
    restart = isinstance(law, str) and restarts

    def other_starts() -> list[Any]:
        out = []
        for factor in (4.0, 0.25):
            try:
                c = _resolve_law(law, recs, factor, n_elements)
                out.append(c.with_params(fixed_values) if fixed_values else c)
            except ContactLabError as exc:
                errors.append(str(exc))
        return out

    (res_law, fitted), tried = _best_start(prob, first, other_starts if restart else None, errors)
    fitted = _zero_at_bound(fitted, first, fixed_names, held)
    res, final_law = prob.joint_fit(fitted, res_law, errors)
    _explained(res, final_law, prob.var, errors)
    every = max(1, math.ceil(sum(r.n for r in recs) / max_samples)) if max_samples else 1
    return JointFit(law=final_law, terms={n: res.params[n].value for n in terms}, result=res,
                    records=[r.name for r in recs], n_samples=int(prob.Fm.size),
                    seconds=time.perf_counter() - t0, thinned_every=every, starts_tried=tried,
                    name=name, notes=held + errors[:3])  # fmt: skip


def _records(records: Any, x: Any, F: Any, fs: float | None, max_samples: Any,
             n_elements: Any) -> list[JointRecord]:  # fmt: skip
    """The records of :func:`fit`'s arguments, with its options checked."""
    if x is not None or F is not None:
        if x is None or F is None:
            raise InputError("give t, x and F of one record, or a list of records")
        recs = as_records((records, x, F), fs=fs)
    else:
        recs = as_records(records, fs=fs)
    for r in recs:
        r.require_force()
    if max_samples is not None and not (isinstance(max_samples, int) and max_samples >= 10):
        raise InputError(
            f"max_samples must be an integer >= 10 (or None: all), got {max_samples!r}"
        )
    if not (isinstance(n_elements, int) and n_elements >= 1):
        raise InputError(f"n_elements must be an integer >= 1, got {n_elements!r}")
    return recs


def _best_start(prob: Problem, first: Any, others: Any,
                errors: list[str]) -> tuple[tuple[FitResult, Any], int]:  # fmt: skip
    """The best search from ``first`` and, when it fails or explains less than 90 % of the
    force's variance, from ``others()`` (stiffer and softer starts)."""
    candidates, tried = [first], 0
    best: tuple[FitResult, Any] | None = None
    while candidates:
        cand = candidates.pop(0)
        tried += 1
        try:
            res, fitted = prob.search(cand)
        except ContactLabError as exc:
            errors.append(str(exc))
            res = None
        if res is not None and (best is None or res.chisqr < best[0].chisqr):
            best = (res, fitted)
        good = best is not None and best[0].success and best[0].chisqr < 0.1 * prob.var
        if others is not None and tried == 1 and not good:
            candidates.extend(others())
    if best is None:
        raise InputError(f"the law {first.name} could not be evaluated from any start: "
                         f"{errors[0] if errors else 'no start'}")  # fmt: skip
    return best, tried


def _explained(res: FitResult, law: Any, var: float, errors: list[str]) -> None:
    """A law that explains under 10 % of the force's variance: said first in the notes, and
    the fit failed when no parameter is determined."""
    explained = 1.0 - res.chisqr / var if var > 0 else math.nan
    if explained < 0.1:
        errors.insert(0, (
            f"the fitted {law.name} law explains {100 * max(explained, 0.0):.0f} % of "
            "the force's variance: it cannot produce these loops (a force of the opposite "
            "sign, whose loops run the active way? a record with no joint motion?)"
        ))  # fmt: skip
        if all(p.identifiable is False for p in res.params.values() if p.vary):
            res.success = False
            res.message = "no parameter is determined by the data: " + errors[0]
