"""The rig's electrodynamic shaker: an armature mass on a suspension, driven by a sine
force switched on from rest, with the contact's force acting back on it.

Part of the rig simulator :mod:`contactlab.synthetic.rig` (``rig_recording(shaker=...)``).
The position servo of the default rig imposes ``x``; a shaker does not: its armature (mass
``M``, suspension stiffness ``M (2π fn)²``, damping ratio ``zeta``) carries the fixture
(the inertia effect's ``m``, which moves with it) and is pushed back by the contact, so

    (M + m) ẍ + c ẋ + k x = F_cmd(t) - F_contact(x) - k_p x - c_v ẋ

with ``F_contact`` the exponential-virgin Masing element with exact memory (PHYSICS.md §1)
and ``k_p``, ``c_v`` the parallel spring and dashpot when present. ``x`` then carries a
start-up transient at the suspension's natural frequency (the sine starts from rest) and
odd harmonics of the drive from the friction's back-action. The other effects (force
modulations, stick-slip) are applied to the joint's force afterwards as on the servo rig;
their own back-action on ``x`` is not modelled. Integrated by semi-implicit Euler on the
rig's internal grid, subdivided so that the contact's stick frequency
``sqrt(h0·ac/(M + m))`` is resolved to 0.05 rad per step; the command's amplitude is found
by iteration so the steady stroke is ``A``.
"""

from __future__ import annotations

import math

import numpy as np

from contactlab.errors import InputError

#: the shaker's figures and their defaults (``rig_recording(shaker=...)``): armature mass
#: (kg), suspension natural frequency (Hz), damping ratio of the suspension
SHAKER_DEFAULTS = {"mass": 0.2, "fn": 20.0, "zeta": 0.05}
#: the cycles the command's amplitude is calibrated on (:func:`shaker_motion`)
CALIBRATE_CYCLES = 12


def shaker_parameters(shaker) -> dict[str, float] | None:
    """``shaker`` (None, or a mapping of :data:`SHAKER_DEFAULTS`' names) checked, with the
    defaults filled in; None for no shaker."""
    if shaker is None:
        return None
    try:
        items = dict(shaker).items()
    except (TypeError, ValueError) as exc:
        raise InputError(
            f"rig_recording: shaker must be None or a mapping, got {shaker!r}"
        ) from exc
    out = dict(SHAKER_DEFAULTS)
    for k, v in items:
        if k not in out:
            raise InputError(
                f"rig_recording: shaker has no figure {k!r} (figures: {', '.join(out)})"
            )
        try:
            out[k] = float(v)
        except (TypeError, ValueError) as exc:
            raise InputError(f"rig_recording: shaker {k} must be a number, got {v!r}") from exc
    for k in ("mass", "fn"):
        if not (math.isfinite(out[k]) and out[k] > 0):
            raise InputError(f"rig_recording: shaker {k} must be a finite number > 0, got {out[k]}")
    if not (math.isfinite(out["zeta"]) and out["zeta"] >= 0):
        raise InputError(f"rig_recording: shaker zeta must be >= 0, got {out['zeta']}")
    return out


def _integrate(wave, dt, M, k, c, h0, ac, steps):
    """``x`` on the grid of ``wave`` (the command force, N) from rest: semi-implicit Euler
    with ``steps`` substeps per grid step, the Masing element's memory exact."""
    n = wave.size
    xs = np.zeros(n)
    h = dt / steps
    x = v = 0.0
    Fc = 0.0
    stack: list[tuple[float, float]] = []
    direc = 0.0
    two_h0 = 2.0 * h0
    half_ac = 0.5 * ac
    exp = math.exp
    for i in range(n - 1):
        c0 = wave[i]
        dc = (wave[i + 1] - c0) / steps
        for s in range(steps):
            cmd = c0 + dc * (s + 1)
            v += h * (cmd - k * x - c * v - Fc) / M
            xn = x + h * v
            step = xn - x
            if step != 0.0:
                di = 1.0 if step > 0 else -1.0
                if direc != 0.0 and di != direc:
                    stack.append((x, Fc))
                direc = di
            x = xn
            while True:
                if not stack:
                    Fc = h0 * (1.0 - exp(-ac * abs(x)))
                    if x < 0:
                        Fc = -Fc
                    break
                ur, Fr = stack[-1]
                lim = stack[-2][0] if len(stack) >= 2 else -stack[0][0]
                if direc * (x - lim) >= 0.0:
                    del stack[-2 if len(stack) >= 2 else -1 :]
                    continue
                du = x - ur
                g = two_h0 * (1.0 - exp(-half_ac * abs(du)))
                Fc = Fr + (g if du > 0 else -g)
                break
        xs[i + 1] = x
    return xs


def shaker_motion(ti, dt, f, A, ramp, h0, ac, shaker, *, m=0.0, k_p=0.0, c_v=0.0):
    """The armature's ``x`` on the internal grid ``ti`` (step ``dt``): the command
    ``F0·ramp·sin ωt`` with ``F0`` found so that the stroke over the second half of the
    first :data:`CALIBRATE_CYCLES` cycles is ``2A`` (within 0.5 %), and ``F0``."""
    M = shaker["mass"] + max(m, 0.0)
    wn = 2 * math.pi * shaker["fn"]
    k = shaker["mass"] * wn**2 + k_p
    c = 2 * shaker["zeta"] * shaker["mass"] * wn + c_v
    w = 2 * math.pi * f
    stiff = math.sqrt((h0 * ac + abs(k)) / M)
    steps = max(1, math.ceil(stiff * dt / 0.05))
    wave = ramp * np.sin(w * ti)
    # the command's amplitude is found on the first CALIBRATE_CYCLES cycles (at most the
    # record), the stroke read over their second half
    pre = ti <= min(ti[-1], CALIBRATE_CYCLES / f)
    tail = ti[pre] >= 0.5 * ti[pre][-1]
    # first guess: the linear armature's force for A, plus the friction's level
    F0 = abs(complex(k - M * w**2, c * w)) * A + h0 * (1.0 - math.exp(-ac * A))
    x = np.zeros_like(ti)
    prev = None
    for _ in range(12):
        x = _integrate(F0 * wave[pre], dt, M, k, c, h0, ac, steps)
        a = 0.5 * float(np.ptp(x[tail]))
        if not (a > 0 and math.isfinite(a)):
            raise InputError("rig_recording: the shaker did not move; give a larger acA")
        if abs(a / A - 1.0) < 0.005:
            break
        # secant on log stroke against log force where two tries exist, else proportional
        if prev is not None and prev[1] != a:
            slope = (math.log(a) - math.log(prev[1])) / (math.log(F0) - math.log(prev[0]))
            slope = min(max(slope, 0.2), 5.0)
        else:
            slope = 1.0
        prev = (F0, a)
        F0 = F0 * math.exp((math.log(A) - math.log(a)) / slope)
    x = x if bool(pre.all()) else _integrate(F0 * wave, dt, M, k, c, h0, ac, steps)
    return x, F0
