"""The diagnosis's closing checks on its final model (issue 29, items 1-3): both channels'
noise (:mod:`.detection`), the stated power of every candidate not named (:mod:`.power`) and
the structure the final residual still holds (:mod:`.misfit`), in one call for the workflow.
(Kept apart from :mod:`.detection`, which the other two build on: no import cycle.)"""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np

from ._family import Prepared
from .detection import channel_noise, model_slope
from .eiv import input_noise_spectrum, is_coloured, reweighted
from .misfit import (
    BACKBONE_Z,
    BACKBONE_Z_CORRECTED,
    SHAPE_ABSORBERS,
    backbone_misfit,
    eiv_bias,
    eiv_tolerance,
    unexplained_structure,
)
from .power import POWER, _setting, bounds_for

__all__ = ["assess"]


def assess(
    family: Any,
    d: Prepared,
    current: Any,
    sigma: float,
    *,
    z: float,
    gain_floor: float,
    folds: int,
    candidates: list[str],
    declared_output: float | None = None,
    seed: int = 0,
) -> dict[str, Any]:
    """The diagnosis's closing checks (issue 29, items 1-3) on its final model.

    Returns a dict with ``noise`` (:class:`~.detection.ChannelNoise`), ``not_detected`` (a list of
    :class:`contactlab.diagnose.power.Detectable`, every candidate not in the final model)
    and ``unexplained`` (:class:`contactlab.diagnose.misfit.Unexplained` or None), plus the
    settings they were computed at (``z``, ``gain_floor``, ``folds``, ``candidates``).
    """
    params = dict(current.full.params)
    effects = tuple(current.effects)
    residual = -current.full_residual(d)  # measured minus model
    slope = model_slope(family, params, d)
    noise = channel_noise(
        d, residual, declared_output=declared_output, slope=slope,
        input_unit=family.input_unit, output_unit=family.output_unit,
    )  # fmt: skip
    st = _setting(d, current, noise, slope, sigma, z, gain_floor, folds, seed)
    bounds = bounds_for(family, params, effects, candidates, d, noise, sigma, current, st)
    # errors in variables: the structure the input's noise alone leaves, simulated and
    # taken out of the residual before the phase-bin test (the interval null then only
    # covers what the simulation misses)
    bias = eiv_bias(family, params, effects, d, seed=seed)
    tested = residual if bias is None else residual - bias
    # the input noise the model sees, from its spectrum where it is coloured (a white-noise
    # estimate from neighbouring samples misses a low-passed sensor's noise)
    spec = input_noise_spectrum(d)
    seen = noise.input_seen
    dm = d
    coloured = spec is not None and is_coloured(d, spec)
    if coloured:
        seen = max(seen, spec.seen)
        # the samples where that noise dominates the output's error are left out
        # (from the input noise the detection's weights already carry: d.extra["u_seen"])
        dm = reweighted(d, slope, sigma, float(d.extra.get("u_seen", noise.input_seen)), seen)
    misfit = unexplained_structure(
        dm, tested, sigma, unit=family.output_unit,
        tolerance=eiv_tolerance(slope, seen, corrected=bias is not None),
    )  # fmt: skip
    if misfit is None and coloured:
        # the coloured noise dominates every bin: rather than no verdict, the bins at the
        # white weights, with the spectral tolerance (fresh chain seeds 7004, 7502)
        dm = d
        misfit = unexplained_structure(
            d, tested, sigma, unit=family.output_unit,
            tolerance=eiv_tolerance(slope, seen, corrected=bias is not None),
        )  # fmt: skip
    if misfit is not None and spec is not None:
        misfit = dataclasses.replace(
            misfit, input_noise={"rms": spec.rms, "seen": seen, "white": noise.input}
        )
    if misfit is not None and bias is not None:
        misfit = dataclasses.replace(misfit, eiv_bias_rms=float(np.sqrt(np.mean(bias * bias))))
    if misfit is not None and getattr(family, "kind", "") == "tangential" and "ac" in params:
        # a virgin curve of another shape, partly absorbed by a named effect
        # on the residual as measured: taking the simulated input-noise bias out lowered the
        # held-out t of tanh virgin curves (tuning seeds: 3 of 10; fresh seeds 60500-60529:
        # flagged 11 -> 8 of 27), so this test keeps its interval of z instead; only a
        # noise-free input, where there is no such bias, gets the lower z
        z_bb = BACKBONE_Z_CORRECTED if not noise.input > 0 else BACKBONE_Z
        # a coloured input noise's bias is itself shaped like a virgin curve (and several
        # times what white noise leaves): there the test reads the corrected residual
        # (fresh chain seed 6000, x noise 2 % behind an LVDT: held-out t 5.27 > 4.5 as
        # measured)
        # (coloured: whether or not the detection's weights already carried it, dm is d)
        bb_res = tested if coloured else residual
        bb = backbone_misfit(dm, bb_res, float(params["ac"]), sigma, z=z_bb)
        if bb is not None:
            flagged = misfit.flagged or bb["flagged"]
            misfit = dataclasses.replace(misfit, backbone=bb, flagged=flagged)
    if misfit is not None and misfit.flagged:
        # a named effect that reshapes the virgin curve and still leaves structure over the
        # phase bins absorbed part of a misfit it does not model: its signature test failed
        absorbing = tuple(e for e in effects if e in SHAPE_ABSORBERS)
        misfit = dataclasses.replace(misfit, absorbing=absorbing)
    return {
        "noise": noise,
        "not_detected": bounds,
        "unexplained": misfit,
        "z": z,
        "gain_floor": st.gain_floor,
        "folds": folds,
        "power": POWER,
        "candidates": list(candidates),
    }
