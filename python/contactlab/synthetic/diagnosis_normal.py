"""Hidden-effect recordings of a normal contact joint (Konowalski's rig, PHYSICS.md §2).

Pressure ``p(t) = p0 + pa(t) sin φ(t)`` in three smooth blocks (``pa = (0.3, 0.6, 0.9)·p0``
at frequencies ``(1, 1.7, 0.6)·f0``, or ``frequencies·f0``), the joint a Kelvin-Voigt element
with the paper's order of magnitude (``k = 1.3 MPa/µm``, ``ψ = 0.0887``, ``p0 = 0.5 MPa``,
``f0 = 1 Hz``) plus the requested effects, and sensor noise on both channels. See
:func:`contactlab.synthetic.diagnosis.hidden_effect_recording` (``model="normal"``) for the
arguments.
The delay is simulated by driving the joint with the closed-form pressure at ``t - τ``.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping, Sequence

import numpy as np
from scipy.optimize import brentq

from ..diagnose.candidates_normal import (
    frequency_domain,
    kelvin_voigt,
    kelvin_voigt_asymmetric,
    nonlinear_viscous,
)
from ..errors import InputError
from ._common import (
    HiddenEffectRecording,
    block_excitation,
    block_frequencies,
    effect_sizes,
    measure,
    rms,
    start_index,
)

NORMAL_EFFECTS = (
    "stiffness_nonlinearity",
    "hysteretic_damping",
    "creep_drift",
    "channel_delay",
    "asymmetric_branches",
)

_PARAM_NAME = {
    "stiffness_nonlinearity": "kappa",
    "hysteretic_damping": "eta",
    "creep_drift": "D",
    "channel_delay": "tau",
    "asymmetric_branches": "a",
}


def _displacement(
    effects: Mapping[str, float],
    t: np.ndarray,
    pfun: Callable[[np.ndarray], np.ndarray],
    k: float,
    psi: float,
    omega: float,
    delta_r: float,
) -> np.ndarray:
    tau = effects.get("channel_delay", 0.0)
    pd = pfun(t - tau)
    if "hysteretic_damping" in effects:
        delta = frequency_domain(t, pd, k, psi, omega, effects["hysteretic_damping"])
    elif "stiffness_nonlinearity" in effects:
        kap = effects["stiffness_nonlinearity"]
        delta = nonlinear_viscous(t, pd, (k, 0.0, k * kap / delta_r**2), psi, omega, passes=8)
    elif "asymmetric_branches" in effects:  # the signs of δ' until they settle
        delta = kelvin_voigt_asymmetric(t, pd, k, psi, omega, effects["asymmetric_branches"],
                                        passes=50, tol=1e-12)  # fmt: skip
    else:
        delta = kelvin_voigt(t, pd, k, psi, omega)
    if "creep_drift" in effects:
        delta = delta + effects["creep_drift"] * -np.expm1(-(t - t[0]) / (0.25 * t[-1]))
    return delta


#: ``|a|`` of ``asymmetric_branches`` at most: the loss asymmetry changes the displacement by
#: at most about ``|a| ψ / π`` of its RMS (1.3 % at the default ψ and this cap), so a larger
#: magnitude is out of reach; the record then has this ``a`` and ``truth["magnitudes"]``
#: the size it makes
ASYMMETRY_CAP = 0.9


def hidden_effect_recording_normal(
    effects: Iterable[str] | Mapping[str, float] = (),
    *,
    magnitude: float = 0.05,
    noise: float = 0.01,
    seed: int = 0,
    cycles_per_block: int = 6,
    samples_per_cycle: int = 120,
    input_noise: float | None = None,
    anti_alias: tuple[float, float] | None = None,
    bits: int | None = None,
    start: str = "rest",
    frequencies: Sequence[float] | None = None,
    **base: float,
) -> HiddenEffectRecording:
    """Normal-contact recording (``p`` in Pa, ``delta`` in m) with hidden effects.

    Base parameters: ``k`` (Pa/m, default 1.3e12), ``psi`` (default 0.0887), ``p0`` (Pa,
    default 5e5), ``f0`` (Hz, default 1). Other arguments as
    :func:`contactlab.synthetic.diagnosis.hidden_effect_recording`.
    """
    sizes = effect_sizes(effects, magnitude, NORMAL_EFFECTS)
    if (
        len({"stiffness_nonlinearity", "hysteretic_damping", "asymmetric_branches"} & set(sizes))
        > 1
    ):
        raise InputError(
            "one of stiffness_nonlinearity, hysteretic_damping and asymmetric_branches at a time"
        )
    k = float(base.pop("k", 1.3e12))
    psi = float(base.pop("psi", 0.0887))
    p0 = float(base.pop("p0", 5e5))
    f0 = float(base.pop("f0", 1.0))
    if base:
        raise InputError(f"unknown base parameter(s) {sorted(base)} for the normal model")
    rng = np.random.default_rng(seed)
    pfun, T, fmax = block_excitation(
        np.array([0.3, 0.6, 0.9]) * p0, block_frequencies(frequencies) * f0, cycles_per_block
    )
    fs = samples_per_cycle * f0
    t = np.arange(round(T * fs) + 1) / fs
    omega = 2.0 * np.pi * f0
    d0 = _displacement({}, t, pfun, k, psi, omega, 1.0)
    dr = rms(d0)

    def size(name: str, value: float) -> float:
        return rms(_displacement({name: value}, t, pfun, k, psi, omega, dr) - d0) / dr

    params: dict[str, float] = {}
    for name, target in sizes.items():
        sign = 1.0
        if name in ("creep_drift", "asymmetric_branches"):
            sign = 1.0 if rng.random() < 0.5 else -1.0
        hi = {
            "stiffness_nonlinearity": 3.0,
            "hysteretic_damping": 1.0,
            "creep_drift": 3.0 * dr,
            "channel_delay": 0.25 / (fmax * 1.0),
            "asymmetric_branches": ASYMMETRY_CAP,
        }[name]

        def g(s: float, name: str = name, target: float = target, sign: float = sign) -> float:
            return size(name, sign * s) - target

        for _ in range(8):  # the bracket's end must keep the joint's stiffness positive
            try:
                g_hi = g(hi)
                break
            except InputError:
                hi *= 0.5
        else:
            raise InputError(f"magnitude {target:g} is out of reach for {name}")
        if g_hi < 0 and name == "asymmetric_branches":
            params[name] = sign * hi  # the largest loss asymmetry: magnitudes says its size
            sizes[name] = g_hi + target
            continue
        if g_hi < 0:
            raise InputError(f"magnitude {target:g} is out of reach for {name}")
        params[name] = sign * brentq(g, 0.0, hi, xtol=1e-12 * hi, rtol=1e-6)
    delta = _displacement(params, t, pfun, k, psi, omega, dr)
    p = p0 + pfun(t)
    keep = start_index(start, t, f0, 0.6 * f0)
    tau_c = 0.25 * float(t[-1])
    t, p, delta = t[keep:] - t[keep], p[keep:], delta[keep:]
    pd_amp = float(np.max(np.abs(p - p0)))
    p_noise = 0.2 * noise * rms(p - p0) if input_noise is None else input_noise * pd_amp
    d_noise = noise * rms(delta)
    pm, dm, info = measure(
        t,
        p,
        delta,
        rng,
        u_noise=p_noise,
        y_noise=d_noise,
        anti_alias=anti_alias,
        bits=bits,
        f_ref=f0,
    )
    truth = {
        "model": "normal",
        "base": {"k": k, "psi": psi, "p0": p0, "f0": f0, "delta_r": dr},
        "effects": {n: {_PARAM_NAME[n]: v} for n, v in params.items()},
        "magnitudes": dict(sizes),
        "noise_rms": {"p": p_noise, "delta": d_noise},
        "sensors": {"anti_alias": anti_alias, "bits": bits, "start": start, **info},
    }
    if "creep_drift" in params:
        truth["effects"]["creep_drift"]["tau_c"] = tau_c
    return HiddenEffectRecording(
        t,
        {"p": pm, "delta": dm},
        {"p": "Pa", "delta": "m"},
        source="hidden_effect_recording",
        meta={"kind": "normal"},
        truth=truth,
        model="normal",
    )
