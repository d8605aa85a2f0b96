"""Amplitude-dependent stiffness and damping of a joint law, and laws fitted to them.

For a joint displaced harmonically, ``x = A cos θ``, the first harmonic of its force gives an
equivalent (secant, first-harmonic) stiffness and the loop area the dissipated energy:

    k_eq(A) = (1 / (π A)) ∮ F cos θ dθ,    E(A) = ∮ F dx,    c_eq(A) = E / (π ω A²),

the describing-function linearisation of T. K. Caughey, *Sinusoidal excitation of a system
with bilinear hysteresis*, J. Appl. Mech. 27 (1960) 640-643, used for jointed structures in
e.g. M. R. W. Brake (ed.), *The Mechanics of Jointed Structures*, Springer 2018, ch. 3. The
joint's complex stiffness is ``K(A) = k_eq(A) + i E(A) / (π A²)``.

Closed forms where they exist, numerical cycles elsewhere:

- **Jenkins** (``k``, slip force ``fs``, slip displacement ``u = fs/k``): ``E = 4 fs (A − u)``
  for ``A > u`` (else 0); ``k_eq = (k/π)(θ* − sin θ* cos θ*)`` with ``cos θ* = 1 − 2u/A``
  (Caughey 1960, eq. 17); backbone ``min(k A, fs)``.
- **Iwan / Segalman** (and any Masing law): the energy from the laws' closed forms
  (:meth:`contactlab.joints.Segalman.loop_energy`; Segalman, J. Appl. Mech. 72 (2005):
  ``E = 4 R A^(χ+3) / ((χ+2)(χ+3))`` in micro-slip), the first-harmonic stiffness from the
  Masing branch ``F(θ) = f(A) − 2 f(A (1 − cos θ) / 2)`` of the closed-form virgin curve
  ``f`` by Gauss-Legendre quadrature.
- **Others** (LuGre, Dahl, Maxwell-slip, Bouc-Wen, compositions): the law driven over
  ``cycles`` periods of ``A sin(ω t)`` from the relaxed state; the last period gives k_eq and
  E (trapezoid rule).

Fits: :func:`fit_amplitude` fits a law to a table of equivalent damping, energy per cycle
and/or stiffness against amplitude; :func:`fit_stepped_sine` fits a single-mode model with a
joint (``m ẍ + c0 ẋ + k x + F_joint(x) = F``, first harmonic balance) to stepped-sine
first-harmonic responses and predicts the backbone (natural frequency and damping ratio
against amplitude). A law that cannot be evaluated at an amplitude is reported there (the
``failures`` of the result), never raised out of the fit.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .._arrays import as_1d
from ..errors import ContactLabError, InputError
from ..fitting import FitResult, Parameter, json_number, least_squares_fit

#: Gauss-Legendre nodes on [0, π] (64 panels of 8), for the Masing branch integrals
_PANELS, _ORDER = 64, 8


def _gl_nodes() -> tuple[np.ndarray, np.ndarray]:
    z, w = np.polynomial.legendre.leggauss(_ORDER)
    edges = np.linspace(0.0, math.pi, _PANELS + 1)
    h = np.diff(edges) / 2.0
    mid = (edges[1:] + edges[:-1]) / 2.0
    th = (mid[:, None] + h[:, None] * z[None, :]).reshape(-1)
    wt = (h[:, None] * w[None, :]).reshape(-1)
    return th, wt


_TH, _WT = _gl_nodes()


def _amplitudes(A: Any) -> tuple[np.ndarray, bool]:
    a = np.asarray(A, dtype=float)
    scalar = a.ndim == 0
    a = as_1d(a.reshape(-1), "amplitude")
    if not np.all(a > 0):
        i = int(np.argmax(~(a > 0)))
        raise InputError(f"amplitude[{i}] = {a[i]} must be > 0")
    return a, scalar


def _virgin(law: Any) -> Any:
    """The closed-form virgin curve of a Masing-type law (odd ``f(u)``), or None."""
    name = getattr(law, "name", "")
    if name == "jenkins":
        k, fs = law.k, law.fs
        return lambda u: np.sign(u) * np.minimum(k * np.abs(u), fs)
    if name in ("segalman", "iwan") and hasattr(law, "virgin"):
        return law.virgin
    if name == "masing" and getattr(law, "scale", 2.0) == 2.0:
        model = law.masing()
        return lambda u: np.asarray(model.virgin(np.asarray(u, dtype=float)), dtype=float)
    return None


def closed_form_available(law: Any) -> bool:
    """Whether :func:`equivalent_properties` uses closed forms (no simulated cycles)."""
    return _virgin(law) is not None


def _masing_first_harmonic(f: Any, A: np.ndarray) -> np.ndarray:
    """``k_eq`` of the Masing loop of virgin curve ``f`` at amplitudes ``A``."""
    th = _TH[None, :]
    a = A[:, None]
    Fdesc = f(a) - 2.0 * f(a * (1.0 - np.cos(th)) / 2.0)
    return 2.0 / (math.pi * A) * np.sum(Fdesc * np.cos(th) * _WT[None, :], axis=1)


def _jenkins(law: Any, A: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    k, fs = law.k, law.fs
    u = fs / k
    E = np.where(A > u, 4.0 * fs * (A - u), 0.0)
    c = np.clip(1.0 - 2.0 * u / A, -1.0, 1.0)
    th = np.arccos(c)
    keq = np.where(A > u, k / math.pi * (th - np.sin(th) * c), k)
    return keq, E, np.minimum(k * A, fs) / A


def simulated_cycle(
    law: Any, amplitude: float, frequency: float = 1.0, *, cycles: int = 3, n_per_cycle: int = 1024
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The law driven over ``cycles`` periods of ``A sin(2π f t)`` from the relaxed state at 0;
    returns ``(θ, x, F)`` of the last period (``θ`` from 0 to 2π)."""
    n = int(n_per_cycle)
    t = np.arange(cycles * n + 1) / (n * frequency)
    th = 2.0 * math.pi * frequency * t
    x = amplitude * np.sin(th)
    F = np.asarray(law.force(t, x, 0.0), dtype=float)
    s = slice((cycles - 1) * n, None)
    return th[s] - th[s][0], x[s], F[s]


def _numeric(
    law: Any, A: np.ndarray, frequency: float, cycles: int, n_per_cycle: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray, dict[int, str]]:
    keq, E, ksec = (np.full(A.size, np.nan) for _ in range(3))
    failures: dict[int, str] = {}
    for i, a in enumerate(A):
        try:
            th, x, F = simulated_cycle(law, float(a), frequency, cycles=cycles,
                                       n_per_cycle=n_per_cycle)  # fmt: skip
        except ContactLabError as exc:
            failures[i] = str(exc)
            continue
        if not np.all(np.isfinite(F)):
            failures[i] = "the simulated force is not finite"
            continue
        # x = A sin θ here: the in-phase part is ∮ F sin θ dθ
        keq[i] = float(np.trapezoid(F * np.sin(th), th)) / (math.pi * a)
        E[i] = float(np.trapezoid(F, x))
        ksec[i] = float(np.max(np.abs(F))) / a
    return keq, E, ksec, failures


@dataclass
class EquivalentProperties:
    """First-harmonic properties of a law at amplitudes ``amplitude`` [m].

    ``k_eq`` [N/m] first-harmonic (in-phase) stiffness, ``energy`` [J] dissipated per cycle,
    ``c_eq`` [N s/m] ``= E / (π ω A²)`` (NaN without a frequency), ``k_secant`` [N/m] the
    backbone's ``F(A)/A`` (the loop tip's for simulated laws), ``failures``: index -> why the
    law could not be evaluated there (its values are NaN), ``method``: "closed form" or
    "simulated cycles".
    """

    amplitude: np.ndarray
    k_eq: np.ndarray
    energy: np.ndarray
    c_eq: np.ndarray
    k_secant: np.ndarray
    frequency: float | None
    method: str
    failures: dict[int, str] = field(default_factory=dict)

    def to_dict(self) -> dict[str, Any]:
        return {
            "amplitude": self.amplitude.tolist(),
            "k_eq": [json_number(v) for v in self.k_eq],
            "energy": [json_number(v) for v in self.energy],
            "c_eq": [json_number(v) for v in self.c_eq],
            "k_secant": [json_number(v) for v in self.k_secant],
            "frequency": json_number(self.frequency),
            "method": self.method,
            "failures": {str(k): v for k, v in self.failures.items()},
            "units": {"amplitude": "m", "k_eq": "N/m", "energy": "J", "c_eq": "N s/m",
                      "k_secant": "N/m", "frequency": "Hz"},
        }  # fmt: skip


def equivalent_properties(
    law: Any,
    amplitude: Any,
    frequency: float | None = None,
    *,
    cycles: int = 3,
    n_per_cycle: int = 1024,
) -> EquivalentProperties:
    """Equivalent stiffness, energy per cycle and equivalent damping of ``law`` at the given
    amplitudes (closed forms where the module docstring lists them, else simulated cycles
    at ``frequency`` [Hz], needed for a rate-dependent law).

    Examples
    --------
    >>> from contactlab.joints import Jenkins
    >>> p = equivalent_properties(Jenkins(k=1e4, fs=10.0), [5e-4, 2e-3])
    >>> p.energy.tolist()  # 4 fs (A - fs/k)
    [0.0, 0.04]
    """
    A, _ = _amplitudes(amplitude)
    if frequency is not None and not (math.isfinite(frequency) and frequency > 0):
        raise InputError(f"frequency must be a finite number > 0 Hz, got {frequency}")
    failures: dict[int, str] = {}
    if getattr(law, "name", "") == "jenkins":
        keq, E, ksec = _jenkins(law, A)
        method = "closed form"
    elif (f := _virgin(law)) is not None:
        keq = _masing_first_harmonic(f, A)
        E = (np.asarray(law.loop_energy(A), dtype=float) if hasattr(law, "loop_energy")
             else np.asarray(law.masing().loop_energy(A), dtype=float))  # fmt: skip
        ksec = np.abs(np.asarray(f(A), dtype=float)) / A
        method = "closed form"
    else:
        if law.rate_dependent and frequency is None:
            raise InputError(f"{law.name} is rate-dependent: give the frequency of the cycles")
        keq, E, ksec, failures = _numeric(law, A, frequency or 1.0, cycles, n_per_cycle)
        method = "simulated cycles"
    c = (E / (math.pi * 2.0 * math.pi * frequency * A**2) if frequency is not None
         else np.full(A.size, np.nan))  # fmt: skip
    return EquivalentProperties(A, keq, E, c, ksec, frequency, method, failures)


def energy_per_cycle(law: Any, amplitude: Any, frequency: float | None = None) -> Any:
    """Energy [J] the law dissipates per symmetric cycle of the given amplitude(s)."""
    A, scalar = _amplitudes(amplitude)
    E = equivalent_properties(law, A, frequency).energy
    return float(E[0]) if scalar else E


def secant_stiffness(law: Any, amplitude: Any, frequency: float | None = None) -> Any:
    """Backbone (virgin-curve) secant stiffness ``f(A)/A`` [N/m] (closed form for the Masing
    laws; the loop tip's ``max|F|/A`` of a simulated cycle otherwise)."""
    A, scalar = _amplitudes(amplitude)
    k = equivalent_properties(law, A, frequency).k_secant
    return float(k[0]) if scalar else k


# ----------------------------------------------------------------------------------------
# fits


#: parameter ranges the fits keep to by default, narrower than the laws' own where a
#: value the law can evaluate has no physical meaning: Segalman's power-law exponent
#: −1 < χ < 0 (a slip-force density that diverges at 0 slip and a dissipation growing as
#: A^(3+χ), between A² and A³; Segalman 2005; kept 0.01 off −1, where the density's
#: normalisation diverges). ``bounds`` widens them.
PHYSICAL_BOUNDS: dict[str, dict[str, tuple[float, float]]] = {"segalman": {"chi": (-0.99, 0.0)}}


def physical_bounds(law: Any, bounds: Mapping[str, tuple[float, float]] | None
                    ) -> dict[str, tuple[float, float]]:  # fmt: skip
    """``bounds`` over the physical ranges of :data:`PHYSICAL_BOUNDS` for ``law`` (a
    composite's children's names prefixed)."""
    out: dict[str, tuple[float, float]] = {}
    for name in law.param_names:
        *owners, own = name.split(".")
        # the law owning the parameter: the composite's child prefix ("segalman",
        # "segalman1" when two children share a name) or the law itself
        owner = owners[-1].rstrip("0123456789") if owners else law.name
        b = PHYSICAL_BOUNDS.get(owner, {}).get(own)
        if b is not None:
            out[name] = b
    out.update(bounds or {})
    return out


def out_of_range_notes(law: Any) -> list[str]:
    """A note per parameter outside its physical range (a fit given wider ``bounds``)."""
    notes = []
    for n, (lo, hi) in physical_bounds(law, None).items():
        v = law.params[n]
        if not lo <= v <= hi:
            notes.append(f"{n} = {v:.3g} is outside the physical range ({lo:g}, {hi:g}] of "
                         f"{law.name} (the fit was given wider bounds)")  # fmt: skip
    return notes


def _law_params(law: Any, fixed: set[str], bounds: Mapping[str, tuple[float, float]] | None,
                ) -> dict[str, Parameter]:  # fmt: skip
    out = {}
    bounds = physical_bounds(law, bounds)
    for n, v in law.params.items():
        lo, hi = bounds.get(n, law.bounds[n])
        v = min(max(v, lo), hi) if n in bounds else v
        if lo == 0.0 and v > 0 and n not in (bounds or {}):
            lo = 1e-9 * v
        out[n] = Parameter(n, float(v), vary=n not in fixed, min=lo, max=hi,
                           unit=law.units[n], scale=None if v != 0 else 1.0)  # fmt: skip
    return out


def _mark_identifiability(res: FitResult) -> None:
    for n, p in res.params.items():
        if p.identifiable is False and not p.note.startswith("not identifiable"):
            why = next((s for s in res.notes if n in s), None) or p.note or "unconstrained"
            p.note = f"not identifiable: {why}"
            p.stderr = None


@dataclass
class AmplitudeFit:
    """A law fitted to amplitude-dependent properties (:func:`fit_amplitude`).

    ``measured`` and ``predicted`` map each fitted quantity (``c_eq``, ``energy``,
    ``k_eq``, ``k_secant``) to arrays over ``amplitude``; ``failures`` maps an amplitude's
    index to why the law could not be evaluated there at the end point.
    """

    law: Any
    result: FitResult
    amplitude: np.ndarray
    measured: dict[str, np.ndarray]
    predicted: dict[str, np.ndarray]
    frequency: float | None
    failures: dict[int, str] = field(default_factory=dict)

    @property
    def success(self) -> bool:
        return bool(self.result.success)

    def rms_relative_error(self, quantity: str) -> float:
        """RMS of ``predicted / measured − 1`` over the amplitudes evaluated."""
        m, p = self.measured[quantity], self.predicted[quantity]
        ok = np.isfinite(p) & (m != 0)
        return float(np.sqrt(np.mean((p[ok] / m[ok] - 1.0) ** 2))) if ok.any() else math.nan

    def to_dict(self) -> dict[str, Any]:
        return {
            "law": self.law.name,
            "law_repr": repr(self.law),
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
            "amplitude": self.amplitude.tolist(),
            "measured": {k: [json_number(x) for x in v] for k, v in self.measured.items()},
            "predicted": {k: [json_number(x) for x in v] for k, v in self.predicted.items()},
            "rms_relative_error": {
                k: json_number(self.rms_relative_error(k)) for k in self.measured
            },
            "failures": {str(k): v for k, v in self.failures.items()},
            "notes": list(self.result.notes),
        }


def _start_from_table(name: str, A: np.ndarray, E: np.ndarray | None,
                      k: np.ndarray | None) -> Any:  # fmt: skip
    """A Segalman / Iwan / Jenkins law started from the table: the log-log slope of E gives
    χ (E ∝ A^(χ+3) in micro-slip), its level R, and the stiffness (or, without one, a
    macro-slip displacement 10× the largest amplitude: a K_T held there leaves F_S room to
    set R while every amplitude stays in micro-slip) K_T."""
    from .laws import LAWS

    amax = float(np.max(A))
    if name in ("iwan", "jenkins"):
        chi = 0.0
    elif E is not None and np.sum(E > 0) >= 2:
        ok = E > 0
        slope = float(np.polyfit(np.log(A[ok]), np.log(E[ok]), 1)[0])
        chi = min(max(slope - 3.0, -0.9), 0.0)
    else:
        chi = -0.5
    KT = float(np.max(k)) * 1.05 if k is not None else None
    if E is not None and np.any(E > 0):
        i = int(np.argmax(E))
        R = float(E[i]) * (chi + 2.0) * (chi + 3.0) / (4.0 * float(A[i]) ** (chi + 3.0))
    else:
        R = None
    if KT is None and R is not None:
        # φmax = 10 A_max with β = 0: K_T = R φmax^(χ+1) / (χ+1)
        KT = R * (10.0 * amax) ** (chi + 1.0) / (chi + 1.0)
    if KT is None:
        raise InputError("give an energy or damping column, or a stiffness column, to start from")
    if R is not None:
        # φmax from K_T = R φmax^(χ+1)/(χ+1) (β = 0), F_S = R φmax^(χ+2) / (χ+2)
        phi = (KT * (chi + 1.0) / R) ** (1.0 / (chi + 1.0))
        phi = max(phi, 1.5 * amax)
    else:
        phi = 3.0 * amax
    FS = KT * phi * (chi + 1.0) / (chi + 2.0)
    if name == "segalman":
        return LAWS["segalman"](F_S=FS, K_T=KT, chi=chi, beta=0.0)
    if name == "iwan":
        return LAWS["iwan"](k=KT, fs_max=FS)
    if name == "jenkins":
        return LAWS["jenkins"](k=KT, fs=0.5 * FS)
    raise InputError(f"law {name!r}: start values from a table are known for segalman, iwan and "
                     "jenkins; give a law instance to start from")  # fmt: skip


def _resolve(law: Any, A: np.ndarray, E: np.ndarray | None, k: np.ndarray | None) -> Any:
    from .laws import JointLaw

    if isinstance(law, JointLaw):
        return law
    if isinstance(law, str):
        return _start_from_table(law.lower(), A, E, k)
    raise InputError(f"law must be a name or a law instance, got {type(law).__name__}")


def fit_amplitude(
    amplitude: Any,
    *,
    damping: Any = None,
    energy: Any = None,
    stiffness: Any = None,
    stiffness_kind: str = "k_eq",
    frequency: Any = None,
    law: Any = "segalman",
    fixed: Sequence[str] | None = None,
    bounds: Mapping[str, tuple[float, float]] | None = None,
    viscous: bool = False,
) -> AmplitudeFit:
    """Fit a law to amplitude-dependent properties: equivalent damping [N s/m], energy per
    cycle [J] and/or stiffness [N/m] against displacement amplitude [m].

    Residuals are relative (``model / measured − 1``), so every column and amplitude weighs
    alike.

    Parameters
    ----------
    amplitude : array
        Displacement amplitudes, m (> 0).
    damping, energy, stiffness : array, optional
        Measured equivalent viscous damping ``c_eq = E / (π ω A²)`` (needs ``frequency``),
        energy per cycle, and stiffness (``stiffness_kind``: "k_eq" first-harmonic or
        "k_secant" backbone secant).
    frequency : float or array, optional
        Frequency of the cycles, Hz (one, or one per amplitude).
    law : str or law
        "segalman" (default), "iwan", "jenkins" started from the table, or a law instance.
    fixed : names, optional
        Parameters held. Default: Segalman's ``beta``, and without a stiffness column its
        ``K_T`` (Iwan's ``k``), which micro-slip damping cannot separate from the others
        (the result's notes say so).
    viscous : bool
        Add a linear viscous damping ``c0`` [N s/m] to ``c_eq`` (structural damping besides
        the joint's).

    Returns
    -------
    AmplitudeFit
        With ``failures`` per amplitude; ``success=False`` when the fit did not converge.
    """
    A, _ = _amplitudes(amplitude)
    cols: dict[str, np.ndarray] = {}
    for key, val in (("c_eq", damping), ("energy", energy), (stiffness_kind, stiffness)):
        if val is not None:
            v = as_1d(val, key)
            if v.size != A.size:
                raise InputError(f"{key} has {v.size} values for {A.size} amplitudes")
            if not np.all(v != 0):
                raise InputError(f"{key}[{int(np.argmax(v == 0))}] is 0: relative residuals "
                                 "need non-zero measured values")  # fmt: skip
            cols[key] = v
    if stiffness_kind not in ("k_eq", "k_secant"):
        raise InputError(f"stiffness_kind must be 'k_eq' or 'k_secant', got {stiffness_kind!r}")
    if not cols:
        raise InputError("give at least one of damping, energy, stiffness")
    freq = None
    if frequency is not None:
        fa = np.broadcast_to(np.asarray(frequency, dtype=float), A.shape).copy()
        if not np.all(np.isfinite(fa) & (fa > 0)):
            raise InputError("frequency must be finite and > 0 Hz")
        freq = fa
    if "c_eq" in cols and freq is None:
        raise InputError("damping (c_eq = E / (π ω A²)) needs the frequency")
    E_meas = cols.get("energy")
    if E_meas is None and "c_eq" in cols:
        E_meas = cols["c_eq"] * math.pi * 2.0 * math.pi * freq * A**2
    start = _resolve(law, A, E_meas, cols.get(stiffness_kind))
    fixed_set, why = _default_fixed(start, fixed, stiffness_kind in cols)
    params = _law_params(start, fixed_set, bounds)
    if viscous:
        if "c_eq" not in cols:
            raise InputError("viscous=True adds to c_eq: give damping")
        params["c0"] = Parameter("c0", 0.05 * float(np.min(cols["c_eq"])), min=0.0,
                                 unit="N s/m")  # fmt: skip
    names = list(start.param_names)
    f_single = float(np.median(freq)) if freq is not None else None
    last_fail: dict[int, str] = {}

    def predict(v: Mapping[str, float]) -> tuple[dict[str, np.ndarray], dict[int, str]]:
        lw = start.with_params([v[n] for n in names])
        p = equivalent_properties(lw, A, f_single)
        out = {"energy": p.energy, "k_eq": p.k_eq, "k_secant": p.k_secant}
        if freq is not None:
            out["c_eq"] = p.energy / (math.pi * 2.0 * math.pi * freq * A**2) + v.get("c0", 0.0)
        return out, p.failures

    def residual(v: Mapping[str, float]) -> np.ndarray:
        pred, fails = predict(v)
        last_fail.clear()
        last_fail.update(fails)
        r = np.concatenate([pred[k] / cols[k] - 1.0 for k in cols])
        return np.where(np.isfinite(r), r, 10.0)  # an amplitude the law failed at: penalised

    res = least_squares_fit(residual, params)
    if why:
        res.notes.append(f"held: {why}")
    _mark_identifiability(res)
    pred, fails = predict(res.values)
    fitted = start.with_params([res.params[n].value for n in names])
    res.notes.extend(out_of_range_notes(fitted))
    return AmplitudeFit(fitted, res, A, cols, {k: pred[k] for k in cols}, f_single, fails)


# ----------------------------------------------------------------------------------------
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


#: parameters a damping-dominated fit holds by default, and why
_HELD = {
    "segalman": (
        ("beta", "K_T"),
        "in micro-slip the energy and the loss of stiffness depend "
        "only on χ and R = F_S (χ+1) / (φmax^(χ+2) (β + (χ+1)/(χ+2))), not on K_T, "
        "F_S and β apart (Segalman 2005); K_T and β are held, F_S carries R",
    ),
    "iwan": (
        ("k",),
        "in micro-slip the energy k² A³ / (3 fs_max) depends only on "
        "k² / fs_max; k is held, fs_max carries the ratio",
    ),
}


def _default_fixed(law: Any, fixed: Sequence[str] | None, stiffness_given: bool
                   ) -> tuple[set[str], str | None]:  # fmt: skip
    """The parameters to hold and a note saying why (None when ``fixed`` was given)."""
    if fixed is not None:
        return set(fixed), None
    held, why = _HELD.get(law.name, ((), None))
    if law.name == "segalman" and stiffness_given:
        return {"beta"}, None
    if law.name == "iwan" and stiffness_given:
        return set(), None
    return set(held), why


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
    f = np.concatenate([s.frequency for s in sw])
    F = np.concatenate([s.force for s in sw])
    X = np.concatenate([s.displacement * np.exp(1j * s.phase) for s in sw])
    A = np.abs(X)
    w = 2.0 * math.pi * f
    K = F / X
    if not np.all(K.imag > 0):
        i = int(np.argmax(~(K.imag > 0)))
        raise InputError(f"point {i} ({f[i]:.4g} Hz): the response leads the force (phase "
                         f"{np.angle(X[i]):.3g} rad), which a passive mode cannot do")  # fmt: skip
    res_pts = [p for s in sw if (p := s.phase_resonance()) is not None]
    if not res_pts:
        raise InputError("no sweep crosses phase resonance (−π/2): cannot start the fit")
    Ar = np.array([p["displacement"] for p in res_pts])
    cr = np.array([p["c_eq"] for p in res_pts])
    fr = np.array([p["frequency"] for p in res_pts])
    order = np.argsort(Ar)
    Ar, cr, fr = Ar[order], cr[order], fr[order]
    # viscous part: half the damping at the smallest amplitude, the joint's the rest
    c0_start = max(0.5 * float(cr[0]), 1e-12)
    E_start = np.clip(cr - c0_start, 1e-3 * cr, None) * math.pi * 2 * math.pi * fr * Ar**2
    start = _resolve(law, Ar, E_start, None)
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

    zero = np.zeros_like(w)
    # linear columns (k, m, c0) of the two residual parts
    Lr = np.concatenate([np.stack([1.0 / sR, -(w**2) / sR, zero], axis=1),
                         np.stack([zero, zero, w / sI], axis=1)], axis=0)  # fmt: skip
    lin_names = ["k", "m", "c0"]
    lin_units = ["N/m", "kg", "N s/m"]
    if sweep_stiffness:
        # each sweep's own modal stiffness change (a drift between sweeps), relative to k
        sizes = [s.frequency.size for s in sw]
        start_i = np.cumsum([0, *sizes])
        for j in range(1, len(sw)):
            col = np.zeros(2 * A.size)
            col[start_i[j] : start_i[j + 1]] = 1.0 / sR[start_i[j] : start_i[j + 1]]
            Lr = np.column_stack([Lr, col])
            lin_names.append(f"dk_{j}")
            lin_units.append("N/m")

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
