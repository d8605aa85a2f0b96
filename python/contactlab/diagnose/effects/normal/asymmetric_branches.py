"""``asymmetric_branches``: loading and unloading dissipate differently."""

from __future__ import annotations

import numpy as np

from ..._family import ParamSpec
from .._base import EffectModel, register


def startup_samples(d) -> np.ndarray:
    """The samples of the record's start that no fold holds out: before the excitation's
    first maximum (``cycle == -1`` there), where a record from rest builds its amplitude."""
    cyc = d.cycles.cycle
    maxima = d.cycles.reversals[d.cycles.is_max]
    out = np.zeros(cyc.size, bool)
    if maxima.size:
        out[: int(maxima[0])] = True
    return out


#: the stiffening law and the loss asymmetry, each fitted alone, are told apart only where
#: the likelihood ratio of the one over the other (:func:`shape_test`) lies this many of
#: its standard deviations from a tie (one-sided 2.3 %); nearer, neither is named: the
#: record shows a shape beyond the ellipse it cannot attribute. The ideal test of issue 29
#: calls either effect visible where its direction beyond the other's reaches a
#: noncentrality of 44.8; there the ratio's mean lies 3.35 deviations out, so the rule
#: names it in 91 % of records and names the other in at most 2.3 % of records where the
#: two cannot be told apart (at 0 (stop 49) a coin: package generator, one tone from
#: rest at the issue's conditions, tuning seeds 49710000-009, see docs/effects.md §2)
SHAPE_Z = 2.0


def shape_test(d, current, stiff, asym) -> tuple[float, float, float, float]:
    """:func:`shape_evidence`'s ``(total, held-out part, start-up part)`` and its
    significance ``z``: the total over its standard deviation where the two fit alike, as a
    test of two non-nested accounts (Vuong 1989; Cox). The noise moves the two sums of
    squares apart by ``2 Σ w e (f_s - f_a)`` (``f_s``, ``f_a`` the two fits), of standard
    deviation ``2 ‖f_s - f_a‖_w / σ`` in χ² units over the samples compared (the held-out
    cycles and the start-up); ``z`` near 0 whatever the total's sign where the two fits
    nearly coincide. Positive: the law fits better."""
    from ..._signal import noise_rms
    from ...select import sample_weight

    total, held, start = shape_evidence(d, current, stiff, asym)
    sigma2 = noise_rms(current.full_residual(d)) ** 2
    if not sigma2 > 0:
        return total, held, start, 0.0
    rows = (d.cycles.cycle >= 0) | startup_samples(d)
    gap = np.asarray(stiff.fitted, float) - np.asarray(asym.fitted, float)
    w = sample_weight(d)
    ok = rows & np.isfinite(gap)
    scale = 2.0 * float(np.sqrt(np.sum((w * gap * gap)[ok]) / sigma2))
    return total, held, start, (total / scale if scale > 0 else 0.0)


def shape_evidence(d, current, stiff, asym) -> tuple[float, float, float]:
    """The log-likelihood ratio (χ² units, noise variance σ² of the current model's
    residual) of the stiffening law over the loss asymmetry, both
    :class:`~contactlab.diagnose.select.Trial` of one step: ``(total, held-out part,
    start-up part)``.

    The held-out part is what the two models' held-out cycles say (their held-out errors,
    each corrected to the current model's input-noise term, over the held-out samples); the
    start-up part adds the samples before the first maximum of the excitation, which no
    fold holds out: the fits to all data there (their parameters are set by the cycles
    after, so these samples are nearly out of sample). On one tone at one amplitude the
    two draw the same 2ω signature once ``p0`` has taken each one's mean shift; from rest
    the mean shift builds with the amplitude, and it differs (docs/effects.md §2)."""
    from ..._signal import noise_rms
    from ...select import sample_weight

    sigma2 = noise_rms(current.full_residual(d)) ** 2
    if not sigma2 > 0:
        return 0.0, 0.0, 0.0
    w = sample_weight(d)
    held = current.heldout & stiff.heldout & asym.heldout
    nh = float(np.sum(w[held])) if np.any(held) else 0.0

    def mse(tr):
        return tr.heldout_mse - float(getattr(tr, "heldout_noise", 0.0))

    part_h = nh * (mse(asym) - mse(stiff)) / sigma2
    start = startup_samples(d)
    rs, ra = stiff.fitted - d.y, asym.fitted - d.y
    part_s = float(np.sum((w * (ra * ra - rs * rs))[start])) / sigma2
    return part_h + part_s, part_h, part_s


@register
class AsymmetricBranches(EffectModel):
    """Loading and unloading dissipate differently: ``p - p0 = k_s δ + h (1 + a sgn δ') δ'``.

    docs/effects.md §2: plastic flattening of the asperities on loading, elastic recovery on
    unloading. Beyond the symmetric Kelvin-Voigt loss the loading branch (``δ' > 0``) carries
    ``a h |δ'|`` more pressure: an even distortion of the loop's centre curve locked to the
    rate (largest at mid-stroke, nothing at the turning points) that grows with the
    excitation frequency, while the energy per cycle stays that of ``h`` to first order.
    Solved exactly on the linear Kelvin-Voigt joint
    (:func:`contactlab.diagnose.candidates_normal.kelvin_voigt_asymmetric`); not combined
    with a stiffness law or a hysteretic element (each is another account of the loop's
    shape beyond the ellipse).
    """

    name = "asymmetric_branches"
    kind = "normal"
    params = (ParamSpec("a", "-", 0.0, -0.95, 0.95, "one"),)
    description = "loading and unloading branches damped differently, h (1 + a sgn δ') δ'"
    physics = (
        "Asperities flatten plastically on loading and recover elastically on unloading: "
        "the damping differs between the branches, p - p0 = k_s δ + h (1 + a sgn δ') δ' "
        "(a > 0: the loading branch lies farther from the centre curve)."
    )
    stage = "loss"
    rank = 0
    order = 4
    size_param = "a"
    #: the stiffness law's κ1 δ² takes the same 2ω signature (docs/effects.md §2): the
    #: stated bound is what shows beyond it
    rivals = ("stiffness_nonlinearity",)
    #: the stated bound asks the asymmetry to win the comparison with the law by
    #: :data:`SHAPE_Z` deviations, as :meth:`yields_to_tried` does
    rival_z = SHAPE_Z
    #: the stated bound is given also where it lies beyond the range |a| < 0.95 (stop 53):
    #: on one tone through a sensor chain the asymmetry's bound is 1.1-1.6 times the ideal
    #: test's size (the comparison with the law, ``rival_z``, and the residual's
    #: correlation), so on a low-loss joint (ψ 0.15: ideal |a| 1.9) or near its visibility
    #: (true |a| 0.7-0.95 at a noncentrality of 48) the bound left the range and the
    #: report said nothing in the bound's place (chain of benches/chain_normal.py at the
    #: stop-53 blind-miss conditions, tuning seeds 53300010-012); the number says how far
    #: the record is from promising any asymmetry, and its note says it is beyond the range
    bound_beyond_range = True

    def yields_to_tried(self, p, v, cand, tried, current, d):
        """Why a loss asymmetry is not named when the stiffening law tried at the same step
        (accepted or not, not implausible) fits the record at least as well counting its
        start from rest (:func:`shape_evidence` ≥ 0), or None. When the law did not pass
        on its own (its gain not significant across cycles, which its second parameter
        makes harder), neither is named: the shape beyond the ellipse is the law's reading
        as much as the asymmetry's (chain of ``benches/eval_normal_lookalike.py``, fresh
        seed 108: a law 1.3 % at the amplitude, 0.027 σ² at t = 2.64 against the
        asymmetry's 0.023 σ², was named ``asymmetric_branches``).

        On one tone at one amplitude both candidates put their signature along cos 2θ
        (docs/effects.md §2: ``κ1 δ²`` against ``a h |δ'|``) and tie to a few per cent of
        their held-out gains; the search's parsimony rule then names the asymmetry, which
        has one parameter to the law's two. They differ in how the mean displacement
        builds with the amplitude from rest (for the same 2ω part the law's mean shift is
        the opposite of the asymmetry's, 1 against -3/2) and by the kink of ``|δ'|`` at
        the turning points: the likelihood over the held-out cycles and the start-up
        decides, not the parameter count."""
        rival = tried.get("stiffness_nonlinearity")
        if rival is None:
            return None
        rv, rc = rival
        if (rv.reason or "").startswith("implausible"):
            return None
        total, held, start, z = shape_test(d, current, rc, cand)
        if z <= -SHAPE_Z:
            return None
        if total < 0.0:
            return (
                f"a = {p['a']:.3g} ({v.gain:.3g} σ² held out) against the stiffening law "
                f"({rv.gain:.3g} σ²): the asymmetry fits the record better by only "
                f"{-total:.3g} χ² units ({-held:.3g} on the held-out cycles, {-start:.3g} on "
                f"the start-up), z = {-z:.3g} below {SHAPE_Z:g}: the record does not tell "
                "the two apart, so neither is named"
            )
        tail = (
            ""
            if rv.accepted and z >= SHAPE_Z
            else f"; the law itself did not pass ({rv.reason}), so neither is named: the "
            "record shows a shape beyond the ellipse that it cannot attribute"
            if not rv.accepted
            else f" (z = {z:.3g}, below {SHAPE_Z:g}: the law is not named either)"
        )
        return (
            f"a = {p['a']:.3g} ({v.gain:.3g} σ² held out) against the stiffening law "
            f"({rv.gain:.3g} σ²): the law fits the record better by {total:.3g} χ² units "
            f"({held:.3g} on the held-out cycles, {start:.3g} on the start-up, where the "
            f"mean displacement builds as δ², not as |δ'|){tail}"
        )

    def rival_rows(self, d) -> np.ndarray:
        """The samples the stated bound compares the asymmetry with its rival on, as
        :meth:`yields_to_tried` does (:func:`shape_evidence`): the held-out cycles and the
        start-up before the first pressure maximum. The bound is the size at which the
        asymmetry passes the rules on its own *and* fits better than the stiffening law
        fitted in its place (:func:`contactlab.diagnose.power._rival_wins`), not the size
        at which its direction beyond the law alone would pass them: that one demanded of
        the 4ω kink of ``|δ'|`` (a twentieth of the direction) the gain a named effect
        needs, and stated |a| 1.3-1.4, beyond the range (no bound), on chains where
        a = -0.3 was named (fresh seed 49300001: fs 1 kHz, 18 Hz, 29 cycles)."""
        return (d.cycles.cycle >= 0) | startup_samples(d)

    def power_note(self, d, p):
        """What the record's drive leaves of the asymmetry beyond the stiffening law (its
        rival in the bound): on one excitation frequency the law's ``κ1 δ²`` takes the
        asymmetry's 2ω signature, so only the kink of ``|δ'|`` at the turning points and a
        start from rest tell them apart; several frequencies would (the asymmetry grows
        with ω, the law does not). Empty on a record at several frequencies."""
        from .channel_delay import SINGLE_TONE_SPAN, frequency_span

        span = frequency_span(d)
        if span >= SINGLE_TONE_SPAN:
            return ""
        per = float(d.cycles.period_samples)
        rest = float(np.sum(startup_samples(d))) / per if per > 0 else 0.0
        start = (
            f"a start-up of {rest:.2g} periods before the first pressure maximum"
            if rest >= 0.25
            else "no start from rest"
        )
        return (
            f"one excitation frequency (cycle periods within a factor {span:.2f}): the "
            "stiffening law takes the asymmetry's 2ω signature, and the bound is what its "
            f"kink at the turning points and {start} show beyond it; excitation at "
            "several frequencies would tell the two apart (the asymmetry grows with ω)"
        )

    def apply(self, delta, p, ctx):
        return ctx.family.asymmetric(delta, p, ctx.d)

    def argument(self, d, p):
        return (
            f"the loading branch is damped {100 * abs(p['a']):.0f} % "
            f"{'more' if p['a'] > 0 else 'less'} and unloading {100 * abs(p['a']):.0f} % "
            f"{'less' if p['a'] > 0 else 'more'} than the Kelvin-Voigt mean (a function of "
            "|δ'|, growing with the frequency, not of δ)"
        )
