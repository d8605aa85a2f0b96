"""A linear term of a candidate against the record's own simulated null (issue 29).

On a single-frequency drive a mass between sensor and contact is ``m ẍ = -mω² x``, a
negative parallel stiffness. Where the loops reach no flat plateau (``ac·A`` below
:data:`~.effects.tangential.inertia.STEADY_SEPARABLE_ACA`) the base Masing element takes most
of such a linear term into its own stiffness and curvature; what it cannot take is small
(refitting h0, ac and an offset to a noise-free Masing loop minus mω²x absorbs 99.7 % of
the mass's force at ac·A 0.5, 99 % at 1, 96 % at 2 and 89 % at 3.4:
``benches/inertia_absorption.py --aca 0.5,0.9,1,2,3.4 --share 0.02``; the rest has a fixed
shape), and the input channel's noise biases the base model the same way (errors
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

__all__ = [
    "MASS_NULL_ALPHA",
    "MASS_NULL_DRAWS",
    "LinearNull",
    "NullBound",
    "linear_term_null",
    "null_bound",
]

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
    #: the linearised size per unit of a candidate in the data, which acts through the true
    #: input (:func:`linear_term_null`'s ``kept_at``; NaN when not asked): below 1 where the
    #: direction the size is read along carries the input's differentiated noise (errors in
    #: variables dilute the regression)
    kept: float = math.nan
    #: the same per copy (each copy's own noisy direction; paired with ``null``), empty when
    #: not asked
    kept_draws: np.ndarray = dataclasses.field(default_factory=lambda: np.zeros(0))

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
    kept_at: float | None = None,
    signal: Any = None,
) -> LinearNull | None:
    """The linearised size of candidate ``name`` (parameter ``size_param``, additive and
    linear in it) on the record and on ``draws`` copies simulated from the base model
    ``(base, effects)`` with the record's own noise on both channels (module docstring).

    ``sigma``: the diagnosis's noise RMS, the output noise drawn where the residual's own
    level beyond the input's share cannot be read. None where the record carries no
    measured input noise, the model cannot be driven by the simulated input, or too few
    copies could be drawn. ``kept_at`` (true): also the linearised size per unit of the
    candidate acting through the denoised input (``LinearNull.kept``, for the bound of
    :func:`null_bound`); ``draws`` 0 then skips the copies. ``signal``: a map of a record to
    the one its candidate's direction is read on (default: itself)."""
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
        sig = (lambda v: v) if signal is None else signal
        # the candidate's direction on the record and its copies alike from the local ẍ
        # (``mass_local``: a mass's ẍ from the drive's harmonics is for the search's fits;
        # this null and its bound were calibrated on the local one)
        ds = sig(dataclasses.replace(d, extra={**d.extra, "fixed": {}, "mass_local": True}))
        g = np.asarray(family.predict(p1, full, ds), float) - np.asarray(
            family.predict(p0, full, ds), float
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
            # (``u_raw``: the copy's measured input, which the mass's ẍ is read from)
            ex = {**dk.extra, "fixed": {}, "u_raw": u_raw, "mass_local": True}
            dg = sig(dataclasses.replace(dk, ud=ud, udd=udd, extra=ex))
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
        kept, g_true = math.nan, None
        if kept_at:  # a candidate in the data acts through the true input's derivatives
            g_true = direction(d_true, x_true)
            kept = size(g_true, g)
        if draws <= 0:  # the share alone
            return LinearNull(m_obs, np.zeros(0), math.nan, 0.0, float(sigma), kept)
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
        null: list[float] = []
        per_unit: list[float] = []
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
            if g_true is not None:
                per_unit.append(size(g_true, gk))
    except (ContactLabError, ValueError, ArithmeticError, np.linalg.LinAlgError):
        return None
    v = np.asarray(null, float)
    ku = np.asarray(per_unit, float)
    return LinearNull(m_obs, v, _upper(v, alpha), su, float(sig_out), kept, ku)


#: the power the null's bound is stated at (as :data:`contactlab.diagnose.power.POWER`)
NULL_POWER = 0.95


@dataclasses.dataclass(frozen=True)
class NullBound:
    """The smallest size of a candidate whose linearised size on the record would stand
    beyond the record's own simulated null with probability :data:`NULL_POWER`.

    Attributes
    ----------
    bound : float or None
        The size (units of the size parameter); None: see ``reason``.
    null : LinearNull
        The null it was read from.
    kept : float
        The linearised size per unit of the candidate (``LinearNull.kept``).
    reason : str
        Why there is no bound (empty otherwise).
    """

    bound: float | None
    null: LinearNull | None
    kept: float
    reason: str = ""


def null_bound(
    family: Any,
    base: dict[str, float],
    effects: tuple[str, ...],
    name: str,
    size_param: str,
    d: Prepared,
    sigma: float,
    *,
    alpha: float = MASS_NULL_ALPHA,
    power: float = NULL_POWER,
    seed: int = 0,
    signal: Any = None,
) -> NullBound:
    """The bound of candidate ``name`` from the record's own simulated null
    (:func:`linear_term_null`, the test the search names it by): its linearised size on a
    record holding it at size ``b`` is ``e + κ b``, ``e`` a draw of the null and ``κ`` the
    size per unit of the candidate acting through the denoised input, read along the
    record's own noisy direction (the input's differentiated noise dilutes the regression:
    ``κ`` 0.02-0.6 on the rig's single-frequency records; the base's noise-free refit
    absorbs a mass as its linearisation does, leaving 1.00-1.01 of it). Both are taken per
    copy (``LinearNull.null`` and ``kept_draws``, paired; the copies' ``κ`` scaled to the
    record's own where that is smaller), so that ``κ``'s scatter from record to record
    counts; the bound is the smallest ``b`` whose sizes ``e_k + κ_k b``
    have their lower ``power`` prediction bound (Student's, over the ``k`` copies) at the
    null's upper bound ``T``."""
    from .misfit import t_quantile

    res = linear_term_null(
        family,
        base,
        effects,
        name,
        size_param,
        d,
        sigma,
        alpha=alpha,
        seed=seed,
        kept_at=True,
        signal=signal,
    )
    if res is None:
        return NullBound(
            None,
            None,
            math.nan,
            "the record's null could not be simulated (no "
            "measured input noise, or the base model cannot be driven by it)",
        )
    v = res.null[np.isfinite(res.null)]
    if v.size < 4 or not np.isfinite(res.threshold):
        return NullBound(None, res, math.nan, "too few simulated copies of the record")
    ku = res.kept_draws
    ok = np.isfinite(res.null) & np.isfinite(ku) if ku.size == res.null.size else []
    e, ku = res.null[ok], ku[ok]
    if e.size < 4:
        return NullBound(None, res, res.kept, "too few simulated copies of the record")
    # the copies' directions carry the input noise as the null simulates it, which on the
    # rig dilutes them less than the record's own (a mass moved the record's size by
    # 0.021-0.59 per kg where its own κ read 0.028-0.58 and the copies' 0.08-0.64: fresh
    # seeds 6700-6701 of three factor sets): the copies' κ scaled to the record's own,
    # keeping their scatter
    kept = min(float(np.mean(ku)), res.kept) if np.isfinite(res.kept) else math.nan
    if np.isfinite(kept) and kept > 0:
        ku = ku * (kept / float(np.mean(ku)))
    if not (np.isfinite(kept) and kept > 0):
        return NullBound(
            None,
            res,
            kept,
            (
                f"a {name} in the data moves its size along the direction it is read by "
                f"{kept:.2g} per unit (the input's differentiated noise in that direction): "
                "no size of it stands out of the record's null"
            )
            if np.isfinite(kept)
            else (
                f"how far a {name} in the data moves its size could not be read (the "
                "denoised input's direction is degenerate on this record)"
            ),
        )
    q = t_quantile(power, e.size - 1) * math.sqrt(1.0 + 1.0 / e.size)

    def short(b: float) -> float:
        """How far the lower ``power`` bound of the sizes at ``b`` falls below ``T``."""
        z = e + ku * b
        return res.threshold - (float(np.mean(z)) - q * float(np.std(z, ddof=1)))

    hi = max(res.threshold - float(np.mean(e)), 1e-12 * abs(res.threshold), 1e-300) / kept
    for _ in range(60):
        if short(hi) <= 0:
            break
        hi *= 2.0
    else:
        return NullBound(
            None,
            res,
            kept,
            (
                f"the {name}'s effect on its size scatters from copy to copy as much as it grows "
                "(the input's differentiated noise): no size stands out of the record's null"
            ),
        )
    lo = hi / 2.0 if short(hi / 2.0) > 0 else 0.0
    for _ in range(50):
        mid = 0.5 * (lo + hi)
        if short(mid) > 0:
            lo = mid
        else:
            hi = mid
        if hi - lo < 1e-3 * hi:
            break
    return NullBound(float(hi), res, kept)
