"""Stepped-sine first-harmonic responses of a mode with a joint (:class:`Sweep`) and the fit
of a joint law to them (:func:`fit_stepped_sine`): backbone frequency and damping against
amplitude, with the law's uncertainty."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .._arrays import as_1d
from ..errors import ContactLabError, InputError
from ..fitting import FitResult, Parameter, json_number, least_squares_fit
from .amplitude import (
    _amplitudes,
    _default_fixed,
    _law_params,
    _mark_identifiability,
    _resolve,
    closed_form_available,
    equivalent_properties,
    out_of_range_notes,
)

# stepped sine


@dataclass
class Sweep:
    """First-harmonic stepped-sine points of one sweep: ``frequency`` [Hz], ``force`` [N]
    amplitude, response displacement amplitude ``displacement`` [m] and ``phase`` [rad] of
    the response relative to the force (receptance phase: −π/2 at phase resonance)."""

    frequency: np.ndarray
    force: np.ndarray
    displacement: np.ndarray
    phase: np.ndarray
    name: str = ""

    @classmethod
    def from_acceleration(cls, frequency: Any, force: Any, acceleration: Any, phase: Any,
                          name: str = "") -> Sweep:  # fmt: skip
        """From an accelerance amplitude [m/s²] (displacement ``a / ω²``) and the phase of the
        response (the displacement's: −π/2 at phase resonance)."""
        f = as_1d(frequency, f"{name}: frequency")
        a = as_1d(acceleration, f"{name}: acceleration")
        if f.size != a.size:
            raise InputError(f"sweep {name!r}: {f.size} frequencies, {a.size} amplitudes")
        if not np.all(f > 0):
            raise InputError(f"sweep {name!r}: frequencies must be > 0 Hz")
        return cls(f, as_1d(force, f"{name}: force"), a / (2.0 * math.pi * f) ** 2,
                   as_1d(phase, f"{name}: phase"), name)  # fmt: skip

    def __post_init__(self) -> None:
        n = self.frequency.size
        for k in ("force", "displacement", "phase"):
            a = as_1d(getattr(self, k), f"sweep {self.name!r}: {k}")
            if a.size != n:
                raise InputError(f"sweep {self.name!r}: {k} has {a.size} points, frequency {n}")
            setattr(self, k, a)
        if not (np.all(self.force > 0) and np.all(self.displacement > 0)):
            raise InputError(f"sweep {self.name!r}: force and response amplitudes must be > 0")

    def phase_resonance(self) -> dict[str, float] | None:
        """The point where the phase crosses −π/2 (linear interpolation between the two
        points around it): frequency, force, displacement and the equivalent damping
        ``c = F / (ω X)`` [N s/m] there (interpolated as ``Im(F/X) / ω``, equal to it at
        phase resonance); None when the sweep does not cross it."""
        ph = np.unwrap(self.phase) + math.pi / 2.0
        idx = np.flatnonzero(np.sign(ph[:-1]) != np.sign(ph[1:]))
        if idx.size == 0:
            return None
        i = int(idx[np.argmin(np.abs(ph[idx]))])
        w = ph[i] / (ph[i] - ph[i + 1])

        def at(a: np.ndarray) -> float:
            return float(a[i] + w * (a[i + 1] - a[i]))

        f, F, X = at(self.frequency), at(self.force), at(self.displacement)
        # the damping from the quadrature part of the dynamic stiffness, Im(F/X)/ω, which
        # varies slowly across resonance (F and X each pass through an extreme there)
        K = self.force / (self.displacement * np.exp(1j * self.phase))
        c = at(K.imag / (2.0 * math.pi * self.frequency))
        return {"frequency": f, "force": F, "displacement": X, "c_eq": c}


@dataclass
class SteppedSineFit:
    """A single-mode model with a joint fitted to stepped-sine responses.

    The mode: ``m ẍ + c0 ẋ + k x + F_joint(x) = F`` in the measured response coordinate;
    ``law`` is the joint, ``modal`` holds ``m`` [kg], ``k`` [N/m], ``c0`` [N s/m].
    """

    law: Any
    modal: dict[str, float]
    result: FitResult
    sweeps: list[str]
    frequency: float
    failures: dict[str, str] = field(default_factory=dict)

    @property
    def success(self) -> bool:
        return bool(self.result.success)

    def backbone(self, amplitude: Any) -> dict[str, np.ndarray]:
        """Natural frequency ``f_n`` [Hz] (``k + k_eq(A) = m ω_n²``), damping ratio ``zeta``
        and equivalent damping ``c_eq = c0 + E / (π ω_n A²)`` [N s/m] at displacement
        amplitudes ``amplitude``, with their standard errors (first-order propagation of the
        fit's covariance; NaN where it is not determined) and ``failures``."""
        A, _ = _amplitudes(amplitude)
        names = list(self.law.param_names)

        def props(v: Mapping[str, float]) -> np.ndarray:
            lw = self.law.with_params([v[n] for n in names])
            p = equivalent_properties(lw, A, self.frequency)
            kk = v["k"] + p.k_eq
            wn = np.sqrt(np.clip(kk / v["m"], 0.0, None))
            c = v["c0"] + p.energy / (math.pi * wn * A**2)
            zeta = c / (2.0 * v["m"] * wn)
            return np.concatenate([wn / (2.0 * math.pi), zeta, c])

        failures: dict[str, str] = {}
        try:
            val = props(self.result.values)
        except ContactLabError as exc:
            return {"amplitude": A, "failures": {"all": str(exc)}}  # type: ignore[dict-item]
        try:
            _, err = self.result.propagate(props)
        except ContactLabError as exc:  # a parameter at its bound: the difference steps leave it
            err = np.full(val.size, np.nan)
            failures["stderr"] = f"standard errors not propagated: {exc}"
        n = A.size
        val = np.asarray(val, dtype=float)
        err = np.asarray(err, dtype=float)
        return {"amplitude": A, "f_n": val[:n], "zeta": val[n : 2 * n], "c_eq": val[2 * n :],
                "f_n_stderr": err[:n], "zeta_stderr": err[n : 2 * n],
                "c_eq_stderr": err[2 * n :], "failures": failures}  # fmt: skip

    def to_dict(self) -> dict[str, Any]:
        return {
            "law": self.law.name,
            "law_repr": repr(self.law),
            "modal": {k: json_number(v) for k, v in self.modal.items()},
            "params": {
                n: {
                    "value": json_number(p.value),
                    "stderr": json_number(p.stderr),
                    "identifiable": p.identifiable,
                    "note": p.note,
                    "unit": p.unit,
                }
                for n, p in self.result.params.items()
            },
            "success": bool(self.result.success),
            "message": self.result.message,
            "sweeps": list(self.sweeps),
            "failures": dict(self.failures),
            "notes": list(self.result.notes),
        }


def fit_stepped_sine(sweeps: Sequence[Sweep], *, law: Any = "segalman",
                     fixed: Sequence[str] | None = None, sweep_stiffness: bool = True,
                     weighting: str = "relative",
                     bounds: Mapping[str, tuple[float, float]] | None = None
                     ) -> SteppedSineFit:  # fmt: skip
    """Fit a mode with a joint to first-harmonic stepped-sine points (all sweeps at once).

    At each point the measured dynamic stiffness ``K = F / X`` (``X = |X| e^{iφ}``, the
    response relative to the force) is compared with the model's first harmonic balance
    ``D = k − m ω² + k_eq(A) + i (ω c0 + E(A) / (π A²))``, ``A = |X|``, with the joint's
    ``k_eq`` and ``E`` from :func:`equivalent_properties`. Residuals: the real part over
    ``|K|`` (stiffness) and the imaginary part over ``Im K`` (damping: a relative error at
    every point, not only near resonance, where a small drift of the natural frequency
    between sweeps would otherwise outweigh it). ``m``, ``k``, ``c0`` enter linearly and are
    eliminated at each trial of the law's parameters (variable projection), then fitted
    jointly with them for the covariance.

    The law is started from the phase-resonance points of the sweeps (their equivalent
    damping against amplitude, :meth:`Sweep.phase_resonance`); by default the parameters
    that micro-slip data cannot separate are held (Segalman's ``K_T`` and ``β``, Iwan's
    ``k``: the result's notes say why). Points at which the law cannot be evaluated are
    penalised and listed in ``failures``; nothing is raised for them.

    Parameters
    ----------
    sweeps : list of Sweep
        The stepped-sine sweeps, fitted together.
    law : str or law
        "segalman" (default), "iwan", "jenkins" started from the phase-resonance table, or
        a law instance.
    fixed : names, optional
        Law parameters held (default: those micro-slip cannot separate, see above).
    sweep_stiffness : bool, default True
        Give each sweep after the first its own modal stiffness offset ``dk_j``: the natural
        frequency of a built-up beam drifts between sweeps (temperature, settling; on the
        Brake-Reuss beam data it moves non-monotonically by 0.3 Hz with amplitude, which no
        softening joint produces), and without the offsets that drift is taken for joint
        stiffness and biases the damping. The backbone uses the first sweep's stiffness.
    weighting : {"relative", "resonance"}
        "relative": the damping residual of each point relative to its own ``Im K``;
        "resonance": relative to ``|K|`` (the points near resonance weigh most).
    bounds : mapping, optional
        ``name -> (lo, hi)`` of law parameters, over the defaults (the law's own range, and
        Segalman's physical −1 < χ <= 0, :data:`PHYSICAL_BOUNDS`).
    """
    if not sweeps:
        raise InputError("give at least one sweep")
    sw = list(sweeps)
    f, A, K = _points(sw)
    w = 2.0 * math.pi * f
    start = _resonance_start(sw, law)
    fixed_set, why = _default_fixed(start, fixed, False)
    names = list(start.param_names)
    # a law without closed forms is simulated on a log-spaced amplitude grid, interpolated
    grid = np.geomspace(float(A.min()) * 0.98, float(A.max()) * 1.02, 48)
    fmid = float(np.median(f))
    failures: dict[str, str] = {}
    if weighting not in ("resonance", "relative"):
        raise InputError(f"weighting must be 'resonance' or 'relative', got {weighting!r}")
    sR = np.abs(K)
    sI = K.imag if weighting == "relative" else sR

    def joint(v: Mapping[str, float]) -> tuple[np.ndarray, np.ndarray]:
        lw = start.with_params([v[n] for n in names])
        if closed_form_available(lw):  # cheap: at every point's own amplitude
            p = equivalent_properties(lw, A, fmid)
            return p.k_eq, p.energy / (math.pi * A**2)
        p = equivalent_properties(lw, grid, fmid)
        failures.clear()  # those of the latest trial: the end point's when the fit is done
        for i, reason in p.failures.items():
            failures[f"{grid[i]:.4g} m"] = reason
        ok = np.isfinite(p.k_eq) & np.isfinite(p.energy)
        if not ok.any():
            return np.full(A.size, np.nan), np.full(A.size, np.nan)
        lg = np.log(grid[ok])
        keq = np.interp(np.log(A), lg, p.k_eq[ok])
        im = np.interp(np.log(A), lg, p.energy[ok] / (math.pi * grid[ok] ** 2))
        return keq, im

    Lr, lin_names, lin_units = _linear_columns(sw, w, sR, sI, sweep_stiffness)

    def base(v: Mapping[str, float]) -> np.ndarray:
        keq, im = joint(v)
        return np.concatenate([(keq - K.real) / sR, (im - K.imag) / sI])

    def residual_nl(v: Mapping[str, float]) -> np.ndarray:
        b = base(v)
        if not np.all(np.isfinite(b)):
            return np.where(np.isfinite(b), b, 10.0)
        beta = np.linalg.lstsq(Lr, -b, rcond=None)[0]
        return b + Lr @ beta

    params = _law_params(start, fixed_set, bounds)
    res1 = least_squares_fit(residual_nl, params)
    v1 = res1.values
    beta = np.linalg.lstsq(Lr, -base(v1), rcond=None)[0]
    params = _law_params(start.with_params([v1[n] for n in names]), fixed_set, bounds)
    for n, b, u in zip(lin_names, beta, lin_units, strict=True):
        params[n] = Parameter(n, float(b), unit=u, scale=abs(float(b)) or 1.0)

    def residual(v: Mapping[str, float]) -> np.ndarray:
        r = base(v) + Lr @ np.array([v[n] for n in lin_names])
        return np.where(np.isfinite(r), r, 10.0)

    res = least_squares_fit(residual, params)
    if not res1.success:
        res.notes.append(f"the search over the law's parameters ended: {res1.message}")
    if why:
        res.notes.append(f"held: {why}")
    _mark_identifiability(res)
    joint(res.values)  # the end point's failures
    law_fit = start.with_params([res.params[n].value for n in names])
    res.notes.extend(out_of_range_notes(law_fit))
    modal = {n: res.params[n].value for n in ("k", "m", "c0")}
    return SteppedSineFit(law_fit, modal, res, [s.name for s in sw], fmid, dict(failures))


def _points(sw: list[Sweep]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Frequency [Hz], amplitude [m] and dynamic stiffness ``F / X`` of every point of the
    sweeps; a point where the response leads the force is refused."""
    f = np.concatenate([s.frequency for s in sw])
    F = np.concatenate([s.force for s in sw])
    X = np.concatenate([s.displacement * np.exp(1j * s.phase) for s in sw])
    K = F / X
    if not np.all(K.imag > 0):
        i = int(np.argmax(~(K.imag > 0)))
        raise InputError(f"point {i} ({f[i]:.4g} Hz): the response leads the force (phase "
                         f"{np.angle(X[i]):.3g} rad), which a passive mode cannot do")  # fmt: skip
    return f, np.abs(X), K


def _resonance_start(sw: list[Sweep], law: Any) -> Any:
    """The law started from the sweeps' phase-resonance points (their equivalent damping
    against amplitude; half the damping at the smallest amplitude taken as viscous)."""
    res_pts = [p for s in sw if (p := s.phase_resonance()) is not None]
    if not res_pts:
        raise InputError("no sweep crosses phase resonance (−π/2): cannot start the fit")
    Ar = np.array([p["displacement"] for p in res_pts])
    cr = np.array([p["c_eq"] for p in res_pts])
    fr = np.array([p["frequency"] for p in res_pts])
    order = np.argsort(Ar)
    Ar, cr, fr = Ar[order], cr[order], fr[order]
    c0_start = max(0.5 * float(cr[0]), 1e-12)
    E_start = np.clip(cr - c0_start, 1e-3 * cr, None) * math.pi * 2 * math.pi * fr * Ar**2
    return _resolve(law, Ar, E_start, None)


def _linear_columns(sw: list[Sweep], w: np.ndarray, sR: np.ndarray, sI: np.ndarray,
                    sweep_stiffness: bool) -> tuple[np.ndarray, list[str], list[str]]:  # fmt: skip
    """The linear columns (k, m, c0, and each later sweep's stiffness offset ``dk_j``: a
    drift between sweeps) of the two residual parts, their names and units."""
    zero = np.zeros_like(w)
    Lr = np.concatenate([np.stack([1.0 / sR, -(w**2) / sR, zero], axis=1),
                         np.stack([zero, zero, w / sI], axis=1)], axis=0)  # fmt: skip
    names, units = ["k", "m", "c0"], ["N/m", "kg", "N s/m"]
    if sweep_stiffness:
        start_i = np.cumsum([0, *[s.frequency.size for s in sw]])
        for j in range(1, len(sw)):
            col = np.zeros(2 * w.size)
            col[start_i[j] : start_i[j + 1]] = 1.0 / sR[start_i[j] : start_i[j + 1]]
            Lr = np.column_stack([Lr, col])
            names.append(f"dk_{j}")
            units.append("N/m")
    return Lr, names, units
