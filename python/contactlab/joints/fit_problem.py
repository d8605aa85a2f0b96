"""The least-squares problem of a joint fit (:func:`contactlab.joints.fit`): the records as
the law is driven with them, the residual with the linear terms eliminated (variable
projection), its Jacobian from the Rust core's forward sensitivities where the law has them,
the search from one start and the final joint fit of every parameter (the covariance)."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import ContactLabError, InputError
from ..fitting import FitResult, Parameter, least_squares_fit
from ._solve import lm_solver
from .records import JointRecord

#: linear terms in parallel with the law: name -> unit of the coefficient
TERMS = {"offset": "N", "k_parallel": "N/m", "c_parallel": "N s/m", "mass": "kg",
         "asymmetry": ""}  # fmt: skip
#: terms whose column is computed from the displacement (the others from the law's force)
_STATIC = ("offset", "k_parallel", "c_parallel", "mass")


def _derivatives(t: np.ndarray, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    v = np.gradient(x, t, edge_order=2) if t.size > 2 else np.gradient(x, t)
    a = np.gradient(v, t, edge_order=2) if t.size > 2 else np.gradient(v, t)
    return v, a


def _term_columns(terms: Sequence[str], t: np.ndarray, x: np.ndarray) -> np.ndarray:
    terms = [n for n in terms if n in _STATIC]
    cols = []
    v = a = None
    if "c_parallel" in terms or "mass" in terms:
        v, a = _derivatives(t, x)
    for n in terms:
        if n == "offset":
            cols.append(np.ones_like(x))
        elif n == "k_parallel":
            cols.append(x - x[0])
        elif n == "c_parallel":
            cols.append(v)
        elif n == "mass":
            cols.append(a)
    return np.column_stack(cols) if cols else np.zeros((x.size, 0))


def turning_points(x: np.ndarray, gate: float) -> np.ndarray:
    """Indices of the turning points of ``x``: the extremes between which it moves by more
    than ``gate`` (a hysteresis threshold, as the gate of ASTM E1049-85 peak counting; 0
    keeps every local extremum)."""
    d = np.diff(x)
    nz = np.flatnonzero(d != 0)
    if nz.size == 0:
        return np.zeros(0, dtype=np.int64)
    s = np.sign(d[nz])
    # candidates: the last sample of each monotone run (a change of sign of the steps)
    cand = nz[np.flatnonzero(s[1:] != s[:-1])] + 1
    if gate <= 0 or cand.size == 0:
        return cand.astype(np.int64)
    # hysteresis over the candidates (the first sample included: the first run's start)
    pts = np.concatenate([[0], cand]).astype(np.int64)
    v = x[pts]
    out: list[int] = []
    hi = lo = 0  # positions in pts while no direction is set
    direction, ext = 0, 0
    for j in range(1, pts.size):
        if direction == 0:
            if v[j] > v[hi]:
                hi = j
            if v[j] < v[lo]:
                lo = j
            if v[hi] - v[lo] > gate:
                first, ext, direction = (lo, hi, 1) if hi > lo else (hi, lo, -1)
                out.append(int(pts[first]))
            continue
        if direction > 0:
            if v[j] >= v[ext]:
                ext = j
            elif v[ext] - v[j] > gate:
                out.append(int(pts[ext]))
                direction, ext = -1, j
        else:
            if v[j] <= v[ext]:
                ext = j
            elif v[j] - v[ext] > gate:
                out.append(int(pts[ext]))
                direction, ext = 1, j
    if direction != 0:
        out.append(int(pts[ext]))
    return np.asarray(out, dtype=np.int64)


def thin_indices(rec: JointRecord, keep_every: int, gate: float = 1e-3) -> np.ndarray:
    """Every ``keep_every``-th sample plus each turning point of ``x``, first and last.

    Turning points: :func:`turning_points` with a gate of ``gate`` times the range of ``x``.
    A rate-independent law gives the same force at the kept samples as on the whole record
    (its force depends only on the sequence of turning points and the current displacement),
    up to the effect of reversals smaller than the gate (exact with ``gate=0``).
    """
    n = rec.n
    if keep_every <= 1:
        return np.arange(n)
    x = rec.x
    rng = float(np.max(x) - np.min(x))
    keep = np.zeros(n, bool)
    keep[::keep_every] = True
    keep[-1] = True
    keep[turning_points(x, gate * rng)] = True
    return np.flatnonzero(keep)


@dataclass
class _Prepared:
    """A record as a fit evaluates it: the samples the law runs on, the compared ones."""

    rec: JointRecord
    run: np.ndarray  # indices of the samples the law is driven with
    cmp: np.ndarray | None  # positions within ``run`` compared (None: all of them)
    F: np.ndarray  # measured force at the compared samples
    phi: np.ndarray  # linear terms' columns at the compared samples
    t: np.ndarray  # time and displacement at ``run`` (taken once, not at every evaluation)
    x: np.ndarray


def _prepare(recs: list[JointRecord], terms: Sequence[str],
             max_samples: int | None) -> list[_Prepared]:  # fmt: skip
    total = sum(r.n for r in recs)
    every = 1 if max_samples is None or total <= max_samples else math.ceil(total / max_samples)
    out = []
    for r in recs:
        F = r.require_force()
        run = thin_indices(r, every)
        sel = np.ones(r.n, bool) if r.mask is None else r.mask
        cmp = np.flatnonzero(sel[run])
        if cmp.size == 0:
            cmp = np.arange(run.size)
        phi = _term_columns(terms, r.t, r.x)[run[cmp]]
        every_one = cmp.size == run.size
        t_run = r.t if run.size == r.n else np.ascontiguousarray(r.t[run])
        x_run = r.x if run.size == r.n else np.ascontiguousarray(r.x[run])
        out.append(_Prepared(r, run, None if every_one else cmp, F[run[cmp]], phi, t_run,
                             x_run))  # fmt: skip
    return out


def _law_forces(law: Any, prep: list[_Prepared]) -> np.ndarray:
    parts = []
    for p in prep:
        f = np.asarray(law.force(p.t, p.x, float(p.x[0])), dtype=float)
        parts.append(f if p.cmp is None else f[p.cmp])
    return parts[0] if len(parts) == 1 else np.concatenate(parts)


def has_sensitivities(law: Any) -> bool:
    """True when the Rust core carries the law's forward sensitivities (its Jacobian in one
    pass); the other laws are differentiated by finite differences."""
    from .. import _core

    try:
        return bool(_core.joint_has_sens(law.spec()))
    except (ContactLabError, ValueError, TypeError):
        return False


def _law_forces_jac(law: Any, prep: list[_Prepared]) -> tuple[np.ndarray, np.ndarray]:
    """The law's forces at the compared samples and their derivatives in every parameter
    (columns in the order of ``law.param_names``), from the forward sensitivities."""
    from .. import _core

    Ps, Js = [], []
    spec = law.spec()
    for p in prep:
        f, J = _core.joint_force_sens(spec, p.t, p.x, float(p.x[0]))
        Ps.append(f if p.cmp is None else f[p.cmp])
        Js.append(J if p.cmp is None else J[p.cmp])
    if len(Ps) == 1:
        return Ps[0], Js[0]
    return np.concatenate(Ps), np.concatenate(Js, axis=0)


def _project_out(cols: np.ndarray, J: np.ndarray) -> np.ndarray:
    """``(I - Π) J``, ``Π`` the orthogonal projection onto the span of ``cols`` (the
    variable-projection Jacobian, Kaufman's form when the columns depend on the law)."""
    if cols.shape[1] == 0:
        return J
    sc = np.sqrt(np.sum(cols**2, axis=0))
    sc[sc == 0] = 1.0
    Q = np.linalg.qr(cols / sc)[0]
    return J - Q @ (Q.T @ J)


def _guarded(residual: Any, Fm: np.ndarray) -> Any:
    """``residual`` that, once it has been evaluated, answers a trial point the law refuses
    (a Bouc-Wen whose β(γ+δ) turns negative, a force out of range) with a residual 10× the
    measured force's size, so that the solver steps back instead of the fit failing; at the
    start point the law's error is raised (bad input)."""
    started = False
    big = 10.0 * (float(np.sqrt(np.mean(Fm**2))) or 1.0)

    def wrapped(v: Mapping[str, float]) -> np.ndarray:
        nonlocal started
        try:
            out = residual(v)
        except InputError:
            if not started:
                raise
            return np.full(Fm.size, big)
        started = True
        return out

    return wrapped


def _linear_solve(phi: np.ndarray, rhs: np.ndarray) -> np.ndarray:
    if phi.shape[1] == 0:
        return np.zeros(0)
    sc = np.sqrt(np.sum(phi**2, axis=0))
    sc[sc == 0] = 1.0
    beta = np.linalg.lstsq(phi / sc, rhs, rcond=None)[0]
    return beta / sc


def _parameters(law: Any, fixed: set[str], bounds: Mapping[str, tuple[float, float]] | None
                ) -> dict[str, Parameter]:  # fmt: skip
    from .amplitude import physical_bounds

    units = law.units
    lb = law.bounds
    bounds = physical_bounds(law, bounds)
    out = {}
    for n, v in law.params.items():
        lo, hi = lb[n]
        if bounds and n in bounds:
            lo, hi = bounds[n]
            v = min(max(v, lo), hi)
        scale = None
        if v == 0:
            scale = 1.0
        # a parameter whose lower bound is excluded (stiffness, forces) is kept off it
        if lo == 0.0 and v > 0 and n not in fixed:
            lo = 1e-9 * v if not (bounds and n in bounds) else lo
        out[n] = Parameter(n, float(v), vary=n not in fixed, min=lo, max=hi, unit=units[n],
                           scale=scale)  # fmt: skip
    return out


def _identifiability_notes(res: FitResult) -> None:
    """``not identifiable: <why>`` on every parameter the fit flagged."""
    for n, p in res.params.items():
        if p.identifiable is False:
            why = next((s for s in res.notes if n in s), None)
            if p.note and p.note.startswith("not identifiable"):
                continue
            text = why or p.note or "the data do not constrain it"
            p.note = f"not identifiable: {text}"
            p.stderr = None


@dataclass
class Problem:
    """Records, linear terms and options of one fit; :meth:`search` fits the law's
    parameters from a start, :meth:`joint_fit` all parameters from the search's end."""

    prep: list[_Prepared]
    terms: list[str]
    fixed: set[str]
    bounds: Mapping[str, tuple[float, float]] | None
    max_nfev: int | None

    def __post_init__(self) -> None:
        self.Fm = np.concatenate([p.F for p in self.prep])
        self.phi = np.concatenate([p.phi for p in self.prep], axis=0)
        self.asym = "asymmetry" in self.terms
        self.var = float(np.sum((self.Fm - self.Fm.mean()) ** 2))

    @classmethod
    def build(cls, recs: list[JointRecord], terms: list[str], max_samples: int | None,
              fixed: set[str], bounds: Any, max_nfev: int | None) -> Problem:  # fmt: skip
        return cls(_prepare(recs, terms, max_samples), terms, fixed, bounds, max_nfev)

    def _cols(self, P: np.ndarray) -> np.ndarray:
        return np.column_stack([self.phi, np.abs(P)]) if self.asym else self.phi

    def _fit(self, residual: Any, params: dict[str, Parameter], jac: Any) -> FitResult:
        fn = _guarded(residual, self.Fm)
        return least_squares_fit(fn, params, max_nfev=self.max_nfev, jac=jac,
                                 solver=None if jac is None else lm_solver(fn, jac))  # fmt: skip

    def search(self, start: Any) -> tuple[FitResult, Any]:
        """The law's parameters fitted from ``start``, the linear terms eliminated."""
        names = list(start.param_names)

        def law_of(v: Mapping[str, float]) -> Any:
            return start.with_params([v[n] for n in names])

        def residual(v: Mapping[str, float]) -> np.ndarray:
            P = _law_forces(law_of(v), self.prep)
            if not self.terms:
                return P - self.Fm
            cols = self._cols(P)
            return P + cols @ _linear_solve(cols, self.Fm - P) - self.Fm

        def jacobian(v: Mapping[str, float]) -> dict[str, np.ndarray]:
            P, J = _law_forces_jac(law_of(v), self.prep)
            cols = self._cols(P)
            if self.asym:
                a = _linear_solve(cols, self.Fm - P)[-1]
                J = J * (1.0 + a * np.sign(P))[:, None]
            J = _project_out(cols, J)
            return {n: J[:, j] for j, n in enumerate(names)}

        params = _parameters(start, self.fixed, self.bounds)
        res = self._fit(residual, params, jacobian if has_sensitivities(start) else None)
        return res, law_of(res.values)

    def joint_fit(self, fitted: Any, res_law: FitResult,
                  errors: list[str]) -> tuple[FitResult, Any]:  # fmt: skip
        """All parameters (the law's and the linear terms') from the search's end point:
        their covariance. On failure the search's result is returned (noted in ``errors``)."""
        terms, phi, Fm, asym = self.terms, self.phi, self.Fm, self.asym
        P = _law_forces(fitted, self.prep)
        beta = _linear_solve(self._cols(P), Fm - P)
        params = _parameters(fitted, self.fixed, self.bounds)
        for p in params.values():  # the nonlinear fit's end point: keep its bounds' sense
            p.min = min(p.min, p.value)
        for i, n in enumerate(terms):
            params[n] = Parameter(n, float(beta[i]), unit=TERMS[n],
                                  scale=None if beta[i] != 0 else 1.0)  # fmt: skip
        names = list(fitted.param_names)
        static = [n for n in terms if n in _STATIC]

        def residual(v: Mapping[str, float]) -> np.ndarray:
            P = _law_forces(fitted.with_params([v[n] for n in names]), self.prep)
            out = P + phi @ np.array([v[n] for n in static]) - Fm
            return out + v["asymmetry"] * np.abs(P) if asym else out

        def jacobian(v: Mapping[str, float]) -> dict[str, np.ndarray]:
            P, J = _law_forces_jac(fitted.with_params([v[n] for n in names]), self.prep)
            if asym:
                J = J * (1.0 + v["asymmetry"] * np.sign(P))[:, None]
            out = {n: J[:, j] for j, n in enumerate(names)}
            out.update({n: phi[:, i] for i, n in enumerate(static)})
            if asym:
                out["asymmetry"] = np.abs(P)
            return out

        try:
            res = self._fit(residual, params, jacobian if has_sensitivities(fitted) else None)
            final_law = fitted.with_params([res.params[n].value for n in names])
        except ContactLabError as exc:
            errors.append(f"the joint covariance fit failed ({exc}); the law's fit is reported")
            return res_law, fitted
        if not res_law.success and res.success:
            res.notes.append(f"the search over the law's parameters ended: {res_law.message}")
        _identifiability_notes(res)
        return res, final_law
