"""Calibration of the normal-contact naming rules on ``chain_normal`` (stop 45).

Each seed draws one single-tone chain from rest (``benches/chain_normal.py``: actuator,
sensor filters, hum, jitter, ADC) over the range of the normal-contact issue: fs 1, 2, 5 or
10 kHz, drive 1-50 Hz (log-uniform, at least 20 samples a cycle), 5-50 cycles, white noise
0.5-2 % of each channel's range; then the clean record and one record per effect at a small
visible size:

- ``stiffness_nonlinearity``: κ1-type law (``a2``), relative change 0.012-0.05 at the
  amplitude, either sign;
- ``creep_drift``: ``D`` 0.02-0.15 of the displacement amplitude, ``τ_c`` 0.05-0.5 of the
  record's duration, either sign;
- ``asymmetric_branches``: ``a`` 0.15-0.35, either sign.

For every record it keeps what ``diagnose`` names, whether the misfit is flagged, and the
verdict on each candidate at the first step (held-out gain in σ², t, ΔBIC, reason) and
every verdict of the search's rules (``judged``: gain, floor, t), so that the rules can be
read off one run. ``--drift``: a bowed drift of the displacement sensor (0.2-2 % of its
range) on half the chains; ``--small``: creeps of 0.5-5 % and asymmetries of 0.2-0.6;
``--no-strong``: rule 2 without the normal family's large-gain route (the "before").
Stop 45 tuned on seeds 45000-45007 and 45100-45116 and reported on 46000 on
(``benches/results/normal_strong_gain_stop45.md``).

    nice .venv/bin/python benches/eval_normal_calibrate.py --seeds 0-19 --base 45000 \
        --out /tmp/cal.json
"""

from __future__ import annotations

import argparse
import json
import sys
import time
import warnings
from collections import defaultdict
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from chain_normal import chain_record

EFFECTS = ("stiffness_nonlinearity", "creep_drift", "asymmetric_branches")


def factors(rng: np.random.Generator) -> dict:
    """One chain's settings over the issue's range."""
    f = float(np.exp(rng.uniform(np.log(1.0), np.log(50.0))))
    rates = [fs for fs in (1000.0, 2000.0, 5000.0, 10000.0) if fs / f >= 20.0]
    return {
        "fs": float(rng.choice(rates)),
        "f": f,
        "cycles": int(rng.integers(5, 51)),
        "ratio": float(rng.uniform(0.2, 0.8)),
        "noise_p": float(rng.uniform(0.005, 0.02)),
        "noise_d": float(rng.uniform(0.005, 0.02)),
        "bits": int(rng.choice([14, 16])),
        "psi": float(rng.uniform(0.05, 0.3)),
    }


_JUDGED: list = []


def _instrument() -> None:
    """Keep every verdict of the search's rules (the candidate, its gain, t, the
    proportional t and the floor it met) in ``_JUDGED``."""
    from contactlab.diagnose import search, select

    if getattr(search.judge, "_kept", False):
        return
    orig = select.judge

    def judge(name, current, cand, sigma, z, min_gain, d=None, rel_scale=1.0, **kw):
        v = orig(name, current, cand, sigma, z, min_gain, d, rel_scale, **kw)
        pt = float(select.proportional_t(current, cand, d)) if d is not None else None
        _JUDGED.append({"name": name, "effects": list(current.effects), "gain": v.gain,
                        "t": v.t_stat, "pt": pt, "floor": min_gain, "ok": v.accepted,
                        "reason": v.reason,
                        "params": {k: float(x) for k, x in cand.full.params.items()}})  # fmt: skip
        return v

    judge._kept = True  # type: ignore[attr-defined]
    search.judge = judge


def diagnose(t, p, d):
    import contactlab

    _instrument()
    _JUDGED.clear()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        r = contactlab.diagnose({"t": t, "p": p, "delta": d}, "normal")
    rd = r.to_dict()
    first = {}
    if len(r.steps) > 0:
        for v in r.steps[0].candidates:
            first[v.name] = {"gain": v.gain, "t": v.t_stat, "dbic": v.delta_bic,
                             "ok": v.accepted, "reason": v.reason}  # fmt: skip
    bounds = {b.to_dict()["effect"]: b.to_dict().get("detectable_above") for b in r.not_detected}
    un = rd.get("unexplained", {})
    return {
        "named": list(r.effect_names),
        "flagged": bool(un.get("flagged", False)),
        "first": first,
        "bounds": bounds,
        "judged": list(_JUDGED),
    }


def draw(rng, effect, fac, small=False):
    """An effect's size (``small``: creeps of 0.005-0.05 of the amplitude and loss
    asymmetries of 0.2-0.6 instead)."""
    if effect == "stiffness_nonlinearity":
        fac["law"] = "a2"
        return float(rng.uniform(0.012, 0.05)) * float(rng.choice([-1, 1]))
    if effect == "creep_drift":
        fac["tau_frac"] = float(np.exp(rng.uniform(np.log(0.05), np.log(0.5))))
        lo, hi = (0.005, 0.05) if small else (0.02, 0.15)
        return float(rng.uniform(lo, hi)) * float(rng.choice([-1, 1]))
    lo, hi = (0.2, 0.6) if small else (0.15, 0.35)
    return float(rng.uniform(lo, hi)) * float(rng.choice([-1, 1]))


def run(seed: int, only: str | None = None, drift: bool = False, small: bool = False) -> dict:
    rng = np.random.default_rng(seed)
    fac = factors(rng)
    if drift:  # a slow drift of the displacement sensor on half the chains (own stream)
        rd = np.random.default_rng(seed + 9000)
        if rd.uniform() < 0.5:
            fac["sensor_drift"] = float(rd.uniform(0.002, 0.02)) * float(rd.choice([-1, 1]))
            fac["sensor_bow"] = float(rd.uniform(-1, 1))
    out = {"seed": seed, "fac": dict(fac), "rows": {}}
    t0 = time.process_time()
    if only is None or "clean" in only.split(","):
        t, p, d, _ = chain_record(None, 0.0, fac, seed)
        out["rows"]["clean"] = {"size": 0.0, **diagnose(t, p, d)}
    for e in EFFECTS:
        f2 = dict(fac)
        size = draw(rng, e, f2, small)
        if only is not None and e not in only.split(","):
            continue
        if e == "creep_drift":
            T = min(f2["cycles"], max(5, int(150_000 * f2["f"] / f2["fs"]))) / f2["f"]
            f2["tau_c"] = f2["tau_frac"] * T
        t, p, d, _ = chain_record(e, size, f2, seed + 500)
        out["rows"][e] = {"size": size, "tau_frac": f2.get("tau_frac"), **diagnose(t, p, d)}
    out["cpu"] = time.process_time() - t0
    return out


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--seeds", default="0-3")
    ap.add_argument("--base", type=int, default=46000)
    ap.add_argument("--only", default=None, help="clean and/or effects, comma-separated")
    ap.add_argument("--out", default=None)
    ap.add_argument("--drift", action="store_true", help="sensor drift on half the chains")
    ap.add_argument("--small", action="store_true", help="smaller creeps, larger asymmetries")
    ap.add_argument("--no-strong", action="store_true", help="rule 2 without the large-gain route")
    a = ap.parse_args()
    if a.no_strong:
        from contactlab.diagnose.candidates_normal import NormalFamily

        NormalFamily.strong_gain = None
    lo, hi = (int(s) for s in a.seeds.split("-"))
    res = []
    tally: dict = defaultdict(lambda: defaultdict(int))
    for s in range(lo, hi + 1):
        r = run(a.base + s, a.only, a.drift, a.small)
        res.append(r)
        f = r["fac"]
        print(f"seed {a.base + s}: fs {f['fs']:.0f} f {f['f']:.2f} cyc {f['cycles']} noise p/d "
              f"{100 * f['noise_p']:.2f}/{100 * f['noise_d']:.2f} % ψ {f['psi']:.2f} "
              f"cpu {r['cpu']:.0f}s", flush=True)  # fmt: skip
        for e, v in r["rows"].items():
            best = max(v["first"].items(), key=lambda kv: kv[1]["gain"] or -1e9, default=None)
            note = f" best {best[0]} g {best[1]['gain']:.3g} t {best[1]['t']:.2f}" if best else ""
            print(f"   {e:24s} size {v['size']:+.3f} named {v['named']} "
                  f"flagged {v['flagged']}{note}", flush=True)  # fmt: skip
            if e == "clean":
                tally[e]["ok" if not v["named"] and not v["flagged"] else "alarm"] += 1
            else:
                tally[e]["exact" if v["named"] == [e] else "other"] += 1
        if a.out:
            Path(a.out).write_text(json.dumps(res, indent=1, default=str))
    print()
    for e, c in tally.items():
        print(f"{e:24s} " + " ".join(f"{k} {n}" for k, n in sorted(c.items())))


if __name__ == "__main__":
    main()
