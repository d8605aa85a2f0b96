"""A rig simulator of the whole measurement chain, written from ``docs/effects.md`` only.

It is the second, independent generator of issue 29: it shares no code with the diagnosis or
its generators. The chain, from the command to the stored samples:

tangential
    actuator (a position servo, second order, driven from rest by a ramped sine) → the contact
    (its own Masing operator with exact non-local memory, or another contact law) with the
    effects of ``docs/effects.md`` → load cell (second-order dynamics) → anti-alias filters on
    both channels (4th-order Butterworth, corner tolerances → a small channel skew) →
    sampling → quantisation; displacement-sensor noise and drift, force noise, each from its
    own random stream.
normal
    pressure actuator (ramped tone blocks from the static preload) → the joint (Kelvin-Voigt
    with the normal effects, solved for δ by an implicit integrator) → pressure cell
    (second-order dynamics) → the same filters, sampling, quantisation and noise.

Everything analogue runs on an internal grid ``oversample`` times finer than the sampling
rate; the filters are discretised exactly for piecewise-linear input (first-order hold).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from scipy import integrate, interpolate, signal

from contactlab.errors import InputError

__all__ = [
    "NEW_EFFECTS",
    "NORMAL_EFFECTS",
    "TANGENTIAL_EFFECTS",
    "RigRecording",
    "Virgin",
    "butterworth",
    "discretise",
    "load_cell",
    "masing_force",
    "play_operator",
    "rig_recording",
    "segalman_parameters",
]

TANGENTIAL_EFFECTS = (
    "viscous_damping",
    "inertia",
    "parallel_stiffness",
    "series_compliance",
    "force_offset",
    "force_drift",
    "displacement_offset",
    "channel_delay",
    "asymmetry",
    "non_masing_scaling",
    "parameter_drift",
    "stribeck",
    "position_friction",
    "stick_slip",
    "normal_load",
)
NORMAL_EFFECTS = (
    "stiffness_nonlinearity",
    "hysteretic_damping",
    "creep_drift",
    "channel_delay",
    "asymmetric_branches",
)
#: Candidates ``docs/effects.md`` reserves for real joints (tangential), plus a virgin curve
#: of another shape (``tanh_virgin``) that no candidate names.
NEW_EFFECTS = ("power_law_microslip", "backlash", "rate_dependent_presliding", "tanh_virgin")

# Each effect's parameters (docs/effects.md names), with the value used when not given.
_DEFAULTS: dict[str, dict[str, float]] = {
    "viscous_damping": {"c": 0.0},
    "inertia": {"m": 0.0},
    "parallel_stiffness": {"k_p": 0.0},
    "series_compliance": {"k_s": math.inf},
    "force_offset": {"F0": 0.0},
    "force_drift": {"rate": 0.0},
    "displacement_offset": {"x0": 0.0},
    "channel_delay": {"tau": 0.0},
    "asymmetry": {"a": 0.0},
    "non_masing_scaling": {"lam": 2.0},
    "parameter_drift": {"beta": 0.0},
    "stribeck": {"s": 0.0, "v_s": math.nan},
    "position_friction": {"eps": 0.0, "L": math.nan, "phi": 0.0},
    "stick_slip": {"b": 0.0, "d_c": math.nan},
    "normal_load": {"eps": 0.0, "f_n": math.nan, "phi": 0.0},
    "power_law_microslip": {"chi": -0.5, "beta": 0.0},
    "backlash": {"b": 0.0},
    "rate_dependent_presliding": {"sigma1": 0.0, "fs_over_fc": 1.0, "v_s": math.nan},
    "tanh_virgin": {},
    "stiffness_nonlinearity": {"a2": 0.0, "a3": 0.0},
    "hysteretic_damping": {"eta": 0.0},
    "creep_drift": {"D": 0.0, "tau_c": math.nan},
    "asymmetric_branches": {"a": 0.0},
}


# --------------------------------------------------------------------------------------------
# The contact: Masing with exact non-local memory (PHYSICS.md §1, rules 1-4)
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Virgin:
    """An odd virgin curve f(u) with its derivative.

    Parameters
    ----------
    f, df : callable
        f(u) for u ≥ 0 (N) and its derivative (N/m); odd-extended here.
    name : str
        Shown in the truth.
    """

    f: Callable[[np.ndarray], np.ndarray]
    df: Callable[[np.ndarray], np.ndarray]
    name: str = "custom"

    def __call__(self, u: np.ndarray) -> np.ndarray:
        u = np.asarray(u, dtype=float)
        return np.sign(u) * self.f(np.abs(u))

    def slope(self, u: np.ndarray) -> np.ndarray:
        return self.df(np.abs(np.asarray(u, dtype=float)))

    @staticmethod
    def exponential(h0: float, ac: float) -> Virgin:
        """f(u) = h0 (1 − exp(−ac u)) (the tangential seed paper, eq. 3)."""
        return Virgin(
            lambda u: -h0 * np.expm1(-ac * u), lambda u: h0 * ac * np.exp(-ac * u), "exponential"
        )

    @staticmethod
    def tanh(h0: float, ac: float) -> Virgin:
        """f(u) = h0 tanh(ac u): same initial slope and saturation, another shape."""
        return Virgin(
            lambda u: h0 * np.tanh(ac * u), lambda u: h0 * ac / np.cosh(ac * u) ** 2, "tanh"
        )

    @staticmethod
    def segalman(F_S: float, K_T: float, chi: float, beta: float) -> Virgin:
        """Segalman's (2005) four-parameter Iwan virgin curve (power-law micro-slip)."""
        phi_max, R, _S = segalman_parameters(F_S, K_T, chi, beta)

        def f(u: np.ndarray) -> np.ndarray:
            w = np.minimum(u, phi_max)
            return np.where(
                u < phi_max, K_T * w - R * w ** (chi + 2) / ((chi + 1) * (chi + 2)), F_S
            )

        def df(u: np.ndarray) -> np.ndarray:
            w = np.minimum(u, phi_max)
            return np.where(u < phi_max, K_T - R * w ** (chi + 1) / (chi + 1), 0.0)

        return Virgin(f, df, "segalman")


def segalman_parameters(F_S: float, K_T: float, chi: float, beta: float) -> tuple[float, ...]:
    """φ_max (m), R and S of Segalman's density from (F_S, K_T, χ, β).

    Parameters
    ----------
    F_S : float
        Force at macro-slip (N).
    K_T : float
        Initial tangential stiffness (N/m).
    chi : float
        Power-law exponent, −1 < χ < 0 (dissipation ∝ A^(3+χ)).
    beta : float
        Weight of the Dirac at φ_max, ≥ 0.

    Returns
    -------
    tuple of float
        (φ_max, R, S).
    """
    if not (-1.0 < chi < 0.0) or beta < 0 or F_S <= 0 or K_T <= 0:
        raise InputError(
            f"Segalman parameters: need -1 < chi < 0, beta >= 0, F_S > 0, K_T > 0 "
            f"(got chi={chi}, beta={beta}, F_S={F_S}, K_T={K_T})"
        )
    q = beta + (chi + 1) / (chi + 2)
    phi_max = F_S * (1 + beta) / (K_T * q)
    R = F_S * (chi + 1) / (phi_max ** (chi + 2) * q)
    S = F_S * beta / (phi_max * q)
    return phi_max, R, S


def _directions(x: np.ndarray) -> np.ndarray:
    """Direction of motion into each sample (+1/−1), zeros carried forward."""
    d = np.sign(np.diff(x))
    if d.size == 0:
        return np.zeros(0)
    idx = np.where(d != 0, np.arange(d.size), 0)
    np.maximum.accumulate(idx, out=idx)
    d = d[idx]
    nz = np.flatnonzero(d)
    if nz.size:
        d[: nz[0]] = d[nz[0]]
    return d


def _runs(d: np.ndarray) -> list[tuple[int, int, float]]:
    """Monotone runs (first sample, end sample exclusive, direction) of samples 1..n-1."""
    if d.size == 0:
        return []
    cuts = np.flatnonzero(np.diff(d) != 0) + 1
    starts = np.concatenate([[0], cuts])
    ends = np.concatenate([cuts, [d.size]])
    return [(int(a) + 1, int(b) + 1, float(d[a])) for a, b in zip(starts, ends, strict=True)]


def masing_force(
    x: np.ndarray,
    virgin: Virgin,
    *,
    lam: float = 2.0,
    k_s: float = math.inf,
) -> tuple[np.ndarray, np.ndarray]:
    """Masing hysteresis with exact non-local memory (PHYSICS.md §1), from rest at u = 0.

    Parameters
    ----------
    x : ndarray
        Displacement the operator sees (m).
    virgin : Virgin
        The virgin curve f.
    lam : float
        Branch scale: a branch from the turning point (u_r, F_r) is F_r + λ f((u − u_r)/λ).
        λ = 2 is Masing (memory with wiping-out and the return to the virgin curve); any other
        λ anchors each branch at the last actual turning point (docs/effects.md).
    k_s : float
        Stiffness (N/m) of an element in series with the contact: x = u + F/k_s.

    Returns
    -------
    (F, u) : tuple of ndarray
        Force (N) and contact slip (m); u equals x without series compliance.
    """
    x = np.asarray(x, dtype=float)
    n = x.size
    F = np.empty(n)
    U = np.empty(n)
    if n == 0:
        return F, U
    if not lam > 0:
        raise InputError(f"masing_force: branch scale lam must be > 0, got {lam}")
    memory = lam == 2.0
    series = math.isfinite(k_s)
    fsup = float(virgin.f(np.array([np.inf]))[0])
    if series and not k_s > 0:
        raise InputError(f"masing_force: series stiffness k_s must be > 0, got {k_s}")

    def branch(anchor: tuple[float, float] | None, xs: np.ndarray) -> tuple[np.ndarray, ...]:
        if anchor is None:

            def fb(u: np.ndarray) -> np.ndarray:
                return virgin(u)

            def dfb(u: np.ndarray) -> np.ndarray:
                return virgin.slope(u)
        else:
            ur, Fr = anchor

            def fb(u: np.ndarray) -> np.ndarray:
                return Fr + lam * virgin((u - ur) / lam)

            def dfb(u: np.ndarray) -> np.ndarray:
                return virgin.slope((u - ur) / lam)

        if not series:
            return xs, fb(xs)
        # x = u + F(u)/k_s on this branch: monotone in u (slope 1 + F'/k_s ≥ 1), and
        # |F| ≤ |F_r| + λ sup f, which brackets the root.
        bound = fsup * (1.0 if anchor is None else lam) + (abs(anchor[1]) if anchor else 0.0)
        lo = xs - 1.01 * bound / k_s
        hi = xs + 1.01 * bound / k_s
        u = np.clip(xs - fb(xs) / k_s, lo, hi)
        scale = float(np.max(np.abs(xs))) + bound / k_s
        for _ in range(100):
            g = u + fb(u) / k_s - xs
            lo = np.where(g < 0, u, lo)
            hi = np.where(g > 0, u, hi)
            un = u - g / (1.0 + dfb(u) / k_s)
            bad = (un <= lo) | (un >= hi)
            un = np.where(bad, 0.5 * (lo + hi), un)
            done = float(np.max(np.abs(un - u), initial=0.0)) <= 1e-14 * scale
            u = un
            if done:
                break
        return u, fb(u)

    u0, F0 = branch(None, x[:1])
    U[0], F[0] = float(u0[0]), float(F0[0])
    d = _directions(x)
    stack: list[tuple[float, float]] = []
    anchor: tuple[float, float] | None = None  # non-memory mode
    prev_dir = 0.0
    if d.size and d[0] * U[0] < 0:  # the first motion returns towards rest
        stack.append((U[0], F[0]))
        anchor = (U[0], F[0])
    for i, j, di in _runs(d):
        # samples i..j-1 move in direction di; sample i-1 is the turning point
        if prev_dir != 0 and di != prev_dir:
            stack.append((float(U[i - 1]), float(F[i - 1])))
            anchor = stack[-1]
        prev_dir = di
        k = i
        while k < j:
            lim: float | None
            if memory:
                cur = stack[-1] if stack else None
                if len(stack) >= 2:
                    lim = stack[-2][0]
                elif len(stack) == 1:
                    lim = -stack[0][0]
                else:
                    lim = None
            else:
                cur, lim = anchor, None
            u, Fk = branch(cur, x[k:j])
            if lim is not None:
                hit = np.flatnonzero(di * (u - lim) >= 0)
                if hit.size:
                    h = int(hit[0])
                    U[k : k + h], F[k : k + h] = u[:h], Fk[:h]
                    if len(stack) >= 2:
                        del stack[-2:]
                    else:
                        stack.clear()
                    k += h
                    continue
            U[k:j], F[k:j] = u, Fk
            k = j
    return F, U


def play_operator(x: np.ndarray, b: float, u0: float = 0.0) -> np.ndarray:
    """Backlash (lost motion): u stands still until |x − u| = b, then follows at distance b.

    Parameters
    ----------
    x : ndarray
        Input (m).
    b : float
        Half-width of the dead band (m), ≥ 0.
    u0 : float
        Initial output.

    Returns
    -------
    ndarray
        The output u (m).
    """
    x = np.asarray(x, dtype=float)
    if b < 0:
        raise InputError(f"backlash: half-width b must be >= 0, got {b}")
    u = np.empty_like(x)
    if x.size == 0:
        return u
    u[0] = min(max(u0, x[0] - b), x[0] + b)
    cur = float(u[0])
    for i, j, di in _runs(_directions(x)):
        seg = x[i:j]
        out = np.maximum(cur, seg - b) if di > 0 else np.minimum(cur, seg + b)
        u[i:j] = out
        cur = float(out[-1])
    return u


def _lugre(
    t: np.ndarray, v: np.ndarray, sigma0: float, sigma1: float, Fc: float, Fs: float, vs: float
) -> np.ndarray:
    """LuGre friction (Canudas de Wit et al. 1995) without σ2, exact per step for constant v."""
    z = 0.0
    F = np.empty_like(v)
    dt = np.diff(t, prepend=t[0])
    for i in range(v.size):
        vi = v[i]
        g = Fc + (Fs - Fc) * math.exp(-((vi / vs) ** 2))
        if vi != 0.0:
            zss = math.copysign(g / sigma0, vi)
            z = zss + (z - zss) * math.exp(-sigma0 * abs(vi) * dt[i] / g)
        zdot = vi - sigma0 * abs(vi) * z / g
        F[i] = sigma0 * z + sigma1 * zdot
    return F


# --------------------------------------------------------------------------------------------
# The measurement chain: analogue filters discretised exactly for piecewise-linear input
# --------------------------------------------------------------------------------------------


def butterworth(fc: float, order: int = 4) -> tuple[np.ndarray, np.ndarray]:
    """Analogue Butterworth low-pass (b, a) in s, corner fc (Hz)."""
    return signal.butter(order, 2 * math.pi * fc, analog=True)


def load_cell(fn: float, zeta: float) -> tuple[np.ndarray, np.ndarray]:
    """Second-order sensor ωn² / (s² + 2ζωn s + ωn²), natural frequency fn (Hz)."""
    wn = 2 * math.pi * fn
    return np.array([wn**2]), np.array([1.0, 2 * zeta * wn, wn**2])


def discretise(ba: tuple[np.ndarray, np.ndarray], dt: float) -> tuple[np.ndarray, np.ndarray]:
    """Discrete (b, a) of an analogue filter, exact for piecewise-linear input (FOH)."""
    bd, ad, _ = signal.cont2discrete(ba, dt, method="foh")
    return np.atleast_1d(np.squeeze(bd)), np.atleast_1d(np.squeeze(ad))


def _filter(ba: tuple[np.ndarray, np.ndarray], dt: float, u: np.ndarray) -> np.ndarray:
    """Filter from rest (the chain starts at rest: zero initial state, input starting at u[0])."""
    b, a = discretise(ba, dt)
    # start in the steady state for a constant u[0] (a sensor at rest reading a constant)
    zi = signal.lfilter_zi(b, a) * u[0]
    y, _ = signal.lfilter(b, a, u, zi=zi)
    return y


def _noise_gain(ba: tuple[np.ndarray, np.ndarray], dt: float) -> float:
    """RMS gain of the discretised filter for white input (√Σh²)."""
    b, a = discretise(ba, dt)
    imp = np.zeros(20000)
    imp[0] = 1.0
    h = signal.lfilter(b, a, imp)
    return float(np.sqrt(np.sum(h**2)))


def _adc_range(peak: float) -> float:
    """Full-scale range of an ADC channel: the 1-2-5 step at or above 1.25 × peak."""
    need = 1.25 * peak
    if not need > 0:
        return 1.0
    e = math.floor(math.log10(need))
    for m in (1.0, 2.0, 5.0, 10.0):
        if m * 10**e >= need:
            return m * 10**e
    return 10.0 ** (e + 1)


def _quantise(y: np.ndarray, fsr: float, bits: int | None) -> tuple[np.ndarray, float]:
    if bits is None:
        return y, 0.0
    q = 2 * fsr / 2**bits
    return np.clip(np.round(y / q) * q, -fsr, fsr - q), q


# --------------------------------------------------------------------------------------------
# The recording
# --------------------------------------------------------------------------------------------


@dataclass
class RigRecording:
    """A simulated recording with its truth.

    Attributes
    ----------
    kind : str
        "tangential" (channels ``x`` m, ``F`` N) or "normal" (``p`` Pa, ``delta`` m).
    t : ndarray
        Sample times (s).
    channels : dict
        The measured channels.
    truth : dict
        Effects with their parameters (docs/effects.md units), the base model, the chain.
    """

    kind: str
    t: np.ndarray
    channels: dict[str, np.ndarray]
    truth: dict[str, Any] = field(default_factory=dict)

    def __getattr__(self, name: str) -> np.ndarray:
        ch = self.__dict__.get("channels", {})
        if name in ch:
            return ch[name]
        raise AttributeError(name)

    def to_csv(self, path: str | Path) -> Path:
        """Write ``t`` and the channels as a CSV (SI units, one header line)."""
        path = Path(path)
        names = list(self.channels)
        cols = np.column_stack([self.t] + [self.channels[k] for k in names])
        np.savetxt(
            path, cols, delimiter=",", header=",".join(["t", *names]), comments="", fmt="%.10g"
        )
        return path


def _effect_params(effects: Mapping[str, Mapping[str, float]] | Sequence[str], allowed: tuple):
    if not isinstance(effects, Mapping):
        effects = {name: {} for name in effects}
    out: dict[str, dict[str, float]] = {}
    for name, params in effects.items():
        if name not in allowed:
            raise InputError(
                f"rig_recording: unknown effect {name!r} for this kind; known: {', '.join(allowed)}"
            )
        base = dict(_DEFAULTS[name])
        for k, v in dict(params or {}).items():
            if k not in base:
                raise InputError(
                    f"rig_recording: effect {name!r} has no parameter {k!r} "
                    f"(parameters: {', '.join(base) or 'none'})"
                )
            if not np.isfinite(float(v)) and not (k == "k_s" and v == math.inf):
                raise InputError(f"rig_recording: {name}.{k} must be finite, got {v}")
            base[k] = float(v)
        out[name] = base
    return out


def _check_positive(**kw: float) -> None:
    for k, v in kw.items():
        if not (np.isfinite(v) and v > 0):
            raise InputError(f"rig_recording: {k} must be a finite number > 0, got {v}")


def rig_recording(
    effects: Mapping[str, Mapping[str, float]] | Sequence[str] = (),
    kind: str = "tangential",
    *,
    seed: int = 0,
    fs: float = 2000.0,
    f: float = 5.0,
    cycles: int = 10,
    acA: float = 2.0,
    h0: float = 40.0,
    ac: float = 4.0e4,
    k: float = 1.3e12,
    psi: float = 0.0887,
    p0: float = 0.5e6,
    pa: float = 0.4e6,
    frequencies: Sequence[float] = (1.0,),
    x_noise: float = 0.01,
    F_noise: float = 0.01,
    x_drift: float = 0.0,
    ramp_cycles: float = 1.0,
    actuator_f: float | None = None,
    actuator_zeta: float = 0.7,
    cell_fn: float | None = None,
    cell_zeta: float = 0.05,
    aa_ratio: float = 0.4,
    aa_tolerance: float = 0.01,
    bits: int | None = 16,
    oversample: int | None = None,
) -> RigRecording:
    """Simulate a recording of the whole measurement chain with the given effects.

    Parameters
    ----------
    effects : mapping or sequence of str
        ``{name: {parameter: value}}`` with names and parameters of ``docs/effects.md``
        (SI units); missing parameters take defaults (see ``_DEFAULTS``). Tangential also takes
        ``NEW_EFFECTS``. A sequence of names uses the defaults (mostly "no effect").
    kind : {"tangential", "normal"}
        Which joint.
    seed : int
        Seed of the independent random streams (noise of each channel, filter tolerances).
    fs : float
        Sampling rate (Hz).
    f : float
        Drive frequency (Hz); for ``normal`` the reference of ``frequencies``.
    cycles : int
        Cycles of the drive (per frequency block for ``normal``).
    acA : float
        Tangential: ac·A, the regime (A = acA/ac is the displacement amplitude).
    h0, ac : float
        Tangential virgin curve: saturation force (N) and curvature (1/m).
    k, psi, p0, pa : float
        Normal Kelvin-Voigt joint: stiffness (Pa/m), loss coefficient ψ (c = ψk/(2π·2πf)),
        static and dynamic pressure (Pa).
    frequencies : sequence of float
        Normal: frequencies of successive tone blocks relative to ``f``.
    x_noise : float
        Displacement-sensor noise RMS as a fraction of the displacement amplitude (max |x| or
        max |δ|), after the anti-alias filter.
    F_noise : float
        Force (pressure) channel noise RMS as a fraction of the force amplitude (max |F|, or pa).
    x_drift : float
        Drift of the displacement sensor over the record, fraction of the amplitude.
    ramp_cycles : float
        Length of the raised-cosine start-up of the command (cycles); 0 starts the sine
        abruptly (still from rest: the actuator smooths it).
    actuator_f, actuator_zeta : float
        Position servo: natural frequency (Hz; default 15 f) and damping.
    cell_fn, cell_zeta : float
        Load cell: natural frequency (Hz; default max(2.5 fs, 50 f)) and damping.
    aa_ratio, aa_tolerance : float
        Anti-alias corners = aa_ratio·fs·(1 + tolerance·N(0,1)), independently per channel.
    bits : int or None
        ADC resolution (None: no quantisation).
    oversample : int, optional
        Internal grid rate / fs (default: enough for the load cell, ≥ 8).

    Returns
    -------
    RigRecording
        ``t``, ``channels`` and ``truth``.
    """
    if kind not in ("tangential", "normal"):
        raise InputError(f"rig_recording: kind must be 'tangential' or 'normal', got {kind!r}")
    _check_positive(fs=fs, f=f, h0=h0, ac=ac, acA=acA, k=k, psi=psi, pa=pa)
    if not (isinstance(cycles, (int, np.integer)) and cycles >= 1):
        raise InputError(f"rig_recording: cycles must be an integer >= 1, got {cycles}")
    if f > fs / 8:
        raise InputError(f"rig_recording: f = {f} Hz needs fs >= 8 f (fs = {fs} Hz)")
    for name, v in (("x_noise", x_noise), ("F_noise", F_noise)):
        if not (np.isfinite(v) and v >= 0):
            raise InputError(f"rig_recording: {name} must be >= 0, got {v}")
    allowed = TANGENTIAL_EFFECTS + NEW_EFFECTS if kind == "tangential" else NORMAL_EFFECTS
    eff = _effect_params(effects, allowed)

    ss = np.random.SeedSequence(int(seed))
    rng_x, rng_F, rng_tol, _spare = (np.random.default_rng(s) for s in ss.spawn(4))
    cell_fn = float(cell_fn) if cell_fn is not None else max(2.5 * fs, 50 * f)
    if oversample is None:
        oversample = int(max(8, math.ceil(6 * cell_fn / fs)))
    fsi = fs * oversample
    dt = 1.0 / fsi

    if kind == "tangential":
        duration = cycles / f
    else:
        if not frequencies or any(not (r > 0) for r in frequencies):
            raise InputError("rig_recording: frequencies must be positive ratios")
        duration = sum(cycles / (f * r) for r in frequencies)
    n = round(duration * fs) + 1
    ti = np.arange((n - 1) * oversample + 1) * dt
    t = ti[::oversample].copy()

    fc_x = aa_ratio * fs * (1 + aa_tolerance * rng_tol.standard_normal())
    fc_F = aa_ratio * fs * (1 + aa_tolerance * rng_tol.standard_normal())
    aa_x, aa_F = butterworth(fc_x), butterworth(fc_F)
    cell = load_cell(cell_fn, cell_zeta)
    # low-frequency group delays (s): Butterworth 4: Σ 1/(ωc·sin θk); cell: 2ζ/ωn
    gd_x = _group_delay(aa_x)
    gd_F = _group_delay(aa_F) + _group_delay(cell)
    truth: dict[str, Any] = {
        "kind": kind,
        "effects": eff,
        "chain": {
            "fs": fs,
            "oversample": oversample,
            "aa_corner": {"x": fc_x, "F": fc_F},
            "cell_fn": cell_fn,
            "cell_zeta": cell_zeta,
            "bits": bits,
            # the output channel behind the input at low frequency (s)
            "channel_skew": (gd_F - gd_x) if kind == "tangential" else (gd_x - gd_F),
            "ramp_cycles": ramp_cycles,
        },
    }

    if kind == "tangential":
        out_ch, in_ch, meta = _tangential(
            ti,
            eff,
            f=f,
            h0=h0,
            ac=ac,
            acA=acA,
            ramp_cycles=ramp_cycles,
            actuator_f=actuator_f or 15 * f,
            actuator_zeta=actuator_zeta,
            cell=cell,
            dt=dt,
        )
        names = ("x", "F")
    else:
        out_ch, in_ch, meta = _normal(
            ti,
            eff,
            f=f,
            k=k,
            psi=psi,
            p0=p0,
            pa=pa,
            frequencies=frequencies,
            cycles=cycles,
            ramp_cycles=ramp_cycles,
            cell=cell,
            dt=dt,
        )
        names = ("delta", "p")
    truth["base"] = meta

    # displacement channel: x = in_ch for tangential, delta = out_ch for normal
    force, disp = out_ch, in_ch
    disp_amp = meta["displacement_amplitude"]
    force_amp = meta["force_amplitude"]
    disp = disp + x_drift * disp_amp * ti / ti[-1]
    g_x = _noise_gain(aa_x, dt)
    g_F = _noise_gain(aa_F, dt)
    disp = disp + rng_x.standard_normal(ti.size) * (x_noise * disp_amp / g_x)
    force = force + rng_F.standard_normal(ti.size) * (F_noise * force_amp / g_F)
    disp_f = _filter(aa_x, dt, disp)
    force_f = _filter(aa_F, dt, force)

    tau = 0.0
    if "channel_delay" in eff:
        tau = eff["channel_delay"]["tau"]
    # the delayed channel (F tangential, δ normal: the output) is sampled at t − τ
    disp_s = disp_f[::oversample]
    force_s = force_f[::oversample]
    if tau != 0.0:
        if kind == "tangential":
            force_s = _sample_at(ti, force_f, t - tau)
        else:
            disp_s = _sample_at(ti, disp_f, t - tau)
    if kind == "tangential" and "force_offset" in eff:
        force_s = force_s + eff["force_offset"]["F0"]
    if kind == "tangential" and "force_drift" in eff:
        force_s = force_s + eff["force_drift"]["rate"] * t
    fsr_x = _adc_range(float(np.max(np.abs(disp_s))))
    fsr_F = _adc_range(float(np.max(np.abs(force_s))))
    disp_q, q_x = _quantise(disp_s, fsr_x, bits)
    force_q, q_F = _quantise(force_s, fsr_F, bits)
    truth["chain"].update(
        {
            "adc_range": {"x": fsr_x, "F": fsr_F},
            "quantum": {"x": q_x, "F": q_F},
            "noise_rms": {"x": x_noise * disp_amp, "F": F_noise * force_amp},
            "x_drift": x_drift * disp_amp,
        }
    )
    if kind == "tangential":
        channels = {"x": disp_q, "F": force_q}
    else:
        channels = {"p": force_q, "delta": disp_q}
    del names
    return RigRecording(kind, t, channels, truth)


def _group_delay(ba: tuple[np.ndarray, np.ndarray]) -> float:
    """Low-frequency group delay (s) of an analogue filter: a1/a0 − b1/b0 (coefficients in s)."""
    b, a = (np.asarray(c, dtype=float) for c in ba)
    a0, a1 = a[-1], (a[-2] if a.size > 1 else 0.0)
    b0, b1 = b[-1], (b[-2] if b.size > 1 else 0.0)
    return float(a1 / a0 - b1 / b0)


def _sample_at(ti: np.ndarray, y: np.ndarray, tq: np.ndarray) -> np.ndarray:
    """Cubic interpolation of the fine-grid signal (before the record: its first value)."""
    spline = interpolate.CubicSpline(ti, y)
    return np.where(tq < ti[0], y[0], spline(np.clip(tq, ti[0], ti[-1])))


def _ramp(ti: np.ndarray, f: float, ramp_cycles: float) -> np.ndarray:
    if ramp_cycles <= 0:
        return np.ones_like(ti)
    tr = ramp_cycles / f
    r = np.clip(ti / tr, 0.0, 1.0)
    return 0.5 - 0.5 * np.cos(math.pi * r)


def _tangential(ti, eff, *, f, h0, ac, acA, ramp_cycles, actuator_f, actuator_zeta, cell, dt):
    w = 2 * math.pi * f
    A = acA / ac
    # actuator: position servo ωa²/(s² + 2ζωa s + ωa²) from rest; command scaled so the
    # steady amplitude is A
    wa = 2 * math.pi * actuator_f
    act = (np.array([wa**2]), np.array([1.0, 2 * actuator_zeta * wa, wa**2]))
    _, H = signal.freqs(*act, worN=[w])
    cmd = (A / abs(H[0])) * _ramp(ti, f, ramp_cycles) * np.sin(w * ti)
    bd, ad = discretise(act, dt)
    x = signal.lfilter(bd, ad, cmd)  # from rest: zero state, cmd[0] = 0
    v = np.gradient(x, dt, edge_order=2)
    acc = np.gradient(v, dt, edge_order=2)

    # the contact law
    if "power_law_microslip" in eff:
        p = eff["power_law_microslip"]
        virgin = Virgin.segalman(h0, h0 * ac, p["chi"], p["beta"])
    elif "tanh_virgin" in eff:
        virgin = Virgin.tanh(h0, ac)
    else:
        virgin = Virgin.exponential(h0, ac)
    lam = eff.get("non_masing_scaling", {}).get("lam", 2.0)
    k_s = eff.get("series_compliance", {}).get("k_s", math.inf)
    u_in = x
    if "backlash" in eff:
        if math.isfinite(k_s):
            raise InputError("rig_recording: backlash with series_compliance is not modelled")
        u_in = play_operator(x, eff["backlash"]["b"])
    if "rate_dependent_presliding" in eff:
        p = eff["rate_dependent_presliding"]
        vs = p["v_s"] if np.isfinite(p["v_s"]) else 0.3 * A * w
        Fj = _lugre(ti, np.gradient(u_in, dt), h0 * ac, p["sigma1"], h0, h0 * p["fs_over_fc"], vs)
    else:
        Fj, _u = masing_force(u_in, virgin, lam=lam, k_s=k_s)

    # friction modulations (docs/effects.md: F = g·M[x])
    g = np.ones_like(ti)
    if "parameter_drift" in eff:
        g *= 1 + eff["parameter_drift"]["beta"] * (ti - 0.5 * ti[-1])
    if "stribeck" in eff:
        p = eff["stribeck"]
        vs = p["v_s"] if np.isfinite(p["v_s"]) else 0.3 * A * w
        g *= 1 + p["s"] * np.exp(-((v / vs) ** 2))
    if "position_friction" in eff:
        p = eff["position_friction"]
        L = p["L"] if np.isfinite(p["L"]) else 2 * A
        g *= 1 + p["eps"] * np.cos(2 * math.pi * x / L + p["phi"])
    if "normal_load" in eff:
        p = eff["normal_load"]
        fn = p["f_n"] if np.isfinite(p["f_n"]) else 2 * f
        g *= 1 + p["eps"] * np.cos(2 * math.pi * fn * ti + p["phi"])
    Fj = g * Fj
    if "stick_slip" in eff:
        p = eff["stick_slip"]
        dc = p["d_c"] if np.isfinite(p["d_c"]) else 0.25 * A
        Fj = Fj + p["b"] * h0 * _breakaway(x, dc)
    if "viscous_damping" in eff:
        Fj = Fj + eff["viscous_damping"]["c"] * v
    if "inertia" in eff:
        Fj = Fj + eff["inertia"]["m"] * acc
    if "parallel_stiffness" in eff:
        Fj = Fj + eff["parallel_stiffness"]["k_p"] * x

    Fc = _filter(cell, dt, Fj)  # load cell dynamics (from rest)
    if "asymmetry" in eff:
        Fc = Fc * (1 + eff["asymmetry"]["a"] * np.sign(Fc))
    x_meas = x + eff.get("displacement_offset", {}).get("x0", 0.0)
    meta = {
        "h0": h0,
        "ac": ac,
        "A": A,
        "acA": acA,
        "f": f,
        "virgin": virgin.name if "rate_dependent_presliding" not in eff else "lugre",
        "displacement_amplitude": A,
        "force_amplitude": float(np.max(np.abs(Fj))),
        "actuator_f": actuator_f,
    }
    return Fc, x_meas, meta


def _breakaway(x: np.ndarray, dc: float) -> np.ndarray:
    """sgn(ẋ)·(s/d_c)·e^(1 − s/d_c), s the travel since the last turning point."""
    d = np.concatenate([[0.0], _directions(x)]) if x.size > 1 else np.zeros_like(x)
    if d.size > 1:
        d[0] = d[1]
    turn = np.zeros(x.size, dtype=bool)
    turn[1:] = d[1:] != d[:-1]
    idx = np.where(turn, np.arange(x.size) - 1, 0)
    idx[0] = 0
    np.maximum.accumulate(idx, out=idx)
    s = np.abs(x - x[idx])
    # before the first turning point there is no breakaway (first loading from rest)
    first = np.flatnonzero(turn)
    out = d * (s / dc) * np.exp(1 - s / dc)
    if first.size:
        out[: first[0]] = 0.0
    else:
        out[:] = 0.0
    return out


def _normal(ti, eff, *, f, k, psi, p0, pa, frequencies, cycles, ramp_cycles, cell, dt):
    # tone blocks, each an integer number of cycles starting at phase 0 (continuous p)
    edges = [0.0]
    for r in frequencies:
        edges.append(edges[-1] + cycles / (f * r))
    edges_a = np.array(edges)
    rates = np.array([f * r for r in frequencies])
    w_ref = 2 * math.pi * f
    c = psi * k / (2 * math.pi * w_ref)
    eta = eff.get("hysteretic_damping", {}).get("eta", 0.0)
    a2 = eff.get("stiffness_nonlinearity", {}).get("a2", 0.0)
    a3 = eff.get("stiffness_nonlinearity", {}).get("a3", 0.0)
    asym = eff.get("asymmetric_branches", {}).get("a", 0.0)
    tr = ramp_cycles / f

    def block(tt: float) -> int:
        return int(min(np.searchsorted(edges_a, tt, side="right") - 1, len(rates) - 1))

    def pdyn(tt: float) -> float:
        b = block(tt)
        r = 1.0 if tr <= 0 else 0.5 - 0.5 * math.cos(math.pi * min(tt / tr, 1.0))
        return pa * r * math.sin(2 * math.pi * rates[b] * (tt - edges_a[b]))

    def rhs(tt: float, y: np.ndarray) -> np.ndarray:
        dlt = y[0]
        b = block(tt)
        ce = c + eta * k / (2 * math.pi * rates[b])
        R = pdyn(tt) - (k + a2 * dlt + a3 * dlt**2) * dlt
        return np.array([R / (ce * (1 + asym * math.copysign(1.0, R)))])

    t_end = float(ti[-1])
    p_dyn = _pdyn_vec(ti, edges_a, rates, pa, tr)
    if a2 == 0.0 and a3 == 0.0 and asym == 0.0:
        delta = _kelvin_voigt_blocks(ti, p_dyn, k, c, eta, edges_a, rates)
    else:
        sol = integrate.solve_ivp(
            rhs,
            (0.0, t_end),
            [0.0],
            method="Radau",
            dense_output=True,
            rtol=1e-8,
            atol=1e-9 * pa / k,
            max_step=1 / (40 * max(rates)),
        )
        if not sol.success:
            raise InputError(
                f"rig_recording: the normal joint's integration failed ({sol.message})"
            )
        delta = sol.sol(ti)[0]

    if "creep_drift" in eff:
        pc = eff["creep_drift"]
        tc = pc["tau_c"] if np.isfinite(pc["tau_c"]) else 0.25 * t_end
        delta = delta + pc["D"] * -np.expm1(-ti / tc)
    # pressure channel: the cell sees the applied pressure (dynamic part, offset p0 added)
    p_meas = p0 + _filter(cell, dt, p_dyn)
    meta = {
        "k": k,
        "psi": psi,
        "c": c,
        "p0": p0,
        "pa": pa,
        "f": f,
        "frequencies": list(frequencies),
        "displacement_amplitude": float(np.max(np.abs(delta))) or pa / k,
        "force_amplitude": pa,
    }
    return p_meas, delta, meta


def _kelvin_voigt_blocks(ti, p, k, c, eta, edges, rates):
    """k δ + c_b δ' = p exactly for piecewise-linear p, c_b = c + η k / ω_b in each block."""
    h = float(ti[1] - ti[0])
    delta = np.zeros_like(p)
    blk = np.clip(np.searchsorted(edges, ti, side="right") - 1, 0, len(rates) - 1)
    start = 0
    for b in range(len(rates)):
        idx = np.flatnonzero(blk == b)
        if idx.size == 0:
            continue
        stop = int(idx[-1]) + 1
        cb = c + eta * k / (2 * math.pi * rates[b])
        tau = cb / k
        E = math.exp(-h / tau)
        g = tau * (1 - E) / h
        bb = np.array([(1 - g) / k, (g - E) / k])
        aa = np.array([1.0, -E])
        i0 = max(start - 1, 0)
        zi = signal.lfiltic(bb, aa, y=[delta[i0]], x=[p[i0]])
        delta[i0 + 1 : stop], _ = signal.lfilter(bb, aa, p[i0 + 1 : stop], zi=zi)
        start = stop
    return delta


def _pdyn_vec(ti, edges_a, rates, pa, tr):
    b = np.clip(np.searchsorted(edges_a, ti, side="right") - 1, 0, len(rates) - 1)
    r = np.ones_like(ti) if tr <= 0 else 0.5 - 0.5 * np.cos(math.pi * np.clip(ti / tr, 0, 1))
    return pa * r * np.sin(2 * math.pi * rates[b] * (ti - edges_a[b]))
