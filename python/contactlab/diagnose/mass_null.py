"""A linear term of a candidate against the record's own simulated null (issue 29).

On a single-frequency drive a mass between sensor and contact is ``m ẍ = -mω² x``, a
negative parallel stiffness. Where the loops reach no flat plateau (``ac·A`` below
:data:`~.effects.tangential.inertia.STEADY_SEPARABLE_ACA`) the base Masing element takes most
of such a linear term into its own stiffness and curvature; what it cannot take is small
(fitting a Masing loop to Masing − k·x at ac·A 0.5-3.5 absorbs 86-93 % of the term, the rest
has a fixed shape), and the input channel's noise biases the base model the same way (errors
in variables: a noisy x makes the contact look softer). So a fitted mass is compared with
what the record's own null gives (:func:`linear_term_null`): copies of the record simulated
from the base model fitted without the candidate, driven by the record's input with its
noise taken away (:func:`.misfit_null.denoised_input`) plus fresh input noise of the
record's own spectrum, with output noise at the residual's own level
(:func:`.misfit_null.output_noise_shape`). On each copy (its base refitted, ``refit``), and
on the record, the candidate's size is read as the fit would take it, linearised: the
residual of the base model projected off the base model's Jacobian (weighted as the fit
weights the samples) and regressed on the candidate's direction (its effect per unit of its
size, off the same Jacobian), each copy's direction from its own noisy input (a mass reads
ẍ of the measured x, whose noise correlates with the force error it makes through the base:
a clean rig record's size is positive by itself, tuning seed 920000 of
``benches/eval_inertia_null.py``: 1.7 % of the force amplitude at x noise 1.3 %). The record's
size must stand beyond the upper prediction bound of the copies' sizes at
:data:`MASS_NULL_ALPHA` (Student's, as :func:`.misfit_null.calibrated_flag`).
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any

import numpy as np

from ..errors import ContactLabError
from ._family import Prepared
from ._filters import savgol_filter
from ._parallel import one_blas_thread
from ._signal import derivatives

__all__ = ["MASS_NULL_ALPHA", "MASS_NULL_DRAWS", "LinearNull", "linear_term_null"]

#: copies of the record drawn under the null
MASS_NULL_DRAWS = 24
#: the one-sided false-alarm rate of the test (a new draw from the null's normal)
MASS_NULL_ALPHA = 0.01


@dataclasses.dataclass(frozen=True)
class LinearNull:
    """A candidate's linearised size on the record and on its simulated null copies.

    Attributes
    ----------
    size : float
        The record's size (units of the candidate's size parameter).
    null : ndarray
        The sizes on the copies drawn under the null (the base model is the truth).
    threshold : float
        The upper prediction bound of the null's sizes at :data:`MASS_NULL_ALPHA`.
    input_rms, output_rms : float
        The noise drawn on the input (before the candidates' filter) and the output.
    """

    size: float
    null: np.ndarray
    threshold: float
    input_rms: float
    output_rms: float

    @property
    def beyond(self) -> bool:
        """Whether the record's size is positive and beyond the null's upper bound."""
        return bool(
            np.isfinite(self.size)
            and np.isfinite(self.threshold)
            and self.size > 0
            and self.size > self.threshold
        )

    @property
    def z(self) -> float:
        """The record's size in standard deviations of the null's, from the null's mean."""
        v = self.null[np.isfinite(self.null)]
        if v.size < 2:
            return math.nan
        sd = float(np.std(v, ddof=1))
        return (self.size - float(np.mean(v))) / sd if sd > 0 else math.nan


def _upper(v: np.ndarray, alpha: float) -> float:
    from .misfit import t_quantile

    v = v[np.isfinite(v)]
    if v.size < 4:
        return math.nan
    k = v.size
    sd = float(np.std(v, ddof=1))
    return float(np.mean(v)) + t_quantile(1.0 - alpha, k - 1) * sd * math.sqrt(1.0 + 1.0 / k)


@one_blas_thread
def linear_term_null(
    family: Any,
    base: dict[str, float],
    effects: tuple[str, ...],
    name: str,
    size_param: str,
    d: Prepared,
    sigma: float,
    *,
    draws: int = MASS_NULL_DRAWS,
    alpha: float = MASS_NULL_ALPHA,
    seed: int = 0,
    refit: bool = True,
) -> LinearNull | None:
    """The linearised size of candidate ``name`` (parameter ``size_param``, additive and
    linear in it) on the record and on ``draws`` copies simulated from the base model
    ``(base, effects)`` with the record's own noise on both channels (module docstring).

    ``sigma``: the diagnosis's noise RMS, the output noise drawn where the residual's own
    level beyond the input's share cannot be read. None where the record carries no
    measured input noise, the model cannot be driven by the simulated input, or too few
    copies could be drawn."""
    from .eiv import _coloured, input_noise_spectrum, is_coloured
    from .misfit_null import (
        _drive,
        _jacobian,
        _output_beyond_input,
        denoised_input,
        output_noise_shape,
    )
    from .select import sample_weight

    su = float(d.extra.get("u_noise", 0.0) or 0.0)
    wlen = int(d.extra.get("u_filter", 0))
    kept = "raw_input" in d.extra
    if not sigma > 0 or kept:
        return None
    spec = input_noise_spectrum(d) if su > 0 and wlen else None
    if spec is not None and not is_coloured(d, spec):
        spec = None
    if spec is not None:
        su = max(su, spec.rms)
    if not wlen:
        su = 0.0

    def filt(u: np.ndarray) -> np.ndarray:
        return savgol_filter(u, wlen, 3, mode="interp") if wlen else u

    rng = np.random.default_rng(seed)
    try:
        full = (*effects, name)
        p0 = {**base, size_param: 0.0}
        p1 = {**base, size_param: 1.0}
        g = np.asarray(family.predict(p1, full, d), float) - np.asarray(
            family.predict(p0, full, d), float
        )
        fitted = np.asarray(family.predict(base, effects, d), float)
        J = _jacobian(family, base, effects, d)
        w = np.asarray(sample_weight(d), float)
        use = np.isfinite(d.y) & (w > 0) & np.isfinite(g) & np.isfinite(fitted)
        sw = np.sqrt(w[use])
        Q = None
        if J is not None:
            A = J[use] * sw[:, None]
            nrm = np.linalg.norm(A, axis=0)
            nrm[nrm == 0] = 1.0
            Q, _ = np.linalg.qr(A / nrm)

        def off(v: np.ndarray) -> np.ndarray:
            x = v[use] * sw
            return x - Q @ (Q.T @ x) if Q is not None else x

        def size(r: np.ndarray, g: np.ndarray) -> float:
            gp = off(g)
            den = float(gp @ gp)
            return float(off(r) @ gp) / den if den > 0 else math.nan

        def direction(dk: Prepared, u_raw: np.ndarray) -> np.ndarray:
            # the candidate's direction on the copy, from the copy's own input: a mass reads
            # ẍ of the measured x, whose noise correlates with the noise the base model
            # turns into force error (errors in variables in the regressor itself)
            ud, udd = derivatives(u_raw, d.dt, d.window)
            dg = dataclasses.replace(dk, ud=ud, udd=udd, extra={**dk.extra, "fixed": {}})
            return np.asarray(family.predict(p1, full, dg), float) - np.asarray(
                family.predict(p0, full, dg), float
            )

        r_obs = np.asarray(d.y, float) - fitted
        m_obs = size(r_obs, g)
        x_true, _ = denoised_input(d)
        d_true = _drive(d, filt(x_true))
        if d_true is None:
            return None
        truth = np.asarray(family.predict(base, effects, d_true), float)
        driven = []
        for _ in range(draws):
            u = x_true + _coloured(rng, x_true.size, spec) * su if su > 0 else x_true
            dk = _drive(d, filt(u))
            if dk is not None:
                mk = np.asarray(family.predict(base, effects, dk), float)
                driven.append((dk, mk, direction(dk, u)))
        if len(driven) < max(8, draws // 2):
            return None
        out_shape = output_noise_shape(d, r_obs)
        sig_out = sigma
        if out_shape is not None:
            out_shape, sig_out = _output_beyond_input(
                d, out_shape, truth, [(dk, mk) for dk, mk, _ in driven], sigma
            )
        null = []
        if refit:
            from .select import fit

            scales = family.scales(d)
            every = np.ones(d.y.size, bool)
        for dk, mk, gk in driven:
            yk = truth + _coloured(rng, truth.size, out_shape) * sig_out
            if refit:  # the base refitted to the copy, as the record's was
                dy = dataclasses.replace(dk, y=yk)
                pk = fit(family, effects, dy, every, dict(base), scales).params
                mk = np.asarray(family.predict(pk, effects, dk), float)
            null.append(size(yk - mk, gk))
    except (ContactLabError, ValueError, ArithmeticError, np.linalg.LinAlgError):
        return None
    v = np.asarray(null, float)
    return LinearNull(m_obs, v, _upper(v, alpha), su, float(sig_out))
