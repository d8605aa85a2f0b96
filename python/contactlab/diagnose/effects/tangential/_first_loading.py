"""The first loading from rest: what tells a branch scale and the offsets apart.

In steady state at one amplitude a branch scale λ ≠ 2, a force offset and a displacement
offset draw the same loop: a Masing loop shifted by a constant force (docs/effects.md §1).
What separates them is the first loading from rest, before the first turning point: an
offset is there at rest (F = F0 before the motion), the branch scale's shift appears only
with the motion (the virgin curve starts at F = 0). The stepwise search ranks candidates by
their error on held-out *cycles*, which begin at the first maximum of the input: the first
loading is in no held-out cycle, so on a record without amplitude changes the held-out
errors of the three are equal to within the noise and the one named is a draw. These
helpers give the first loading's samples and a candidate model's misfit there, which the
effects' :meth:`plausible` checks hold against the loop shift the candidate draws.
"""

from __future__ import annotations

import numpy as np

from ..._family import Prepared
from ._common import record_turns

#: a model's first-loading misfit counts when its mean lies this many standard errors from 0
FIRST_LOADING_SIGMAS = 3.0

#: parameters whose effect on the first loading :func:`model_first_loading` computes (the
#: base, the branch scale — whose virgin curve is the base's — and the terms that add to
#: or scale it); a model with any other effect is not checked
HANDLED = frozenset({"h0", "ac", "lam", "F0", "F1", "x0", "k_p", "c", "m", "alpha", "beta"})


def first_loading(d: Prepared) -> int | None:
    """The number of samples from the record's first sample up to its first actual turning
    point (:func:`~._common.record_turns`: the input noise's wiggles at rest are no turns),
    or None when there is no such stretch of at least 3 samples followed by a second turn."""
    turns = record_turns(d.u, d.extra.get("u_noise", 0.0))
    if turns.size < 2 or int(turns[0]) < 3:
        return None
    return int(turns[0])


def model_first_loading(p: dict[str, float], d: Prepared, n: int) -> np.ndarray | None:
    """The model's force on the first ``n`` samples, all on the virgin curve from rest:
    ``f(x - x0)`` of ``(h0, ac)`` with the drift factor, the asymmetry and the additive terms
    of the model's parameters; None when the model has an effect outside :data:`HANDLED`."""
    from ....masing import Masing

    if not set(p) <= HANDLED:
        return None
    x = d.u[:n] - p.get("x0", 0.0)
    h = Masing(p["h0"], p["ac"]).virgin(x)
    t = d.t[:n] - d.t[0]
    if "beta" in p:
        h = h * (1.0 + p["beta"] * (t / d.duration - 0.5))
    if "alpha" in p:
        h = h + p["alpha"] * np.abs(h)
    F = h + p.get("k_p", 0.0) * x + p.get("c", 0.0) * d.ud[:n] + p.get("m", 0.0) * d.udd[:n]
    return F + p.get("F0", 0.0) + p.get("F1", 0.0) * t / d.duration


def misfit(r: np.ndarray, u: np.ndarray) -> tuple[float, float]:
    """The residual ``r`` at rest and its standard error: the intercept at ``u = 0`` of a
    straight line through ``r`` against the travel ``u`` from rest (a model's virgin curve is
    0 at rest whatever its parameters, but a fit can bend it to meet the data further up the
    loading: a λ = 4.2 fit of a force-offset record met the data at the first turn and
    missed them by the whole offset at rest), with the effective sample count of the
    residual's lag-1 autocorrelation (the filtered input's noise seen through the branch's
    slope is correlated from sample to sample)."""
    A = np.column_stack([np.ones_like(u), u])
    coef, *_ = np.linalg.lstsq(A, r, rcond=None)
    c = r - A @ coef
    den = float(c @ c)
    rho = float(c[1:] @ c[:-1]) / den if den > 0 and r.size > 3 else 0.0
    rho = min(max(rho, 0.0), 0.95)
    inflate = (1.0 + rho) / (1.0 - rho)
    s2 = den / max(r.size - 2, 1) * inflate
    cov = s2 * np.linalg.pinv(A.T @ A)
    return float(coef[0]), float(np.sqrt(max(cov[0, 0], 0.0)))


def first_loading_misfit(p: dict[str, float], d: Prepared) -> tuple[float, float, int] | None:
    """``(misfit at rest, its standard error, samples)`` of the measured minus the model's
    force over the first loading from rest (:func:`misfit`), or None when the record has
    none or the model is not checked."""
    n = first_loading(d)
    if n is None:
        return None
    F = model_first_loading(p, d, n)
    if F is None or not np.all(np.isfinite(F)):
        return None
    u = np.abs(d.u[:n] - d.u[0])
    m, se = misfit(d.y[:n] - F, u)
    return m, se, n


def unexplained_start(p: dict[str, float], d: Prepared, shift: float, what: str) -> str | None:
    """Why the model does not explain the record's first loading from rest, or None.

    ``shift``: the constant force by which the effect moves the closed loop (the loop
    shift it draws, N). The model is refused when its misfit at rest (:func:`misfit`) is
    significant (:data:`FIRST_LOADING_SIGMAS` standard errors) *and* more than half that
    shift: the data's first loading then lies nearer the other explanation of the same
    loop (the shift present at rest, or absent at rest) than this one's."""
    got = first_loading_misfit(p, d)
    if got is None or not np.isfinite(shift):
        return None
    m, se, n = got
    if abs(m) > FIRST_LOADING_SIGMAS * se and abs(m) > 0.5 * abs(shift):
        return (
            f"it does not explain the first loading from rest: at rest (read off the {n} "
            f"samples before the first turning point) the data lie {m:+.3g} ± {se:.2g} N "
            "from the model, "
            f"more than half the {shift:+.3g} N by which {what} shifts the loop — the "
            "record's start, the one thing that tells a branch scale from a force or "
            "displacement offset, says the other"
        )
    return None


def start_tells(
    p: dict[str, float], d: Prepared, shift: float, what: str, other: str, sigmas: float
) -> str | None:
    """Why the record's first loading does not tell the model from the other explanation
    of the same closed loop, or None (it does, or the record has no first loading to read).

    The model and ``other`` draw the same loop; they differ at rest by ``shift`` (the
    other puts the loop's shift there before the motion). The model is identified when its
    misfit at rest lies more than ``sigmas`` standard errors from ``shift``."""
    got = first_loading_misfit(p, d)
    if got is None or not np.isfinite(shift):
        return None
    m, se, n = got
    if abs(m - shift) <= sigmas * se:
        return (
            f"not identifiable: {what} shifts the loop by {shift:+.3g} N, as {other} would; "
            f"only the first loading from rest tells them apart, and there (the {n} samples "
            f"before the first turning point) the data lie {m:+.3g} ± {se:.2g} N from it, "
            f"within {sigmas:g} standard errors of what {other} gives"
        )
    return None
