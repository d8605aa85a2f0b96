"""Creep of the joint against drift of the displacement sensor near the stated bound (stop 47).

Each seed draws one single-tone chain of ``chain_normal`` from rest over the range of the
normal-contact issue (``eval_normal_calibrate.factors``: fs 1-10 kHz, 1-50 Hz at 20 samples
a cycle or more, 5-50 cycles, noise 0.5-2 % of range on both channels). ``diagnose`` states
the creep bound ``D`` at ``at.tau_c`` on the clean record; then

- ``creep``: the clean record with a creep ``factor · D (1 - exp(-t/τc))`` added to δ
  (either sign), ``τc`` the stated one times a factor log-uniform in ``--tau-span``
  (within the plausible range);
- ``drift``: the clean record with a drift of the displacement sensor of 0.2-2 % of δ's
  range over the record, straight or bowed (``u + bow (u² - u)``, bow uniform in -1..1),
  no creep.

For every record: what is named, and :func:`~contactlab.diagnose.effects.normal.creep_drift.
drift_test`'s χ² and z at each creep verdict (the last kept). ``--rule chi2`` runs the
former rule (refused at χ² < 0), ``--rule z`` the current one.

    nice .venv/bin/python benches/eval_normal_drift_creep.py --seeds 0-19 --base 5610000 \\
        --factor 1.0 --out /tmp/x.json
"""

from __future__ import annotations

import argparse
import json
import sys
import warnings
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from chain_normal import chain_record
from eval_normal_calibrate import factors

_LOG: list = []


def _hook() -> None:
    from contactlab.diagnose.effects.normal import creep_drift as cd

    if getattr(cd.drift_test, "_kept", False):
        return
    orig = cd.drift_test

    def drift_test(d, current, cand, tau_c):
        out = orig(d, current, cand, tau_c)
        _LOG.append([float(out[0]), float(out[1]), float(out[3]) / float(d.duration)])
        return out

    drift_test._kept = True  # type: ignore[attr-defined]
    cd.drift_test = drift_test


def diagnose(t, p, d):
    import contactlab

    _LOG.clear()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        r = contactlab.diagnose({"t": t, "p": p, "delta": d}, "normal")
    b = {x.to_dict()["effect"]: x.to_dict() for x in r.not_detected}.get("creep_drift", {})
    flagged = bool(r.to_dict().get("unexplained", {}).get("flagged", False))
    return list(r.effect_names), flagged, b, list(_LOG)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--seeds", default="0-3")
    ap.add_argument("--base", type=int, default=5610000)
    ap.add_argument("--factor", type=float, default=1.0)
    ap.add_argument("--tau-span", default="0.3,3.0", help="τc over the stated, log-uniform")
    ap.add_argument("--rule", choices=("chi2", "z"), default="z")
    ap.add_argument("--z", type=float, default=None, help="DRIFT_Z for --rule z")
    ap.add_argument("--no-drift", action="store_true", help="creep records only")
    ap.add_argument("--out", default=None)
    a = ap.parse_args()
    from contactlab.diagnose.effects.normal import creep_drift as cd

    if a.rule == "chi2":
        cd.DRIFT_Z = None
    elif a.z is not None:
        cd.DRIFT_Z = a.z
    _hook()
    tlo, thi = (float(x) for x in a.tau_span.split(","))
    lo, hi = (int(s) for s in a.seeds.split("-"))
    rows: list = []
    tally = {"clean_alarm": 0, "creep_named": 0, "creep_exact": 0, "creep_n": 0,
             "drift_creep": 0, "drift_alarm": 0, "drift_n": 0}  # fmt: skip
    for s in range(lo, hi + 1):
        seed = a.base + s
        rng = np.random.default_rng(seed)
        fac = factors(rng)
        t, p, d, _ = chain_record(None, 0.0, fac, seed)
        tt = np.asarray(t, float)
        u = (tt - tt[0]) / (tt[-1] - tt[0])
        cn, cf, b, _ = diagnose(t, p, d)
        tally["clean_alarm"] += bool(cn or cf)
        row = {"seed": seed, "fac": fac, "clean": cn, "clean_flagged": cf}
        D = b.get("detectable_above")
        if D is not None:
            period = 1.0 / fac["f"]
            dur = float(tt[-1] - tt[0])
            tc = float(b["at"]["tau_c"]) * float(np.exp(rng.uniform(np.log(tlo), np.log(thi))))
            tc = float(np.clip(tc, 0.3 * period, 0.95 * dur))
            sign = 1.0 if rng.uniform() < 0.5 else -1.0
            size = sign * a.factor * float(D)
            nm, fl, _, log = diagnose(t, p, d + size * -np.expm1(-(tt - tt[0]) / tc))
            tally["creep_n"] += 1
            tally["creep_named"] += "creep_drift" in nm
            tally["creep_exact"] += nm == ["creep_drift"]
            row["creep"] = {"size": size, "rel": b.get("relative_size"), "tau_c": tc,
                            "tau_frac": tc / dur, "named": nm, "flagged": fl,
                            "test": log}  # fmt: skip
        rd = np.random.default_rng(seed + 9000)
        sd = float(rd.uniform(0.002, 0.02)) * float(rd.choice([-1, 1]))
        bow = float(rd.uniform(-1, 1))
        dn, dfl, dlog = [], False, []
        if not a.no_drift:
            dn, dfl, _, dlog = diagnose(t, p, d + sd * np.ptp(d) * (u + bow * (u * u - u)))
        tally["drift_n"] += not a.no_drift
        tally["drift_creep"] += "creep_drift" in dn
        tally["drift_alarm"] += bool(dn or dfl)
        row["drift"] = {"frac": sd, "bow": bow, "named": dn, "flagged": dfl, "test": dlog}
        rows.append(row)
        c = row.get("creep", {})
        nan = float("nan")
        print(f"seed {seed}: fs {fac['fs']:.0f} f {fac['f']:.1f} cyc {fac['cycles']} noise "
              f"{100 * fac['noise_p']:.2f}/{100 * fac['noise_d']:.2f} %: clean {cn} {cf}; "
              f"creep rel {c.get('rel', nan):.3g} τ/T {c.get('tau_frac', nan):.2f}"
              f" -> {c.get('named')} {c.get('test')}; drift {100 * sd:+.2f} % bow {bow:+.2f} -> "
              f"{dn} {dlog}", flush=True)  # fmt: skip
        if a.out:
            Path(a.out).write_text(json.dumps(rows, indent=1, default=str))
    print(f"\nrule {a.rule} factor {a.factor}: " + ", ".join(f"{k} {v}" for k, v in tally.items()))


if __name__ == "__main__":
    main()
