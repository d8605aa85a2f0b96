"""Is the stated ``creep_drift`` bound found at its own size? (issue 29, stop 46)

For each seed: a clean normal record of the package's generator
(:func:`contactlab.synthetic.diagnosis.hidden_effect_recording`, ``model="normal"``: three
blocks or one tone, from rest or steady, 3-16 cycles a block, 40-300 samples a cycle, noise
0.7-2 % on both channels) or of the rig simulator
(:func:`contactlab.synthetic.rig.rig_recording`: one tone 1-20 Hz, fs 1-5 kHz, 8-40 cycles,
noise 0.5-2 %); ``diagnose`` states the creep bound ``D`` at ``at.tau_c`` on it; then the
same record with a creep ``factor · D (1 - exp(-t/τc))`` added to its displacement (either
sign), ``τc`` the stated one (``--tau``: that many times it instead). Counts how often the
creep is named (exactly, and at all), and what is named on the clean record.

    nice .venv/bin/python benches/eval_normal_creep_bound.py --seeds 0-9 --base 294600 \
        --gen package --factor 1.0
"""

from __future__ import annotations

import argparse
import json
import warnings
from pathlib import Path

import numpy as np


def diagnose(t, p, d):
    import contactlab

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        r = contactlab.diagnose({"t": t, "p": p, "delta": d}, "normal")
    b = {x.to_dict()["effect"]: x.to_dict() for x in r.not_detected}.get("creep_drift", {})
    flagged = bool(r.to_dict().get("unexplained", {}).get("flagged", False))
    return list(r.effect_names), flagged, b


def record(gen: str, seed: int):
    rng = np.random.default_rng(seed)
    if gen == "package":
        from contactlab.synthetic.diagnosis import hidden_effect_recording

        noise = float(rng.uniform(0.007, 0.02))
        kw = {"noise": noise, "input_noise": noise, "seed": seed,
              "cycles_per_block": int(rng.integers(3, 17)),
              "samples_per_cycle": int(rng.choice([40, 120, 300])),
              "start": str(rng.choice(["rest", "steady"])),
              "frequencies": [1.0] if rng.uniform() < 0.5 else None}  # fmt: skip
        r = hidden_effect_recording([], model="normal", **kw)
        desc = {k: v for k, v in kw.items() if k != "seed"}
    else:
        from contactlab.synthetic.rig import rig_recording

        f = float(np.exp(rng.uniform(np.log(1.0), np.log(20.0))))
        kw = {"fs": float(rng.choice([1000.0, 2000.0, 5000.0])), "f": f,
              "cycles": int(rng.integers(8, 41)), "x_noise": float(rng.uniform(0.005, 0.02)),
              "F_noise": float(rng.uniform(0.005, 0.02)), "psi": float(rng.uniform(0.05, 0.3)),
              "k": 1.3e12, "p0": 5e5, "pa": float(rng.uniform(0.2, 0.8)) * 5e5,
              "ramp_cycles": 1.0}  # fmt: skip
        r = rig_recording({}, "normal", seed=seed, **kw)
        desc = kw
    ch = r.channels if isinstance(getattr(r, "channels", None), dict) else r.data
    return np.asarray(r.t, float), ch["p"], ch["delta"], desc


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--seeds", default="0-3")
    ap.add_argument("--base", type=int, default=294600)
    ap.add_argument("--gen", choices=("package", "rig"), default="package")
    ap.add_argument("--factor", type=float, default=1.0)
    ap.add_argument("--tau", type=float, default=1.0, help="τc as a multiple of the stated")
    ap.add_argument("--out", default=None)
    a = ap.parse_args()
    lo, hi = (int(s) for s in a.seeds.split("-"))
    rows, named, exact, clean_alarm = [], 0, 0, 0
    for s in range(lo, hi + 1):
        seed = a.base + s
        t, p, d, desc = record(a.gen, seed)
        cn, cf, b = diagnose(t, p, d)
        clean_alarm += bool(cn or cf)
        D = b.get("detectable_above")
        row = {"seed": seed, "desc": desc, "clean": cn, "clean_flagged": cf, "bound": b}
        if D is None:
            print(f"seed {seed}: clean {cn} {cf}: no bound ({b.get('reason', '')[:100]})")
            rows.append(row)
            continue
        tc = a.tau * float(b["at"]["tau_c"])
        sign = 1.0 if np.random.default_rng(seed + 1).uniform() < 0.5 else -1.0
        size = sign * a.factor * D
        tt = np.asarray(t, float)
        nm, fl, _ = diagnose(t, p, d + size * -np.expm1(-(tt - tt[0]) / tc))
        named += "creep_drift" in nm
        exact += nm == ["creep_drift"]
        row.update({"size": size, "tau_c": tc, "named": nm, "flagged": fl})
        rows.append(row)
        print(
            f"seed {seed}: clean {cn} {cf}; bound rel {b['relative_size']:.3g} τc {tc:.3g} s "
            f"(T {tt[-1] - tt[0]:.3g} s) -> {nm} {fl}",
            flush=True,
        )
        if a.out:
            Path(a.out).write_text(json.dumps(rows, indent=1, default=str))
    n = sum(1 for r in rows if "named" in r)
    print(
        f"\n{a.gen} factor {a.factor} tau x{a.tau}: creep named {named}/{n} (exact {exact}/{n}); "
        f"clean named or flagged {clean_alarm}/{len(rows)}"
    )


if __name__ == "__main__":
    main()
