"""The whole-record document of a tangential recording analysed window by window.

``contactlab analyze`` of a long recording (more than :data:`STREAM_ABOVE` samples; normal-contact
recordings likewise, :func:`pooled_normal_document`) runs the
streamed analysis (:func:`contactlab.track`, memory bounded by one chunk and one window) and
writes the document a whole-file analysis writes, with the same keys, each filled from the
windows:

- a quantity with a standard error: the weighted mean over the windows that determine it
  (:func:`pool`: weights by window size, a window's own error only where it is far above the
  typical one), its error widened by the Birge ratio when the windows scatter beyond their
  errors (as :meth:`~contactlab.studies.TrackResult.combined`);
- the fit's parameters likewise; its covariance ``(Σ C_k⁻¹)⁻¹`` over the windows' covariances
  (independent data), ``chisqr``, ``ndata``, ``nfev`` summed;
- extensive quantities summed (``n_cycles``, ``loop_area_recorded`` with its error in
  quadrature); other numbers (``loop_area_ratio``, ``ac_times_amplitude_regime``) averaged;
- the regime: the most frequent one, its reason saying how many windows had it; the
  identifiability flags: a parameter counts as identified when it is in every window;
- warnings: each distinct window warning once, with the number of windows that gave it;
- ``stick_slip``: ``n_reversals`` summed over the windows; the search's counts and means
  over the windows that searched for sticks (null where none did: a streamed window of a
  pre-sliding or transition loop counts its reversals but does not search them, see
  :func:`contactlab.tangential.window.analyze_window`).

``streamed`` (True), ``streamed_reason``, ``n_windows``, ``n_samples`` and ``every`` say how
it was made.
"""

from __future__ import annotations

import math
from collections import Counter
from typing import Any

import numpy as np

from .._arrays import median

#: samples above which ``contactlab analyze`` streams a tangential recording (a whole-file
#: analysis peaked at 317 MB on 1e6 samples, 1.9 GB on 1e7; streamed: about 200 MB at any length)
STREAM_ABOVE = 1 << 19

_SUMMED = ("n_cycles",)
_NO_POOL = ("force_sign",)


def _num(v: Any) -> float:
    return (
        float(v)
        if isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)
        else math.nan
    )


#: a window's own standard error sets its weight only when it exceeds this many times the
#: error typical of its size (``c/√n``, ``c`` the median of ``s·√n`` over the windows)
OWN_ERROR_ABOVE = 3.0


def pool(
    values: list[Any] | np.ndarray,
    errors: list[Any] | np.ndarray,
    sizes: list[Any] | np.ndarray | None = None,
) -> tuple[float, float, float]:
    """``(mean, stderr, birge)`` of windows with a finite value and a positive error.

    With ``sizes`` (cycles or samples per window, three windows or more): each window is
    weighted by the error typical of its size, ``c/√n`` with ``c`` the median of ``s·√n``,
    unless its own error ``s`` is more than :data:`OWN_ERROR_ABOVE` times that (a window
    that determines the quantity badly keeps its own, smaller weight). A window's own
    error is estimated from the same noisy samples as its value and is correlated with it (a
    window whose h0 came out low also came out with a smaller error), so inverse-variance
    weights bias the mean: 666 windows of 3 cycles, 1 % noise on both channels, h0 −0.31 %
    (z −4.9) with ``1/s²`` against −0.13 % with these weights. Without sizes: ``1/s²``.

    ``stderr`` is ``1/sqrt(Σ w)`` times the Birge ratio ``sqrt(χ²/(n-1))`` when that
    exceeds 1, χ² with the errors the weights use (a window's own error is an estimate from
    few cycles: with 4-cycle normal windows, χ² over the windows' own errors read a Birge
    ratio of 1.7-2 where the errors were right on average). Without any error: the plain
    mean and the standard error of the windows' scatter (NaN, NaN, NaN without a value). Weights are
    relative to the smallest error and values to the largest, so that quantities of 1e±300
    do not overflow the sums.
    """
    v = np.array([_num(a) for a in values])
    s = np.array([_num(a) for a in errors])
    ok = np.isfinite(v) & np.isfinite(s) & (s > 0)
    if not ok.any():
        fin = v[np.isfinite(v)]
        if not fin.size:
            return math.nan, math.nan, math.nan
        big = float(np.max(np.abs(fin))) or 1.0
        u = fin / big
        se = big * float(np.std(u, ddof=1)) / math.sqrt(fin.size) if fin.size > 1 else math.nan
        return big * float(np.mean(u)), se, math.nan
    vk, sk = v[ok], s[ok]
    smin = float(np.min(sk))
    rel = sk / smin
    if sizes is not None and ok.sum() >= 3:
        n = np.array([_num(a) for a in sizes])[ok]
        c = float(median(rel * np.sqrt(n))) if np.all(np.isfinite(n) & (n > 0)) else math.nan
        if math.isfinite(c):
            typical = c / np.sqrt(n)
            rel = np.where(rel > OWN_ERROR_ABOVE * typical, rel, typical)
    w = 1.0 / rel**2
    vbig = float(np.max(np.abs(vk))) or 1.0
    mean = vbig * float(np.sum(w * (vk / vbig)) / np.sum(w))
    err = smin / math.sqrt(float(np.sum(w)))
    birge = 1.0
    if ok.sum() > 1:
        with np.errstate(over="ignore"):  # inf: windows scattering beyond any error
            r = (vk - mean) / (smin * rel)
            chi2 = float(np.sum(r * r))
        birge = math.sqrt(chi2 / (ok.sum() - 1))
    return mean, err * max(birge, 1.0), birge


def _pool_fit(fits: list[dict[str, Any]]) -> dict[str, Any]:
    out = dict(fits[0])
    sizes = [f.get("ndata") for f in fits]
    params = {}
    for name, p0 in fits[0]["params"].items():
        vals = [f["params"].get(name, {}).get("value") for f in fits]
        errs = [f["params"].get(name, {}).get("stderr") for f in fits]
        m, e, _ = pool(vals, errs, sizes)
        p = dict(p0, value=None if math.isnan(m) else m, stderr=None if math.isnan(e) else e)
        p["identifiable"] = all(f["params"].get(name, {}).get("identifiable") for f in fits)
        p["init_value"] = None
        params[name] = p
    out["params"] = params
    names = fits[0]["var_names"]
    same = [f for f in fits if f["var_names"] == names and f.get("covar") is not None]
    covar = correl = None
    if same:
        try:
            info = sum(np.linalg.inv(np.asarray(f["covar"], dtype=float)) for f in same)
            c = np.linalg.inv(np.asarray(info))
            d = np.sqrt(np.clip(np.diag(c), 0.0, None))
            with np.errstate(divide="ignore", invalid="ignore"):
                r = c / np.outer(d, d)
            covar = c.tolist()
            r = np.nan_to_num(r)
            correl = {
                a: {b: float(r[i, j]) for j, b in enumerate(names) if j != i}
                for i, a in enumerate(names)
            }
        except (np.linalg.LinAlgError, ValueError):
            covar = correl = None
    out["covar"], out["correl"] = covar, correl
    for k in ("chisqr", "ndata", "nfev"):
        tot = [_num(f.get(k)) for f in fits]
        out[k] = float(np.nansum(tot)) if k == "chisqr" else int(np.nansum(tot))
    for k in ("aic", "bic"):
        out[k] = float(np.nansum([_num(f.get(k)) for f in fits]))
    dof = out["ndata"] - len(fits) * int(fits[0].get("nvarys") or 0)
    out["redchi"] = out["chisqr"] / dof if dof > 0 else None
    out["condition"] = float(np.nanmax([_num(f.get("condition")) for f in fits]))
    out["success"] = all(bool(f.get("success")) for f in fits)
    out["message"] = f"{len(fits)} window fits pooled (weights by window size, see pool)"
    notes = Counter(n for f in fits for n in f.get("notes") or [])
    out["notes"] = [f"{n} ({c} of {len(fits)} windows)" for n, c in notes.items()]
    return out


def pooled_document(docs: list[dict[str, Any]], *, reason: str) -> dict[str, Any]:
    """The whole-record document from the windows' :meth:`TangentialAnalysis.to_dict`
    documents (see the module docstring)."""
    if not docs:
        raise ValueError("no window to pool")
    n = len(docs)
    out: dict[str, Any] = {}
    first = docs[0]
    sizes = [d.get("n_cycles") for d in docs]
    for k, v0 in first.items():
        if k.endswith("_stderr"):
            continue
        if k == "fit":
            out[k] = _pool_fit([d[k] for d in docs if d.get(k)])
        elif k == "loop_area_recorded":
            out[k] = float(np.nansum([_num(d.get(k)) for d in docs]))
            errs = [_num(d.get(f"{k}_stderr")) for d in docs]
            out[f"{k}_stderr"] = float(math.sqrt(np.nansum(np.square(errs))))
        elif k in _SUMMED:
            out[k] = int(sum(int(d.get(k) or 0) for d in docs))
        elif f"{k}_stderr" in first:
            m, e, _ = pool([d.get(k) for d in docs], [d.get(f"{k}_stderr") for d in docs], sizes)
            out[k] = None if math.isnan(m) else m
            out[f"{k}_stderr"] = None if math.isnan(e) else e
        elif k in _NO_POOL or isinstance(v0, (str, bool)) or v0 is None:
            out[k] = v0
        elif isinstance(v0, (int, float)):
            vals = [_num(d.get(k)) for d in docs]
            out[k] = float(np.nanmean(vals)) if np.any(np.isfinite(vals)) else None
        else:
            out[k] = v0
    # the regime and its reason: the most frequent
    regimes = Counter(str(d.get("regime")) for d in docs)
    name, count = regimes.most_common(1)[0]
    out["regime"] = name
    example = next(d for d in docs if str(d.get("regime")) == name)
    out["regime_reason"] = f"{count} of {n} windows: {example.get('regime_reason', '')}"
    out["ac_times_amplitude_source"] = example.get("ac_times_amplitude_source")
    # identifiability: flags over all windows, numbers of the pooled fit
    ident = dict(first.get("identifiable") or {})
    for key in ("h0", "ac", "h0_ac"):
        if key in ident:
            ident[key] = all(bool((d.get("identifiable") or {}).get(key)) for d in docs)
    for key in ("h0", "ac", "h0_ac"):
        v, e = out.get(key), out.get(f"{key}_stderr")
        if f"rel_stderr_{key}" in ident and isinstance(v, float) and isinstance(e, float) and v:
            ident[f"rel_stderr_{key}"] = abs(e / v)
    n_id = sum(bool((d.get("identifiable") or {}).get("h0")) for d in docs)
    ident["message"] = (
        f"h0 and ac are identified in {n_id} of {n} windows (pooled values); "
        f"window message: {ident.get('message', '')}"
    )
    out["identifiable"] = ident
    # warnings: distinct, counted
    out["warnings"] = _counted_warnings(docs)
    sticks = [d["stick_slip"] for d in docs if isinstance(d.get("stick_slip"), dict)]
    template = {
        "n_reversals": None,
        "reversals_with_stick": None,
        "stick_duration": None,
        "breakaway_force": None,
        "breakaway_force_stderr": None,
        "velocity_threshold": None,
        "smooth_turn_dwell": None,
        "reversals_with_dwell": None,
        "units": {
            "stick_duration": "s",
            "breakaway_force": "N",
            "breakaway_force_stderr": "N",
            "velocity_threshold": "m/s",
            "smooth_turn_dwell": "s",
        },
    }
    if sticks:
        st = dict(sticks[0])
        for k in template:
            if k != "units":
                vals = [_num(s.get(k)) for s in sticks]
                st[k] = float(np.nanmean(vals)) if np.any(np.isfinite(vals)) else None
        for k in ("n_reversals", "reversals_with_stick", "reversals_with_dwell"):
            # over the windows that counted them (streamed windows below gross sliding count
            # their reversals but do not search them for sticks: null when none did)
            vals = [_num(s.get(k)) for s in sticks]
            st[k] = float(np.nansum(vals)) if np.any(np.isfinite(vals)) else None
        out["stick_slip"] = st
    else:
        out["stick_slip"] = template
    units = dict(first.get("units") or {})
    for d in docs:
        for k, u in (d.get("units") or {}).items():
            units.setdefault(k, u)
    out["units"] = units
    out["streamed"] = True
    out["streamed_reason"] = reason
    return out


def _counted_warnings(docs: list[dict[str, Any]]) -> list[str]:
    warns = Counter(w for d in docs for w in d.get("warnings") or [])
    return [f"{w} ({c} of {len(docs)} windows)" for w, c in warns.items()]


#: normal-contact keys summed over the windows
_NORMAL_SUMMED = ("n_cycles", "n_discarded")


def pooled_normal_document(docs: list[dict[str, Any]], *, reason: str) -> dict[str, Any]:
    """The whole-record document of a normal-contact recording from its windows'
    :meth:`NormalAnalysis.to_dict` documents, with the whole-file analysis' keys: ``E_d``
    (and any quantity with a ``*_stderr``) pooled by :func:`pool`; counts (``n_cycles``,
    ``n_discarded``) summed; other numbers (ψ, ψ_KV, k_tan, k_sec, the b coefficients, the
    cycle scatter, ...) and the polynomials (coefficient by coefficient) averaged over the
    windows; flags true when true in any window; texts from the first window; warnings each
    once with the number of windows that gave it."""
    if not docs:
        raise ValueError("no window to pool")
    first = docs[0]
    out: dict[str, Any] = {}
    sizes = [d.get("n_cycles") for d in docs]
    for k, v0 in first.items():
        if k.endswith("_stderr") or k in ("warnings", "units"):
            continue
        vals = [d.get(k) for d in docs]
        if k in _NORMAL_SUMMED:
            out[k] = int(sum(int(_num(v)) if math.isfinite(_num(v)) else 0 for v in vals))
        elif f"{k}_stderr" in first:
            m, e, _ = pool(vals, [d.get(f"{k}_stderr") for d in docs], sizes)
            out[k] = None if math.isnan(m) else m
            out[f"{k}_stderr"] = None if math.isnan(e) else e
        elif isinstance(v0, bool):
            out[k] = any(bool(v) for v in vals)
        elif isinstance(v0, (int, float)):
            num = [_num(v) for v in vals]
            mean = float(np.nanmean(num)) if np.any(np.isfinite(num)) else None
            out[k] = round(mean) if isinstance(v0, int) and mean is not None else mean
        elif isinstance(v0, list) and all(isinstance(c, (int, float)) for c in v0):
            same = [np.asarray(v, dtype=float) for v in vals if isinstance(v, list)]
            same = [a for a in same if a.shape == (len(v0),)]
            out[k] = np.mean(same, axis=0).tolist() if same else v0
        else:
            out[k] = v0
    out["warnings"] = _counted_warnings(docs)
    units: dict[str, str] = {}
    for d in docs:
        for k, u in (d.get("units") or {}).items():
            units.setdefault(k, u)
    out["units"] = units
    out["streamed"] = True
    out["streamed_reason"] = reason
    return out


__all__ = ["STREAM_ABOVE", "pool", "pooled_document", "pooled_normal_document"]
