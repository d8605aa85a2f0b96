"""A mass's plateau tilt against a backbone of another shape (issue 29, stop 46).

Single-frequency records from rest; per record what ``diagnose`` names, the misfit flag and
the ``inertia``/``viscous_damping`` verdicts per step, with ``inertia.SHAPE_CHECK`` on or off
(``--shape``). Generators (``--kind``):

- ``inertia``, ``tanh``, ``clean``: the rig simulator (``contactlab.synthetic.rig``, read back
  through its CSV) with a mass (``m ω² A`` a ``share`` of the force amplitude
  ``h0 (1 - exp(-ac·A))``), its ``tanh_virgin`` backbone, or nothing;
- ``plain_tanh``: ``h0 tanh(ac x)`` through :func:`contactlab.diagnose.scaled_masing`'s Masing
  rules, a sine from rest (one ramp cycle) at ac·A 4.72, 2 kHz, 5 cycles, white noise.

Per seed ``s`` the factors are drawn from ``default_rng(s)`` in this order: f (log-uniform
in ``--f``), cycles (``--cycles lo,hi``: integers, else fixed), ac·A (``--aca lo,hi``:
log-uniform, else fixed), x noise, F noise (uniform in ``--xn``, ``--fn``, shares of the
channel's range), share (``--share lo,hi``: uniform, else fixed). The stop-46 figures:

    nice .venv/bin/python benches/eval_inertia_shape.py --kind inertia --seed0 991100 --n 12 \\
        --aca 2.6,5 --share 0.02,0.1 --cycles 5,12 --shape on
    nice .venv/bin/python benches/eval_inertia_shape.py --kind tanh --seed0 991000 --n 12 \\
        --aca 2.6,5 --shape off
    nice .venv/bin/python benches/eval_inertia_shape.py --kind plain_tanh --seed0 997000 --n 12 \\
        --xn 0.003,0.016 --fn 0.005,0.014
"""

from __future__ import annotations

import argparse
import json
import math
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np

H0, AC = 40.0, 4.0e4


def _range(text: str) -> tuple[float, ...]:
    return tuple(float(v) for v in text.split(","))


def draw(seed: int, a: argparse.Namespace) -> tuple[dict, dict, np.random.Generator]:
    """The record's factors rounded (the rig's), unrounded (``plain_tanh``'s) and the
    generator the plain record's noise is drawn from next."""
    rng = np.random.default_rng(seed)
    flo, fhi = _range(a.f)
    f = float(np.exp(rng.uniform(np.log(flo), np.log(fhi))))
    cyc = _range(a.cycles)
    cycles = int(rng.integers(int(cyc[0]), int(cyc[1]))) if len(cyc) > 1 else int(cyc[0])
    aca = _range(a.aca)
    acA = float(np.exp(rng.uniform(*np.log(aca)))) if len(aca) > 1 else aca[0]
    xn = float(rng.uniform(*_range(a.xn)))
    fn = float(rng.uniform(*_range(a.fn)))
    sh = _range(a.share)
    share = float(rng.uniform(*sh)) if len(sh) > 1 else sh[0]
    raw = {"f": f, "cycles": cycles, "acA": acA, "xn": xn, "Fn": fn, "share": share}
    digits = {"f": 2, "acA": 2, "xn": 4, "Fn": 4, "share": 3}
    fac = {k: round(v, digits[k]) if k in digits else v for k, v in raw.items()}
    return fac, raw, rng


def record(kind: str, seed: int, fac: dict, fs: float, raw: dict, rng: np.random.Generator):
    import contactlab

    if kind == "plain_tanh":
        from contactlab.diagnose.scaled_masing import memory, scaled_force

        A = 1e-5
        ac = raw["acA"] / A
        t = np.arange(int(raw["cycles"] * fs / raw["f"])) / fs
        x = A * np.sin(2 * np.pi * raw["f"] * t) * np.clip(t * raw["f"], 0, 1)
        F = scaled_force(lambda s: 50.0 * np.tanh(ac * s), 2.0, memory(x))
        xm = x + rng.normal(0, raw["xn"] * np.ptp(x), x.size)
        return t, xm, F + rng.normal(0, raw["Fn"] * np.ptp(F), F.size)
    from contactlab.synthetic.rig import rig_recording

    A = fac["acA"] / AC
    w = 2 * math.pi * fac["f"]
    eff: dict = {}
    if kind == "inertia":
        eff = {"inertia": {"m": fac["share"] * H0 * (1 - math.exp(-fac["acA"])) / (A * w * w)}}
    elif kind == "tanh":
        eff = {"tanh_virgin": {}}
    rec = rig_recording(eff, "tangential", seed=seed, fs=fs, f=fac["f"], cycles=fac["cycles"],
                        acA=fac["acA"], x_noise=fac["xn"], F_noise=fac["Fn"])  # fmt: skip
    with tempfile.TemporaryDirectory() as tmp:
        return contactlab.read_recording(str(rec.to_csv(Path(tmp) / "r.csv")))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--kind", choices=("inertia", "tanh", "clean", "plain_tanh"), required=True)
    ap.add_argument("--seed0", type=int, required=True)
    ap.add_argument("--n", type=int, default=12)
    ap.add_argument("--fs", type=float, default=2000.0)
    ap.add_argument("--f", default="5,50")
    ap.add_argument("--cycles", default="5")
    ap.add_argument("--aca", default="4.72")
    ap.add_argument("--xn", default="0.005,0.016")
    ap.add_argument("--fn", default="0.007,0.014")
    ap.add_argument("--share", default="0")
    ap.add_argument("--shape", choices=("on", "off"), default="on")
    a = ap.parse_args()
    warnings.simplefilter("ignore")
    import contactlab
    import contactlab.diagnose.effects.tangential.inertia as inertia

    inertia.SHAPE_CHECK = a.shape == "on"
    for s in range(a.seed0, a.seed0 + a.n):
        fac, raw, rng = draw(s, a)
        t0 = time.process_time()
        rep = contactlab.diagnose(record(a.kind, s, fac, a.fs, raw, rng), model="tangential")
        un = rep.unexplained
        verdicts = [
            (i, v.name, round(float(v.gain or 0), 4), bool(v.accepted), (v.reason or "")[:160])
            for i, st in enumerate(rep.steps)
            for v in st.candidates
            if v.name in ("inertia", "viscous_damping")
        ]
        out = {"seed": s, "kind": a.kind, "shape": a.shape, **fac, "named": rep.effect_names,
               "flagged": bool(un is not None and getattr(un, "flagged", False)),
               "cpu": round(time.process_time() - t0, 1), "verdicts": verdicts}  # fmt: skip
        print(json.dumps(out, default=str), flush=True)


if __name__ == "__main__":
    main()
