"""What ``diagnose`` names on every measured recording in ../shared/data (issue 29, item 5).

For each record: the effects named with their parameters and plausibility argument, the
regime ``analyze`` and ``diagnose`` report, the final model's h0 against the plateau
``analyze`` finds (bar: within 5 %), the largest named delay as a share of the period
(bar: a few per cent) and whether two velocity-like terms were named together.

Records, read as the CLI reads them:

- friction_frame, 250 g and 450 g: ``--frame 3.0799,0.669,1191`` (force reconstructed from
  the displacements: a channel delay is refused);
- microtribometer: ``--force-sign -1`` (its force follows the opposite sign convention),
  resampled to its median step by the reader;
- friction_damper, harmonic tests (all 13, or those given): t = arange(N)/1024.

    python benches/eval_measured_diagnose.py [frame] [tribo] [damper[:i,j,...]]

Prints one JSON line per record, then a table.
"""

from __future__ import annotations

import json
import sys
import time
from pathlib import Path

import numpy as np

import contactlab
from contactlab.io import Recording

DATA = Path(__file__).resolve().parents[1].parent / "shared" / "data"
VELOCITY = {"channel_delay", "viscous_damping", "stribeck", "inertia"}


def frame_records() -> list[tuple[str, object, int]]:
    from contactlab.tangential import read_frame

    out = []
    for load in ("250", "450"):
        path = DATA / "friction_frame" / f"frame_disc{load}g.csv"
        rec = read_frame(str(path), 3.0799, 0.669, 1191.0).recording(str(path))
        out.append((f"frame_{load}g", rec, 1))
    return out


def tribo_records() -> list[tuple[str, object, int]]:
    """The tribometer as the command line reads it: ``--resample`` (its 5 and 9-10 ms
    steps brought to the median step), units µN and mm to SI, the whole record."""
    from contactlab.io import read_recording

    path = DATA / "microtribometer" / "test_data_2.txt"
    rec = read_recording(str(path), kind="tangential", resample=True)
    return [("microtribometer", rec, -1)]


def damper_records(which: list[int]) -> list[tuple[str, object, int]]:
    out = []
    for i in which:
        x = np.load(DATA / "friction_damper" / f"harmonic_test{i}_x.npy").ravel()
        F = np.load(DATA / "friction_damper" / f"harmonic_test{i}_F.npy").ravel()
        t = np.arange(x.size) / 1024.0
        rec = Recording(t, {"x": x, "F": F}, {"x": "m", "F": "N"})
        out.append((f"damper_{i}", rec, 1))
    return out


def flipped(rec: object) -> object:
    ch = dict(rec.data)
    ch["F"] = -ch["F"]
    return Recording(rec.t, ch, dict(rec.units), rec.source, dict(rec.meta or {}))


def run(name: str, rec: object, sign: int) -> dict:
    t0 = time.perf_counter()
    an = contactlab.analyze_tangential(rec, force_sign=sign, warn=False)
    an_d = an.to_dict()
    try:
        rep = contactlab.diagnose(rec, force_sign=sign)
    except TypeError:  # before diagnose took force_sign
        rec = flipped(rec) if sign == -1 else rec
        rep = contactlab.diagnose(rec)
    doc = rep.to_dict()
    p = rep.final_model.params
    d = rep.prepared
    period = float(d.cycles.period_samples * d.dt) if d is not None else np.nan
    h0_an = an_d.get("h0")
    named = rep.effect_names
    out = {
        "record": name,
        "seconds": round(time.perf_counter() - t0, 1),
        "analyze_regime": an_d.get("regime"),
        "diagnose_regime": doc.get("regime", {}).get("regime")
        if isinstance(doc.get("regime"), dict)
        else doc.get("regime"),
        "h0_analyze": h0_an,
        "h0_final": p.get("h0"),
        "h0_ratio": (p.get("h0") / h0_an) if h0_an else None,
        "named": named,
        "effects": doc["effects"],
        "velocity_terms": sorted(VELOCITY & set(named)),
        "period": period,
        "tau_share": (abs(p["tau"]) / period if "channel_delay" in named and period > 0 else 0.0),
        "where": rep.where,
        "h0_check": doc.get("h0_check"),
    }
    u = rep.unexplained  # the misfit flag (issue 29, item 3)
    out["misfit"] = None if u is None else {
        "flagged": u.flagged,
        "T_over_threshold": u.statistic / u.threshold,
        "backbone_t": None if u.backbone is None else u.backbone["t"],
        "eiv_bias_rms": u.eiv_bias_rms,
        "input_noise": u.input_noise if hasattr(u, "input_noise") else None,
        "detectable_rms": u.detectable_rms,
        "rivals": [dict(r) for r in getattr(u, "rivals", ())],
        "calibrated": getattr(u, "calibrated", None),
        "patches": [dict(r) for r in getattr(u, "patches", ())],
        "flagged_before_calibration": bool(
            u.statistic > u.threshold
            or (u.backbone or {}).get("flagged")
            or getattr(u, "rivals", ())
        ),
        "sentence": u.sentence(),
        "flagged_white_null": _white_null_flag(rep),
    }  # fmt: skip
    return out


def _white_null_flag(rep: object) -> bool | None:
    """The misfit flag as the null before the input noise's spectrum was read would give it
    on the same final model: white input noise at the white estimate's level, no simulation
    on kept records, the tolerance from the white noise after the candidates' filter."""
    from contactlab.diagnose.detection import channel_noise, model_slope
    from contactlab.diagnose.eiv import eiv_bias
    from contactlab.diagnose.misfit import (
        BACKBONE_Z,
        BACKBONE_Z_CORRECTED,
        backbone_misfit,
        eiv_tolerance,
        unexplained_structure,
    )

    m, d = rep.final_model, rep.prepared
    if m is None or d is None:
        return None
    fam, p, eff = m.family, dict(m.params), tuple(m.effects)
    residual = d.y - np.asarray(fam.predict(p, eff, d), float)
    slope = model_slope(fam, p, d)
    noise = channel_noise(d, residual, slope=slope)
    bias = eiv_bias(fam, p, eff, d, coloured=False)
    tested = residual if bias is None else residual - bias
    tol = eiv_tolerance(slope, noise.input_seen, corrected=bias is not None)
    u = unexplained_structure(d, tested, rep.noise_rms, tolerance=tol)
    if u is None:
        return None
    flagged = u.flagged
    if getattr(fam, "kind", "") == "tangential" and "ac" in p:
        z = BACKBONE_Z_CORRECTED if not noise.input > 0 else BACKBONE_Z
        bb = backbone_misfit(d, residual, float(p["ac"]), rep.noise_rms, z=z)
        flagged = flagged or bool(bb and bb["flagged"])
    return bool(flagged)


def _flag(m: dict | None) -> str:
    """The misfit flag's verdict and T over its threshold."""
    if m is None:
        return "-"
    c = m.get("calibrated") or {}
    by = "+".join(c.get("by") or []) + ("+patch" if m.get("patches") else "")
    if m.get("rivals"):
        by += "+rival"
    before = "FLAG" if m.get("flagged_before_calibration") else "no"
    now = "FLAG" if m["flagged"] else "no"
    return f"{now} ({by or '-'}; before {before}) {m['T_over_threshold']:.2f}"


def main(argv: list[str]) -> None:
    want = argv or ["frame", "tribo", "damper"]
    recs = []
    for w in want:
        if w == "frame":
            recs += frame_records()
        elif w == "tribo":
            recs += tribo_records()
        elif w.startswith("damper"):
            ids = [int(k) for k in w.split(":")[1].split(",")] if ":" in w else list(range(13))
            recs += damper_records(ids)
    rows = []
    for name, rec, sign in recs:
        try:
            row = run(name, rec, sign)
        except Exception as exc:  # a record that fails is a row, not the end of the run
            row = {"record": name, "error": f"{type(exc).__name__}: {exc}"}
        rows.append(row)
        print(json.dumps(row, default=str), flush=True)
    print()
    print(f"{'record':<16}{'regime a/d':<30}{'h0 a':>9}{'h0 d':>9}{'ratio':>7}  misfit  named")
    for r in rows:
        if "error" in r:
            print(f"{r['record']:<16}ERROR {r['error'][:100]}")
            continue
        reg = f"{r['analyze_regime']}/{r['diagnose_regime']}"
        ratio = r["h0_ratio"]
        print(
            f"{r['record']:<16}{reg:<30}{r['h0_analyze'] or float('nan'):>9.4g}"
            f"{r['h0_final']:>9.4g}{ratio if ratio else float('nan'):>7.3f}  "
            f"{_flag(r.get('misfit')):<7} {', '.join(r['named']) or '-'}"
        )


if __name__ == "__main__":
    main(sys.argv[1:])
