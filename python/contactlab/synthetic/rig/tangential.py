"""The rig's tangential joint: a position servo from rest driving the contact law with the
effects of ``docs/effects.md``, seen through a load cell.

Part of the rig simulator :mod:`contactlab.synthetic.rig`.
"""

from __future__ import annotations

import math

import numpy as np
from scipy import signal

from contactlab.errors import InputError

from .chain import _filter, _ramp, discretise
from .contact import Virgin, _breakaway, _lugre, masing_force, play_operator
from .shaker import shaker_motion

#: the contact laws the shaker's back-action (an exponential Masing element) does not model
_NOT_SHAKEN = ("power_law_microslip", "rate_dependent_presliding", "tanh_virgin")


def _tangential(
    ti, eff, f, h0, ac, acA, ramp_cycles, actuator_f, actuator_zeta, cell, dt, harmonics=(),
    shaker=None,
):  # fmt: skip
    """The tangential joint on the internal grid: ``(cell force, measured x, base truth)``.
    ``shaker`` (checked figures of :func:`.shaker.shaker_parameters`): the electrodynamic
    shaker drives ``x`` in place of the position servo (:func:`.shaker.shaker_motion`)."""
    w = 2 * math.pi * f
    A = acA / ac
    if shaker is not None:
        return _shaken(ti, eff, f, h0, ac, A, acA, ramp_cycles, cell, dt, shaker, harmonics)
    # actuator: position servo ωa²/(s² + 2ζωa s + ωa²) from rest; command scaled so the
    # steady amplitude is A
    wa = 2 * math.pi * actuator_f
    act = (np.array([wa**2]), np.array([1.0, 2 * actuator_zeta * wa, wa**2]))
    _, H = signal.freqs(*act, worN=[w])
    wave = np.sin(w * ti)
    for k, share in enumerate(harmonics, start=2):  # the actuator's distortion
        wave = wave + share * np.sin(k * w * ti)
    cmd = (A / abs(H[0])) * _ramp(ti, f, ramp_cycles) * wave
    bd, ad = discretise(act, dt)
    x = signal.lfilter(bd, ad, cmd)  # from rest: zero state, cmd[0] = 0
    meta = {"actuator_f": actuator_f}
    return _joint(ti, eff, f, h0, ac, A, acA, x, cell, dt, meta)


def _shaken(ti, eff, f, h0, ac, A, acA, ramp_cycles, cell, dt, shaker, harmonics):
    """:func:`_tangential` with the shaker's armature driving ``x``."""
    for name in ("series_compliance", "backlash", *_NOT_SHAKEN):
        if name in eff:
            raise InputError(f"rig_recording: {name} with a shaker is not modelled")
    if harmonics:
        raise InputError("rig_recording: drive_harmonics with a shaker are not modelled")
    x, F0 = shaker_motion(
        ti, dt, f, A, _ramp(ti, f, ramp_cycles), h0, ac, shaker,
        m=eff.get("inertia", {}).get("m", 0.0),
        k_p=eff.get("parallel_stiffness", {}).get("k_p", 0.0),
        c_v=eff.get("viscous_damping", {}).get("c", 0.0),
    )  # fmt: skip
    meta = {"shaker": {**shaker, "F0": F0}}
    return _joint(ti, eff, f, h0, ac, A, acA, x, cell, dt, meta)


def _joint(ti, eff, f, h0, ac, A, acA, x, cell, dt, extra):
    """The joint's force through the load cell for the motion ``x`` on the internal grid."""
    w = 2 * math.pi * f
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
        **extra,
    }
    return Fc, x_meas, meta
