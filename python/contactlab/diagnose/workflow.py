"""The discrepancy workflow: fit the base model, locate the residual, name the missing
effect from the candidate library, add it, repeat, and show the gap shrink.

Steps (issue 5): (1) fit the base model — Masing with exponential virgin curve for a
tangential joint, linear Kelvin-Voigt for a normal joint (PHYSICS.md §1, §2); (2) describe
where the residual lives (:mod:`.locate`); (3) fit every candidate extension of the current
model, rank by the error on held-out cycles and accept the best only if it passes the rules
of :mod:`.select` against the noise level estimated from the data; (4) after each addition,
refit without each effect named so far and drop one that, added back, would no longer pass
those rules (backward elimination: a wrong effect picked first is not kept once the right
ones are in); repeat until no candidate helps; then, with the set full (``max_effects``) or
two or more named, try replacing each named effect by each candidate not in the model and
keep the swap the held-out rules prefer (a wrong effect picked while the set filled up
would otherwise keep the right one from ever being tried), and go on; when neither an
addition nor a swap passes but a candidate still lowered the held-out error by
:data:`PAIR_GATE` σ², try two candidates at once (:func:`_pair_search`: two effects can each
be weak or misleading alone and plain together), each of which must be needed beside the
other; (5) report held-out RMS, peak error and loop-energy error after each step.
"""

from __future__ import annotations

import copy
import dataclasses
import itertools
import json
import sys
from collections.abc import Sequence
from dataclasses import dataclass, field
from functools import partial
from typing import Any

import numpy as np

from ..errors import ConvergenceError, InputError
from ._family import Family, Prepared
from ._filters import decimate, savgol_coeffs
from ._inputs import arrays as _arrays
from ._inputs import check_channels, check_glitches
from ._kept import RawInput, knots_at
from ._parallel import EvaluationCounter, one_blas_thread, pmap
from ._signal import (
    Cycles,
    check_uniform,
    derivatives,
    dominant_period_samples,
    filter_input,
    find_cycles,
    input_noise,
    noise_rms,
    shortest_period_samples,
    smooth_window,
)
from .locate import locate
from .model import ExtendedModel
from .select import MIN_RELATIVE_GAIN, FitOut, Trial, Verdict, evaluate, fit, fold_masks, judge

__all__ = ["DiagnosisReport", "Effect", "Step", "diagnose"]


@dataclass(frozen=True)
class Effect:
    """An effect added to the model, with fitted parameters and standard errors.

    A standard error of ``inf`` means the parameter is not identifiable from this record.
    """

    name: str
    parameters: dict[str, float]
    stderr: dict[str, float]

    def to_dict(self) -> dict[str, Any]:
        return {
            "name": self.name,
            "parameters": dict(self.parameters),
            "stderr": {k: _finite_or_none(v) for k, v in self.stderr.items()},
        }


@dataclass(frozen=True)
class Step:
    """Held-out errors of the model after one step (``added`` is None for the base fit).

    ``heldout_rms`` and ``heldout_peak``: RMS and largest absolute error of the output over
    the held-out cycles (each cycle predicted by the fit that did not see it);
    ``energy_error``: ``Σ |E_model - E_measured| / Σ |E_measured|`` over the held-out cycles,
    ``E`` the loop area of one cycle; ``candidates``: the verdict on each candidate tried
    after this step. A step of the backward elimination has ``removed`` set (and ``added``
    None): the effect dropped because, refitted without it, the model no longer needs it
    (``removal`` is the verdict on adding it back). A swap has both: ``removed`` replaced by
    ``added``, which predicts the held-out cycles better (``removal`` is the verdict on it).
    A pair move (:func:`_pair_search`) has ``added`` ``"a + b"``: both added at once.
    """

    added: str | None
    heldout_rms: float
    heldout_peak: float
    energy_error: float
    candidates: tuple[Verdict, ...] = ()
    #: the effect the backward step dropped (``added`` is None then), with the verdict on it
    removed: str | None = None
    removal: Verdict | None = None

    @property
    def label(self) -> str:
        """``base model``, ``+ name`` (added), ``- name`` (dropped by the backward step) or
        ``out ⇄ in`` (a swap)."""
        if self.removed is not None and self.added is not None:
            return f"{self.removed} ⇄ {self.added}"
        if self.removed is not None:
            return f"- {self.removed}"
        return "base model" if self.added is None else f"+ {self.added}"

    def to_dict(self) -> dict[str, Any]:
        return {
            "added": self.added,
            "removed": self.removed,
            "heldout_rms": self.heldout_rms,
            "heldout_peak": self.heldout_peak,
            "energy_error": _finite_or_none(self.energy_error),
        }


def _finite_or_none(v: float) -> float | None:
    return float(v) if np.isfinite(v) else None


@dataclass
class DiagnosisReport:
    """What :func:`diagnose` found. ``to_dict()`` gives the JSON layout of issue 5.

    Attributes
    ----------
    model : str
        ``"tangential"`` or ``"normal"``.
    effects : list of Effect
        Effects added, in the order added (empty when the base model suffices).
    steps : list of Step
        Held-out RMS / peak / loop-energy error of the base model and after each addition,
        with the verdict on every candidate tried at that step.
    where : list of str
        Where the base model's residual lives, as statements with numbers.
    noise_rms : float
        Output noise RMS estimated from the data (units of the output).
    final_model : ExtendedModel
        The base model plus the effects, ready to simulate or refit.
    """

    model: str
    effects: list[Effect]
    steps: list[Step]
    where: list[str]
    noise_rms: float
    final_model: ExtendedModel
    location: dict[str, Any] = field(repr=False, default_factory=dict)
    _data: Prepared | None = field(repr=False, default=None)
    _trials: list[Trial] = field(repr=False, default_factory=list)
    #: whether ``model`` was inferred from the recording's channels (``diagnose(model=None)``)
    model_inferred: bool = False

    @property
    def effect_names(self) -> list[str]:
        return [e.name for e in self.effects]

    @property
    def prepared(self) -> Prepared | None:
        """The data as the diagnosis saw it (filtered, weighted, cycles found), for plots."""
        return self._data

    @property
    def trials(self) -> list[Trial]:
        """Every model fitted along the way, base first (for plots and inspection)."""
        return list(self._trials)

    def to_dict(self) -> dict[str, Any]:
        return {
            "model": self.model,
            "effects": [e.to_dict() for e in self.effects],
            "steps": [s.to_dict() for s in self.steps],
            "where": list(self.where),
            "noise_rms": self.noise_rms,
            "final_model": self.final_model.to_dict(),
            # a frame's reconstructed force: its mass read from an inertia term
            **(
                {"frame_constants": dict(self.location["frame_constants"])}
                if "frame_constants" in self.location
                else {}
            ),
        }

    def to_json(self, indent: int = 2) -> str:
        return json.dumps(self.to_dict(), indent=indent, allow_nan=False)

    def table(self, unit: str = "") -> str:
        """The gap-shrink table as text (``unit``: the output's, named in the header)."""
        u = f" [{unit}]" if unit else ""
        lines = [
            f"{'step':<24}{'held-out RMS' + u:>18}{'/ noise':>9}{'peak' + u:>12}{'energy err':>12}",
        ]
        for s in self.steps:
            name = s.label
            lines.append(
                f"{name:<24}{s.heldout_rms:>18.4g}{s.heldout_rms / self.noise_rms:>9.2f}"
                f"{s.heldout_peak:>12.4g}{100 * s.energy_error:>11.2f}%"
            )
        return "\n".join(lines)

    def param_units(self) -> dict[str, str]:
        """SI unit of every parameter name of the family (base and candidates)."""
        fam = self.final_model.family
        specs = list(getattr(fam, "base_params", ()))
        for cand in getattr(fam, "candidates", {}).values():
            specs.extend(getattr(cand, "params", ()))
        return {s.name: s.unit for s in specs}

    def noise_text(self) -> str:
        """``noise RMS (declared|estimated from the data): 0.0123 N``, as the console and the
        HTML report both say it."""
        how = "declared" if self.location.get("noise_declared") else "estimated from the data"
        unit = getattr(self.final_model.family, "output_unit", "")
        return f"noise RMS ({how}): {self.noise_rms:.4g} {unit}".rstrip()

    def summary(self) -> str:
        """Findings, effects with parameters (with their units), and the gap-shrink table."""
        how = " (inferred from the channels; model= sets it)" if self.model_inferred else ""
        out = [f"contactlab diagnose — {self.model} model{how}", ""]
        import textwrap

        def wrap(text: str, first: str, rest: str) -> str:
            return textwrap.fill(text, width=100, initial_indent=first, subsequent_indent=rest,
                                 break_long_words=False, break_on_hyphens=False)  # fmt: skip

        out += ["Where the base model disagrees:"] + [wrap(w, "  - ", "    ") for w in self.where]
        out.append("")
        if not self.effects:
            out.append("No candidate improves the held-out error significantly.")
        units = self.param_units()
        for e in self.effects:
            parts = []
            for k, v in e.parameters.items():
                u = f" {units[k]}" if units.get(k) else ""
                se = e.stderr.get(k, np.nan)
                pm = f" ± {se:.2g}" if np.isfinite(se) else " (error not identifiable)"
                parts.append(f"{k} = {v:.4g}{pm}{u}")
            out.append(wrap(f"Added {e.name}: {', '.join(parts)}", "", "    "))
        coeffs = self.final_model.coefficients()
        if coeffs is not None and ({"a", "kappa"} & set(self.final_model.params)):
            out.append(
                "Stiffness law (eq. 6): "
                + ", ".join(
                    f"{k} = {v:.4g} {u}"
                    for (k, v), u in zip(coeffs.items(), ("Pa/m", "Pa/m²", "Pa/m³"), strict=True)
                )
                + f" (κ and a are relative to δ_r = {self.final_model.context['delta_r']:.4g} m)"
            )
        unit = getattr(self.final_model.family, "output_unit", "")
        out += ["", self.table(unit), self.noise_text()]
        return "\n".join(out)

    # -- figures ------------------------------------------------------------------------------
    def plot_overlay(self, step: int | None = None, ax: Any = None) -> Any:
        """Measured and modelled loops (output against input), base model and final model."""
        from .plots import plot_overlay

        return plot_overlay(self, step=step, ax=ax)

    def plot_residual(self, ax: Any = None) -> Any:
        """Held-out residual over time, before (base) and after (final model)."""
        from .plots import plot_residual

        return plot_residual(self, ax=ax)

    def plot_location(self, ax: Any = None) -> Any:
        """Where the base residual lives: residual power by position in the branch."""
        from .plots import plot_location

        return plot_location(self, ax=ax)

    def write_html(self, directory: Any) -> Any:
        """Write a self-contained ``diagnose.html`` (figures embedded, also as PNGs under
        ``figures/``) and ``diagnose.json`` into ``directory``; returns the HTML's path."""
        from ._html import write_html

        return write_html(self, directory)

    def plot_gap(self, ax: Any = None) -> Any:
        """Held-out RMS (in units of the noise level) after each step."""
        from .plots import plot_gap

        return plot_gap(self, ax=ax)


def _family(model: Any) -> tuple[Family, dict[str, float], dict[str, float]]:
    """Model family, starting parameters and context from a name or a model object."""
    from ..masing import Masing

    if isinstance(model, str):
        if model == "tangential":
            from .candidates_tangential import TangentialFamily

            return TangentialFamily(), {}, {}
        if model == "normal":
            from .candidates_normal import NormalFamily

            return NormalFamily(), {}, {}
        raise InputError(
            f"model must be 'tangential' or 'normal' (or a model object), got {model!r}"
        )
    if isinstance(model, Masing):
        from .candidates_tangential import TangentialFamily

        if not model.is_exponential:
            raise InputError("diagnose needs the exponential Masing model (h0, ac)")
        return TangentialFamily(), {"h0": model.h0, "ac": model.ac}, {}
    if isinstance(model, ExtendedModel):
        return model.family, dict(model.params), dict(model.context)
    from .candidates_normal import NormalFamily, start_from_model

    start = start_from_model(model)
    if start is not None:
        if getattr(model, "p0", None) is not None:
            start["p0"] = float(model.p0)
        ctx = {"omega": float(model.omega)} if hasattr(model, "omega") else {}
        return NormalFamily(), start, ctx
    raise InputError(f"cannot diagnose a model of type {type(model).__name__}")


#: longest record diagnosed sample by sample. Longer tangential ones keep every q-th sample
#: over their whole length with the turning points between them (:func:`subsample_long`);
#: longer normal ones likewise (:func:`subsample_normal`). :func:`reduce_long` (decimated,
#: anti-aliased, zero phase, to no fewer than MIN_SAMPLES_PER_CYCLE per period of the fastest
#: cycles and cut to the first MAX_SAMPLES samples) is the route before
MAX_SAMPLES = 24_000
#: Model evaluations (residual calls of every fit, numerical Jacobians included) a diagnosis
#: may spend. Typical runs use 1 000-8 000; the slowest of 657 random fuzz inputs 7 237 (a
#: minute on a loaded machine); without a bound the search (candidates x rounds x folds fits
#: of up to 400 iterations each) could take hours. Once spent, the candidates not yet tried
#: are reported as untested, with a sentence saying so.
MAX_EVALUATIONS = 40_000
MIN_SAMPLES_PER_CYCLE = 64


#: an effect may refine the base model, not replace it: the base parameters that carry the
#: joint's physics (tangential h0, the friction force; normal k, the contact stiffness) may
#: move by at most this fraction from the base fit when an effect is added
MAX_BASE_SHIFT = 0.3
_ANCHORS = {"tangential": ("h0",), "normal": ("k",)}


def _takes_over(family: Family, base: dict[str, float], p: dict[str, float]) -> str | None:
    for name in _ANCHORS.get(family.kind, ()):
        b, v = base[name], p[name]
        if b > 0 and abs(v / b - 1.0) > MAX_BASE_SHIFT:
            return (
                f"it takes over the base model ({name} from {b:.4g} to {v:.4g}): the base "
                "is in the wrong regime or the effect is not what the data show"
            )
    return None


def _not_fitted(name: str, exc: Exception) -> Verdict:
    """The verdict on a candidate whose fit failed: not named, and the reason kept."""
    return Verdict(name, np.nan, np.nan, np.nan, np.nan, False, f"could not be fitted: {exc}")


def reduce_long(
    t: np.ndarray, u: np.ndarray, y: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray, str]:
    """A long record brought to at most :data:`MAX_SAMPLES` samples, and a sentence saying
    how (empty when the record is used as it is).

    Both channels go through the same zero-phase FIR anti-alias filter before every q-th
    sample is kept, so neither channel is delayed against the other and the noise of both
    is reduced alike (the noise level is then estimated on the decimated record).
    """
    n = t.size
    if n <= MAX_SAMPLES:
        return t, u, y, ""
    check_uniform(t)
    per = dominant_period_samples(u)
    fastest = shortest_period_samples(u, per)
    q = max(1, int(min(fastest // MIN_SAMPLES_PER_CYCLE, -(-n // MAX_SAMPLES))))
    how = []
    if q > 1:
        u = decimate(u, q, ftype="fir", zero_phase=True)
        y = decimate(y, q, ftype="fir", zero_phase=True)
        t = t[::q][: u.size]
        how.append(f"decimated by {q} (zero-phase anti-alias filter on both channels)")
    if t.size > MAX_SAMPLES:
        cycles = t.size * q / per
        t, u, y = t[:MAX_SAMPLES], u[:MAX_SAMPLES], y[:MAX_SAMPLES]
        how.append(
            f"diagnosed on its first {MAX_SAMPLES * q / per:.0f} of {cycles:.0f} excitation cycles"
        )
    return t, u, y, f"the record of {n} samples was " + " and ".join(how)


#: fewest samples per cycle of the fastest cycles that a tangential record is subsampled to
#: (:func:`subsample_long`): the Masing memory is exact at any rate with the knots, but the
#: delay's interpolation, the reversal anchors and the cycle split want a dozen per cycle
MIN_KEPT_PER_CYCLE = 12


def subsample_long(t: np.ndarray, u: np.ndarray, y: np.ndarray) -> tuple[Prepared, str]:
    """A long tangential record kept every q-th sample over its whole length (q from the
    record's length, so that at most :data:`MAX_SAMPLES` are kept), ready for the
    candidates, and a sentence saying how.

    Everything the candidates see is computed at the raw rate and then sampled: the
    filtered input, its derivatives, the cycles and the input noise. No anti-alias filter:
    the kept force samples are the measured ones, so the model at the kept samples is the
    full-rate model there (a low-pass filter would take the loop's corners out of the
    force but not out of the model's prediction). The turning points between the kept
    samples go with them as :class:`~contactlab.diagnose._signal.Knots`, which the Masing
    element runs over, so its memory holds the true extremes. When the fastest cycles
    would keep fewer than :data:`MIN_KEPT_PER_CYCLE` samples, q is lowered and only the
    first :data:`MAX_SAMPLES` kept samples are diagnosed (said so).
    """
    n = t.size
    dt = check_uniform(t)
    per = dominant_period_samples(u)
    ud, udd = derivatives(u, dt, smooth_window(per))
    cyc = find_cycles(u, per)
    sig = input_noise(u)
    uf, wf = filter_input(u, per, sig)
    half = np.diff(cyc.reversals)
    fastest = min(per, 2.0 * float(np.percentile(half, 10))) if half.size >= 4 else per
    q = -(-n // MAX_SAMPLES)
    if fastest / q < MIN_KEPT_PER_CYCLE:
        q = max(1, int(fastest // MIN_KEPT_PER_CYCLE))
    stop = min(n, (MAX_SAMPLES - 1) * q + 1)
    g = slice(0, stop, q)
    raw, exact = RawInput.build(
        float(t[0]), dt, uf, ud, udd, cyc.reversals, q, limit=4 * MAX_SAMPLES
    )
    knots = knots_at(raw, np.arange(0, stop, q))
    cycle = cyc.cycle[g].copy()
    last = ((stop - 1) // q) * q
    if stop < n:  # the cycle cut at the end belongs to no fold
        cycle[cycle > np.count_nonzero(cyc.reversals[cyc.is_max] <= last) - 2] = -1
    keep = cyc.reversals <= last
    cycles = Cycles(
        np.rint(cyc.reversals[keep] / q).astype(int),
        cyc.is_max[keep],
        cycle,
        cyc.phase_in_branch[g],
        per / q,
    )
    extra: dict[str, Any] = {
        "u_raw": u[g], "u_noise": sig, "u_filter": wf, "knots": knots, "raw_input": raw,
    }  # fmt: skip
    d = Prepared(t[g], uf[g], y[g], dt * q, smooth_window(per / q), ud[g], udd[g], cycles, extra)
    how = []
    if q > 1:
        whole = "" if stop < n else " over its whole length"
        how.append(f"kept one sample in {q}{whole} (no filter; the {knots.pos.size} turning "
                   "points between them kept in the Masing memory)")  # fmt: skip
    if not exact:
        how.append("the input's local extrema too many: its reversals only kept as turning points")
    if stop < n:
        how.append(
            f"diagnosed on its first {stop / per:.0f} of {n / per:.0f} excitation cycles "
            f"(the fastest cycles have {fastest:.0f} samples)"
        )
    return d, f"the record of {n} samples was " + " and ".join(how)


#: fewest samples per cycle of the fastest cycles that a normal record is kept at
#: (:func:`subsample_normal`): the model integrates the pressure's cubic Hermite between kept
#: samples with the slopes taken at the raw rate, whose error is ``(2π/s)⁴/384`` of the
#: displacement at ``s`` samples per cycle (2e-4 at 12, a fortieth of 1 % output noise)
MIN_KEPT_PER_CYCLE_NORMAL = 12


def subsample_normal(t: np.ndarray, u: np.ndarray, y: np.ndarray) -> tuple[Prepared, str]:
    """A long normal-contact record kept every q-th sample over its whole length (q from
    the record's length, so that at most :data:`MAX_SAMPLES` are kept), ready for the
    candidates, and a sentence saying how.

    As :func:`subsample_long` does for a tangential record: the filtered pressure, its slope
    and the cycles are computed at the raw rate and then sampled, and the displacement
    samples kept are the measured ones (no anti-alias filter, which would act on the
    measured displacement but not on the model's). The model integrates the pressure
    between kept samples by its cubic Hermite with the raw-rate slopes (``d.extra["u_slope"]``),
    so a drift, a creep and the frequency blocks are seen over the whole record, and a
    channel delay is evaluated on the pressure at the raw shifted times
    (:func:`contactlab.diagnose._kept.shifted`). When the fastest cycles would keep fewer
    than :data:`MIN_KEPT_PER_CYCLE_NORMAL` samples, q is lowered and only the first
    :data:`MAX_SAMPLES` kept samples are diagnosed (said so).
    """
    n = t.size
    dt = check_uniform(t)
    per = dominant_period_samples(u)
    ud, udd = derivatives(u, dt, smooth_window(per))
    cyc = find_cycles(u, per)
    sig = input_noise(u)
    uf, _ = filter_input(u, per, sig)
    fastest = shortest_period_samples(u, per)
    q = -(-n // MAX_SAMPLES)
    if fastest / q < MIN_KEPT_PER_CYCLE_NORMAL:
        q = max(1, int(fastest // MIN_KEPT_PER_CYCLE_NORMAL))
    stop = min(n, (MAX_SAMPLES - 1) * q + 1)
    g = slice(0, stop, q)
    cycle = cyc.cycle[g].copy()
    last = ((stop - 1) // q) * q
    if stop < n:  # the cycle cut at the end belongs to no fold
        cycle[cycle > np.count_nonzero(cyc.reversals[cyc.is_max] <= last) - 2] = -1
    keep = cyc.reversals <= last
    cycles = Cycles(
        np.rint(cyc.reversals[keep] / q).astype(int),
        cyc.is_max[keep],
        cycle,
        cyc.phase_in_branch[g],
        per / q,
    )
    raw = RawInput(float(t[0]), dt, uf, ud, udd, cyc.reversals, cyc.reversals, q)
    uk = np.ascontiguousarray(uf[g])
    # the input noise as the candidates see it: the filtered pressure's noise, folded into
    # the kept band (white there), read off the kept samples with no further filter
    extra: dict[str, Any] = {
        "u_raw": uk, "u_noise": sig, "u_filter": 0, "u_slope": np.ascontiguousarray(ud[g]),
        "raw_input": raw,
    }  # fmt: skip
    d = Prepared(
        np.ascontiguousarray(t[g]), uk, np.ascontiguousarray(y[g]), dt * q,
        smooth_window(per / q), ud[g], udd[g], cycles, extra,
    )  # fmt: skip
    how = []
    if q > 1:
        whole = "" if stop < n else " over its whole length"
        how.append(f"kept one sample in {q}{whole} (no filter; the pressure between them from "
                   "its full-rate slopes)")  # fmt: skip
    if stop < n:
        how.append(
            f"diagnosed on its first {stop / per:.0f} of {n / per:.0f} excitation cycles "
            f"(the fastest cycles have {fastest:.0f} samples)"
        )
    return d, f"the record of {n} samples was " + " and ".join(how)


def eiv_weight(
    family: Family, params: dict[str, float], d: Prepared, sigma: float
) -> tuple[np.ndarray, float] | None:
    """Errors-in-variables weights of the samples and the candidates' gain budget.

    ``w = σy² / (σy² + (s σu')²)`` with ``s`` the base model's local slope ``|dy/du|``
    (:meth:`Family.slope`) and ``σu'`` the noise left in the input the candidates see (the
    estimated input noise times the filter's noise gain). The budget, in units of ``σy²``, is
    the mean of ``(s σu')² w``: what the input's noise contributes to the weighted error,
    the most that smoothing the input (a delay shorter than a sample) or absorbing the
    noise's bias (turning points pushed outward) could lower it; every candidate's held-out
    gain must beat it. None when the family has no slope or the input carries no measurable
    noise.
    """
    su = float(d.extra.get("u_noise", 0.0))
    if not su > 0.0:
        return None
    s = family.slope(params, d)
    if s is None:
        return None
    wlen = int(d.extra.get("u_filter", 0))
    gain = float(np.sum(savgol_coeffs(wlen, 3) ** 2)) if wlen else 1.0
    var = (s * su) ** 2 * gain
    w = sigma**2 / (sigma**2 + var)
    prior = d.extra.get("weight")  # samples weighted out before (sticks, a filter's ends)
    if prior is None:
        return w, float(np.mean(var * w)) / sigma**2
    w = w * prior
    return w, float(np.sum(var * w) / max(float(np.sum(prior)), 1.0)) / sigma**2


def _declared(
    recording: Any,
    family: Family,
    taps: Any,
    noise: float | None,
    n: int,
    y: np.ndarray | None = None,
) -> tuple[np.ndarray | None, float | None]:
    """The output's declared measurement filter and noise RMS: the arguments, else the
    recording's ``meta`` (``output_filter``, ``output_noise``); checked (a noise RMS above the
    output's whole swing ``y`` is not a noise level of that channel, and its square would
    overflow the weights)."""
    meta = getattr(recording, "meta", None)
    if not isinstance(meta, dict):
        meta = {}
    if taps is None:
        taps = meta.get("output_filter")
    if noise is None:
        noise = meta.get("output_noise")
    if taps is not None:
        if family.kind != "tangential":
            raise InputError("output_filter is supported for the tangential model only")
        try:
            a = np.asarray(taps, dtype=float)
        except (TypeError, ValueError):
            raise InputError("output_filter must be a sequence of filter taps (numbers)") from None
        if a.ndim != 1 or a.size % 2 != 1 or not np.all(np.isfinite(a)):
            raise InputError(
                f"output_filter must be an odd number of finite taps (a zero-phase filter), "
                f"got shape {a.shape}"
            )
        if not abs(float(np.sum(a)) - 1.0) < 1e-6:
            raise InputError(
                f"output_filter's taps sum to {float(np.sum(a)):.6g}; a measurement filter "
                "passes a constant force unchanged (sum 1)"
            )
        if a.size >= n // 4:
            raise InputError(
                f"output_filter has {a.size} taps for a record of {n} samples: too long a "
                "filter to leave anything to diagnose"
            )
        taps = None if a.size == 1 else a
    if noise is not None:
        if not (isinstance(noise, (int, float, np.floating)) and np.isfinite(noise) and noise > 0):
            raise InputError(f"output_noise must be a finite number > 0, got {noise!r}")
        noise = float(noise)
        swing = float(np.ptp(y)) if y is not None and y.size else None
        if swing is not None and noise > swing:
            unit = family.output_unit
            raise InputError(
                f"output_noise {noise:.6g} {unit} exceeds the whole swing of channel "
                f"{family.output_name!r} ({swing:.6g} {unit} peak to peak): not a noise RMS "
                "of that channel — check its value and unit"
            )
    return taps, noise


def _same_clock(recording: Any, names: list[str], candidates: Sequence[str] | None) -> str | None:
    """A recording whose ``meta["same_clock"]`` is true has an output computed from the
    input's own samples (e.g. a friction force reconstructed from the displacements of a
    frame, :meth:`contactlab.tangential.FrameForce.recording`): the two channels cannot be
    skewed in time, so ``channel_delay`` is not tried (unless asked for by name in
    ``candidates``); removed from ``names`` in place, and the sentence that says so."""
    meta = getattr(recording, "meta", None)
    if not (isinstance(meta, dict) and meta.get("same_clock")) or candidates is not None:
        return None
    if "channel_delay" not in names:
        return None
    names.remove("channel_delay")
    return (
        "channel_delay not tried: the output was computed from the input's own samples "
        "(same clock), so it cannot lag them"
    )


def _frame_constants(
    recording: Any, effects: list[Effect], where: list[str], location: dict[str, Any]
) -> list[Effect]:
    """A force reconstructed from a frame's equation of motion (``meta["frame"]``:
    :meth:`contactlab.tangential.FrameForce.recording`, ``F = K (y - x) + C (y' - x') - M x''``)
    contains the frame's inertia ``- M x''``: an ``inertia`` term ``m x''`` in the diagnosis is
    exactly a different ``M`` (``M + m``), whether ``M`` is off or the two displacement
    channels' filters differ in phase. It is reported as that reading of ``M``
    (``location["frame_constants"]`` and a sentence) and not named as an effect of the joint;
    the final model keeps the term. Other effects stay named: a parallel stiffness or a
    viscous term acts on ``x`` alone, the frame's ``K`` and ``C`` on ``x - y``."""
    meta = getattr(recording, "meta", None)
    frame = meta.get("frame") if isinstance(meta, dict) else None
    if not isinstance(frame, dict) or "M" not in frame:
        return effects
    kept = []
    for e in effects:
        if e.name != "inertia" or "m" not in e.parameters:
            kept.append(e)
            continue
        M0, m = float(frame["M"]), float(e.parameters["m"])
        sm = e.stderr.get("m")
        sm = float(sm) if sm is not None and np.isfinite(sm) else float("nan")
        location["frame_constants"] = {
            "M_given": M0,
            "M_read": M0 + m,
            "M_read_stderr": _finite_or_none(sm),
            "relative": m / M0 if M0 > 0 else None,
            "from_effect": "inertia",
            "units": {"M_given": "kg", "M_read": "kg", "M_read_stderr": "kg"},
        }
        rel = f" ({100.0 * m / M0:+.2f} %)" if M0 > 0 else ""
        where.append(
            f"the frame's mass reads M = {M0 + m:.5g} ± {sm:.2g} kg where {M0:.5g} kg was given"
            f"{rel}: an inertia term m = {m:.3g} kg in a force reconstructed from the frame's "
            "equation of motion is its own M x'' (M off, or the x and y channels filtered with "
            "different phase); reported as a reading of M, not as an effect of the joint"
        )
    return kept


def _prior_weight(
    family: Family, d: Prepared, taps: np.ndarray | None
) -> tuple[dict[str, Any] | None, list[str]]:
    """Samples no candidate is judged on, weighted 0 in every fit and held-out error
    (``d.extra["weight"]``): the half filter at either end of a record whose output passed a
    declared filter (:func:`diagnose`'s ``output_filter``, set as ``d.extra["output_filter"]``
    here) and the family's sticking samples (:meth:`TangentialFamily.sticking`). Returns the
    report's ``location`` entries and sentences, or ``(None, [])`` when nothing is weighted
    out."""
    w = np.ones(d.y.size)
    loc: dict[str, Any] = {}
    notes = []
    if taps is not None:
        d.extra["output_filter"] = taps
        h = taps.size // 2
        w[:h] = 0.0
        w[w.size - h :] = 0.0
        loc["output_filter"] = {"taps": int(taps.size), "span_s": float(taps.size * d.dt)}
        notes.append(
            f"the force passed a declared filter of {taps.size} taps ({1e3 * taps.size * d.dt:.3g} "
            "ms, e.g. a reconstruction's smoothing): every candidate's prediction passes the "
            f"same filter; the {h} samples at either end, where it is not defined, are not used"
        )
    stuck = family.sticking(d) if hasattr(family, "sticking") else None
    if stuck is not None and np.any(stuck):
        if taps is not None:  # the filter spreads the stuck force over half its span
            stuck = np.convolve(stuck, np.ones(taps.size), mode="same") > 0.5
        w[stuck] = 0.0
        share = float(np.mean(stuck))
        loc["sticking_fraction"] = share
        notes.append(
            f"{100 * share:.0f} % of the samples stick (the displacement stands still within "
            "its noise at the reversals while the force changes): the force there is set by "
            "what holds the body, not by the displacement, and no candidate is judged on them"
        )
    if not loc:
        return None, []
    d.extra["weight"] = w
    return loc, notes


def _start_new(
    family: Family, current: Trial, new: tuple[str, ...], d: Prepared
) -> dict[str, float]:
    """Starting parameters of the current model with the effects ``new`` added."""
    start = dict(current.full.params)
    if hasattr(family, "start_effect"):
        for e in new:
            start.update(family.start_effect(e, start, d, -current.full_residual(d)))
    return start


def _try_candidate(
    name: str,
    family: Family,
    current: Trial,
    effects: tuple[str, ...],
    d: Prepared,
    scales: dict[str, float],
    folds: int,
    sigma: float,
    z: float,
    min_gain: float,
    budget: float,
    base_fit: dict[str, float],
    all_samples: np.ndarray,
    also: tuple[str, ...] = (),
    full: FitOut | None = None,
) -> tuple[Verdict, Trial | None]:
    """The verdict on adding ``name`` to the current model (and its trial when it was
    cross-validated); ``also``: effects added together with it (the pair move); ``full``:
    the candidate model's fit to all data when it is at hand (:func:`_pair_search`)."""
    trial_effects = (*effects, *also, name)
    start_c = _start_new(family, current, (*also, name), d)
    # screening: a candidate whose fit to all data lowers the error by less than
    # min_gain σ² cannot do better on held-out cycles; no cross-validation for it
    if full is None:
        try:
            full = fit(family, trial_effects, d, all_samples, start_c, scales)
        except ConvergenceError as exc:  # e.g. a trial stiffness with no equilibrium
            return _not_fitted(name, exc), None
    in_gain = (current.full.mse - full.mse) / sigma**2
    if in_gain < min_gain:
        reason = f"in-sample gain {in_gain:.3g} σ² below {min_gain:g} σ²"
        return Verdict(name, np.nan, float(in_gain), np.nan, np.nan, False, reason), None
    try:
        cand = evaluate(family, trial_effects, d, start_c, scales, folds, full)
    except ConvergenceError as exc:
        return _not_fitted(name, exc), None
    p = cand.full.params
    # errors in variables: every candidate must beat what the input's noise alone does to
    # the weighted error (the budget). A sub-sample delay wins by smoothing the input; a
    # track-dependent friction by the turning points noisy x pushes outward (at 1 % x noise
    # position_friction gained 0.08 σ² on clean records against a budget of 0.70 σ²)
    extra = budget
    prop = d if getattr(family, "proportional_gain", False) else None
    v = judge(name, current, cand, sigma, z, min_gain + extra, prop)
    # every effect of the candidate model, not only the new one: a refit can push an
    # effect added before to the edge of its physical range
    why = next(
        (w for e in trial_effects if (w := family.implausible(e, p, d))), None
    ) or _takes_over(family, base_fit, p)
    if v.accepted and why:
        v = dataclasses.replace(v, accepted=False, reason=f"implausible: {why}")
    return v, cand


def _fit_cost(family: Family, name: str) -> int:
    """Expected work of trying candidate ``name``, for the order the candidates of a step
    start in on threads (:func:`~contactlab.diagnose._parallel.pmap`; the results do not
    depend on it): its parameter count (the Jacobian's columns; the candidates with a
    nonlinear frequency, slip distance or speed carry two or more)."""
    return len(family.candidates[name].params)


#: rounds of the stepwise search (each adds one effect, then drops redundant ones) at most,
#: per effect the model may hold: room for every addition and as many swaps
ROUNDS_PER_EFFECT = 2


def _drop_check(
    name: str,
    family: Family,
    current: Trial,
    d: Prepared,
    scales: dict[str, float],
    folds: int,
    sigma: float,
    z: float,
    min_gain: float,
    budget: float,
) -> tuple[Verdict, Trial | None]:
    """The verdict on keeping ``name`` in the current model (backward elimination).

    The model without ``name`` is refitted (from the current fit) and cross-validated; then
    ``name`` is judged as a candidate added back to it by the rules of a forward step
    (:func:`contactlab.diagnose.select.judge`, with the input-noise budget). Not
    accepted means the other effects explain what it did: it is dropped. Returns the verdict
    and the reduced model's trial (None when that could not be fitted: then it is kept).
    """
    rest = tuple(e for e in current.effects if e != name)
    try:
        reduced = evaluate(family, rest, d, current.full.params, scales, folds)
    except ConvergenceError as exc:
        return _not_fitted(name, exc), None
    extra = budget  # the forward rule's input-noise floor (_try_candidate)
    prop = d if getattr(family, "proportional_gain", False) else None
    return judge(name, reduced, current, sigma, z, min_gain + extra, prop), reduced


#: the swap move's threshold on the t statistic of the per-cycle gain (see _swap_search)
SWAP_Z = 0.0


def _swap_search(
    family: Family,
    names: list[str],
    current: Trial,
    named: tuple[str, ...],
    visited: set[frozenset[str]],
    d: Prepared,
    scales: dict[str, float],
    folds: int,
    sigma: float,
    min_gain: float,
    budget: float,
    base_fit: dict[str, float],
    all_samples: np.ndarray,
) -> tuple[tuple[str, Verdict, Trial] | None, list[Verdict], int]:
    """The swap move: every effect ``named`` by this diagnosis replaced by every candidate
    not in the model.

    Each swapped model is judged against the current one by the rules of a forward step
    (:func:`_try_candidate` with the effect taken out: the in-sample screening, the held-out
    gain of at least ``min_gain`` σ² and :data:`~contactlab.diagnose.select.MIN_RELATIVE_GAIN`
    of the current error, the BIC, plausibility), except that the gain across held-out
    cycles need only be positive on average (``t > SWAP_Z``), not significant: a swap does
    not make the model larger, it picks the better of two of the same size. Returns the
    best accepted swap ``(effect out, verdict on the one in, its trial)`` or None, every
    verdict (named ``"out ⇄ in"``), and the model evaluations spent.
    """
    spent = d.extra["evaluations"]
    effects = current.effects
    pairs = [
        (out, name)
        for out in named
        for name in names
        if name not in effects
        and family.check(rest := (*(e for e in effects if e != out), name))
        and frozenset(rest) not in visited
    ]

    def one(pair: tuple[str, str]) -> tuple[Verdict, Trial | None]:
        out, name = pair
        rest = tuple(e for e in effects if e != out)
        return _try_candidate(
            name, family, current, rest, d, scales, folds, sigma, SWAP_Z, min_gain, budget,
            base_fit, all_samples,
        )  # fmt: skip

    before = spent.total
    results = pmap(one, pairs, cost=lambda pair: _fit_cost(family, pair[1]))
    verdicts, best = [], None
    for (out, _), (v, cand) in zip(pairs, results, strict=True):
        verdicts.append(dataclasses.replace(v, name=f"{out} ⇄ {v.name}"))
        if cand is not None and v.accepted and (best is None or v.gain > best[1].gain):
            best = (out, v, cand)
    return best, verdicts, spent.total - before


#: the pair move (families with ``pair_move``: tangential; a normal joint's fits integrate
#: an ODE, and its library combines few effects) tries pairs among this many candidates not
#: in the model, those with the largest gains seen at any step of the search (_pair_search)
PAIR_POOL = 6
#: ... when a single candidate at the current step lowered the error by at least this many
#: σ² (held out, or in its fit to all data) but was not accepted; below it, nothing is left
#: that two effects could share. Far from the noise (a real loop the library cannot
#: follow, 66 σ after the search) the bar is MIN_RELATIVE_GAIN of the current error
#: instead: a few σ² there are a sliver of a larger misfit, as for a single effect
PAIR_GATE = 1.0
#: ... and cross-validates this many of the pair models, those whose fits to all data
#: lower the error most
PAIR_TRIALS = 4


def _pair_search(
    family: Family,
    pool: list[str],
    current: Trial,
    named: tuple[str, ...],
    max_effects: int,
    visited: set[frozenset[str]],
    d: Prepared,
    scales: dict[str, float],
    folds: int,
    sigma: float,
    z: float,
    min_gain: float,
    budget: float,
    base_fit: dict[str, float],
    all_samples: np.ndarray,
) -> tuple[tuple[str | None, tuple[str, str], Verdict, Trial] | None, list[Verdict], int]:
    """The pair move: two candidates added at once, to the current model or in place of
    one effect ``named`` by this diagnosis.

    Greedy steps add the one candidate that helps most alone. Two effects can each be weak
    or misleading alone and plain together: a force offset and a force drift (a ramp that
    starts at 0 needs the offset to centre it), or a channel delay and a breakaway after
    each reversal (each alone is mimicked by a branch scale, which a greedy step then
    names). Every pair ``{a, b}`` of ``pool`` (the candidates with the largest gains seen
    so far) gives the models ``current + a + b`` and ``current - out + a + b``; each is
    fitted to all data, and the :data:`PAIR_TRIALS` that lower the error most are judged
    against the current model by the rules of a forward step (:func:`_try_candidate`:
    significance ``t > z``, the gain thresholds, the BIC, plausibility of every effect).
    Since a pair is two claims, each of ``a`` and ``b`` must also pass those rules added
    back to the pair model without it (:func:`_drop_check`): each is needed beside the
    other. Returns the best accepted move ``(effect out or None, (a, b), verdict, trial)``
    or None, the verdicts on the pair models judged (named ``"a + b"`` or
    ``"out ⇄ a + b"``), and the model evaluations spent.
    """
    spent = d.extra["evaluations"]
    effects = current.effects
    moves: list[tuple[str | None, tuple[str, str]]] = []
    # added to the model while there is room (an effect the pair makes redundant is then
    # dropped by the backward step), else in place of one named effect
    outs = [None] if len(named) + 2 <= max_effects else list(named)
    for out in outs:
        rest = tuple(e for e in effects if e != out)
        for a, b in itertools.combinations(pool, 2):
            if family.check((*rest, a, b)) and frozenset((*rest, a, b)) not in visited:
                moves.append((out, (a, b)))

    def rest_of(move: tuple[str | None, tuple[str, str]]) -> tuple[str, ...]:
        return tuple(e for e in effects if e != move[0])

    def full_fit(move: tuple[str | None, tuple[str, str]]) -> FitOut | None:
        start = _start_new(family, current, move[1], d)
        try:
            return fit(family, (*rest_of(move), *move[1]), d, all_samples, start, scales)
        except ConvergenceError:
            return None

    def judged(
        item: tuple[tuple[str | None, tuple[str, str]], FitOut],
    ) -> tuple[Verdict, Trial | None]:
        move, full = item
        (a, b), rest = move[1], rest_of(move)
        v, cand = _try_candidate(
            b, family, current, rest, d, scales, folds, sigma, z, min_gain, budget,
            base_fit, all_samples, also=(a,), full=full,
        )  # fmt: skip
        if cand is None or not v.accepted:
            return v, cand
        for e in (a, b):  # each is needed beside the other
            w, _ = _drop_check(e, family, cand, d, scales, folds, sigma, z, min_gain, budget)
            if not w.accepted:
                why = f"{e} not needed beside the other: {w.reason}"
                return dataclasses.replace(v, accepted=False, reason=why), cand
        return v, cand

    before = spent.total
    fits = pmap(full_fit, moves)
    ranked = sorted(
        ((m, f) for m, f in zip(moves, fits, strict=True) if f is not None),
        key=lambda mf: mf[1].mse,
    )[:PAIR_TRIALS]
    results = pmap(judged, ranked)
    verdicts, best = [], None
    for ((out, pair), _), (v, cand) in zip(ranked, results, strict=True):
        label = " + ".join(pair) if out is None else f"{out} ⇄ {' + '.join(pair)}"
        verdicts.append(dataclasses.replace(v, name=label))
        if cand is not None and v.accepted and (best is None or v.gain > best[2].gain):
            best = (out, pair, v, cand)
    return best, verdicts, spent.total - before


@one_blas_thread
def infer_model(recording: Any) -> str:
    """The model family of a recording when none is given, as the command line infers it:
    ``"tangential"`` for channels ``x``, ``F``, ``"normal"`` for ``p``, ``delta`` (a
    :class:`~contactlab.io.Recording`'s ``kind``, a dict's keys); a tuple ``(t, x, F)`` is
    tangential. Anything else is an :class:`~contactlab.InputError` asking for ``model=``.

    Examples
    --------
    >>> import numpy as np
    >>> infer_model({"t": np.arange(3.0), "p": np.ones(3), "delta": np.ones(3)})
    'normal'
    """
    kind = getattr(recording, "kind", None)
    if kind in ("tangential", "normal"):
        return str(kind)
    if isinstance(recording, dict):
        # the family whose channels are there (the family's own check then names a missing
        # one: {"x": ..., "force": ...} is a tangential recording without 'F')
        if "x" in recording or "F" in recording:
            return "tangential"
        if "p" in recording or "delta" in recording:
            return "normal"
    if isinstance(recording, tuple):
        return "tangential"
    raise InputError(
        "cannot tell the model of the recording (channels x, F: tangential; p, delta: "
        "normal): give model='tangential' or 'normal'"
    )


def diagnose(
    recording: Any,
    model: Any = None,
    *,
    candidates: Sequence[str] | None = None,
    max_effects: int = 3,
    folds: int = 2,
    z: float = 3.0,
    min_gain: float = 0.05,
    base: Any = None,
    output_filter: Any = None,
    output_noise: float | None = None,
) -> Any:
    """Find where a model and a measurement disagree, name the missing effect, add it.

    Parameters
    ----------
    recording : contactlab.io.Recording, dict or tuple
        The measurement: a Recording with channels ``x``, ``F`` (tangential) or ``p``,
        ``delta`` (normal) in SI units, a dict with ``t`` and those keys, or a tuple
        ``(t, x, F)`` / ``(t, p, delta)``. Uniform sampling; several excitation cycles.
    model : {"tangential", "normal"}, model object or None
        Base model family (None, the default: inferred from the recording's channels by
        :func:`infer_model`, as the command line infers it; the report's ``model_inferred``
        says so), or a model whose parameters start the fit
        (:class:`contactlab.Masing`, a normal-contact model, or an :class:`ExtendedModel`
        from an earlier diagnosis, whose effects are kept).
    candidates : sequence of str, optional
        Restrict the candidate library to these names (default: all of the family).
    max_effects : int
        Stop after this many additions.
    folds : int
        Cycles are split into this many interleaved folds for the held-out error.
    z : float
        Significance threshold (t statistic across held-out cycles).
    min_gain : float
        Minimum held-out MSE reduction, in units of the estimated noise variance.
    base : IdentifiedModel or path, optional
        Diagnose a structure instead: an identified structure
        (:func:`contactlab.structure.identify`, or its saved JSON) is the base model and
        ``recording`` is ``(t, u, y)``; the same when ``model`` is an ``IdentifiedModel``.
        Returns a :class:`~contactlab.diagnose.structure.StructureDiagnosis` (see
        :func:`~contactlab.diagnose.structure.diagnose_structure`).
    output_filter : array_like, optional
        Tangential only: the taps (odd count, zero phase) of a smoothing the force channel
        went through, e.g. a force reconstructed from a frame's equation of motion
        (:attr:`contactlab.tangential.FrameForce.force_filter`). Every candidate's predicted
        force passes the same filter, and the half filter at either end of the record
        (where it is not defined) counts for nothing. Default: the recording's
        ``meta["output_filter"]`` (set by :meth:`~contactlab.tangential.FrameForce.recording`).
    output_noise : float, optional
        The output channel's noise RMS when known (a filtered channel's noise is correlated
        and its differences understate it). Default: ``meta["output_noise"]`` of the
        recording, else estimated from the base model's residual.

    Returns
    -------
    DiagnosisReport

    Examples
    --------
    >>> import contactlab
    >>> from contactlab.diagnose import hidden_effect_recording
    >>> rec = hidden_effect_recording(["force_offset"], magnitude=0.05, seed=2)
    >>> report = contactlab.diagnose(rec, model="tangential")
    >>> report.effect_names
    ['force_offset']
    """
    # an IdentifiedModel can only exist once contactlab.structure is imported: no need to
    # import it (a fifth of a second) to tell
    structure = sys.modules.get("contactlab.structure")
    if base is not None or (structure is not None and isinstance(model, structure.IdentifiedModel)):
        from .structure import diagnose_structure

        return diagnose_structure(
            recording, model if base is None else base, candidates=candidates,
            max_effects=max_effects, z=z, min_gain=min_gain,
        )  # fmt: skip
    inferred = model is None and base is None
    if inferred:
        model = infer_model(recording)
    family, start, context = _family(model)
    t, u, y = _arrays(recording, family)
    named = {family.input_name: (u, family.input_unit), family.output_name: (y, family.output_unit)}
    check_channels(t, named)
    check_glitches(t, named)
    if folds < 2:
        raise InputError(f"folds must be >= 2, got {folds}")
    if max_effects < 0:
        raise InputError(f"max_effects must be >= 0, got {max_effects}")
    if not (z > 0 and min_gain >= 0):
        raise InputError(f"z must be > 0 and min_gain >= 0, got z={z}, min_gain={min_gain}")
    names = list(family.candidates) if candidates is None else list(candidates)
    for n in names:
        if n not in family.candidates:
            raise InputError(
                f"unknown {family.kind} candidate {n!r}; choose from {', '.join(family.candidates)}"
            )
    taps, declared_noise = _declared(recording, family, output_filter, output_noise, t.size, y)
    clock_note = _same_clock(recording, names, candidates)
    n_in = t.size
    if taps is not None and n_in > MAX_SAMPLES:  # a filter at the raw rate: no subsampling
        t, u, y = t[:MAX_SAMPLES], u[:MAX_SAMPLES], y[:MAX_SAMPLES]
        reduced = (
            f"the record of {n_in} samples was diagnosed on its first {MAX_SAMPLES} (its force "
            "passed a declared filter, which holds at the raw rate only)"
        )
        d = Prepared.build(t, u, y)
    elif family.kind == "tangential" and n_in > MAX_SAMPLES:
        d, reduced = subsample_long(t, u, y)
    elif family.kind == "normal" and n_in > MAX_SAMPLES:
        d, reduced = subsample_normal(t, u, y)
    else:
        t, u, y, reduced = reduce_long(t, u, y)
        d = Prepared.build(t, u, y)
    d.extra.update(context)
    prior, prior_notes = _prior_weight(family, d, taps)
    d.extra["evaluations"] = spent = EvaluationCounter()  # counted by select.fit
    family.prepare(d)
    scales = family.scales(d)
    effects: tuple[str, ...] = tuple(model.effects) if isinstance(model, ExtendedModel) else ()
    if not start:
        start = family.initial_base(d)
    fold_masks(d, folds)  # too few cycles to hold any out: said before fitting
    # the base fitted to all data gives the noise level and the weights; its cross-validation
    # is run once, with the weights it ends up with
    base_all = fit(family, effects, d, np.ones(d.y.size, bool), start, scales)
    sigma = declared_noise or noise_rms(family.predict(base_all.params, effects, d) - d.y)
    if sigma <= 0:
        raise InputError("the output channel has no noise at all; cannot judge significance")
    budget = 0.0
    w = eiv_weight(family, base_all.params, d, sigma)
    if w is not None:  # errors in variables: refit the base with the likelihood's weights
        d.extra["weight"], budget = w
        current = evaluate(family, effects, d, base_all.params, scales, folds, parallel=True)
        sigma = declared_noise or noise_rms(current.full_residual(d))
    else:
        current = evaluate(family, effects, d, start, scales, folds, base_all, parallel=True)
    anchored = None
    if hasattr(family, "anchor"):  # on a copy: a model passed in keeps its own family
        family = copy.copy(family)
        anchored = family.anchor(current.full.params, current.full.stderr, d)
    unanchored = {}
    if anchored:  # the base was in the wrong regime: fixed before any effect is tried
        unanchored = {
            "heldout_rms": current.heldout_rms,
            "h0": current.full.params["h0"],
            "h0_stderr": _finite_or_none(current.full.stderr["h0"]),
        }
        current = evaluate(family, effects, d, current.full.params, scales, folds, parallel=True)
    where, location = locate(d, current.full_residual(d), family)
    if anchored:
        location["base_unanchored"] = unanchored
        where.insert(0, anchored)
    where.insert(0, family.regime(current.full.params, d))
    if reduced:
        where.insert(1, reduced)
    location["samples"] = {"recording": n_in, "diagnosed": int(d.t.size)}
    location["noise_declared"] = declared_noise is not None
    if prior is not None:
        location.update(prior)
        where[2 if reduced else 1 : 2 if reduced else 1] = prior_notes
    if clock_note:
        where.insert(1, clock_note)
    if w is not None:
        low = float(np.mean(d.extra["weight"] < 0.5))
        location["low_weight_fraction"] = low
        if low > 0.01:
            where.append(
                f"{100 * low:.0f} % of the samples count less than half (input noise "
                f"{d.extra['u_noise']:.3g} seen through a steep local slope, e.g. sticking "
                "phases after reversals): what the model does there is barely tested"
            )
    trials = [current]
    steps = [Step(None, current.heldout_rms, current.heldout_peak, current.energy_error)]
    added: list[str] = []
    base_fit = dict(current.full.params)
    all_samples = np.ones(d.y.size, bool)
    untested: list[str] = []
    used = spent.total  # by the base; then as a serial run would count (below)
    visited = {frozenset(effects)}  # effect sets reached (the stepwise search never returns)
    seen: dict[str, float] = {}  # the largest held-out (or screening) gain of each candidate
    for _round in range(ROUNDS_PER_EFFECT * max_effects + 1):
        tried = [
            n
            for n in names
            if len(added) < max_effects
            and n not in effects
            and family.check((*effects, n))
            and frozenset((*effects, n)) not in visited
        ]
        # the candidates of one step are independent fits: on threads (the model evaluations
        # release the GIL), each verdict in the library's order as a serial run gives it
        try_one = partial(
            _try_candidate,
            family=family,
            current=current,
            effects=effects,
            d=d,
            scales=scales,
            folds=folds,
            sigma=sigma,
            z=z,
            min_gain=min_gain,
            budget=budget,
            base_fit=base_fit,
            all_samples=all_samples,
        )

        def counted(name: str, try_one: Any = try_one) -> tuple[Verdict, Trial | None, int]:
            before = spent.mine()  # a task runs on one thread: these are its evaluations
            v, cand = try_one(name)
            return v, cand, spent.mine() - before

        def unless_spent(name: str) -> tuple[Verdict, Trial | None, int] | None:
            return None if spent.total >= MAX_EVALUATIONS else counted(name)

        # the budget as a serial run spends it: a candidate is tried only while the base and
        # the candidates before it in the library's order are within it. On threads the
        # candidates start early; one that finds the budget spent by the others does not
        # start, and is run here after all if the serial count says it would have been.
        verdicts, best = [], None
        outs = pmap(unless_spent, tried, cost=partial(_fit_cost, family))
        for name, out in zip(tried, outs, strict=True):
            if used >= MAX_EVALUATIONS:
                untested.append(name)
                why = f"not tested: the budget of {MAX_EVALUATIONS} model evaluations is spent"
                verdicts.append(Verdict(name, np.nan, np.nan, np.nan, np.nan, False, why))
                continue
            v, cand, n = out if out is not None else counted(name)
            used += n
            verdicts.append(v)
            if cand is not None and v.accepted and (best is None or v.gain > best[0].gain):
                best = (v, cand)
        if verdicts:
            steps[-1] = dataclasses.replace(
                steps[-1], candidates=tuple(sorted(verdicts, key=lambda v: v.heldout_rms))
            )
        for v in verdicts:  # the pair move's pool: the largest gains seen at any step
            if np.isfinite(v.gain):
                seen[v.name] = max(seen.get(v.name, -np.inf), v.gain)
        swapped = False
        if best is None and added and used < MAX_EVALUATIONS and len(added) >= min(2, max_effects):
            # swap move: no effect can be added (the set is full, or nothing else helps);
            # an effect named early may stand in for one never tried because the set filled
            swap, swap_verdicts, n = _swap_search(
                family, names, current, tuple(added), visited, d, scales, folds, sigma,
                min_gain, budget, base_fit, all_samples,
            )  # fmt: skip
            used += n
            if swap_verdicts:
                steps[-1] = dataclasses.replace(
                    steps[-1], candidates=steps[-1].candidates + tuple(swap_verdicts)
                )
            if swap is not None:
                out, v, current = swap
                effects = current.effects
                added[added.index(out)] = v.name
                trials.append(current)
                visited.add(frozenset(effects))
                steps.append(
                    Step(v.name, current.heldout_rms, current.heldout_peak,
                         current.energy_error, removed=out, removal=v)
                )  # fmt: skip
                where.append(
                    f"swap: {out} replaced by {v.name} (the model with {v.name} instead "
                    f"predicts the held-out cycles better: gain {v.gain:.3g} σ², t = "
                    f"{v.t_stat:.2f})"
                )
                best, swapped = None, True
        if best is None and not swapped:
            # pair move: no single effect can be added or swapped in, yet one of them
            # lowered the error by a sizeable amount without significance; two together may
            pool = [n for n in sorted(seen, key=lambda n: -seen[n]) if n not in effects]
            gains = [v.gain for v in verdicts if np.isfinite(v.gain)]
            pair = None
            if (
                getattr(family, "pair_move", False)
                and max(gains, default=0.0)
                >= max(PAIR_GATE, MIN_RELATIVE_GAIN * current.heldout_mse / sigma**2)
                and used < MAX_EVALUATIONS
                and len(pool) > 1
            ):
                pair, pair_verdicts, n_pair = _pair_search(
                    family, pool[:PAIR_POOL], current, tuple(added), max_effects, visited, d,
                    scales, folds, sigma, z, min_gain, budget, base_fit, all_samples,
                )  # fmt: skip
                used += n_pair
                if pair_verdicts:
                    steps[-1] = dataclasses.replace(
                        steps[-1], candidates=steps[-1].candidates + tuple(pair_verdicts)
                    )
            if pair is None:
                break
            gone, (a, b), v, current = pair
            effects = current.effects
            if gone is not None:
                added.remove(gone)
            added += [a, b]
            trials.append(current)
            visited.add(frozenset(effects))
            steps.append(
                Step(f"{a} + {b}", current.heldout_rms, current.heldout_peak,
                     current.energy_error, removed=gone, removal=v if gone else None)
            )  # fmt: skip
            where.append(
                f"pair: {a} and {b} added together{f' in place of {gone}' if gone else ''} "
                f"(neither was accepted alone; together they predict the held-out cycles "
                f"better: gain {v.gain:.3g} σ², t = {v.t_stat:.2f}, and each is needed beside "
                "the other)"
            )
        if best is not None:
            v, current = best
            effects = current.effects
            added.append(v.name)
            trials.append(current)
            steps.append(
                Step(v.name, current.heldout_rms, current.heldout_peak, current.energy_error)
            )
            visited.add(frozenset(effects))
        # backward elimination (after an addition or a swap): an effect named early may be
        # redundant once later ones are in
        while len(added) >= 2 and used < MAX_EVALUATIONS:
            back = partial(
                _drop_check, family=family, current=current, d=d, scales=scales,
                folds=folds, sigma=sigma, z=z, min_gain=min_gain, budget=budget,
            )  # fmt: skip
            before = spent.total
            checks = pmap(back, list(added))
            used += spent.total - before
            drop = [(v, r) for v, r in checks if r is not None and not v.accepted]
            if not drop:
                break
            v, current = min(drop, key=lambda vr: vr[0].gain)
            effects = current.effects
            added.remove(v.name)
            trials.append(current)
            visited.add(frozenset(effects))
            steps.append(
                Step(None, current.heldout_rms, current.heldout_peak, current.energy_error,
                     removed=v.name, removal=v)
            )  # fmt: skip
            where.append(
                f"backward step: {v.name} dropped (refitted without it, the other effects "
                f"leave it nothing to add: {v.reason})"
            )
    if untested:
        where.append(
            f"the candidate search stopped after {used} model evaluations (its budget "
            f"is {MAX_EVALUATIONS}); not tested: {', '.join(dict.fromkeys(untested))}"
        )
    p, se = current.full.params, current.full.stderr
    out_effects = []
    for name in added:
        ps = {s.name: p[s.name] for s in family.candidates[name].params}
        ss = {s.name: se[s.name] for s in family.candidates[name].params}
        more = {"effects": effects, "d": d} if getattr(family, "derived_from_data", False) else {}
        dp, ds = family.derived(p, se, name, **more)
        out_effects.append(Effect(name, {**ps, **dp}, {**ss, **ds}))
    final = ExtendedModel(family, effects, p, se, family.context(d))
    out_effects = _frame_constants(recording, out_effects, where, location)
    gap = current.heldout_rms / sigma
    if gap > 1.5:
        where.append(
            f"after {'the additions' if added else 'the base fit'} the held-out RMS is still "
            f"{gap:.1f}× the noise level: the remaining discrepancy is not explained by any "
            "candidate of the library"
        )
    return DiagnosisReport(
        family.kind, out_effects, steps, where, sigma, final, location, d, trials, inferred
    )
