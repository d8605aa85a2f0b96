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
