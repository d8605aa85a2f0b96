"""Rig Stribeck terms, some speed-strengthening (s < 0), diagnosed (stop 50, helper confuse):
does ``Stribeck.yields_to_tried`` (a strengthening term yields to a dashpot tried at the same
step with at least ``DASHPOT_SHARE`` of its held-out gain) take true terms? Per record: the
names, the flag and the first step's held-out gains of stribeck, viscous_damping and
inertia. ``DASH=0`` in the environment turns the rule off (the before on one tree)::

    nice .venv/bin/python benches/eval_stribeck_strengthening.py 50710000 6 -0.3,-0.2,-0.1
"""

from __future__ import annotations

import os
import sys
import tempfile
import warnings
from pathlib import Path

import numpy as np


def main() -> None:
    import contactlab
    from contactlab.synthetic.rig import rig_recording

    warnings.simplefilter("ignore")
    base, n = int(sys.argv[1]), int(sys.argv[2])
    signs = tuple(float(v) for v in (sys.argv[3] if len(sys.argv) > 3 else
                                     "-0.2,-0.1,0.1,0.2").split(","))  # fmt: skip
    if os.environ.get("DASH") == "0":
        from contactlab.diagnose.effects import registry

        type(registry("tangential")["stribeck"]).dashpot_check = False
    for s in range(base, base + n):
        rng = np.random.default_rng([s, 99])
        fac = {"fs": float(rng.choice((2000.0, 5000.0, 10000.0))),
               "f": float(np.exp(rng.uniform(np.log(2), np.log(40)))),
               "cycles": int(rng.integers(8, 40)),
               "acA": float(np.exp(rng.uniform(np.log(0.5), np.log(5)))),
               "x_noise": 2 * float(rng.uniform(0.005, 0.02)),
               "F_noise": float(rng.uniform(0.005, 0.015))}  # fmt: skip
        sv = float(rng.choice(signs))
        aw = fac["acA"] / 4e4 * 2 * np.pi * fac["f"]
        vs = float(rng.uniform(0.2, 1.5)) * aw
        eff = {"stribeck": {"s": sv, "v_s": vs}}
        rec = rig_recording(eff, "tangential", seed=s, ramp_cycles=float(rng.uniform(0, 1)), **fac)
        with tempfile.TemporaryDirectory() as tmp:
            r = contactlab.read_recording(str(rec.to_csv(Path(tmp) / "r.csv")))
        rep = contactlab.diagnose(r, model="tangential")
        shown = ("stribeck", "viscous_damping", "inertia")
        g = {v.name: round(float(v.gain), 3) for v in rep.steps[0].candidates
             if v.name in shown} if rep.steps else {}  # fmt: skip
        flag = bool(rep.unexplained is not None and rep.unexplained.flagged)
        print(s, f"s {sv} vs/Aw {vs / aw:.2f} acA {fac['acA']:.2f} f {fac['f']:.1f} "
              f"xn {fac['x_noise'] / 2:.3f}", list(rep.effect_names), "flag", flag, g,
              flush=True)  # fmt: skip


if __name__ == "__main__":
    main()
