"""One normal-contact recording of a study (Konowalski 2009, PHYSICS.md §2).

The loop analysis (:func:`contactlab.normal.analyze_loop`: loading/unloading/centre
polynomials of eq. 1, E_d, E_pu, E_pd, ψ of eqs. 3 and 7, k_tan of eq. 4, k_sec of eq. 5) and
the pressure-dependent stiffness of eq. 16 for this test
(:func:`contactlab.normal.fit_pressure_stiffness`: ``k_s(p) = b1 p³ + b2 p² + b3 p + b4``).
b1..b4 are given in SI (k_s in Pa/m, p in Pa) and, as ``b1_paper`` .. ``b4_paper``, in the
paper's units (k_s in MPa/µm, p in MPa), which is what its Fig. 8 and the study plots show.
"""

from __future__ import annotations

import math
import warnings
from typing import Any

from ..errors import ContactLabWarning
from .manifest import StudyEntry

# SI units of b1..b4 (k_s [Pa/m] = b1 p³ + b2 p² + b3 p + b4, p [Pa]).
B_UNITS = {"b1": "1/(m·Pa^2)", "b2": "1/(m·Pa)", "b3": "1/m", "b4": "Pa/m"}
B_PAPER_UNITS = {"b1": "µm⁻¹·MPa⁻²", "b2": "µm⁻¹·MPa⁻¹", "b3": "µm⁻¹", "b4": "MPa/µm"}


def loop_options(p: Any, tags: Any, options: Any) -> dict[str, Any]:
    """The keyword arguments of :func:`~contactlab.normal.analyze_loop` for a recording with
    pressure channel ``p`` and file-name/manifest ``tags``: ``p0``, ``pa`` as given, else
    from the tags; ``p0`` dropped when the channel holds the total pressure (its mean is
    p0); ω from a ``frequency`` tag unless given. Whole-file, streamed and auto-streamed
    analyses all use this, so that they treat the same options alike."""
    from ..normal.loop import dynamic_only

    opts = dict(options)
    for key in ("p0", "pa"):  # the file-name tags and manifest columns, unless given
        tag = tags.get(key)
        if opts.get(key) is None and isinstance(tag, float) and math.isfinite(tag):
            opts[key] = tag
    if opts.get("p0") is not None and not dynamic_only(p):
        # a total-pressure channel measures p0 itself (its mean); a given value is the check
        opts["p0"] = None
    opts = {k: v for k, v in opts.items() if v is not None or k not in ("p0", "pa")}
    freq = tags.get("frequency")
    if "omega" not in opts and isinstance(freq, float) and math.isfinite(freq) and freq > 0:
        opts["omega"] = 2.0 * math.pi * freq
    return opts


def analyze_normal_recording(
    rec: Any, entry: StudyEntry, **options: Any
) -> tuple[Any, dict[str, Any], dict[str, Any]]:
    """Analyse one normal recording: ``(LoopResult, row dict with units, extra JSON)``.

    ``options`` go to :func:`~contactlab.normal.analyze_loop`; ω defaults to 2π times the
    ``frequency`` tag when the study gives one. Warnings of the analysis are collected into
    the row's ``warnings`` (and the report) rather than raised.
    """
    from ..normal import analyze_loop, fit_pressure_stiffness

    opts = loop_options(rec["p"], entry.tags, options)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", ContactLabWarning)
        result = analyze_loop(rec.t, rec["p"], rec["delta"], **opts)
        stiff = fit_pressure_stiffness([result])
    d = result.to_dict()
    units = dict(d.get("units", {}))
    b = [float(v) for v in stiff.b[0]]
    bp = [float(v) for v in stiff.b_display()[0]]
    for i, name in enumerate(("b1", "b2", "b3", "b4")):
        d[name] = b[i]
        d[f"{name}_paper"] = bp[i]
        units[name] = B_UNITS[name]
        units[f"{name}_paper"] = B_PAPER_UNITS[name]
    d["k_s_p_rms"] = float(stiff.rms[0])
    units["k_s_p_rms"] = "Pa/m"
    # standard error of the mean dissipated energy from its cycle-to-cycle scatter
    n = int(d.get("n_cycles") or 0)
    e_std = d.get("E_d_cycle_std")
    if n > 1 and isinstance(e_std, float) and math.isfinite(e_std):
        d["E_d_stderr"] = e_std / math.sqrt(n)
        units["E_d_stderr"] = units.get("E_d", "J/m^2")
    d["units"] = units
    msgs = [str(w.message) for w in caught if issubclass(w.category, ContactLabWarning)]
    for w in caught:  # anything else (a numpy RuntimeWarning) goes on as raised
        if not issubclass(w.category, ContactLabWarning):
            warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
    d["warnings"] = " | ".join(msgs)
    added = (
        "b1",
        "b2",
        "b3",
        "b4",
        "b1_paper",
        "b2_paper",
        "b3_paper",
        "b4_paper",
        "k_s_p_rms",
        "E_d_stderr",
    )
    extra = {k: d[k] for k in added if k in d}
    extra["warnings"] = msgs
    return result, d, extra


__all__ = ["B_PAPER_UNITS", "B_UNITS", "analyze_normal_recording"]
