"""Scores of predicted joint forces against measured ones: SNR, NRMSE, RRSE, TRAC and the
error of the energy dissipated per cycle.

Definitions (``F`` measured, ``F̂`` predicted, sums over the compared samples):

- **SNR** [dB] ``= 10 log10(Σ F² / Σ (F − F̂)²)``: the signal-to-error ratio with which
  D. Coble, L. Cao, A. Downey, J. Ricles, *Physics-informed machine learning for dry
  friction and backlash modeling in structural control systems* (2024) score friction
  models (the metric of the friction-damper data set's README).
- **NRMSE** ``= sqrt(Σ (F − F̂)² / N) / (max F − min F)``: the RMS error over the measured
  force's range (Coble et al. 2024, as above).
- **RRSE** ``= sqrt(Σ (F − F̂)² / Σ (F − mean F)²)``: the root relative squared error,
  the error relative to predicting the mean (I. H. Witten, E. Frank, M. A. Hall, *Data
  Mining*, 3rd ed., Morgan Kaufmann 2011, §5.8); 0 is perfect, 1 no better than a constant.
- **TRAC** ``= (Σ F F̂)² / (Σ F² · Σ F̂²)``: the time-response assurance criterion, the
  modal assurance criterion's form (R. J. Allemang, *The modal assurance criterion —
  twenty years of use and abuse*, Sound and Vibration 37 (2003)) applied to two time
  histories, as joint models' responses are compared in R. M. Lacayo et al., *Nonlinear
  modeling of structures with bolted joints: a comparison of two approaches based on a
  time-domain and frequency-domain solver*, MSSP 114 (2019); 1 for proportional histories
  (it is blind to a scale error, which SNR and NRMSE see).
- **Energy per cycle error** ``= (Σ_k Ê_k − Σ_k E_k) / Σ_k E_k`` where ``E_k = ∫ F dx``
  (trapezoid rule) over cycle k, the cycles running from one maximum of ``x`` to the next
  (maxima found with the hysteresis threshold of :mod:`contactlab.reversals`, a band of a
  quarter of the displacement's half range about its mid-range), and ``Ê_k`` the same
  integral of the prediction over the same samples: the relative error of the energy the
  joint dissipates per cycle (Masing loop area, :mod:`contactlab.masing`), signed (positive:
  the model dissipates too much).

Pooled scores (``record = "pooled"``) apply the same sums to all records' compared samples
together (SNR, NRMSE, RRSE, TRAC on the concatenation; the range and mean of the pooled
force), the way the friction-damper data's README quotes its baseline's pooled figures.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .._arrays import as_1d
from ..errors import ContactLabError, InputError
from ..reversals import excursions
from .records import JointRecord, as_records

#: the scores of each row, in table order, with their units
METRICS = {
    "snr_db": "dB",
    "nrmse": "",
    "rrse": "",
    "trac": "",
    "energy_error": "",
}


def _pair(F: Any, Fhat: Any) -> tuple[np.ndarray, np.ndarray]:
    a = as_1d(F, "F (measured)")
    b = as_1d(Fhat, "F (predicted)")
    if a.size != b.size:
        raise InputError(f"measured F has {a.size} samples, the prediction {b.size}")
    return a, b


def snr_db(F: Any, Fhat: Any) -> float:
    """Signal-to-error ratio ``10 log10(Σ F² / Σ (F − F̂)²)`` in dB (inf for a perfect
    prediction).

    Examples
    --------
    >>> snr_db([1.0, -1.0, 1.0, -1.0], [0.9, -0.9, 0.9, -0.9])
    20.0
    """
    a, b = _pair(F, Fhat)
    e = float(np.sum((a - b) ** 2))
    s = float(np.sum(a**2))
    if e == 0:
        return math.inf
    if s == 0:
        return -math.inf
    return round(10.0 * math.log10(s / e), 12)


def nrmse(F: Any, Fhat: Any) -> float:
    """RMS error over the measured force's range ``max F − min F``.

    Examples
    --------
    >>> nrmse([1.0, -1.0, 1.0, -1.0], [0.9, -0.9, 0.9, -0.9])
    0.05
    """
    a, b = _pair(F, Fhat)
    rng = float(np.max(a) - np.min(a))
    if rng == 0:
        raise InputError("NRMSE: the measured force is constant (its range is 0)")
    return round(float(np.sqrt(np.mean((a - b) ** 2))) / rng, 14)


def rrse(F: Any, Fhat: Any) -> float:
    """Root relative squared error ``sqrt(Σ (F − F̂)² / Σ (F − mean F)²)``.

    Examples
    --------
    >>> rrse([1.0, -1.0, 1.0, -1.0], [0.9, -0.9, 0.9, -0.9])
    0.1
    """
    a, b = _pair(F, Fhat)
    d = float(np.sum((a - np.mean(a)) ** 2))
    if d == 0:
        raise InputError("RRSE: the measured force is constant")
    return round(math.sqrt(float(np.sum((a - b) ** 2)) / d), 14)


def trac(F: Any, Fhat: Any) -> float:
    """Time-response assurance criterion ``(Σ F F̂)² / (Σ F² Σ F̂²)`` (1: proportional
    histories, 0: orthogonal ones).

    Examples
    --------
    >>> trac([1.0, 0.0], [1.0, 1.0])
    0.5
    """
    a, b = _pair(F, Fhat)
    d = float(np.sum(a**2)) * float(np.sum(b**2))
    if d == 0:
        return math.nan if float(np.sum(a**2)) == float(np.sum(b**2)) == 0 else 0.0
    return round(float(np.dot(a, b)) ** 2 / d, 14)


def cycle_bounds(x: Any, *, mask: np.ndarray | None = None) -> np.ndarray:
    """Sample indices of the successive maxima of ``x`` that bound whole cycles (each cycle
    runs from one to the next); with ``mask``, only cycles whose samples are all selected.

    Maxima are the extremes of the excursions above a band of a quarter of the half range
    about the mid-range (:func:`contactlab.reversals.excursions`), so noise never makes a
    cycle.
    """
    xa = as_1d(x, "x")
    lo, hi = float(np.min(xa)), float(np.max(xa))
    if not hi > lo:
        return np.zeros(0, dtype=np.int64)
    ex = excursions(xa, 0.5 * (lo + hi), 0.25 * 0.5 * (hi - lo))
    peaks = np.asarray(ex.extreme[(ex.sign > 0) & ex.returned], dtype=np.int64)
    if mask is None or peaks.size < 2:
        return peaks
    m = np.asarray(mask, bool)
    # a cycle [p_k, p_k+1] counts when every sample in it is selected
    bad = np.concatenate([[0], np.cumsum(~m)])
    keep = [k for k in range(peaks.size - 1) if bad[peaks[k + 1] + 1] - bad[peaks[k]] == 0]
    if not keep:
        return np.zeros(0, dtype=np.int64)
    # consecutive kept cycles share bounds; separate runs are joined by the caller's pairs
    return np.asarray(sorted({int(peaks[k]) for k in keep} | {int(peaks[k + 1]) for k in keep}))


def cycle_energies(x: Any, F: Any, bounds: np.ndarray | None = None) -> np.ndarray:
    """``∫ F dx`` (trapezoid rule) over each cycle between successive ``bounds`` (default
    :func:`cycle_bounds` of ``x``) [J for N and m].

    Examples
    --------
    A rectangle loop of force ±2 N over a stroke of ±0.5 m: 4·2·0.5 = 4 J a cycle.

    >>> import numpy as np
    >>> x = np.array([0.5, 0.5, -0.5, -0.5, 0.5, 0.5, -0.5, -0.5, 0.5])
    >>> F = np.array([2.0, -2.0, -2.0, 2.0, 2.0, -2.0, -2.0, 2.0, 2.0])
    >>> cycle_energies(x, F, np.array([0, 4, 8])).tolist()
    [4.0, 4.0]
    """
    xa = as_1d(x, "x")
    Fa = as_1d(F, "F")
    if xa.size != Fa.size:
        raise InputError(f"x has {xa.size} samples, F {Fa.size}")
    b = cycle_bounds(xa) if bounds is None else np.asarray(bounds, dtype=np.int64)
    if b.size < 2:
        return np.zeros(0)
    work = np.concatenate([[0.0], np.cumsum(0.5 * (Fa[1:] + Fa[:-1]) * np.diff(xa))])
    return work[b[1:]] - work[b[:-1]]


def _cycle_pairs(bounds: np.ndarray, x: np.ndarray, mask: np.ndarray | None) -> np.ndarray:
    """(start, stop) of whole selected cycles from :func:`cycle_bounds`."""
    if bounds.size < 2:
        return np.zeros((0, 2), dtype=np.int64)
    pairs = np.stack([bounds[:-1], bounds[1:]], axis=1)
    if mask is None:
        return pairs
    bad = np.concatenate([[0], np.cumsum(~np.asarray(mask, bool))])
    ok = bad[pairs[:, 1] + 1] - bad[pairs[:, 0]] == 0
    # a pair spanning a gap between separate selected runs holds unselected samples: dropped
    return pairs[ok]


def energy_per_cycle_error(x: Any, F: Any, Fhat: Any, *, mask: Any = None) -> dict[str, Any]:
    """Energy dissipated per cycle, measured and predicted, and the relative error of their
    totals over the whole cycles of ``x`` (within ``mask`` when given).

    Returns
    -------
    dict
        ``energy_per_cycle`` (measured mean, J), ``energy_per_cycle_model``, ``energy_error``
        ``(ΣÊ − ΣE)/ΣE`` and ``n_cycles``; the energies and the error are None (with a
        ``note``) when there is no whole cycle or the measured loops dissipate nothing.
    """
    xa = as_1d(x, "x")
    a, b = _pair(F, Fhat)
    m = None if mask is None else np.asarray(mask, bool)
    pairs = _cycle_pairs(cycle_bounds(xa, mask=m), xa, m)
    out: dict[str, Any] = {"energy_per_cycle": None, "energy_per_cycle_model": None,
                           "energy_error": None, "n_cycles": len(pairs)}  # fmt: skip
    if not len(pairs):
        out["note"] = "no whole cycle of x (maximum to maximum) among the compared samples"
        return out
    wa = np.concatenate([[0.0], np.cumsum(0.5 * (a[1:] + a[:-1]) * np.diff(xa))])
    wb = np.concatenate([[0.0], np.cumsum(0.5 * (b[1:] + b[:-1]) * np.diff(xa))])
    Ea = wa[pairs[:, 1]] - wa[pairs[:, 0]]
    Eb = wb[pairs[:, 1]] - wb[pairs[:, 0]]
    out["energy_per_cycle"] = float(np.mean(Ea))
    out["energy_per_cycle_model"] = float(np.mean(Eb))
    total = float(np.sum(Ea))
    if not abs(total) > 0:
        out["note"] = "the measured cycles dissipate no energy"
        return out
    out["energy_error"] = round((float(np.sum(Eb)) - total) / abs(total), 14)
    out["_sums"] = (total, float(np.sum(Eb)))
    return out


def scores(F: Any, Fhat: Any, x: Any = None, *, mask: Any = None) -> dict[str, Any]:
    """Every score of one prediction (on the samples of ``mask`` when given); the energy
    scores need ``x``."""
    a, b = _pair(F, Fhat)
    sel = slice(None) if mask is None else np.asarray(mask, bool)
    fa, fb = a[sel], b[sel]
    out: dict[str, Any] = {
        "n": int(fa.size),
        "snr_db": snr_db(fa, fb),
        "nrmse": nrmse(fa, fb),
        "rrse": rrse(fa, fb),
        "trac": trac(fa, fb),
    }
    if x is not None:
        out.update(energy_per_cycle_error(x, a, b, mask=mask))
    return out


@dataclass
class Comparison:
    """The table of :func:`compare`: one row per (model, record) and a ``pooled`` row per
    model. Rows are dicts with ``model``, ``record``, ``n`` and the scores of
    :data:`METRICS` (None where not computed, with ``error`` or ``note`` saying why)."""

    rows: list[dict[str, Any]]
    models: list[str]
    records: list[str]
    units: dict[str, str] = field(
        default_factory=lambda: dict(METRICS, energy_per_cycle="J", energy_per_cycle_model="J")
    )

    def row(self, model: str, record: str = "pooled") -> dict[str, Any]:
        for r in self.rows:
            if r["model"] == model and r["record"] == record:
                return r
        raise InputError(f"no row for model {model!r} and record {record!r}")

    def pooled(self, model: str) -> dict[str, Any]:
        return self.row(model, "pooled")

    def best(self, metric: str = "snr_db") -> str:
        """The model with the best pooled ``metric`` (highest SNR or TRAC, lowest NRMSE,
        RRSE or |energy error|)."""
        if metric not in METRICS:
            raise InputError(f"unknown metric {metric!r}; one of {', '.join(METRICS)}")
        sign = 1.0 if metric in ("snr_db", "trac") else -1.0
        vals = {}
        for m in self.models:
            v = self.pooled(m).get(metric)
            if v is not None and not (isinstance(v, float) and math.isnan(v)):
                vals[m] = sign * (abs(v) if metric == "energy_error" else v)
        if not vals:
            raise InputError(f"no model has a pooled {metric}")
        return max(vals, key=vals.__getitem__)

    def to_dict(self) -> dict[str, Any]:
        from ..fitting import json_number

        rows = []
        for r in self.rows:
            rows.append({k: (json_number(v) if isinstance(v, float) else v)
                         for k, v in r.items() if not k.startswith("_")})  # fmt: skip
        return {"rows": rows, "models": list(self.models), "records": list(self.records),
                "units": dict(self.units)}  # fmt: skip

    def to_text(self, metrics: Sequence[str] = tuple(METRICS)) -> str:
        """A plain-text table (one line per row)."""
        head = ["model", "record", *metrics]
        lines = []
        for r in self.rows:
            cells = [str(r["model"]), str(r["record"])]
            for k in metrics:
                v = r.get(k)
                cells.append("-" if v is None else (f"{v:.2f}" if k == "snr_db" else f"{v:.4f}"))
            if r.get("error"):
                cells.append(f"error: {r['error']}")
            lines.append(cells)
        body = [c[: len(head)] for c in lines]
        widths = [max(len(str(c)) for c in col) for col in zip(head, *body, strict=True)]
        fmt = "  ".join(f"{{:<{w}}}" for w in widths)
        out = [fmt.format(*head)]
        for cells in lines:
            out.append(fmt.format(*cells[: len(head)]) + ("  " + cells[-1] if len(cells) >
                                                            len(head) else ""))  # fmt: skip
        return "\n".join(out)


def _predictor(model: Any, name: str) -> Callable[[JointRecord, int], np.ndarray]:
    """``predict(record, index)`` of a model given in any of the accepted forms."""
    if hasattr(model, "force"):
        return lambda rec, i: np.asarray(model.force(rec.t, rec.x), dtype=float)
    if isinstance(model, Mapping):

        def by_name(rec: JointRecord, i: int) -> np.ndarray:
            if rec.name not in model:
                raise InputError(f"model {name!r} has no prediction for record {rec.name!r}")
            return np.asarray(model[rec.name], dtype=float).reshape(-1)

        return by_name
    if isinstance(model, Sequence) and not isinstance(model, (str, bytes)):
        seq = list(model)
        return lambda rec, i: np.asarray(seq[i], dtype=float).reshape(-1)
    if callable(model):
        return lambda rec, i: np.asarray(model(rec.t, rec.x), dtype=float)
    raise InputError(
        f"model {name!r}: expected an object with .force(t, x), a callable, or predictions "
        f"(a list per record or a mapping by record name), got {type(model).__name__}"
    )


def _model_name(m: Any, i: int) -> str:
    for attr in ("name", "law_name"):
        v = getattr(m, attr, None)
        if isinstance(v, str) and v:
            return v
    return f"model {i}"


def compare(models: Any, records: Any, *, fs: float | None = None) -> Comparison:
    """Score models' force predictions against measured records.

    Parameters
    ----------
    models : mapping name -> model, or a sequence of models
        A model is an object with ``.force(t, x)`` (a fitted joint, a law), a callable
        ``(t, x) -> F``, or precomputed predictions: a list with one array per record, or a
        mapping ``record name -> array``.
    records : record or sequence of records
        Anything :func:`contactlab.joints.records.as_record` accepts; each needs ``F``. A
        record's ``mask`` selects the samples scored (the model still runs over all of them).
    fs : float, optional
        Sampling rate of records given without a time axis.

    Returns
    -------
    Comparison
        Per-record and pooled rows. A model that fails on a record gets a row with
        ``error`` (the message) and no scores instead of raising.

    Examples
    --------
    >>> import numpy as np
    >>> t = np.linspace(0.0, 2.0, 401)
    >>> x = np.sin(2 * np.pi * t)
    >>> F = np.cos(2 * np.pi * t)
    >>> tab = compare({"half": [0.5 * F]}, [(t, x, F)])
    >>> round(tab.pooled("half")["snr_db"], 3), round(tab.pooled("half")["trac"], 12)
    (6.021, 1.0)
    """
    recs = as_records(records, fs=fs)
    for r in recs:
        r.require_force()
    if isinstance(models, Mapping):
        named = [(str(k), v) for k, v in models.items()]
    elif isinstance(models, Sequence) and not isinstance(models, (str, bytes)):
        named = [(_model_name(m, i), m) for i, m in enumerate(models)]
    else:
        named = [(_model_name(models, 0), models)]
    seen = set()
    for n, _ in named:
        if n in seen:
            raise InputError(f"two models are named {n!r}; give them in a mapping by name")
        seen.add(n)
    rows: list[dict[str, Any]] = []
    for name, model in named:
        predict = _predictor(model, name)
        pooled_F, pooled_P, e_meas, e_model, ncyc = [], [], 0.0, 0.0, 0
        for i, rec in enumerate(recs):
            row: dict[str, Any] = {"model": name, "record": rec.name}
            try:
                P = predict(rec, i)
                if P.shape != rec.x.shape:
                    raise InputError(f"the prediction has {P.size} samples, the record {rec.n}")
                if not np.all(np.isfinite(P)):
                    k = int(np.argmax(~np.isfinite(P)))
                    raise InputError(f"the prediction is not finite at sample {k}")
                row.update(scores(rec.F, P, rec.x, mask=rec.mask))
            except ContactLabError as exc:
                row.update({k: None for k in METRICS}, error=str(exc))
                rows.append(row)
                continue
            sel = slice(None) if rec.mask is None else rec.mask
            pooled_F.append(rec.F[sel])
            pooled_P.append(P[sel])
            if "_sums" in row:
                s_meas, s_model = row.pop("_sums")
                e_meas += s_meas
                e_model += s_model
                ncyc += row["n_cycles"]
            rows.append(row)
        pooled: dict[str, Any] = {"model": name, "record": "pooled"}
        if pooled_F:
            pooled.update(scores(np.concatenate(pooled_F), np.concatenate(pooled_P)))
            pooled["n_records"] = len(pooled_F)
            pooled["n_cycles"] = ncyc
            pooled["energy_error"] = (round((e_model - e_meas) / abs(e_meas), 14)
                                      if abs(e_meas) > 0 else None)  # fmt: skip
        else:
            pooled.update({k: None for k in METRICS}, error="no record could be predicted")
        if len(pooled_F) < len(recs):
            pooled["note"] = f"{len(recs) - len(pooled_F)} record(s) failed and are not pooled"
        rows.append(pooled)
    return Comparison(rows, [n for n, _ in named], [r.name for r in recs])
