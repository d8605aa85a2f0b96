"""``force_offset``: a constant force-sensor bias."""

from __future__ import annotations

import itertools

import numpy as np

from ..._family import ParamSpec, Prepared
from .._base import EffectModel, Plausibility, register
from ._common import REST_SAMPLES, TURN_SHARE, TURN_SIGMAS, reconstructed

#: a record "starts at rest" when the displacement stands still (within the turning points'
#: hysteresis band, :data:`~._common.TURN_SIGMAS` input-noise RMS or
#: :data:`~._common.TURN_SHARE` of its range) for at least this many samples
REST_MIN_SAMPLES = 10
#: the force at rest and a fitted sensor zero ``F0`` disagree when they differ by more than
#: this share of ``|F0|`` and more than :data:`REST_SIGMAS` times the force's spread at rest
REST_SHARE = 0.3
REST_SIGMAS = 4.0


def rest_start(d: Prepared) -> tuple[int, float, float, float] | None:
    """The record's rest at its start: ``(samples, duration s, mean force, force spread)``
    while the displacement has not yet left its first position (by more than the turning
    points' band), or None when it moves from its first samples (a record cut from a
    running test, a frame's record starting mid-stroke).

    A contact at rest before the first motion carries no friction load from the test: the
    force read there is the load cell's zero (plus any residual force the contact holds),
    which is what a sensor's offset ``F0`` must equal."""
    u, y = d.u, d.y
    if y is None or u.size < 2 * REST_MIN_SAMPLES:
        return None
    noise = float(d.extra.get("u_noise", 0.0) or 0.0)
    band = max(TURN_SIGMAS * noise, TURN_SHARE * float(np.ptp(u)))
    x0 = float(np.median(u[:REST_SAMPLES]))
    moved = np.flatnonzero(np.abs(u - x0) > band)
    n = int(moved[0]) if moved.size else int(u.size)
    if n < REST_MIN_SAMPLES or n >= u.size // 2:
        return None
    yr = np.asarray(y[:n], float)
    return n, float(d.t[n - 1] - d.t[0]), float(np.mean(yr)), float(np.std(yr))


def rest_verdict(d: Prepared, F0: float) -> tuple[bool | None, str]:
    """Whether the force at rest at the record's start agrees with a sensor zero ``F0``
    (None: the record does not start at rest, so the rest force cannot check it) and the
    sentence saying so in numbers."""
    rest = rest_start(d)
    if rest is None:
        return None, (
            "the record does not start at rest (the displacement moves from its first "
            "samples), so the force at rest cannot check F0"
        )
    n, dur, fr, spread = rest
    tol = max(REST_SHARE * abs(F0), REST_SIGMAS * spread)
    if abs(fr - F0) > tol:
        return False, (
            f"the record starts at rest ({n} samples, {dur:.3g} s, the displacement still) "
            f"with the force at {fr:.4g} ± {spread:.2g} N, not at F0 = {F0:.4g} N: a sensor's "
            "zero would read there; the shift of the plateaus is the contact's, not the "
            "load cell's"
        )
    return True, (
        f"the record starts at rest with the force at {fr:.4g} ± {spread:.2g} N "
        f"({n} samples), as a sensor's zero F0 = {F0:.4g} N reads"
    )


#: the plateaus' common trend and a fitted drift ``F1`` disagree when they differ by more
#: than this share of ``|F1|`` and more than DRIFT_SIGMAS standard errors of the trend
DRIFT_SHARE, DRIFT_SIGMAS = 0.5, 3.0


def plateau_trend(d: Prepared) -> tuple[float, float, int] | None:
    """How the two directions' force levels move together over the record: each stroke's
    mean force over the second half of its travel (``level_k`` at the stroke's start
    ``t_k``, direction ``s_k = ±1``) regressed on ``1, s_k, t_k, s_k t_k``; returns the
    common change over the record (the ``t_k`` coefficient times the duration: what a
    drifting sensor zero moves both plateaus by), its standard error and the strokes read,
    or None with fewer than six strokes. A change of one direction's friction alone (wear,
    heating on one side) moves the levels apart instead (the ``s_k t_k`` term)."""
    rev = np.asarray(d.cycles.reversals, int)
    rows = []
    for a, b in itertools.pairwise(rev):
        if b - a < 4:
            continue
        s = d.u[a : b + 1] - d.u[a]
        sign = 1.0 if s[-1] > 0 else -1.0
        sel = sign * s > 0.5 * abs(float(s[-1]))
        level = d.y[a : b + 1][sel]
        level = level[np.isfinite(level)]
        if level.size:  # (a stroke whose force is missing says nothing: no "± nan")
            rows.append((float(np.mean(level)), sign, float(d.t[a] - d.t[0])))
    if len(rows) < 6:
        return None
    lv, sg, tt = (np.asarray(c) for c in zip(*rows, strict=True))
    X = np.column_stack([np.ones_like(tt), sg, tt, sg * tt])
    coef, *_ = np.linalg.lstsq(X, lv, rcond=None)
    r = lv - X @ coef
    dof = max(len(rows) - 4, 1)
    cov = float(r @ r) / dof * np.linalg.pinv(X.T @ X)
    T = float(d.t[-1] - d.t[0])
    return float(coef[2]) * T, float(np.sqrt(max(cov[2, 2], 0.0))) * T, len(rows)


def drift_verdict(d: Prepared, p: dict[str, float]) -> tuple[bool | None, str]:
    """Whether a fitted drift of the force sensor's zero by ``p["F1"]`` over the record
    agrees with how the data's two plateaus move together (:func:`plateau_trend`; None:
    too few strokes to tell), and the sentence saying so."""
    got = plateau_trend(d)
    if got is None:
        return None, "too few strokes to follow the plateaus over the record"
    common, se, n = got
    if not (np.isfinite(common) and np.isfinite(se)):
        return None, f"the plateaus' common trend over {n} strokes could not be read"
    F1 = float(p["F1"])
    if abs(common - F1) > max(DRIFT_SHARE * abs(F1), DRIFT_SIGMAS * se):
        return False, (
            f"over {n} strokes the two directions' force levels move together by "
            f"{common:.4g} ± {se:.2g} N over the record, not by F1 = {F1:.4g} N: a drifting "
            "sensor zero would move both by F1"
        )
    return True, (
        f"over {n} strokes the two directions' force levels move together by {common:.4g} ± "
        f"{se:.2g} N over the record, as a sensor zero drifting by F1 = {F1:.4g} N does"
    )


#: a record "starts from rest" (its first loading is the virgin curve from the contact's
#: rest) when the input's speed over its first samples is below this share of the speed it
#: reaches: a drive from rest (a servo, a ramp) starts at zero speed, a record cut from a
#: running test at any speed up to the full one. A force reconstructed from a frame's
#: displacements is never checked there (the frame's records are cut from a running test:
#: frame_450g starts at a low speed, and its first stretch lay 3.1 N, four times h0, from
#: any virgin curve from rest)
START_SPEED_SHARE = 0.25


def starts_slowly(d: Prepared) -> bool:
    """Whether the record starts from rest in the middle of its stroke: the input's first
    :data:`~._common.REST_SAMPLES` samples within a quarter of its range from the stroke's
    middle, their mean speed (the smoothed ``ẋ``) below :data:`START_SPEED_SHARE` of its
    99th-percentile speed. A record cut from a running test is not (at full speed
    mid-stroke, or slowly near a turning point)."""
    from ._common import smoothed_velocity

    v = np.abs(np.asarray(smoothed_velocity(d), float))
    if v.size < 4 * REST_SAMPLES:
        return False
    # a contact at rest sits in the middle of the stroke it is then driven over (within a
    # quarter of the range, as _common.from_rest reads it); a record cut near a turning
    # point starts slowly too, at an end (the friction frame at 450 g: 0.47 of the range
    # from the middle, at 0.17 of the peak speed)
    span = float(np.ptp(d.u))
    mid = 0.5 * (float(np.max(d.u)) + float(np.min(d.u)))
    if not abs(float(np.median(d.u[:REST_SAMPLES])) - mid) <= 0.25 * span:
        return False
    top = float(np.percentile(v, 99.0))
    return bool(top > 0 and float(np.mean(v[:REST_SAMPLES])) < START_SPEED_SHARE * top)


@register
class ForceOffset(EffectModel):
    name = "force_offset"
    kind = "tangential"
    params = (ParamSpec("F0", "N", 0.0, -np.inf, np.inf, "F"),)
    description = "constant force-sensor bias F0"
    physics = (
        "The load cell's zero is off: F = h + F0. Both plateaus move by F0, and a record "
        "that starts at rest reads F0 before the first motion."
    )
    stage = "additive"
    rank = 4
    order = 4
    size_param = "F0"

    def apply(self, F, p, ctx):
        return F + p["F0"]

    def plausible(self, d, p):
        base = super().plausible(d, p)
        if not base.ok:
            return base
        ok, why = rest_verdict(d, float(p["F0"]))
        if ok is False:
            return Plausibility(False, why)
        if {"h0", "ac"} <= set(p) and "lam" not in p and starts_slowly(d) and not reconstructed(d):
            # the first loading from rest before the first turning point (read as the
            # intercept at rest of the residual against the travel: sharper than the still
            # stretch's mean, and there when the motion starts at once): a sensor's zero is
            # there before the motion, a displacement offset's (or a branch scale's) shift
            # of the loop is not (:func:`~._first_loading.unexplained_start`)
            from ._first_loading import unexplained_start

            start = unexplained_start(p, d, float(p["F0"]), f"a force offset F0 = {p['F0']:.3g} N")
            if start:
                return Plausibility(False, start)
        return Plausibility(True, f"{base.reason}; {why}")

    def argument(self, d, p):
        from ._common import meta

        h0 = p.get("h0", np.nan)
        frame = meta(d).get("frame")
        K = frame.get("K") if isinstance(frame, dict) else None
        zero = (
            f"; the force is reconstructed as K (y - x) + ...: F0 is a zero of the two "
            f"displacement sensors off by F0/K = {p['F0'] / K:.3g} m"
            if isinstance(K, (int, float)) and K > 0
            else ""
        )
        return (
            f"F0 = {p['F0']:.4g} N ({100 * p['F0'] / h0:.1f} % of h0 = {h0:.4g} N): both "
            "plateaus shifted alike, a sensor's zero (the virgin curve starts from F0, not "
            f"0){zero}"
        )
