"""Errors in variables in the misfit test (issue 29, item 1): the residual structure the
input channel's noise alone leaves in a fitted nonlinear model, simulated
(:func:`eiv_bias`), which :mod:`.misfit`'s tests take out of the residual before they look
for structure no candidate explains."""

from __future__ import annotations

import dataclasses
import math
from typing import Any

import numpy as np

from ..errors import ContactLabError
from ._family import Prepared
from ._filters import savgol_filter

__all__ = ["EIV_LEVELS", "EIV_REPS", "eiv_bias"]

#: fresh input-noise draws averaged by :func:`eiv_bias` at each added level
EIV_REPS = 6
#: more for short records: ``EIV_SAMPLES / n`` pairs, at most EIV_MAX_REPS
EIV_SAMPLES = 4e5
EIV_MAX_REPS = 48
#: the added input-noise variances of :func:`eiv_bias` (multiples of the measured one)
EIV_LEVELS = (1.0, 2.0, 3.0)
#: caches the models keep in ``d.extra`` (forces per ``ac``, merged knots), emptied in the
#: copies :func:`eiv_bias` drives with another input
_KEEP_EXTRA = ("regime_info", "meta")


def _driven(d: Prepared, u: np.ndarray) -> Prepared:
    """A copy of ``d`` whose model input is ``u`` (the models' caches emptied)."""
    extra = {
        k: ({} if isinstance(v, dict) and k not in _KEEP_EXTRA else v) for k, v in d.extra.items()
    }
    return dataclasses.replace(d, u=u, extra=extra)


def eiv_bias(
    family: Any,
    params: dict[str, float],
    effects: tuple[str, ...],
    d: Prepared,
    *,
    reps: int | None = None,
    seed: int = 0,
) -> np.ndarray | None:
    """The residual structure the input's noise alone leaves in a fitted model's residual
    (errors in variables), by simulation-extrapolation; measured minus model, per sample.

    A nonlinear model driven by a noisy input is biased where it bends: the noise pushes a
    Masing element's turning points outward at every reversal (a shift in proportion to the
    noise's level ``s``) and a curved branch's mean by ``F''·s²/2``, cycle after cycle:
    structure locked to the phase, no misfit. The model is run on the candidates' input
    with fresh draws of the estimated input noise ``σu`` added through the candidates' own
    filter, at added variances :data:`EIV_LEVELS` times the measured one (antithetic pairs,
    ``EIV_SAMPLES / n`` of them, between :data:`EIV_REPS` and :data:`EIV_MAX_REPS`); per
    sample the mean prediction ``y(s)``, ``s = √(1 + λ)``, is fitted by ``c0 + c1 s + c2 s²``
    and extrapolated to ``s = 0`` (no noise): the bias is ``b = y(1) - c0``. The fit to all
    data has already absorbed the part of ``-b`` its parameters can draw, so the residual
    expects ``-(I - P) b`` with ``P`` the weighted projection on the model's Jacobian
    (central differences); that is returned. None when the input carries no measurable
    noise, the record is a kept (decimated) one, or the model cannot be driven.
    """
    from .select import sample_weight, specs_for

    su = float(d.extra.get("u_noise", 0.0))
    wlen = int(d.extra.get("u_filter", 0))
    if not (su > 0 and wlen) or "knots" in d.extra or "raw_input" in d.extra:
        return None

    n = d.u.size
    rng = np.random.default_rng(seed)
    if reps is None:  # the simulation's own noise falls with the record's length
        reps = int(np.clip(round(EIV_SAMPLES / n), EIV_REPS, EIV_MAX_REPS))

    def predict(u: np.ndarray, p: dict[str, float]) -> np.ndarray:
        return np.asarray(family.predict(p, effects, _driven(d, u)), float)

    try:
        # the model's mean prediction with the input's noise raised to s = √(1+λ) times its
        # level, λ = 0 (the input as measured) and each of EIV_LEVELS
        curves = [predict(d.u, params)]
        for lam in EIV_LEVELS:
            acc = np.zeros(n)
            for _ in range(reps):  # antithetic pairs: the noise's linear response cancels
                nu = savgol_filter(rng.normal(0.0, su * math.sqrt(lam), n), wlen, 3, mode="interp")
                acc += predict(d.u + nu, params) + predict(d.u - nu, params)
            curves.append(acc / (2 * reps))
        # per sample, y(s) = c0 + c1 s + c2 s² (a turning point pushed out by the noise
        # moves in proportion to s, a curvature's mean by s²) extrapolated to s = 0
        sv = np.sqrt(1.0 + np.r_[0.0, EIV_LEVELS])
        X = np.column_stack([np.ones(sv.size), sv, sv * sv])
        c0 = np.linalg.pinv(X)[0] @ np.vstack(curves)
        b = curves[0] - c0
        cols = []
        scales = family.scales(d)
        for spec in specs_for(family, effects):
            v = params.get(spec.name)
            if v is None or not np.isfinite(v):
                continue
            h = 1e-4 * max(abs(v), float(scales.get(spec.scale, 1.0)) * 1e-2)
            up, dn = dict(params), dict(params)
            up[spec.name], dn[spec.name] = v + h, v - h
            cols.append((predict(d.u, up) - predict(d.u, dn)) / (2 * h))
    except (ContactLabError, ValueError, ArithmeticError):  # refused: no correction
        return None
    if not np.all(np.isfinite(b)):
        return None
    w = sample_weight(d)
    use = np.isfinite(d.y) & (w > 0)
    if cols:
        J = np.column_stack(cols)[use]
        sw = np.sqrt(w[use])
        A = J * sw[:, None]
        norm = np.linalg.norm(A, axis=0)
        norm[norm == 0] = 1.0
        coef, *_ = np.linalg.lstsq(A / norm, b[use] * sw, rcond=1e-10)
        b = b - (np.column_stack(cols) / norm) @ coef
    return -b
