"""Before/after of ``misfit.ALT_FEW_CYCLES`` (stop 50, helper confuse) on records of few
cycles: virgin curves of ``benches/misfit_chain.py`` (5 kHz, 1-10 Hz, ac·A 0.5-5, noise 0.5-2 %
of the range) and rig records (``rig_recording``, clean or with one effect of
``eval_diagnose_rig.rig_effect``'s sizes). Per record: the final names and flag, whether
``shape.patch_check`` flagged, and :func:`contactlab.diagnose.misfit.alternative_virgin` on the
final model (computed even where another check flagged): "before" its gain-and-t rule,
"after" its flag (the gain and t, or every held-out cycle gaining on a short record). One
process, ``nice``::

    nice .venv/bin/python benches/eval_misfit_few_cycles.py gamma,tanh,rational,exp \\
        50500000,50500001,50500002 2
"""

from __future__ import annotations

import sys
import warnings
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))


def record(kind: str, s: int, cycles: int) -> tuple[Any, dict[str, float]]:
    if kind.startswith("effect:") or kind == "rigclean":
        from contactlab.synthetic.rig import rig_recording
        from eval_diagnose_rig import rig_effect

        rng = np.random.default_rng([s, 77])
        fac = {"fs": 5000.0, "f": float(np.exp(rng.uniform(0, np.log(20)))), "cycles": cycles,
               "acA": float(np.exp(rng.uniform(np.log(0.5), np.log(5)))),
               "x_noise": float(rng.uniform(0.005, 0.02)),
               "F_noise": float(rng.uniform(0.005, 0.02))}  # fmt: skip
        eff = rig_effect(None if kind == "rigclean" else kind[7:], "2f", fac, rng)
        rec = rig_recording(
            eff, "tangential", seed=s, fs=fac["fs"], f=fac["f"], cycles=cycles,
            acA=fac["acA"], x_noise=2 * fac["x_noise"], F_noise=fac["F_noise"],
            ramp_cycles=float(rng.uniform(0, 1)), drive_harmonics=(0.01, 0.005),
        )  # fmt: skip
        ch = rec.channels
        return (np.asarray(rec.t), np.asarray(ch["x"]), np.asarray(ch["F"])), fac
    from misfit_chain import chain_record

    rng = np.random.default_rng([s, 78])
    fac = {"fs": 5000.0, "f": float(np.exp(rng.uniform(0, np.log(10)))), "cycles": cycles,
           "acA": float(np.exp(rng.uniform(np.log(0.5), np.log(5)))),
           "x_noise": float(rng.uniform(0.005, 0.02)),
           "F_noise": float(rng.uniform(0.005, 0.02))}  # fmt: skip
    return chain_record(s, kind, **fac)[0], fac


def main() -> None:
    import contactlab.diagnose.misfit as mf
    import contactlab.diagnose.shape as sh
    from contactlab.diagnose.workflow import diagnose

    warnings.simplefilter("ignore")
    kinds, seeds = sys.argv[1].split(","), [int(s) for s in sys.argv[2].split(",")]
    cycles = int(sys.argv[3])
    cap: dict[str, Any] = {}
    o_pc, o_alt = sh.patch_check, mf.alternative_virgin

    def pc(family, effects, d, p, scales, r1, sigma):
        r = o_pc(family, effects, d, p, scales, r1, sigma)
        cap["patch"] = bool(r)
        cap["alt"] = o_alt(family, effects, d, p, scales, sigma)
        return r

    sh.patch_check = pc
    for kind in kinds:
        for s in seeds:
            cap.clear()
            rec, fac = record(kind, s, cycles)
            rep = diagnose(rec, model="tangential")
            u = rep.unexplained
            a = cap.get("alt")
            before = after = None
            if a is not None:
                before = bool(a["gain"] >= mf.ALT_MIN_GAIN and a["t"] >= mf.ALT_Z)
                after = bool(a["flagged"])
            alt = "alt none" if a is None else (
                f"alt cyc {a['cycles']} gain {a['gain']:.1f} t {a['t']:.2f} "
                f"pc {[round(v, 1) for v in a['per_cycle']]}"
            )  # fmt: skip
            print(f"{kind:22s} {s} acA {fac['acA']:.2f} f {fac['f']:.2f} "
                  f"xn {100 * fac['x_noise']:.1f}% named {list(rep.effect_names)} "
                  f"flag {bool(u is not None and u.flagged)} patch {cap.get('patch')} {alt} "
                  f"before {before} after {after}", flush=True)  # fmt: skip


if __name__ == "__main__":
    main()
