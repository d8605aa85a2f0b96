"""Normal contact: the linear Kelvin-Voigt base model and its candidate extensions.

Base model (PHYSICS.md §2, Konowalski 2009 eqs. 8-15): ``p = k δ + h δ'`` with
``h = ψ k / (2π ω)``, driven by the measured dynamic pressure ``p(t) - p0`` and predicting
the measured displacement ``δ(t)``. ``p0``, the static pressure at which ``δ`` was zeroed,
is fitted with ``k`` and ``ψ`` (the mean of a recording of whole cycles is only close to
it); ``ω``, the angular frequency at which ψ holds, is the excitation's, estimated from the
recording. Evaluated by its exact solution under the pressure between samples that
:class:`contactlab.normal.KelvinVoigt` integrates (:func:`kelvin_voigt_exact`: a linear
first-order response, 15-50 times faster than the package's adaptive integrator, which
approximates it to its tolerance; kept per ψ, as the fits step the other parameters at a
fixed ψ most of the time; computed by the Rust fixed-grid integrator with a constant
stiffness, :func:`_unit_response`); the stiffness candidates by
:meth:`contactlab.normal.NonlinearContact.simulate_grid` (eq. 17 on the record's own
samples; see :data:`GRID_STEPS_PER_PERIOD` for its error against the adaptive solve).

Candidates (name: model, parameters):

- ``stiffness_nonlinearity``: ``k_s(δ) = k (1 + κ1 δ/δ_r + κ (δ/δ_r)²)`` in eq. 17 — the
  paper's own step from the linear to the nonlinear model (eq. 6: ``k_s = a1 + a2 δ + a3
  δ²``): a function of δ that bends both branches of the loop together; ``kappa1``,
  ``kappa``.
- ``asymmetric_branches``: ``p - p0 = k_s δ + h (1 + a sgn δ') δ'`` — loading (δ' > 0) and
  unloading dissipate differently (docs/effects.md §2): an even, rate-locked distortion
  ``a h |δ'|`` of the centre curve that grows with the frequency; ``a``.
- ``hysteretic_damping``: a rate-independent loss ``η k`` besides the viscous one, in the
  frequency domain ``δ̂ = p̂ / (k + i ω h + i η k sgn ω)``; ``eta``.
- ``creep_drift``: ``δ += D (1 - exp(-t/τ_c))``, the joint settling over the cycles;
  ``D`` (m), ``tau_c`` (s).
- ``channel_delay``: ``δ(t) = δ_model(t - τ)``, the displacement channel lags; ``tau`` (s).
  Between samples by Keys' cubic convolution (:func:`~._signal.shift_cubic`): flat over the
  band the filtered input noise lives in, so a fraction of a sample smooths nothing.

Identifiability. A channel delay ``τ`` and the Kelvin-Voigt damping give the same first-order
phase lag at every frequency (``ω τ`` against ``ω h / k``); they differ only in second
order: the damping also lowers the amplitude by ``1/√(1 + (ω h/k)²)``, a drop that grows
with ω². At one frequency the fitted ``k`` absorbs that drop, so a delay is not identifiable
there: :func:`delay_identifiability` says so in the report (with the largest delay the
fitted ψ could hide) and the delay is not named. Across excitation blocks at different
frequencies the drop is not one constant; its signature lives in the blocks farthest from
the mean frequency, so the delay's held-out gain is concentrated in a few cycles and the
family uses the proportional-gain form of the consistency rule (:mod:`.select`,
``proportional_gain``). Below about 0.05 σ² of held-out gain (5 % delay at 1 % output noise)
the second-order signature is under the noise and nothing is named.

``δ_r`` is the RMS of the measured displacement, so ``kappa1`` and ``kappa`` are
dimensionless; the paper's eq. 6 coefficients follow as ``a1 = k``, ``a2 = k κ1 / δ_r``,
``a3 = k κ / δ_r²``. The stiffness candidate keeps the linear joint's viscous damping
(:func:`nonlinear_viscous`: :class:`contactlab.normal.NonlinearContact`'s eq. 17, whose
damping ``ψ k_s / (2π ω)`` follows the stiffness, by its fixed-grid route
:meth:`~contactlab.normal.NonlinearContact.simulate_grid`, corrected to a constant damping);
the loss asymmetry is solved on the linear joint (:func:`kelvin_voigt_asymmetric`). The hysteretic
model is linear and solved by FFT on a smooth periodic continuation of the record (its ideal
form is non-causal, so it has no time-domain integrator); for ``η = 0`` it reproduces the
Kelvin-Voigt integration. Hysteretic damping combined with a stiffness nonlinearity is not offered.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from .. import _core
from .._arrays import next_fast_len
from ..errors import ConvergenceError, InputError
from ._family import Candidate, ParamSpec, Prepared
from ._filters import first_order_response, savgol_coeffs, savgol_filter, welch
from ._kept import shifted
from ._signal import cubic_shift_power, shortest_period_samples
from .effects import ordered, registry
from .effects.normal.channel_delay import SINGLE_TONE_SPAN, frequency_span
from .effects.normal.creep_drift import CREEP_MAX_DURATIONS, CREEP_MIN_PERIODS

_INF = np.inf

#: the library: one :class:`~contactlab.diagnose.effects.EffectModel` per file under
#: ``diagnose/effects/normal/`` (parameters, bounds, what it does, its plausibility)
EFFECTS = registry("normal")
CANDIDATES: dict[str, Candidate] = {name: e.candidate for name, e in EFFECTS.items()}

BASE_PARAMS = (
    ParamSpec("k", "Pa/m", _INF, 0.0, _INF, "k"),
    ParamSpec("psi", "-", _INF, 1e-6, 10.0, "psi"),
    ParamSpec("p0", "Pa", _INF, -_INF, _INF, "p"),
)


#: Relative tolerance of the ODE solves: far below any sensor noise, and cheap.
RTOL = 1e-6
#: Step attempts a solve may take per sample (plus a fixed allowance): fitted models need
#: a few per sample (at most 5 in the slowest fuzz input); a trial parameter set needing
#: far more is stopped there and treated as a failed solve (see _delta), which bounds the
#: cost of one evaluation instead of letting a fit's trial point run unbounded.
MAX_STEPS_PER_SAMPLE = 50


def _max_steps(n: int) -> int:
    return MAX_STEPS_PER_SAMPLE * n + 1000


def _delta(res: Any, n: int) -> np.ndarray:
    """Displacement from an :class:`~contactlab.normal.OdeResult`.

    A solve that stopped early (``success`` False, e.g. a trial stiffness that is not
    positive) gives the samples reached, then holds the last value: a finite, large residual
    that steers the optimiser away instead of aborting the fit.
    """
    d = np.asarray(res.delta, dtype=float)
    if res.success and d.size == n:
        return d
    out = np.empty(n)
    m = d.size
    out[:m] = d
    out[m:] = d[-1] if m else 0.0
    return out


def kelvin_voigt(t: np.ndarray, pd: np.ndarray, k: float, psi: float, omega: float) -> np.ndarray:
    """Linear Kelvin-Voigt response via :class:`contactlab.normal.KelvinVoigt`."""
    from ..normal import KelvinVoigt

    res = KelvinVoigt(k, psi, omega).simulate(t, pd, rtol=RTOL, max_steps=_max_steps(pd.size))
    return _delta(res, pd.size)


def kelvin_voigt_exact(
    t: np.ndarray, pd: np.ndarray, k: float, psi: float, omega: float
) -> np.ndarray:
    """The linear Kelvin-Voigt response the diagnosis fits: the exact solution of
    ``p = k δ + h δ'`` from equilibrium with ``p(t0)``, the pressure between samples the
    cubic Hermite interpolant :class:`contactlab.normal.KelvinVoigt` integrates
    (:func:`contactlab.diagnose._filters.first_order_response`). :func:`kelvin_voigt`'s
    adaptive solve approximates it to :data:`RTOL` (measured: 3e-6 of the displacement's
    range at ψ = 0.09, 26 samples per period, against 4e-11 for this one, both against
    the solver at 1e-11) and takes 15-50 times as long: a stiff step (``ω Δt / ψ`` of 20 on
    a decimated record) needs several solver steps per sample."""
    from ..normal import KelvinVoigt

    kv = KelvinVoigt(k, psi, omega)  # refuses k, ψ, ω as the solver's route does
    return first_order_response(t, pd, 2.0 * np.pi * omega / psi, 1.0 / k, kv.equilibrium(pd[0]))


def kelvin_voigt_asymmetric(
    t: np.ndarray,
    pd: np.ndarray,
    k: float,
    psi: float,
    omega: float,
    a: float,
    dpdt: np.ndarray | None = None,
    start: np.ndarray | None = None,
    passes: int = 4,
    tol: float = 0.0,
) -> np.ndarray:
    """``pd = k δ + h (1 + a sgn δ') δ'`` (``h = ψ k / (2π ω)``) from equilibrium with
    ``pd[0]``: the Kelvin-Voigt joint whose loading branch (``δ' > 0``) is damped by
    ``h (1 + a)`` and unloading by ``h (1 - a)`` (``asymmetric_branches``, docs/effects.md §2).

    The sign of ``δ'`` is that of ``R = pd - k δ``, the pressure the damping carries. On a
    step where ``R`` keeps its sign the equation is linear, ``δ' = k/(h (1 + a s)) (pd/k -
    δ)``, and :func:`contactlab.diagnose._filters.first_order_response` solves it exactly under the
    cubic Hermite pressure (slopes ``dpdt`` at the samples, else differences); a step where
    ``R`` changes sign (a turning point) is split where it does (``R`` linear between the
    samples, the pressure the same cubic on both parts), so the solution is a smooth
    function of the parameters and a record sampled 15 times a cycle stays close to the
    full-rate one. ``R`` comes from ``start`` (a displacement near the
    solution, e.g. the symmetric joint's; else that is solved first) and is updated
    ``passes`` times, each from the mean of the last two solutions (each pass changes only
    the steps at the turning points; the fits take 4, the generator up to 50, until a pass
    changes ``δ`` by less than ``tol`` of its largest value).

    Parameters
    ----------
    t, pd : numpy.ndarray
        Sample times (s) and dynamic pressure ``p - p0`` (Pa).
    k, psi, omega : float
        Contact stiffness (Pa/m), energy dissipation coefficient (-) and the angular
        frequency (rad/s) at which ``ψ`` holds: ``h = ψ k / (2π ω)``.
    a : float
        Loss asymmetry, ``|a| < 1``; ``a > 0`` damps loading more.
    dpdt : numpy.ndarray, optional
        Pressure slopes at the samples (a kept long record's, from the raw rate).
    start : numpy.ndarray, optional
        A displacement near the solution to take the signs of ``R`` from.
    passes, tol : int, float
        Sign updates at most, and the relative change that ends them early.

    Returns
    -------
    numpy.ndarray
        ``δ`` at the samples (m).

    Raises
    ------
    InputError
        ``k`` or ``h`` not positive, or ``|a| >= 1``.
    """

    h = psi * k / (2.0 * np.pi * omega)
    if not (k > 0.0 and h > 0.0 and abs(a) < 1.0):
        raise InputError(f"asymmetric Kelvin-Voigt joint needs k, h > 0 and |a| < 1 (a = {a:g})")
    dt = np.diff(t)
    m = np.gradient(pd, t, edge_order=2) if dpdt is None else np.asarray(dpdt, float)
    m0, m1 = dt * m[:-1], dt * m[1:]
    p0, p1 = pd[:-1], pd[1:]
    coeffs = (dt, p0, m0, 3.0 * (p1 - p0) - 2.0 * m0 - m1, 2.0 * (p0 - p1) + m0 + m1)
    y0 = float(pd[0]) / k
    y = first_order_response(t, pd, k / h, 1.0 / k, y0, coeffs) if start is None else start
    up, down = (k / h) / (1.0 + a), (k / h) / (1.0 - a)
    _, c0, c1, c2, c3 = coeffs
    last = None
    for _ in range(passes):
        r = pd - k * y
        r0, r1 = r[:-1], r[1:]
        lam0 = np.where(r0 > 0.0, up, np.where(r0 < 0.0, down, np.where(r1 >= 0.0, up, down)))
        lam1 = np.where(r1 > 0.0, up, down)
        at = np.flatnonzero(r0 * r1 < 0.0)  # steps with a turning point: split there
        u = r0[at] / (r0[at] - r1[at])
        ps = c0[at] + u * (c1[at] + u * (c2[at] + u * c3[at]))
        ms = (c1[at] + u * (2.0 * c2[at] + 3.0 * u * c3[at])) / dt[at]
        ta = np.insert(t, at + 1, t[at] + u * dt[at])
        pa, ma = np.insert(pd, at + 1, ps), np.insert(m, at + 1, ms)
        da = np.diff(ta)
        n0, n1 = da * ma[:-1], da * ma[1:]
        q0, q1 = pa[:-1], pa[1:]
        ca = (da, q0, n0, 3.0 * (q1 - q0) - 2.0 * n0 - n1, 2.0 * (q0 - q1) + n0 + n1)
        rate = np.insert(lam0, at + 1, lam1[at])
        new = np.delete(
            first_order_response(ta, pa, rate, 1.0 / k, y0, ca), at + 1 + np.arange(at.size)
        )
        done = float(np.max(np.abs(new - y))) <= tol * float(np.max(np.abs(new)))
        y, last = (new, new) if last is None else (0.5 * (new + last), new)
        if done:
            break
    return last if last is not None else y


#: stiffness-law responses kept per recording (a Jacobian's columns: up to 7 parameters)
_NONLINEAR_KEEP = 8
#: unit responses kept per recording (one per ψ, ω tried); 64 of 24 000 samples: 12 MB
_UNIT_KEEP = 64


def _kelvin_voigt_fit(d: Prepared, k: float, psi: float, p0: float, omega: float) -> np.ndarray:
    """:func:`kelvin_voigt_exact` of ``d.u - p0`` as ``(R - p0) / k``: the response is
    linear in the pressure and in ``1/k`` at fixed ``h/k`` (i.e. ψ, ω), and a constant
    pressure from equilibrium stays there, so ``R`` — the unit-stiffness response to the
    measured pressure ``d.u`` — is kept per ``(ψ, ω)``; a fit steps ``k``, ``p0`` and the
    effects' parameters at a fixed ψ for most of its evaluations (to rounding, 1e-16 of
    ``max|d.u| / k``, the same)."""
    from ..normal import KelvinVoigt

    KelvinVoigt(k, psi, omega)  # refuses k, ψ, ω as the solver's route does
    cache = d.extra.setdefault("kv_unit", {})
    key = (psi, omega, d.t.size)
    unit = cache.get(key)
    if unit is None:
        unit = _unit_response(d.t, d.u, psi, omega, d.extra.get("u_slope"))
        unit.flags.writeable = False
        if len(cache) >= _UNIT_KEEP:
            cache.clear()
        cache[key] = unit
    return (unit - p0) / k


def _unit_response(
    t: np.ndarray, u: np.ndarray, psi: float, omega: float, dudt: np.ndarray | None = None
) -> np.ndarray:
    """The unit-stiffness Kelvin-Voigt response to ``u`` from equilibrium with ``u[0]``:
    :func:`contactlab.diagnose._filters.first_order_response` (``a = 2π ω / ψ``, gain 1),
    computed by the Rust fixed-grid integrator with a constant stiffness, which is that exact
    solution under the same cubic Hermite pressure (to 1e-9 of the range, tested) in one pass
    instead of numpy's blocked scan (4-5 times faster at 24 000 samples). ``dudt``: the
    pressure's slopes at the samples (a kept long record's, from the raw rate), else finite
    differences."""
    # (the step's equation is linear for a constant stiffness: solved exactly, ``tol`` unused)
    # (t of a decimated record is a strided view: the core takes contiguous arrays)
    tc, uc = np.ascontiguousarray(t, dtype=float), np.ascontiguousarray(u, dtype=float)
    r = _core.normal_simulate_grid(
        tc, uc, "constant", np.ones(1), psi, omega, float(u[0]), 1, 1.0, dudt
    )
    if int(r.status) != 0:
        raise ConvergenceError(f"Kelvin-Voigt response: {r.message}")
    return np.asarray(r.delta)


def _creep_shape(d: Prepared, tc: float) -> np.ndarray:
    """``1 - exp(-(t - t0)/τ_c)`` of ``creep_drift``, kept per ``τ_c`` (only a step of
    ``τ_c`` changes it)."""
    cache = d.extra.setdefault("creep_shape", {})
    key = (tc, d.t.size)
    shape = cache.get(key)
    if shape is None:
        shape = -np.expm1(-(d.t - d.t[0]) / tc)
        shape.flags.writeable = False
        if len(cache) >= _UNIT_KEEP:
            cache.clear()
        cache[key] = shape
    return shape


#: steps per period of the excitation at least, for :meth:`NonlinearContact.simulate_grid`
#: (the base step; the grid's local error control refines any sample interval whose error
#: estimate exceeds its tolerance, 3e-5 of the displacement scale). Against the adaptive
#: solve at rtol 1e-11, three-tone blocks: at 24/48/96 samples per period one step per sample
#: is 1.9e-6/4.3e-7/1.4e-7 of the range at κ = 3, below 1e-6 at the asymmetric and soft laws;
#: 300 random laws over the candidates' bounds (ψ 0.005-1, 32-2000 samples per period) stay
#: within the test's 1e-4. 96 steps per period (before the error control) cost 2-3× the
#: work on a 1e6-sample record's kept samples for no change in what is named (eval_diagnose
#: normal, 104/104 cases, held-out/noise within 7e-5).
GRID_STEPS_PER_PERIOD = 32


def grid_substeps(t: np.ndarray, omega: float) -> int:
    """Equal steps per sample interval that give :data:`GRID_STEPS_PER_PERIOD` per period
    ``2π/ω`` (at the longest interval)."""
    dt = float(np.max(np.diff(t))) if t.size > 1 else 0.0
    per = 2.0 * np.pi / (omega * dt) if dt > 0 else np.inf
    return int(min(max(1, np.ceil(GRID_STEPS_PER_PERIOD / per)), 1024))


def nonlinear(
    t: np.ndarray,
    pd: np.ndarray,
    coeffs: tuple[float, ...],
    psi: float,
    omega: float,
    dpdt: np.ndarray | None = None,
) -> np.ndarray:
    """Eq. 17 with ``k_s(δ) = Σ coeffs[i] δ^i``, via
    :meth:`contactlab.normal.NonlinearContact.simulate_grid` (the fixed-grid integrator on
    the record's samples, :func:`grid_substeps` steps per interval: 3-7 times faster than
    the adaptive :meth:`~contactlab.normal.NonlinearContact.simulate` at :data:`RTOL`; its
    error, far below the noise, is given at :data:`GRID_STEPS_PER_PERIOD`). ``dpdt``: the
    pressure's slopes at the samples, if known."""
    from ..normal import NonlinearContact

    model = NonlinearContact(k_s_delta=list(coeffs), psi=psi, omega=omega)
    res = model.simulate_grid(t, pd, substeps=grid_substeps(t, omega), dpdt=dpdt)
    return _delta(res, pd.size)


#: passes of :func:`nonlinear_viscous`'s damping correction in a fit (the generator's
#: reference runs them to convergence)
VISCOUS_PASSES = 1


def nonlinear_viscous(
    t: np.ndarray,
    pd: np.ndarray,
    coeffs: tuple[float, ...],
    psi: float,
    omega: float,
    dpdt: np.ndarray | None = None,
    passes: int = VISCOUS_PASSES,
) -> np.ndarray:
    """``pd = k_s(δ) δ + c δ'`` with a constant damping ``c = ψ a1 / (2π ω)``
    (``stiffness_nonlinearity`` of docs/effects.md §2: the stiffness law changes, the
    viscous damping stays that of the linear joint).

    :func:`nonlinear` solves eq. 17, whose damping ``h_s = ψ k_s(δ) / (2π ω)`` follows the
    stiffness; the difference ``(h_s - c) δ'`` is given back as a pressure from the previous
    pass's ``δ`` and ``δ'`` (the integrator's own rate at the samples), ``passes`` times. It is
    ``|k_s/a1 - 1|`` of the damping pressure (a few per cent of 1.4 % of ``p`` at ψ = 0.09),
    and each pass leaves that fraction of the previous error: one pass is within 1e-5 of
    ``δ`` at a 15 % stiffness change (tested against the adaptive solve of the same equation).

    Parameters
    ----------
    t, pd : numpy.ndarray
        Sample times (s) and dynamic pressure ``p - p0`` (Pa).
    coeffs : tuple of float
        ``k_s(δ) = Σ coeffs[i] δ^i`` (Pa/m, Pa/m², Pa/m³), ``coeffs[0]`` the linear stiffness.
    psi, omega : float
        Energy dissipation coefficient (-) and the angular frequency (rad/s) it holds at.
    dpdt : numpy.ndarray, optional
        Pressure slopes at the samples, if known.
    passes : int
        Damping corrections (:data:`VISCOUS_PASSES` in a fit).

    Returns
    -------
    numpy.ndarray
        ``δ`` at the samples (m); a solve that stops early holds its last value
        (:func:`_delta`).
    """
    from ..normal import NonlinearContact

    model = NonlinearContact(k_s_delta=list(coeffs), psi=psi, omega=omega)
    sub = grid_substeps(t, omega)
    res = model.simulate_grid(t, pd, substeps=sub, dpdt=dpdt)
    delta = _delta(res, pd.size)
    if not (res.success and res.delta.size == pd.size):
        return delta
    vel = np.asarray(res.velocity, float)
    scale = psi / (2.0 * np.pi * omega)
    for _ in range(passes):
        ks = np.polynomial.polynomial.polyval(delta, coeffs)
        e = scale * (ks - coeffs[0]) * vel
        slope = None if dpdt is None else dpdt + np.gradient(e, t)
        res = model.simulate_grid(t, pd + e, substeps=sub, dpdt=slope)
        delta = _delta(res, pd.size)
        if not (res.success and res.delta.size == pd.size):
            return delta
        vel = np.asarray(res.velocity, float)
    return delta


def nonlinear_adaptive(
    t: np.ndarray, pd: np.ndarray, coeffs: tuple[float, ...], psi: float, omega: float
) -> np.ndarray:
    """:func:`nonlinear` by the adaptive solve (RODAS4 at :data:`RTOL`): the reference the
    fixed-grid route is checked against."""
    from ..normal import NonlinearContact

    model = NonlinearContact(k_s_delta=list(coeffs), psi=psi, omega=omega)
    return _delta(model.simulate(t, pd, rtol=RTOL, max_steps=_max_steps(pd.size)), pd.size)


def frequency_domain(
    t: np.ndarray,
    pd: np.ndarray,
    k: float,
    psi: float,
    omega: float,
    eta: float,
    history: np.ndarray | None = None,
) -> np.ndarray:
    """``δ̂ = p̂ / (k + i ω h + i η k sgn ω)`` on a periodic continuation of the record.

    The record is continued by a raised-cosine blend from its last value back to its first
    (at least as long as the record and ten Kelvin-Voigt time constants), so the continuation
    is smooth, the record starts in equilibrium with ``p(t0)`` (as the time-domain models do)
    and the non-local hysteretic kernel sees no artificial jump. ``history``: pressure
    samples before the record (at the same spacing) that the joint saw; the response is
    computed over them and returned for the record only.
    """
    if history is not None and history.size:
        m0 = history.size
        full = np.concatenate([history, pd])
        tt = t[0] + (np.arange(full.size) - m0) * float(t[1] - t[0])
        return frequency_domain(tt, full, k, psi, omega, eta)[m0:]
    n = pd.size
    dt = float(t[1] - t[0])
    tau_kv = psi / (2.0 * np.pi * omega)
    pad = int(min(max(n, 10 * tau_kv / dt), 50 * n))
    m = next_fast_len(n + pad, real=True)
    s = np.linspace(0.0, 1.0, m - n + 2)[1:-1]
    blend = pd[-1] + (pd[0] - pd[-1]) * 0.5 * (1.0 - np.cos(np.pi * s))
    # numpy's FFT (pocketfft, as scipy.fft: the same values to the last bit) spares
    # importing scipy.fft, a third of a second of a diagnosis
    P = np.fft.rfft(np.concatenate([pd, blend]))
    w = 2.0 * np.pi * np.fft.rfftfreq(m, dt)
    h = psi * k / (2.0 * np.pi * omega)
    sgn = np.sign(w)
    return np.fft.irfft(P / (k + 1j * w * h + 1j * eta * k * sgn), m)[:n]


#: rule 2's large-gain route of the normal family (:func:`.select._strong_pass`): a
#: held-out gain of at least ``STRONG_GAIN[0]`` times the gain floor (``min_gain`` σ² scaled
#: by :func:`gain_scale`) passes at ``t > STRONG_GAIN[1]`` instead of ``z``. Calibrated on
#: clean single-tone chains from rest (``benches/eval_normal_calibrate.py``, see
#: docs/effects.md §2)
STRONG_GAIN = (2.0, 2.0)


@dataclass(frozen=True)
class NormalContext:
    """What a normal-contact effect's ``apply`` sees: the record and the family (its
    numerics: the hysteretic solve, the creep's shape)."""

    d: Prepared
    family: NormalFamily


class NormalFamily:
    """Kelvin-Voigt base model with the normal-contact candidate library."""

    kind = "normal"
    #: rule 2 of :mod:`.select` may pass by the proportional-gain test: the record's
    #: excitation blocks differ in frequency and amplitude, and an effect's signature (a
    #: delay's amplitude error ∝ ω² once ψ has absorbed its phase, a nonlinearity's ∝ the
    #: amplitude) lives in some blocks only
    proportional_gain = True
    #: the model evaluations release the GIL for milliseconds each (the integrator): a fit's
    #: finite-difference columns run on threads (:func:`._parallel.column_map`)
    parallel_jacobian = True
    #: rule 2's large-gain route (:func:`.select._strong_pass`, :data:`STRONG_GAIN`)
    strong_gain = STRONG_GAIN
    #: the polish after each fit stops at steps below :data:`.select.POLISH_STOP` standard
    #: errors (its central-difference Jacobians were half of a diagnosis' evaluations)
    quick_polish = True
    base_params = BASE_PARAMS
    candidates = CANDIDATES
    input_name = "p"
    output_name = "delta"
    input_unit = "Pa"
    output_unit = "m"

    def prepare(self, d: Prepared) -> None:
        """Mean pressure, excitation angular frequency and displacement scale; the input the
        candidates see smoothed as far as the excitation's band allows (:func:`smooth_input`).

        Values already in ``d.extra`` (from a fitted model's context) are kept: ``omega`` and
        ``delta_r`` belong to the model's parameters.
        """
        d.extra.setdefault("omega", 2.0 * np.pi / (d.cycles.period_samples * d.dt))
        d.extra.setdefault("gain_scale", gain_scale(d.y.size))
        smooth_input(d)
        if "delta_r" not in d.extra:
            if not np.isfinite(d.y).all():
                raise InputError("delta_r is needed to simulate a fitted normal model")
            d.extra["delta_r"] = float(np.sqrt(np.mean(d.y * d.y))) or 1.0

    def context(self, d: Prepared) -> dict[str, float]:
        """What a fitted model needs to be simulated on another excitation."""
        return {"omega": d.extra["omega"], "delta_r": d.extra["delta_r"]}

    def scales(self, d: Prepared) -> dict[str, float]:
        pd = d.u - np.mean(d.u)
        dr = d.extra["delta_r"]
        pr = float(np.sqrt(np.mean(pd * pd)))
        return {
            "k": pr / dr,
            "p": 0.1 * pr,
            "psi": 0.1,
            "one": 1.0,
            "delta": dr,
            "T": d.duration,
            "tau": d.cycles.period_samples * d.dt / 100.0,
        }

    def initial_base(self, d: Prepared) -> dict[str, float]:
        p0 = float(np.mean(d.u))
        pd = d.u - p0
        k = float(pd @ pd) / float(pd @ d.y) if float(pd @ d.y) > 0 else self.scales(d)["k"]
        return {"k": abs(k), "psi": 0.1, "p0": p0}

    def start_effect(
        self, name: str, p: dict[str, float], d: Prepared, residual: np.ndarray
    ) -> dict[str, float]:
        """Starting values of an effect's nonlinear parameters from the current residual
        (the effect's own :meth:`~contactlab.diagnose.effects.EffectModel.start`)."""
        return EFFECTS[name].start(p, d, residual, family=self)

    @staticmethod
    def creep_start(p: dict[str, float], d: Prepared, residual: np.ndarray) -> dict[str, float]:
        """Starting values of ``creep_drift`` from the current residual (measured minus
        model): the ``τ_c`` of :data:`CREEP_START_GRID` whose shape ``1 - exp(-t/τ_c)``,
        its mean removed, explains most of it, ``D`` its least-squares size, and ``p0``
        moved to take that mean back (a constant displacement is ``-Δp0 / k``); nothing
        for the other candidates."""
        r = residual - np.mean(residual)
        best, start = -1.0, {}
        period = d.cycles.period_samples * d.dt
        for tc in np.geomspace(CREEP_MIN_PERIODS * period, CREEP_MAX_DURATIONS * d.duration,
                               CREEP_START_GRID):  # fmt: skip
            sh = _creep_shape(d, float(tc))
            sh = sh - np.mean(sh)
            ss = float(sh @ sh)
            if ss <= 0:
                continue
            sr = float(sh @ r)
            if sr * sr / ss > best:
                best, start = sr * sr / ss, {"D": sr / ss, "tau_c": float(tc)}
        if start:  # p0 takes the drift's mean back: δ = (p - p0) / k at the base
            mean = float(np.mean(_creep_shape(d, start["tau_c"])))
            start["p0"] = p["p0"] + p["k"] * start["D"] * mean
        return start

    def check(self, effects: tuple[str, ...]) -> bool:
        """Whether these effects can be combined: one of the stiffness law, the hysteretic
        element and the loss asymmetry (the last is solved on the linear Kelvin-Voigt joint,
        :func:`kelvin_voigt_asymmetric`; each is a different account of the loop's shape
        beyond the ellipse, so two are never named together)."""
        es = set(effects)
        shaped = {"stiffness_nonlinearity", "hysteretic_damping", "asymmetric_branches"} & es
        return len(shaped) <= 1

    def predict(self, p: dict[str, float], effects: tuple[str, ...], d: Prepared) -> np.ndarray:
        """Measured displacement predicted for the measured pressure ``d.u``."""
        if not self.check(effects):
            raise InputError(
                "one of stiffness_nonlinearity, hysteretic_damping and asymmetric_branches "
                "at a time"
            )
        if "channel_delay" in effects and "raw_input" in d.extra and p["tau"] != 0.0:
            # a kept long record: the model on the pressure at the raw shifted times
            rest = tuple(e for e in effects if e not in ("channel_delay", "creep_drift"))
            delta = self.predict(p, rest, shifted(d, p["tau"]))
            if "creep_drift" in effects:
                delta = delta + p["D"] * _creep_shape(d, max(p["tau_c"], 1e-6 * d.duration))
            return delta
        pd = d.u - p["p0"]
        om = d.extra["omega"]
        k, psi = p["k"], p["psi"]
        chain = ordered("normal", effects)
        staged = lambda name: [e for e in chain if e.stage == name]  # noqa: E731
        laws, elements = staged("law"), staged("element")
        ctx = NormalContext(d, self)
        coeffs: tuple[float, float, float] = (k, 0.0, 0.0)
        for e in laws:
            coeffs = e.apply(coeffs, p, ctx)
        if elements:
            delta = elements[0].apply(pd, p, ctx)
        elif laws:
            # kept per parameters: a fit's Jacobian steps the creep's parameters, and a
            # delay's, at the same stiffness law (a quarter to a third of its evaluations)
            memo = d.extra.setdefault("nonlinear", {})
            key = (coeffs, psi, p["p0"], om, d.t.size)
            delta = memo.get(key)
            if delta is None:
                delta = nonlinear_viscous(d.t, pd, coeffs, psi, om, d.extra.get("u_slope"))
                delta.flags.writeable = False
                if len(memo) >= _NONLINEAR_KEEP:
                    memo.clear()
                memo[key] = delta
        else:
            delta = _kelvin_voigt_fit(d, k, psi, p["p0"], om)
        for e in staged("loss") + staged("additive") + staged("output"):
            delta = e.apply(delta, p, ctx)
        return delta

    @staticmethod
    def asymmetric(delta: np.ndarray, p: dict[str, float], d: Prepared) -> np.ndarray:
        """Displacement of the Kelvin-Voigt joint with the loss asymmetry ``a``
        (:func:`kelvin_voigt_asymmetric`, its signs started from ``delta``)."""
        return kelvin_voigt_asymmetric(d.t, d.u - p["p0"], p["k"], p["psi"], d.extra["omega"],
                                       p["a"], d.extra.get("u_slope"), start=delta)  # fmt: skip

    @staticmethod
    def hysteretic(pd: np.ndarray, p: dict[str, float], d: Prepared) -> np.ndarray:
        """Displacement of the Kelvin-Voigt joint with a hysteretic loss ``eta``
        (:func:`frequency_domain`, with the run-in of a record in steady state)."""
        return frequency_domain(d.t, pd, p["k"], p["psi"], d.extra["omega"], p["eta"],
                                run_in(d, pd))  # fmt: skip

    @staticmethod
    def creep_shape(d: Prepared, tc: float) -> np.ndarray:
        """``1 - exp(-(t - t0)/τ_c)``, kept per ``τ_c``."""
        return _creep_shape(d, tc)

    def noise_variance(self, p: dict[str, float], effects: tuple[str, ...], d: Prepared) -> float:
        """Output variance per sample the input's sensor noise causes through this model
        (errors in variables, :func:`contactlab.diagnose.select.noise_term`).

        ``T = Σ_f S(f) |H(f)|² |L(f)|²`` over the spectrum of the noise in the input the
        candidates see (:func:`input_noise_spectrum`), with ``H = 1/(k (1 + i ω h/k + i η))``
        the Kelvin-Voigt (and hysteretic) compliance and ``L`` the cubic interpolation of a
        channel delay's fractional sample (:func:`~._signal.cubic_shift_power`; 1 on a kept
        long record, whose delay shifts the pressure at the raw rate, far above the band the
        filtered noise lives in). The
        stiffness nonlinearities are taken at their linear stiffness ``k`` (a few per cent
        of ``T`` at the effects' sizes; taking the local stiffness would let a softening
        candidate lower the corrected error by raising ``T`` without bound).
        """
        spec = input_noise_spectrum(d)
        if spec is None:
            return 0.0
        k2 = p["k"] ** 2
        if not k2 > 0.0:  # a compliance 1/k without bound: the limit, not a division by zero
            return np.inf
        f, s = spec
        w = 2.0 * np.pi * f
        den = 1.0 + 1j * w * p["psi"] / (2.0 * np.pi * d.extra["omega"])
        if "hysteretic_damping" in effects:
            den = den + 1j * p["eta"]
        g = s / np.abs(den) ** 2
        if "channel_delay" in effects and "raw_input" not in d.extra:
            g = g * cubic_shift_power(float(p["tau"] / d.dt), w * d.dt)
        return float(np.sum(g)) / k2

    def noise_variance_bound(self, p: dict[str, float], d: Prepared) -> float:
        """:meth:`noise_variance` without damping or delay (its largest value at ``k``)."""
        spec = input_noise_spectrum(d)
        if spec is None:
            return 0.0
        k2 = p["k"] ** 2
        return float(np.sum(spec[1])) / k2 if k2 > 0.0 else np.inf

    def derived(
        self, p: dict[str, float], se: dict[str, float], effect: str
    ) -> tuple[dict[str, float], dict[str, float]]:
        return {}, {}

    def base_model(self, p: dict[str, float], context: dict[str, float]) -> Any:
        from ..normal import KelvinVoigt

        return KelvinVoigt(p["k"], p["psi"], context["omega"], p0=p["p0"])

    def coefficients(
        self, p: dict[str, float], effects: tuple[str, ...], context: dict[str, float]
    ) -> dict[str, float]:
        """The stiffness law's coefficients in the paper's eq. 6 (SI: Pa/m, Pa/m², Pa/m³):
        ``a1 = k``, ``a2 = k κ1 / δ_r``, ``a3 = k κ / δ_r²``. ``κ1`` and ``κ`` are relative to
        ``δ_r``, the RMS of the displacement the fit saw (``context``), which the effects
        themselves change (a 5 % stiffening makes it about 5 % smaller, ``κ`` about 9 %
        smaller than on the linear record's scale): records are compared by these."""
        dr = context.get("delta_r", 1.0)
        on = "stiffness_nonlinearity" in effects
        kap1 = p.get("kappa1", 0.0) if on else 0.0
        kap = p.get("kappa", 0.0) if on else 0.0
        k = p["k"]
        return {"a1": k, "a2": k * kap1 / dr, "a3": k * kap / dr**2}

    def slope(self, p: dict[str, float], d: Prepared) -> None:
        """The linear base has one compliance ``1/k`` everywhere: pressure noise adds the same
        output error at every sample, so no sample is weighted differently."""
        return None

    def implausible(self, name: str, p: dict[str, float], d: Prepared) -> str | None:
        """Why a fitted effect cannot be physical on this rig, or None (the effect's own
        :meth:`~contactlab.diagnose.effects.EffectModel.plausible`: a channel delay on a
        single-tone record is not identifiable, :func:`delay_identifiability`; a creep that
        settles within a quarter of an excitation period is the record's start-up, not the
        joint)."""
        ok, why = EFFECTS[name].plausible(d, p)
        return None if ok else why

    def plausibility(self, name: str, p: dict[str, float], d: Prepared) -> tuple[bool, str]:
        """The effect's plausibility verdict and its argument in numbers."""
        return tuple(EFFECTS[name].plausible(d, p))  # type: ignore[return-value]

    def regime(self, p: dict[str, float], d: Prepared) -> str:
        psi = p["psi"]
        kind = "viscoelastic (Kelvin-Voigt)" if 0.0 < psi < 1.0 else "outside 0 < ψ < 1"
        text = f"base model regime: {kind}; k = {p['k']:.4g} Pa/m, ψ = {psi:.3g}"
        note = delay_identifiability(p, d)
        return text if note is None else f"{text}; {note}"

    @staticmethod
    def loop_energy(u: np.ndarray, y: np.ndarray) -> float:
        """Energy dissipated per cycle per unit area, ``∮ p dδ``."""
        from ..masing import loop_area

        return loop_area(y, u)

    @staticmethod
    def loop_energies(u: np.ndarray, y: np.ndarray, bounds: list[int]) -> np.ndarray:
        """:meth:`loop_energy` of each run ``bounds[k]:bounds[k+1]`` of at least 3 samples
        (NaN below) in one call (``u``, ``y``: contiguous float64, finite)."""
        return _core.loop_areas(y, u, bounds)


#: samples over which the per-sample gain floors (``min_gain`` σ² and
#: :data:`~contactlab.diagnose.select.MIN_RELATIVE_GAIN`) hold as given (:func:`gain_scale`)
GAIN_REFERENCE_SAMPLES = 1000


def gain_scale(n: int) -> float:
    """Factor on the per-sample gain floors of a normal record of ``n`` samples diagnosed:
    ``min(1, GAIN_REFERENCE_SAMPLES / n)``.

    The floors ``min_gain`` σ² and 1 % of the current error are per sample: on ``n``
    independent samples they ask a noncentrality ``n`` times the floor, i.e. an effect's
    size grows ``√n`` times above what its significance (``t > z`` over the cycles, the
    identification rule) needs. Measured on the chain of ``benches/chain_normal.py`` (one
    tone, 21 000 samples kept): the stated bounds were 10-17 times the size a
    noncentrality of 44.8 needs, the floors setting them all. On a normal joint driven
    by its measured pressure, a linear chain (filters, load cell, sensor lags) is absorbed
    by ``k`` and ``ψ`` at one tone; the floors stay what they were at
    :data:`GAIN_REFERENCE_SAMPLES` and keep their total (a noncentrality of 50 and 10
    σ² · samples) beyond.
    """
    return float(min(1.0, GAIN_REFERENCE_SAMPLES / max(int(n), 1)))


#: τ_c tried (log-spaced over the plausible range) for the creep's starting values
CREEP_START_GRID = 24


#: the normal family's input filter (:func:`smooth_input`) passes the excitation up to this
#: many times its fastest frequency (the tones and their second harmonic) ...
INPUT_PASS_HARMONICS = 2.0
#: ... with a gain within this of 1 (a tenth of the second-order signature of a 5 % channel
#: delay, the smallest model difference the diagnosis resolves, 1e-3 of the displacement)
INPUT_PASS_ERROR = 1e-4
#: Savitzky-Golay polynomial orders :func:`smooth_input` chooses among
INPUT_FILTER_ORDERS = (3, 5, 7, 9)
#: its longest window, as a fraction of the fastest excitation period
INPUT_MAX_WINDOW = 0.6


def input_filter_choice(
    fastest_samples: float, current: int, longest: int | None = None
) -> tuple[int, int]:
    """The Savitzky-Golay filter ``(window, order)`` of least white-noise gain ``Σ c²`` whose
    gain stays within :data:`INPUT_PASS_ERROR` of 1 up to :data:`INPUT_PASS_HARMONICS` times
    the fastest excitation frequency (``1 / fastest_samples`` cycles per sample), windows up
    to :data:`INPUT_MAX_WINDOW` of the fastest period; ``(current, 3)`` (the cubic every
    family sees, :func:`contactlab.diagnose._signal.filter_input`) when none smooths more.
    ``longest``: the longest window allowed (samples), if shorter."""
    best = (current, 3)
    best_gain = float(np.sum(savgol_coeffs(current, 3) ** 2)) if current >= 5 else 1.0
    f = np.linspace(0.0, INPUT_PASS_HARMONICS / fastest_samples, 48)

    def flat(n: int, order: int) -> bool:
        c = savgol_coeffs(2 * n + 1, order)
        h = np.exp(-2j * np.pi * np.outer(f, np.arange(-n, n + 1))) @ c
        return float(np.max(np.abs(1.0 - h))) <= INPUT_PASS_ERROR

    top = (int(INPUT_MAX_WINDOW * fastest_samples) - 1) // 2  # half windows
    if longest is not None:
        top = min(top, (int(longest) - 1) // 2)
    for order in INPUT_FILTER_ORDERS:
        lo = order // 2 + 1  # the shortest window that smooths at all: order + 2 or + 3
        if lo > top or not flat(lo, order):
            continue
        hi = top
        while lo < hi:  # the longest flat window (the error grows with the window)
            mid = (lo + hi + 1) // 2
            if flat(mid, order):
                lo = mid
            else:
                hi = mid - 1
        c = savgol_coeffs(2 * lo + 1, order)
        if float(c @ c) < best_gain:
            best, best_gain = (2 * lo + 1, order), float(c @ c)
    return best


def smooth_input(d: Prepared) -> None:
    """The input the normal candidates see: the measured pressure through the Savitzky-Golay
    filter of :func:`input_filter_choice` when it carries noise (``d.extra["u_noise"]`` > 0)
    and was filtered at the record's own rate (not a kept long record, whose input is
    filtered at the raw rate).

    Errors in variables: the input noise the candidates pass on is most of the held-out
    error at 1 % x noise (``T`` of :meth:`NormalFamily.noise_variance`: 1.4 σ² of output
    noise through the every-family cubic over 4 % of a period), and its share differs by
    candidate (a delay instead of damping passes more of it) by more than the second-order
    signature a delay is told from damping by. The pressure of a normal rig is a few tones:
    a filter flat to 1e-4 over their band and their second harmonic and cutting above
    (a 9th-order polynomial over half the fastest period, 5.7 times its frequency at -3 dB)
    removes most of that noise (``T`` 0.65 times, its difference between damping and
    delay a quarter) and leaves the excitation as measured. ``d.extra["u_filter"]`` and
    ``["u_filter_order"]`` record the filter.
    """
    if "u_filter_order" in d.extra or "raw_input" in d.extra:
        return
    if not float(d.extra.get("u_noise", 0.0)) > 0.0 or d.u.size < 64:
        return
    u = np.asarray(d.extra.get("u_raw", d.u), float)
    per = float(d.cycles.period_samples)
    fastest = shortest_period_samples(u, per)
    current = int(d.extra.get("u_filter", 0))
    n, order = input_filter_choice(fastest, current)
    n = min(n, u.size - (1 - u.size % 2))
    if order == 3 or n <= order + 1:
        d.extra["u_filter_order"] = 3
        return
    d.u = savgol_filter(u, n, order, mode="interp")
    d.extra["u_filter"] = n
    d.extra["u_filter_order"] = order
    d.extra.pop("u_noise_spectrum", None)


#: the input-noise spectrum is read above this many times the fastest excitation
#: frequency (the pressure drive is a sum of tones; its window leakage is gone there)
NOISE_BAND_HARMONICS = 6.0


def input_noise_spectrum(d: Prepared) -> tuple[np.ndarray, np.ndarray] | None:
    """The input-noise power per frequency bin in the input the candidates see, or None
    when the input carries no measurable noise (``d.extra["u_noise"]`` 0).

    Welch's periodogram of the measured input (Hann, 1024 samples or the record); above
    :data:`NOISE_BAND_HARMONICS` times the fastest excitation frequency (and 24 bins) it is
    noise only, and below it the noise is taken at the median level of the octave above
    (the drive's tones hide it there). Multiplied by the power response of the zero-phase
    filter the candidates see the input through (``d.extra["u_filter"]``) and by the bin
    width, so that the sum is the filtered noise's variance. Kept in ``d.extra``.
    """
    if "u_noise_spectrum" in d.extra:
        return d.extra["u_noise_spectrum"]
    out = None
    if float(d.extra.get("u_noise", 0.0)) > 0.0 and d.u.size >= 64:
        u = np.asarray(d.extra.get("u_raw", d.u), float)
        nper = min(u.size, 1024)
        fs = 1.0 / d.dt
        f, s = welch(u, fs, nper)
        fast = 1.0 / (shortest_period_samples(u, d.cycles.period_samples) * d.dt)
        nyq = 0.5 * fs
        lo = min(max(NOISE_BAND_HARMONICS * fast, 24.0 * fs / nper), 0.5 * nyq)
        band = (f >= lo) & (f <= min(2.0 * lo, nyq))
        if np.any(band):
            s = np.where(f < lo, float(np.median(s[band])), s)
            wlen = int(d.extra.get("u_filter", 0))
            if wlen:
                c = savgol_coeffs(wlen, int(d.extra.get("u_filter_order", 3)))
                j = np.arange(wlen) - wlen // 2
                s = s * np.abs(np.exp(-2j * np.pi * np.outer(f * d.dt, j)) @ c) ** 2
            out = (f, s * float(f[1] - f[0]))
    d.extra["u_noise_spectrum"] = out
    return out


#: excitation periods (the dominant one) of run-in history before the record that the
#: hysteretic candidate assumes (:func:`run_in`)
RUN_IN_PERIODS = 3.0


def run_in(d: Prepared, pd: np.ndarray) -> np.ndarray | None:
    """The pressure history the hysteretic candidate assumes before the record.

    The ideal hysteretic loss ``i η k sgn ω`` is non-causal with a memory that decays only
    as ``1/t``: the displacement at the start of a record still carries the response to
    what the joint saw before, seconds earlier. A record that starts in steady state was
    preceded by the same excitation; that history is taken as the record's first complete
    cycle (maximum to maximum) repeated over :data:`RUN_IN_PERIODS` dominant periods,
    ramped in from rest over the first of them and ending in phase with the record's first
    sample. None for a record that starts from rest (over the first quarter of a dominant
    period the pressure stays below half the first complete cycle's amplitude) or that has
    no complete cycle.
    """
    rev = d.cycles.reversals[d.cycles.is_max]
    if rev.size < 2:
        return None
    i0, i1 = int(rev[0]), int(rev[1])
    c = i1 - i0
    per = float(d.cycles.period_samples)
    amp = float(np.max(np.abs(pd[i0:i1])))
    if float(np.max(np.abs(pd[: max(int(0.25 * per), 1)]))) < 0.5 * amp:
        return None  # the record starts from rest: no history
    length = int(np.ceil(RUN_IN_PERIODS * per / c)) * c
    reps = length // c + 2
    ext = np.tile(pd[i0:i1], reps)
    end = (reps - 1) * c + (-i0) % c
    hist = ext[end - length : end]
    ramp = np.clip(np.arange(length) / per, 0.0, 1.0)
    return hist * (ramp * ramp * (3.0 - 2.0 * ramp))


def delay_identifiability(p: dict[str, float], d: Prepared) -> str | None:
    """The identifiability statement for a record excited at one frequency, else None.

    A channel delay ``τ`` lags the displacement by ``ωτ``; Kelvin-Voigt damping by
    ``arctan(ψ/2π)`` at the excitation frequency. At one frequency both are one phase
    lag (they differ only by the damping's amplitude drop ``1/√(1 + (ψ/2π)²)``, which the
    fitted ``k`` absorbs), so the fitted ψ may contain a delay of up to
    ``arctan(ψ/2π)/ω``; only a record at several frequencies (the delay's lag grows with
    ω, the damping's levels off) separates them.
    """
    span = frequency_span(d)
    if span >= SINGLE_TONE_SPAN:
        return None
    omega = float(d.extra["omega"])
    lag = float(np.arctan(max(p["psi"], 0.0) / (2.0 * np.pi)))
    return (
        f"delay and viscous lag are indistinguishable at one frequency (cycle periods "
        f"within a factor {span:.2f}): the loop's phase lag {lag:.3g} rad could be the "
        f"damping ψ = {p['psi']:.3g} or a channel delay of up to {lag / omega:.3g} s, so "
        "no channel_delay is named on this record; excite at several frequencies (a factor "
        "≥ 2 apart) to tell them apart"
    )


def start_from_model(model: Any) -> dict[str, float] | None:
    """Starting parameters from a normal-contact model object, or None if not one."""
    k, psi = getattr(model, "k", None), getattr(model, "psi", None)
    if isinstance(k, float | int) and isinstance(psi, float | int):
        return {"k": float(k), "psi": float(psi)}
    return None
