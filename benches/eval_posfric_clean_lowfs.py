"""Clean records at the blind generator's false-name condition for ``position_friction``
(issue 29, stop 52): 1 kHz, ~5-6 Hz, 20 cycles, x noise 2 % of the range, F noise ~1.2 %
of the range, ac·A 3-4, start from rest, on both package generators:

- ``rig``: ``contactlab.synthetic.rig.rig_recording`` (its noise is a share of the amplitude:
  twice the share of the range), single tone, read through the CSV round trip;
- ``pkg``: the exponential Masing law (``contactlab.masing.Masing``) on a single sine from
  rest (a one-cycle raised-cosine ramp), white noise on both channels as SD / range (the
  independent generator's convention), built from the package's pieces.

Per record: the names, the misfit flag, and position_friction's verdicts (gain, reason, and the
locked floor the search used) at every step.

    nice .venv/bin/python benches/eval_posfric_clean_lowfs.py --base 52200000 --n 4
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

H0, AC = 40.0, 4.0e4


def factors(seed: int, xn: float | None, aca: tuple[float, float]) -> dict:
    rng = np.random.default_rng([seed, 5252])
    return {
        "fs": 1000.0,
        "f": round(float(rng.uniform(5.0, 6.2)), 3),
        "cycles": 20,
        "acA": round(float(rng.uniform(*aca)), 3),
        "xn": float(rng.uniform(0.017, 0.021)) if xn is None else xn,
        "Fn": float(rng.uniform(0.009, 0.014)),
    }


def rig(seed: int, fac: dict, effects: dict | None = None):
    import contactlab
    from contactlab.synthetic.rig import rig_recording

    rec = rig_recording(
        effects or {}, "tangential", seed=seed, fs=fac["fs"], f=fac["f"], cycles=fac["cycles"],
        acA=fac["acA"], x_noise=2 * fac["xn"], F_noise=2 * fac["Fn"], bits=16,
    )  # fmt: skip
    with tempfile.TemporaryDirectory() as tmp:
        return contactlab.read_recording(str(rec.to_csv(Path(tmp) / "r.csv")))


def pkg(seed: int, fac: dict, wave: tuple[float, float, float] | None = None):
    """Masing from rest on a sine with a one-cycle raised-cosine ramp; ``wave`` (eps, L, phi):
    the friction h0 (1 + eps cos(2π x/L + phi)) evaluated along the measured-free x (a
    multiplicative factor on the Masing force, as the package's candidate draws it)."""
    from contactlab.masing import Masing

    rng = np.random.default_rng([seed, 77])
    fs, f, cyc = fac["fs"], fac["f"], fac["cycles"]
    A = fac["acA"] / AC
    t = np.arange(round((cyc + 1.25) * fs / f) + 1) / fs
    ramp = np.where(t < 1 / f, 0.5 * (1 - np.cos(np.pi * t * f)), 1.0)
    x = A * ramp * np.sin(2 * np.pi * f * t)
    F = Masing(H0, AC).force(x)
    if wave is not None:
        eps, L, phi = wave
        F = F * (1 + eps * np.cos(2 * np.pi * x / L + phi))
    xm = x + rng.normal(0, fac["xn"] * np.ptp(x), x.size)
    Fm = F + rng.normal(0, fac["Fn"] * np.ptp(F), F.size)
    return (t, xm, Fm)


def one(gen: str, seed: int, fac: dict) -> dict:
    import contactlab
    from contactlab.diagnose import search

    t0 = time.process_time()
    data = rig(seed, fac) if gen == "rig" else pkg(seed, fac)
    rep = contactlab.diagnose(data, model="tangential")
    un = rep.unexplained
    pf = []
    for k, st in enumerate(rep.steps):
        for v in st.candidates:
            if v.name == "position_friction":
                pf.append({"step": k, "gain": round(v.gain, 4), "t": round(v.t_stat, 2),
                           "acc": v.accepted, "why": v.reason[:110]})  # fmt: skip
    ex = rep.prepared.extra
    b = {x.effect: x for x in rep.not_detected}.get("position_friction")
    return {
        "gen": gen,
        "seed": seed,
        **fac,
        "named": list(rep.effect_names),
        "flagged": bool(un is not None and un.flagged),
        "budget": ex.get("input_noise_budget"),
        "locked_only": {k: float(v) for k, v in (ex.get(search.LOCKED_ONLY) or {}).items()},
        "bound": None if b is None else b.detectable_above,
        "pf": pf,
        "cpu": round(time.process_time() - t0, 1),
    }


def main(argv=None):
    import warnings

    warnings.simplefilter("ignore")
    ap = argparse.ArgumentParser()
    ap.add_argument("--base", type=int, required=True)
    ap.add_argument("--n", type=int, default=2)
    ap.add_argument("--gens", default="rig,pkg")
    ap.add_argument("--xn", type=float, default=None, help="x noise, share of the range")
    ap.add_argument("--aca", default="3.0,4.0")
    a = ap.parse_args(argv)
    os.environ.setdefault("CONTACTLAB_DIAGNOSE_THREADS", "1")
    aca = tuple(float(v) for v in a.aca.split(","))
    named = total = 0
    for i in range(a.n):
        for gen in a.gens.split(","):
            s = a.base + i
            r = one(gen, s, factors(s, a.xn, aca))
            total += 1
            named += bool(r["named"])
            print(json.dumps(r, default=float), flush=True)
    print(f"named {named}/{total}", flush=True)


if __name__ == "__main__":
    sys.exit(main())
