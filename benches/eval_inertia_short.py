"""Short records from rest far from gross sliding (issue 29: clean 5-cycle records named
``inertia``): the rig simulator (``contactlab.synthetic.rig``), no ramp (``ramp_cycles`` 0),
Butterworth anti-alias filters, white noise added to the sampled channels (a fraction of each
channel's half range), one drive frequency. Factors drawn per seed: fs 5-10 kHz, drive
11-24 Hz, ``--cycles`` (default 5), ac·A in ``--aca`` (default 0.42-0.62), x noise 1.0-1.6 %,
F noise 0.86-1.2 %. Effects: ``clean``; ``inertia`` (``m ω² A`` a share ``--share`` of the
force amplitude ``h0 (1 - exp(-ac·A))``).

Per record: the names, the misfit flag, every ``inertia`` verdict (gain, t, accepted,
reason) and the stated bound for inertia where it is not named.

    nice .venv/bin/python benches/eval_inertia_short.py --base 49100000 --n 10 \
        --effects clean,inertia
"""

from __future__ import annotations

import argparse
import json
import math
import time

import numpy as np

H0, AC = 40.0, 4.0e4


def factors(seed: int, effect: str, a) -> dict:
    rng = np.random.default_rng([seed, 2929, 0 if effect == "clean" else 1])
    fs = float(rng.uniform(*a.fs))
    return {
        "fs": round(fs, 1),
        "f": round(float(rng.uniform(*a.f)), 3),
        "cycles": int(rng.integers(a.cycles[0], a.cycles[1] + 1)),
        "acA": round(float(rng.uniform(*a.aca)), 3),
        "x_noise": round(float(rng.uniform(*a.xn)), 4),
        "F_noise": round(float(rng.uniform(*a.fn)), 4),
        "share": round(float(rng.uniform(*a.share)), 4),
        "bits": int(rng.integers(14, 17)),
    }


def record(seed: int, effect: str, fx: dict, gen: str = "rig"):
    A = fx["acA"] / AC
    hm = H0 * (1 - math.exp(-fx["acA"]))
    w = 2 * math.pi * fx["f"]
    eff = {"inertia": {"m": fx["share"] * hm / (A * w * w)}} if effect == "inertia" else {}
    if gen == "pkg":
        from contactlab.synthetic.diagnosis import hidden_effect_recording

        size = {"inertia": fx["share"]} if effect == "inertia" else {}
        rec = hidden_effect_recording(
            size, noise=fx["F_noise"], seed=seed, input_noise=fx["x_noise"] * 2,
            cycles_per_block=max(2, fx["cycles"] // 3 + 1),
            samples_per_cycle=int(fx["fs"] / fx["f"]), f0=fx["f"], start="rest",
        )  # fmt: skip
        return rec, rec.truth.get("effects", {})
    if gen == "plain":
        # a sine from x = 0 at t = 0 (the contact virgin), the Masing force, plus m ẍ
        from contactlab.masing import Masing

        t = np.arange(round(fx["cycles"] * fx["fs"] / fx["f"]) + 1) / fx["fs"]
        xt = A * np.sin(w * t)
        F = Masing(H0, AC).force(xt)
        if eff:
            F = F - eff["inertia"]["m"] * w * w * xt
        rng = np.random.default_rng([seed, 6060])
        x = xt + rng.standard_normal(t.size) * fx["x_noise"] * 2 * A
        F = F + rng.standard_normal(t.size) * fx["F_noise"] * float(np.ptp(F))
        return (t, x, F), eff
    from contactlab.synthetic.rig import rig_recording

    rec = rig_recording(
        eff, "tangential", seed=seed, fs=fx["fs"], f=fx["f"], cycles=fx["cycles"],
        acA=fx["acA"], x_noise=0.0, F_noise=0.0, bits=fx["bits"], ramp_cycles=0.0,
    )  # fmt: skip
    x = np.asarray(rec.channels["x"], float).copy()
    F = np.asarray(rec.channels["F"], float).copy()
    t = np.arange(x.size) / fx["fs"]
    rng = np.random.default_rng([seed, 6060])
    x += rng.standard_normal(x.size) * fx["x_noise"] * float(np.ptp(x))
    F += rng.standard_normal(F.size) * fx["F_noise"] * float(np.ptp(F))
    return (t, x, F), eff


def run(seed: int, effect: str, a) -> dict:
    import warnings

    from contactlab.diagnose.workflow import diagnose

    warnings.simplefilter("ignore")
    fx = factors(seed, effect, a)
    rec, eff = record(seed, effect, fx, a.gen)
    t0 = time.process_time()
    out = {"seed": seed, "effect": effect, "fac": fx, "truth": eff}
    try:
        rep = diagnose(rec, model="tangential")
    except Exception as exc:
        out.update(named=[], flagged=False, error=f"{type(exc).__name__}: {exc}"[:300])
        return out
    out["named"] = list(rep.effect_names)
    u = rep.unexplained
    out["flagged"] = bool(u is not None and u.flagged)
    out["params"] = {e.name: dict(e.parameters) for e in rep.effects}
    vs = [v for st in rep.steps for v in st.candidates if v.name == "inertia"]
    out["verdicts"] = [
        (
            round(float(v.gain), 4),
            round(float(v.t_stat), 2),
            bool(v.accepted),
            (v.reason or "")[:140],
        )
        for v in vs
    ]
    nd = {x.effect: x for x in rep.not_detected}.get("inertia")
    out["bound"] = None if nd is None else nd.detectable_above
    out["bound_reason"] = "" if nd is None else (nd.reason or "")[:160]
    out["cpu"] = round(time.process_time() - t0, 1)
    return json.loads(json.dumps(out, default=float))


def main(argv=None):
    ap = argparse.ArgumentParser()
    ap.add_argument("--base", type=int, required=True)
    ap.add_argument("--n", type=int, default=6)
    ap.add_argument("--effects", default="clean,inertia")
    ap.add_argument("--aca", default="0.42,0.62")
    ap.add_argument("--f", default="11,24")
    ap.add_argument("--cycles", default="5,5")
    ap.add_argument("--fs", default="5000,10000")
    ap.add_argument("--xn", default="0.010,0.016", help="x noise, share of the range")
    ap.add_argument("--fn", default="0.0086,0.012", help="F noise, share of the range")
    ap.add_argument("--share", default="0.03,0.10")
    ap.add_argument("--gen", choices=("rig", "plain", "pkg"), default="rig")
    ap.add_argument("--verbose", action="store_true")
    ap.add_argument("--old", action="store_true", help="the mass reads the old ẍ (MASS_GAP off)")
    ap.add_argument("--only", default="", help="comma-separated seeds to run")
    ap.add_argument("--set", default="", help="NAME=VALUE,... of contactlab's inertia module")
    a = ap.parse_args(argv)
    for kv in filter(None, a.set.split(",")):
        from contactlab.diagnose.effects.tangential import inertia

        k, v = kv.split("=")
        setattr(inertia, k, type(getattr(inertia, k))(float(v)))
    if a.old:
        from contactlab.diagnose.effects.tangential import inertia

        inertia.MASS_GAP = False
    for k in ("aca", "f", "share", "fs", "xn", "fn"):
        setattr(a, k, tuple(float(v) for v in getattr(a, k).split(",")))
    a.cycles = tuple(int(v) for v in a.cycles.split(","))
    counts: dict[str, list[int]] = {}
    only = [int(v) for v in a.only.split(",")] if a.only else None
    for e in a.effects.split(","):
        for i in range(a.n):
            if only is not None and a.base + i not in only:
                continue
            r = run(a.base + i, e, a)
            ok = (not r["named"]) if e == "clean" else (r["named"] == [e])
            c = counts.setdefault(e, [0, 0, 0])
            c[0] += 1
            c[1] += ok
            c[2] += "inertia" in r["named"]
            f = r["fac"]
            print(
                r["seed"], e, "+".join(r["named"]) or "-", "F" if r["flagged"] else "",
                f"fs {f['fs']:.0f} f {f['f']:.1f} cyc {f['cycles']} acA {f['acA']:.2f} "
                f"xn {100 * f['x_noise']:.2f} Fn {100 * f['F_noise']:.2f} sh {f['share']:.3f}",
                "bound", r.get("bound"), r.get("cpu"), r.get("error", ""), flush=True,
            )  # fmt: skip
            if a.verbose:
                for v in r.get("verdicts", []):
                    print("   ", v)
                print("    params", r.get("params"), "|", r.get("bound_reason"))
    for e, (n, ok, inert) in counts.items():
        print(f"{e}: n {n}, exact {ok}, named inertia {inert}")


if __name__ == "__main__":
    main()
