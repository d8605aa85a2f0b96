"""The wrong names above the stated bound of issue 29 (stop 43), reproduced on the package's
rig simulator (``contactlab.synthetic.rig``, plain chain: white x noise, Butterworth
anti-alias filters, a start from rest) at the factors where they were seen:

- ``channel_delay`` → ``backlash``: x noise 1.5-1.6 % of the range, ac·A 2.4-2.7,
  12 cycles, 20-40 Hz; the delay at ``--mults`` times the bound its clean twin states;
- ``parallel_stiffness`` → ``normal_load``: x noise 1.5 % of the range, ac·A 3.7-5,
  8-35 cycles;
- ``displacement_offset`` → ``force_offset``: ac·A 0.3, 5 cycles;
- ``non_masing_scaling`` → ``asymmetry`` + ``non_masing_scaling``: ac·A 1.5, 8 cycles.

Per (case, seed): the clean twin is diagnosed (its names are false alarms, its stated bound
for the true effect), then the effect is hidden at each multiple of that bound (fresh noise,
same factors) and diagnosed. Printed per record: the named set, the misfit flag, the bound
the report states for the true effect (or why none), and the held-out gains of the true
effect and its look-alike at the step they were tried. The x noise is given as a share of
the displacement's range (the rig's ``x_noise`` is a share of the amplitude: twice that).

    nice .venv/bin/python benches/eval_confusions.py --base 90000 --n 4 --cases delay
"""

from __future__ import annotations

import argparse
import json
import math
import tempfile
from collections import defaultdict
from pathlib import Path
from typing import Any

import numpy as np

H0, AC = 40.0, 4.0e4

#: case → (true effect, the look-alike named instead, factor ranges)
CASES: dict[str, dict[str, Any]] = {
    "delay": {"effect": "channel_delay", "rival": ("backlash",), "acA": (2.4, 2.7),
              "cycles": (12, 12), "xn": (0.015, 0.016), "f": (20.0, 40.0)},
    "spring": {"effect": "parallel_stiffness", "rival": ("normal_load",), "acA": (3.7, 5.0),
               "cycles": (8, 35), "xn": (0.015, 0.015), "f": (2.0, 30.0)},
    "offset": {"effect": "displacement_offset", "rival": ("force_offset",), "acA": (0.3, 0.3),
               "cycles": (5, 5), "xn": (0.005, 0.02), "f": (2.0, 30.0)},
    "scaling": {"effect": "non_masing_scaling", "rival": ("asymmetry", "force_offset"),
                "acA": (1.5, 1.5), "cycles": (8, 8), "xn": (0.005, 0.02), "f": (2.0, 30.0)},
    # issue 29, stop 46 (helper delay): the blind records' stick_slip confusions
    "damping": {"effect": "viscous_damping", "rival": ("stick_slip",), "acA": (0.6, 0.9),
                "cycles": (20, 20), "xn": (0.008, 0.013), "f": (5.0, 30.0)},
    "stiff": {"effect": "parallel_stiffness", "rival": ("stick_slip",), "acA": (2.5, 3.0),
              "cycles": (50, 50), "xn": (0.008, 0.013), "f": (5.0, 30.0)},
    "stick": {"effect": "stick_slip", "rival": ("channel_delay",), "acA": (1.8, 2.1),
              "cycles": (50, 50), "xn": (0.015, 0.02), "f": (5.0, 30.0)},
    "delay_load": {"effect": "channel_delay", "rival": ("normal_load",), "acA": (3.0, 5.0),
                   "cycles": (8, 8), "xn": (0.008, 0.015), "f": (5.0, 30.0)},
    # issue 29, stop 50 (helper confuse): a dashpot near its bound named stick_slip + stribeck
    # (5 kHz, 17-20 Hz, 20-50 cycles, ac·A 0.8-1.3, x 0.8-0.9 %, F 1.1-1.2 %), a delay near
    # its bound named normal_load (10 kHz, 22-27 Hz, 35-50 cycles, ac·A 1.1-1.2, x 1.5-1.9 %)
    "damp_near": {"effect": "viscous_damping", "rival": ("stick_slip", "stribeck"),
                  "acA": (0.8, 1.35), "cycles": (20, 50), "xn": (0.008, 0.009),
                  "f": (17.0, 20.0), "fs": 5000.0, "fn": (0.011, 0.012)},
    "delay_near": {"effect": "channel_delay", "rival": ("normal_load",), "acA": (1.1, 1.2),
                   "cycles": (35, 50), "xn": (0.015, 0.019), "f": (22.0, 27.0),
                   "fs": 10000.0, "fn": (0.016, 0.017)},
}  # fmt: skip


#: candidates whose held-out gains are printed at every step beside the case's own (the
#: breakaway's look-alikes on one amplitude)
SHOWN = ("stick_slip", "channel_delay", "viscous_damping", "parallel_stiffness", "normal_load")


def factors(case: str, seed: int) -> dict[str, Any]:
    c = CASES[case]
    rng = np.random.default_rng([seed, list(CASES).index(case), 4343])
    f = math.exp(rng.uniform(math.log(c["f"][0]), math.log(c["f"][1])))
    fs = float(rng.choice((2000.0, 5000.0, 10000.0)))
    fs = min(fs, 20000.0 * f / c["cycles"][1])
    fs = float(c.get("fs", fs))
    return {
        "fs": fs, "f": round(f, 3), "cycles": int(rng.integers(c["cycles"][0], c["cycles"][1] + 1)),
        "acA": round(float(rng.uniform(*c["acA"])), 3),
        "x_noise_range": round(float(rng.uniform(*c["xn"])), 4),
        "F_noise": round(float(rng.uniform(*c.get("fn", (0.005, 0.015)))), 4),
        "x_drift": float(rng.uniform(-0.003, 0.003)),
        "sign": 1.0 if rng.random() < 0.5 else -1.0,
        "ramp_cycles": round(float(rng.uniform(0.0, 1.0)), 3),
        # the near-bound cases: a shaker's small 2nd and 3rd harmonics (0-1.5 %, 0-1 %)
        "harmonics": ((round(float(rng.uniform(0.0, 0.015)), 4),
                       round(float(rng.uniform(0.0, 0.01)), 4)) if "fs" in c else ()),
    }  # fmt: skip


#: ``--sensors``: the sensor figures of ``eval_diagnose_rig.py --chain sensors`` (an LVDT's
#: low-pass on x, a piezo or strain-gauge cell, Bessel anti-alias filters, hum, jitter), drawn
#: from the seed's own stream
SENSORS = False


def sensors(seed: int, fs: float) -> dict[str, Any]:
    if not SENSORS:
        return {}
    rng = np.random.default_rng([seed, 424242])
    return {
        "x_lowpass": round(min(math.exp(rng.uniform(math.log(300.0), math.log(2000.0))),
                               0.45 * fs), 3),
        "F_highpass": (round(math.exp(rng.uniform(math.log(0.005), math.log(0.1))), 5)
                       if rng.random() < 0.5 else None),
        "aa_kind": "bessel", "hum": round(float(rng.uniform(0.0, 0.005)), 5),
        "jitter": float(rng.uniform(0.0, 0.02)) / fs,
    }  # fmt: skip


def params(case: str, size: float, fac: dict[str, Any]) -> dict[str, dict[str, float]]:
    """The rig's parameters of the true effect at ``size`` in the diagnosis's parameter."""
    e = CASES[case]["effect"]
    s = fac["sign"]
    return {e: {"channel_delay": {"tau": size}, "parallel_stiffness": {"k_p": size},
                "displacement_offset": {"x0": s * size},
                "non_masing_scaling": {"lam": 2.0 - s * size},
                "viscous_damping": {"c": size}, "stick_slip": {"b": size}}[e]}  # fmt: skip


def record(effects: dict, fac: dict[str, Any], seed: int):
    import contactlab
    from contactlab.synthetic.rig import rig_recording

    rec = rig_recording(
        effects, "tangential", seed=seed, fs=fac["fs"], f=fac["f"], cycles=fac["cycles"],
        acA=fac["acA"], h0=H0, ac=AC, x_noise=2.0 * fac["x_noise_range"],
        F_noise=fac["F_noise"], x_drift=fac["x_drift"], ramp_cycles=fac["ramp_cycles"],
        drive_harmonics=fac.get("harmonics", ()), **fac.get("sensors", {}),
    )  # fmt: skip
    with tempfile.TemporaryDirectory() as tmp:
        return contactlab.read_recording(str(rec.to_csv(Path(tmp) / "r.csv")))


def summary(rep: Any, names: tuple[str, ...]) -> dict[str, Any]:
    nd = {x.effect: x for x in rep.not_detected}
    steps = []
    for st in rep.steps:
        row = {v.name: [round(float(v.gain), 4), bool(v.accepted), (v.reason or "")[:160]]
               for v in st.candidates if v.name in (*names, *SHOWN)}  # fmt: skip
        if row:
            steps.append(row)
    un = rep.unexplained
    return {
        "named": list(rep.effect_names),
        "flagged": bool(un is not None and un.flagged),
        "bounds": {n: (None if n not in nd else nd[n].detectable_above) for n in names},
        "reasons": {n: ("" if n not in nd else (nd[n].reason or "")[:200]) for n in names},
        "steps": steps,
        "where": [w[:300] for w in rep.where if "told apart" in w or "not named" in w],
    }


def without(names: tuple[str, ...]) -> None:
    """Take off this stop's rules (the "before" of a before/after on one tree): ``spring``
    evaluates a parallel spring on the raw input again, ``backlash`` drops the play's
    test away from the turns in the look-alikes not told apart."""
    from contactlab.diagnose.effects import registry

    reg = registry("tangential")
    if "spring" in names:
        type(reg["parallel_stiffness"]).smooth_input = False
    if "stick" in names:  # stop 46: a breakaway yields to a better dashpot or spring again
        type(reg["stick_slip"]).yield_rivals = ()
    if "rank" in names:  # stop 46: the accepted candidates ranked by the raw gain again
        import contactlab.diagnose.search as search

        search.RANK_NET_OF_NOISE = False
    if "backlash" in names and "unfed_samples" in type(reg["backlash"]).__dict__:
        delattr(type(reg["backlash"]), "unfed_samples")


def run_job(job: tuple[str, int, tuple[float, ...]]) -> dict[str, Any]:
    import warnings

    import contactlab

    warnings.simplefilter("ignore")
    case, seed, mults = job
    c = CASES[case]
    names = (c["effect"], *c["rival"])
    fac = factors(case, seed)
    fac["sensors"] = sensors(seed, fac["fs"])
    out: dict[str, Any] = {"case": case, "seed": seed, "factors": fac, "runs": []}
    rep = contactlab.diagnose(record({}, fac, seed), model="tangential")
    out["clean"] = summary(rep, names)
    bound = out["clean"]["bounds"][c["effect"]]
    out["bound"] = bound
    if bound is None or not np.isfinite(bound):
        return json.loads(json.dumps(out, default=float))
    for k, m in enumerate(mults):
        r = contactlab.diagnose(
            record(params(case, m * bound, fac), fac, seed + 7919 * (1 + k)), model="tangential"
        )
        out["runs"].append({"mult": m, "size": m * bound, **summary(r, names)})
    return json.loads(json.dumps(out, default=float))


def verdict(case: str, named: list[str]) -> str:
    c = CASES[case]
    s = set(named)
    if s == {c["effect"]}:
        return "exact"
    if s & set(c["rival"]):
        return "look-alike" + ("+true" if c["effect"] in s else "")
    if c["effect"] in s:
        return "extra"
    return "other" if s else "nothing"


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--base", type=int, required=True)
    ap.add_argument("--n", type=int, default=4)
    ap.add_argument("--cases", default=",".join(CASES))
    ap.add_argument("--mults", default="1.5,3")
    ap.add_argument("--without", default="", help="spring,backlash,stick,rank: these rules off")
    ap.add_argument("--out", type=Path, default=None)
    ap.add_argument("--sensors", action="store_true", help="the sensors' chain (SENSORS)")
    a = ap.parse_args(argv)
    global SENSORS
    SENSORS = a.sensors
    without(tuple(w for w in a.without.split(",") if w))
    mults = tuple(float(m) for m in a.mults.split(","))
    rows = []
    for case in a.cases.split(","):
        for i in range(a.n):
            r = run_job((case, a.base + i, mults))
            rows.append(r)
            fac = r["factors"]
            head = (f"{case:8s} {r['seed']} f {fac['f']:.3g} acA {fac['acA']:.2f} "
                    f"cyc {fac['cycles']} xn {100 * fac['x_noise_range']:.2f}%")  # fmt: skip
            print(f"{head} clean {r['clean']['named']} flag {r['clean']['flagged']} "
                  f"bound {r['bound']}", flush=True)  # fmt: skip
            for run in r["runs"]:
                print(f"    {run['mult']:g}x size {run['size']:.3g} -> {run['named']} "
                      f"flag {run['flagged']} [{verdict(case, run['named'])}] "
                      f"bounds {run['bounds']} steps {run['steps']}", flush=True)  # fmt: skip
                for w in run["where"]:
                    print(f"      where: {w}", flush=True)
                for n, why in run["reasons"].items():
                    if why:
                        print(f"      {n}: {why}", flush=True)
            if a.out:
                a.out.write_text(json.dumps(rows, indent=1))
    tally: dict[tuple[str, float], list[str]] = defaultdict(list)
    for r in rows:
        for run in r["runs"]:
            tally[(r["case"], run["mult"])].append(verdict(r["case"], run["named"]))
    print("\n| case | × bound | n | exact | look-alike | look-alike+true | extra | other | "
          "nothing |\n|---|---|---|---|---|---|---|---|---|")  # fmt: skip
    for (case, m), v in sorted(tally.items()):
        print(f"| {case} | {m:g} | {len(v)} | {v.count('exact')} | {v.count('look-alike')} | "
              f"{v.count('look-alike+true')} | {v.count('extra')} | {v.count('other')} | "
              f"{v.count('nothing')} |")  # fmt: skip
    quiet = sum(not r["clean"]["named"] and not r["clean"]["flagged"] for r in rows)
    print(f"\nclean twins: nothing named or flagged {quiet}/{len(rows)}")


if __name__ == "__main__":
    main()
