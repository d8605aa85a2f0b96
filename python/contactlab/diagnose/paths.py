"""The kind-specific paths of the diagnosis behind one interface (issue 29 item 6).

:func:`contactlab.diagnose.diagnose` runs the same steps for every model family; what
differs between a tangential joint (force against displacement) and a normal one
(displacement against pressure) lives here:

- :meth:`KindPath.orient`: the output's sign (a tangential force recorded with the other
  sign convention, ``force_sign`` as ``analyze`` takes it);
- :meth:`KindPath.prepare`: a long record kept every q-th sample (each kind its own way);
- :meth:`KindPath.regime`: the regime decision — for a tangential joint the one ``analyze``
  makes (:func:`contactlab.tangential.regime.classify` through
  :func:`contactlab.tangential.analyze_tangential`), so that ``analyze``, ``track`` and
  ``diagnose`` say the same, with the plateau's ``h0`` the final model is checked against;
- :meth:`KindPath.check_final`: the final model's physical parameters against what
  ``analyze`` found (tangential: ``h0`` within :data:`H0_TOLERANCE` of the plateau, or why
  it moved).
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..errors import ContactLabError, InputError
from ._family import Family, Prepared
from ._prepare import MAX_SAMPLES, reduce_long, subsample_long, subsample_normal

#: the final model's h0 may differ from the plateau ``analyze`` reads by this share before
#: the report says why (the issue's bar: within 5 %)
H0_TOLERANCE = 0.05


@dataclass
class RegimeDecision:
    """The regime as ``analyze`` decides it, and what it identifies.

    ``name``: "pre-sliding", "transition", "gross sliding" or "stick-slip" (tangential), or
    the family's own wording; ``reason``: analyze's sentence; ``h0``/``h0_stderr``: the
    plateau force in the sliding regimes (None elsewhere); ``breakaway_force``: the mean
    breakaway of the sticks (None without sticks); ``source``: where it came from."""

    name: str
    reason: str
    source: str
    h0: float | None = None
    h0_stderr: float | None = None
    breakaway_force: float | None = None
    extra: dict[str, Any] = field(default_factory=dict)

    @property
    def sliding(self) -> bool:
        return self.name in ("gross sliding", "stick-slip")

    def to_dict(self) -> dict[str, Any]:
        out: dict[str, Any] = {"regime": self.name, "reason": self.reason, "source": self.source}
        if self.h0 is not None:
            out["h0_plateau"] = self.h0
            out["h0_plateau_stderr"] = _finite(self.h0_stderr)
            out["h0_source"] = self.extra.get("h0_source")
        if self.breakaway_force is not None:
            out["breakaway_force"] = _finite(self.breakaway_force)
        return out


def _finite(v: float | None) -> float | None:
    return float(v) if v is not None and np.isfinite(v) else None


class KindPath:
    """What differs between the families (see the module docstring). The base class is the
    behaviour every family shares."""

    kind = ""

    def __init__(self, family: Family) -> None:
        self.family = family

    def orient(
        self, t: np.ndarray, u: np.ndarray, y: np.ndarray, force_sign: Any
    ) -> tuple[np.ndarray, str | None]:
        """The output with the sign to diagnose, and a sentence (None: as recorded)."""
        if force_sign is not None:
            raise InputError(f"force_sign is for the tangential model, not {self.kind!r}")
        return y, None

    def prepare(
        self, t: np.ndarray, u: np.ndarray, y: np.ndarray, taps: np.ndarray | None
    ) -> tuple[Prepared, str]:
        """The record ready for the candidates, and a sentence on how it was reduced."""
        n = t.size
        if taps is not None and n > MAX_SAMPLES:  # a filter at the raw rate: no subsampling
            t, u, y = t[:MAX_SAMPLES], u[:MAX_SAMPLES], y[:MAX_SAMPLES]
            return Prepared.build(t, u, y), (
                f"the record of {n} samples was diagnosed on its first {MAX_SAMPLES} (its "
                "force passed a declared filter, which holds at the raw rate only)"
            )
        if n > MAX_SAMPLES:
            return self.subsample(t, u, y)
        t, u, y, reduced = reduce_long(t, u, y)
        return Prepared.build(t, u, y), reduced

    def subsample(self, t: np.ndarray, u: np.ndarray, y: np.ndarray) -> tuple[Prepared, str]:
        t, u, y, reduced = reduce_long(t, u, y)
        return Prepared.build(t, u, y), reduced

    def regime(self, t: np.ndarray, u: np.ndarray, y: np.ndarray) -> RegimeDecision:
        """No regime decision outside the base fit: the family's own sentence is used."""
        return RegimeDecision("", "", "base fit")

    def check_final(
        self,
        regime: RegimeDecision,
        p: dict[str, float],
        effects: tuple[str, ...],
        model_force: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None,
        strokes: tuple[tuple[float, float], tuple[float, float]] | None = None,
    ) -> tuple[dict[str, Any] | None, str | None]:
        """The final model's physical parameters against ``analyze``'s (None: nothing to
        check), and a sentence when they moved (``model_force``, ``strokes``: the final
        model's output and the stroke levels, as the tangential path takes them; unused
        here)."""
        return None, None


class NormalPath(KindPath):
    kind = "normal"

    def subsample(self, t: np.ndarray, u: np.ndarray, y: np.ndarray) -> tuple[Prepared, str]:
        return subsample_normal(t, u, y)


class TangentialPath(KindPath):
    kind = "tangential"

    def orient(
        self, t: np.ndarray, u: np.ndarray, y: np.ndarray, force_sign: Any
    ) -> tuple[np.ndarray, str | None]:
        """``force_sign`` as ``analyze`` takes it (:func:`contactlab.tangential.orientation.
        orient`): ``"auto"`` (the sign that makes the loop dissipate), ``+1`` or ``-1``;
        None keeps the force as recorded (a loop that runs the wrong way is then refused
        with a sentence saying so)."""
        if force_sign is None:
            return y, None
        from ..tangential.orientation import orient

        ori = orient(u, y, t, force_sign=force_sign)
        if ori.sign == 1:
            return y, None if ori.by == "user" and "<" not in ori.reason else ori.reason
        return -y, f"force sign -1: {ori.reason}"

    def subsample(self, t: np.ndarray, u: np.ndarray, y: np.ndarray) -> tuple[Prepared, str]:
        return subsample_long(t, u, y)

    def regime(self, t: np.ndarray, u: np.ndarray, y: np.ndarray) -> RegimeDecision:
        """The regime ``analyze`` decides on the same record (force sign applied already),
        with its plateau ``h0`` and the sticks' breakaway force; the base fit's own
        sentence when ``analyze`` cannot read the record (too few cycles, no loop)."""
        from ..tangential import analyze_tangential

        try:
            an = analyze_tangential(t=t, x=u, F=y, force_sign=1, warn=False)
        except (ContactLabError, ValueError, FloatingPointError) as exc:
            return RegimeDecision("", "", "base fit", extra={"analyze_error": str(exc)})
        reg = an.regime or {}
        name = str(reg.get("regime", ""))
        h0 = se = None
        plateau = (an.derived or {}).get("h0_plateau")
        h0_source = None
        if name in ("gross sliding", "stick-slip"):
            # the h0 analyze reports: its plateau's where analyze takes h0 from it (no fit, or
            # a fit whose exponential asymptote the plateau contradicts), else its fit's (an
            # exponential loop's plateau mean lies ~1 % under the asymptote at ac·A 5)
            if plateau is not None and an.identifiability.get("h0_source") == "plateau":
                h0, se, h0_source = float(plateau[0]), float(plateau[1]), "plateau"
            elif an.fit is not None:  # sliding, no plateau over the stroke: analyze's fit
                ph = an.fit.params["h0"]
                h0, se, h0_source = float(ph.value), float(ph.stderr), "analyze fit"
        stick = reg.get("stick_slip") or {}
        # the sticks' breakaway, where analyze found sticks (stick-slip)
        fb = stick.get("breakaway_force") if name == "stick-slip" else None
        return RegimeDecision(
            name,
            f"regime (as analyze decides it): {reg.get('regime_reason', name)}",
            "analyze",
            h0,
            se,
            float(fb) if isinstance(fb, (int, float)) else None,
            {"h0_source": h0_source, "ac_lower_bound": _lower_bound(an)},
        )

    def check_final(
        self,
        regime: RegimeDecision,
        p: dict[str, float],
        effects: tuple[str, ...],
        model_force: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None,
        strokes: tuple[tuple[float, float], tuple[float, float]] | None = None,
    ) -> tuple[dict[str, Any] | None, str | None]:
        """The friction force of the final model against the one ``analyze`` reads in gross
        sliding and stick-slip (its plateau, or its fit where the stroke has no plateau).

        ``strokes``: ``((up, down) of the data, (up, down) of the final model)``, the mean
        force over the second half of the strokes with the displacement rising and falling
        (:func:`stroke_levels`, the same samples for both): the like-with-like reading of
        the friction force in each direction, which the report quotes when the two differ.

        ``model_force``: ``(t, x, F_model)``, the final model's force on the record; it is
        read by ``analyze`` exactly as the data were (``h0_model_reading``), which is what a
        user comparing the two would see whatever the effects do to the meaning of ``h0``
        (a branch scale makes the loop's half height ``λ h0 / 2``, a drift makes ``h0`` the
        mid-record value). Within :data:`H0_TOLERANCE`, or a sentence saying why it moved."""
        if regime.h0 is None or not regime.h0 > 0:
            return None, None
        h0 = float(p["h0"])
        read = _model_reading(model_force, regime) if model_force is not None else None
        ratio = (read if read is not None else h0) / regime.h0
        doc: dict[str, Any] = {
            "h0_plateau": regime.h0,
            "h0_plateau_stderr": _finite(regime.h0_stderr),
            "h0_source": regime.extra.get("h0_source"),
            "h0_final": h0,
            "h0_model_reading": read,
            "ratio": ratio,
            "within_tolerance": bool(abs(ratio - 1.0) <= H0_TOLERANCE),
        }
        if strokes is not None:
            (du, dd), (mu, md) = strokes
            half_d, half_m = 0.5 * (du - dd), 0.5 * (mu - md)
            doc["stroke_half"] = {
                "data_up": du, "data_down": dd, "model_up": mu, "model_down": md,
                "ratio": half_m / half_d if half_d > 0 else None,
                "within_tolerance": bool(half_d > 0 and abs(half_m / half_d - 1) <= H0_TOLERANCE),
            }  # fmt: skip
        if doc["within_tolerance"]:
            return doc, None
        why = {
            "parameter_drift": "h0 is the friction force at the record's start (it drifts)",
            "asymmetry": (
                "h0 is half the difference of the two directions' forces h0(1 ± α), as "
                "analyze's plateau is: it does not redefine h0"
            ),
            "position_friction": "h0 is the mean along the track, the plateau a median",
            "normal_load": "h0 is the force at the mean normal load",
        }
        reasons = [f"{e}: {why[e]}" for e in effects if e in why]
        if regime.extra.get("h0_source") != "plateau":
            reasons.append(
                "analyze finds no plateau on the data: its h0 is the asymptote of its "
                "exponential fit, which the force need not reach"
            )
        sh = doc.get("stroke_half")
        if sh is not None and sh["ratio"] is not None:
            reasons.append(
                f"over the second half of each stroke the data's force averages "
                f"{sh['data_up']:.4g} N rising and {sh['data_down']:.4g} N falling (half the "
                f"difference {0.5 * (sh['data_up'] - sh['data_down']):.4g} N), the final "
                f"model's {sh['model_up']:.4g} N and {sh['model_down']:.4g} N "
                f"({0.5 * (sh['model_up'] - sh['model_down']):.4g} N, ratio "
                f"{sh['ratio']:.3f})"
            )
        doc["why"] = reasons
        what = "plateau" if regime.extra.get("h0_source") == "plateau" else "friction force"
        text = (
            f"the final model's friction force ({'read by analyze: ' if read else 'h0 = '}"
            f"{read if read else h0:.4g} N) is {100 * (ratio - 1):+.1f} % from the {what} "
            f"{regime.h0:.4g} N that analyze reads on the data"
        )
        text += (
            f" because {'; '.join(reasons)}"
            if reasons
            else " with no effect that redefines it: the base model trades h0 against a misfit"
        )
        return doc, text


def stroke_levels(
    x: np.ndarray, F: np.ndarray, reversals: np.ndarray
) -> tuple[float, float] | None:
    """The mean force over the second half of the travel of each stroke between two
    reversals, over the strokes with ``x`` rising and those with it falling (a plateau's
    level where the stroke reaches one, the same statistic of any loop otherwise); None
    without a stroke each way."""
    ups: list[float] = []
    downs: list[float] = []
    rev = np.asarray(reversals, int)
    for a, b in itertools.pairwise(rev):
        if b - a < 4:
            continue
        s = x[a : b + 1] - x[a]
        sign = 1.0 if s[-1] > 0 else -1.0
        sel = sign * s > 0.5 * abs(float(s[-1]))
        if np.count_nonzero(sel):
            (ups if sign > 0 else downs).append(float(np.mean(F[a : b + 1][sel])))
    if not (ups and downs):
        return None
    return float(np.mean(ups)), float(np.mean(downs))


def _model_reading(
    model_force: tuple[np.ndarray, np.ndarray, np.ndarray], regime: RegimeDecision
) -> float | None:
    """``h0`` as ``analyze`` reads it off the final model's force on the record (its plateau
    where the data have one, else its fit), None when it cannot."""
    from ..tangential import analyze_tangential

    t, x, F = model_force
    try:
        an = analyze_tangential(t=t, x=x, F=F, force_sign=1, warn=False)
    except (ContactLabError, ValueError, FloatingPointError):
        return None
    plateau = (an.derived or {}).get("h0_plateau")
    if regime.extra.get("h0_source") == "plateau" and plateau is not None:
        return float(plateau[0])
    return float(an.fit.params["h0"].value) if an.fit is not None else None


def _lower_bound(an: Any) -> float | None:
    """``ac``'s lower bound ``analyze`` reads off the plateau (None without one)."""
    v = (an.derived or {}).get("ac_lower_bound")
    return float(v[0]) if v is not None and np.isfinite(v[0]) else None


def kind_path(family: Family) -> KindPath:
    """The path of a family (by its ``kind``)."""
    if family.kind == "tangential":
        return TangentialPath(family)
    if family.kind == "normal":
        return NormalPath(family)
    raise InputError(f"no diagnosis path for a {family.kind!r} model")
