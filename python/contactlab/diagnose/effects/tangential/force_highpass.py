"""``force_highpass``: a piezoelectric load cell's charge leaking through its amplifier's time
constant (a first-order high-pass of the force, corner ``fc``)."""

from __future__ import annotations

import math

import numpy as np

from ..._family import ParamSpec
from .._base import EffectModel, Plausibility, register
from ._common import period, reconstructed

#: the highest corner that leaves the record's loops meaningful, as a fraction of the drive's
#: frequency: at ``fc = f/5`` the high-pass's quadrature term ``-ωc ∫F dt`` is a fifth of the
#: friction force (its gain ``ω/√(ω² + ωc²)`` 0.98, its phase lead 11°); above, the loops are
#: the charge amplifier's more than the contact's
MAX_CORNER_SHARE = 0.2
#: the highest corner plausible in absolute terms: a charge amplifier's shortest time-constant
#: setting is of order 0.1 s (corner 1.6 Hz); an IEPE cell's discharge time constant is
#: longer. A corner above 2 Hz is no load cell's
MAX_CORNER_HZ = 2.0
#: the start's grid (:meth:`ForceHighpass.start`): this many corners, geometrically spaced from
#: a thousandth of the drive's frequency to :data:`MAX_CORNER_SHARE` of it
START_GRID = 24
#: blocks of the exact recursion (:func:`highpass`): at most this many time constants each
#: (``exp`` of it stays far inside the double range)
_BLOCK_DECAY = 300.0


def highpass(F: np.ndarray, t: np.ndarray, fc: float) -> np.ndarray:
    """``F`` through the first-order high-pass ``s / (s + ωc)``, ``ωc = 2π fc``, on the time
    axis ``t`` (uniform or not), starting from rest: the output equals ``F[0]`` at ``t[0]``
    (the charge amplifier reset, the force applied at the record's start), then follows
    ``ẏ = Ḟ - ωc y`` exactly for a force linear between samples (first-order hold):
    ``y_n = e^(-ωc h) y_(n-1) + (F_n - F_(n-1)) (1 - e^(-ωc h)) / (ωc h)``, ``h`` the step.

    Evaluated in closed form (a cumulative sum in blocks of :data:`_BLOCK_DECAY` time
    constants), not sample by sample."""
    F = np.asarray(F, dtype=float)
    if not fc > 0.0 or F.size < 2:
        return F.copy()
    t = np.asarray(t, dtype=float)
    a = 2.0 * math.pi * fc
    ah = a * np.diff(t)
    small = ah < 1e-8
    g = np.where(small, 1.0 - 0.5 * ah, -np.expm1(-ah) / np.where(small, 1.0, ah))
    gdF = g * np.diff(F)
    tau = a * (t - t[0])
    y = np.empty_like(F)
    y[0] = F[0]
    n, s = F.size, 0
    while s < n - 1:
        stop = int(np.searchsorted(tau, tau[s] + _BLOCK_DECAY, side="right")) - 1
        stop = min(max(stop, s + 1), n - 1)
        S = tau[s + 1 : stop + 1] - tau[s]
        y[s + 1 : stop + 1] = np.exp(-S) * (y[s] + np.cumsum(gdF[s:stop] * np.exp(S)))
        s = stop
    return y


def drive_frequency(d) -> float:
    """The drive's frequency (Hz): the inverse of the record's excitation period."""
    per = period(d)
    return 1.0 / per if per > 0 else np.inf


@register
class ForceHighpass(EffectModel):
    name = "force_highpass"
    kind = "tangential"
    params = (ParamSpec("fc", "Hz", 0.0, 0.0, np.inf, "fq"),)
    description = "piezoelectric load cell's high-pass (charge amplifier), corner fc"
    physics = (
        "A piezoelectric load cell's charge leaks through its charge amplifier's time constant "
        "1/ωc (ωc = 2π fc): the force is measured through the first-order high-pass "
        "s/(s + ωc), from rest at the record's start. F_meas ≈ F - ωc ∫F dt: on a steady loop "
        "a term in quadrature with the force (a dashpot c ≈ k ωc/ω² takes it on one drive "
        "frequency), but it follows the integral of the friction force (a triangle under a "
        "square sliding force), scales as 1/ω, takes the force's mean off and leaves a "
        "decaying offset after the first loading."
    )
    #: its steady term is in quadrature with the force, as a dashpot's, a delay's: named
    #: beside one of those only when each stands on its own (search.parsimony)
    acts_through = "velocity"
    stage = "output"
    rank = 1  # after the delay (the two commute: both linear in time, the order is moot)
    order = 8
    size_param = "fc"
    #: the filter's output at a sample depends on the whole force before it: the family
    #: evaluates the whole record and picks the samples asked for
    whole_record = True
    #: its fit reads the force's own history, not the input's derivatives: the input's noise
    #: feeds it through the element only, as it feeds the base
    input_noise_gain = False

    def apply(self, F, p, ctx):
        d = ctx.d
        fc = float(p["fc"])
        if not fc > 0.0:
            return F
        t = ctx.fixed("t_rel", lambda: d.t - d.t[0])
        if np.shape(t) != np.shape(F):  # (only on the whole record: see whole_record)
            raise ValueError("force_highpass: the whole record is needed")
        # the sensor's zero (an offset, a drift of the charge amplifier) is added after the
        # high-pass: it is taken off before, put back after
        zero = 0.0
        if "force_offset" in ctx.effects:
            zero = zero + p["F0"]
        if "force_drift" in ctx.effects:
            zero = zero + p["F1"] * t / d.duration
        return highpass(F - zero, t, fc) + zero

    def start(self, p, d, residual, family=None):
        """The corner on a grid (:data:`START_GRID` from a thousandth of the drive's frequency
        to :data:`MAX_CORNER_SHARE` of it) that best brings the current prediction, filtered,
        onto the data (the likelihood's weights)."""
        r = np.asarray(residual, float)
        if d.t.size < 8 or not np.all(np.isfinite(r)):
            return {}
        f = drive_frequency(d)
        if not np.isfinite(f):
            return {}
        pred = d.y - r
        w = d.extra.get("weight")
        w = np.ones_like(r) if w is None or np.shape(w) != r.shape else np.asarray(w, float)
        best, out = float(np.sum(w * r * r)), {}
        t = d.t - d.t[0]
        top = min(MAX_CORNER_SHARE * f, MAX_CORNER_HZ)
        for fc in np.geomspace(1e-3 * f, top, START_GRID):
            e = d.y - highpass(pred, t, float(fc))
            v = float(np.sum(w * e * e))
            if v < best:
                best, out = v, {"fc": float(fc)}
        return out

    def plausible(self, d, p):
        """The shared rules; a force computed from the displacement has no piezo cell; a corner
        above :data:`MAX_CORNER_SHARE` of the drive's frequency or above
        :data:`MAX_CORNER_HZ` leaves no loop of the contact's to diagnose."""
        base = super().plausible(d, p)
        if not base.ok:
            return base
        why = reconstructed(d)
        if why:
            return Plausibility(False, f"{why}: no load cell measured it, so none high-passed it")
        fc, f = float(p["fc"]), drive_frequency(d)
        if fc > MAX_CORNER_SHARE * f:
            return Plausibility(
                False,
                f"a corner of {fc:.3g} Hz is {fc / f:.2g} times the drive's {f:.3g} Hz (plausible: "
                f"below {MAX_CORNER_SHARE:g} times it): the quadrature term -ωc∫F dt would be "
                f"{100 * fc / f:.0f} % of the friction force, a record of the charge amplifier "
                "more than of the contact; the base model, not the sensor, is off",
            )
        if fc > MAX_CORNER_HZ:
            return Plausibility(
                False,
                f"a corner of {fc:.3g} Hz (time constant {1 / (2 * math.pi * fc):.3g} s) is "
                f"above {MAX_CORNER_HZ:g} Hz: no charge amplifier's time constant is that short",
            )
        return base

    def argument(self, d, p):
        fc, f = float(p["fc"]), drive_frequency(d)
        tc = 1.0 / (2.0 * math.pi * fc)
        return (
            f"fc = {fc:.3g} Hz (time constant {tc:.3g} s, {d.duration / tc:.2g} of them over the "
            f"{d.duration:.3g} s record) = {fc / f:.2g} of the drive's {f:.3g} Hz: a piezo "
            "cell's charge leaking through its amplifier (plausible: below "
            f"{MAX_CORNER_SHARE:g} of the drive and {MAX_CORNER_HZ:g} Hz)"
        )
