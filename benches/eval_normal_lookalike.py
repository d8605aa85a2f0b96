"""Normal-contact single effects on a wide chain, with start-up ramps (issue 29, stop 42).

Each seed draws one chain of ``chain_normal`` (fs 1-10 kHz, 1-50 Hz at 20 samples a cycle or
more, 5-50 cycles, noise 0.5-2 % of range on both channels, ψ 0.05-0.3, the drive's
amplitude ramped in from rest over 0-4 cycles) and diagnoses on it:

- ``clean``: nothing but the chain (nothing may be named or flagged);
- ``stiffness_nonlinearity``: a change of the stiffness of 0.01-0.2 at the amplitude
  (log-uniform), by one of the laws ``a2`` (stiffening, k + a2 δ, a2 > 0, on 2 of 3 draws),
  ``a3``, ``a23``, ``eq17``, ``p`` (see ``chain_normal``);
- ``asymmetric_branches``: ``a`` 0.15-0.7 either sign;
- ``creep_drift``: ``D`` 0.03-0.5 of the amplitude settling with ``τ_c`` log-uniform from
  0.1 period to the record's duration.

Prints what ``diagnose`` names, the flag, the size in the effect's own parameter and the
bound ``diagnose`` states for it; tallies by effect with the confusions.

    nice .venv/bin/python benches/eval_normal_lookalike.py --seeds 0-9 --out /tmp/x.json
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
import warnings
from collections import Counter, defaultdict
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from chain_normal import chain_record

ROWS = ("clean", "stiffness_nonlinearity", "asymmetric_branches", "creep_drift")
LAWS = ("a2", "a2", "a3", "a23", "eq17", "p")


#: the stop-42 rule (the stiffening law against the loss asymmetry by their likelihood):
#: its hooks, which ``--compare`` takes away for the "before" run
HOOKED = ("asymmetric_branches", "stiffness_nonlinearity")


def _without_hooks():
    """A context in which the two effects' ``yields_to_tried`` hooks are gone (main before
    stop 42)."""
    import contextlib

    from contactlab.diagnose.effects import registry

    @contextlib.contextmanager
    def ctx():
        reg = registry("normal")
        saved = {n: type(reg[n]).__dict__.get("yields_to_tried") for n in HOOKED}
        for n in HOOKED:
            if saved[n] is not None:
                delattr(type(reg[n]), "yields_to_tried")
        try:
            yield
        finally:
            for n, f in saved.items():
                if f is not None:
                    type(reg[n]).yields_to_tried = f

    return ctx()


def _hook_fired(r) -> bool:
    return any(
        (v.reason or "").startswith("look-alike:") and v.name in HOOKED
        for st in r.steps
        for v in st.candidates
    )


def diagnose(t, p, d, before=False):
    import contextlib

    import contactlab

    with warnings.catch_warnings(), _without_hooks() if before else contextlib.nullcontext():
        warnings.simplefilter("ignore")
        r = contactlab.diagnose({"t": t, "p": p, "delta": d}, "normal")
    rd = r.to_dict()
    flagged = bool(rd.get("unexplained", {}).get("flagged", False))
    bounds = {b.to_dict()["effect"]: b.to_dict().get("detectable_above") for b in r.not_detected}
    params = {e["name"]: e.get("parameters", {}) for e in rd.get("effects", [])}
    gains = {v.name: float(v.gain) for v in r.steps[0].candidates}
    for v in r.steps[0].candidates:
        gains[v.name + ":why"] = v.reason
    gains["fired"] = _hook_fired(r)
    return list(r.effect_names), flagged, bounds, params, gains, rd.get("refused", {})


def factors(rng: np.random.Generator) -> dict:
    fs = float(rng.choice([1000.0, 2000.0, 5000.0, 10000.0]))
    f = float(np.exp(rng.uniform(np.log(1.0), np.log(min(50.0, fs / 20.0)))))
    return {
        "fs": fs,
        "f": f,
        "cycles": int(rng.integers(5, 51)),
        "ratio": float(rng.uniform(0.2, 0.8)),
        "noise_p": float(rng.uniform(0.005, 0.02)),
        "noise_d": float(rng.uniform(0.005, 0.02)),
        "bits": int(rng.choice([14, 16])),
        "psi": float(rng.uniform(0.05, 0.3)),
        "ramp": float(rng.choice([0.0, 0.0, rng.uniform(1.0, 4.0)])),
    }


#: creep draws (``--creep``): τc from this many periods to this many record durations, and
#: D from ... to ... of the amplitude
CREEP = {"lo_periods": 0.1, "hi_durations": 1.0, "d_lo": 0.03, "d_hi": 0.5}


def row_factors(rng: np.random.Generator, row: str, base: dict) -> tuple[dict, float]:
    fac = dict(base)
    if row == "stiffness_nonlinearity":
        fac["law"] = str(rng.choice(LAWS))
        sign = 1.0 if fac["law"] in ("a3", "a23") or rng.random() < 2 / 3 else -1.0
        return fac, sign * float(np.exp(rng.uniform(np.log(0.01), np.log(0.2))))
    if row == "creep_drift":
        T = fac["cycles"] / fac["f"]
        per = 1.0 / fac["f"]
        lo, hi = CREEP["lo_periods"] * per, CREEP["hi_durations"] * T
        fac["tau_c"] = float(np.exp(rng.uniform(np.log(lo), np.log(hi))))
        size = float(np.exp(rng.uniform(np.log(CREEP["d_lo"]), np.log(CREEP["d_hi"]))))
        return fac, size * float(rng.choice([-1, 1]))
    if row == "asymmetric_branches":
        return fac, float(rng.uniform(0.15, 0.7)) * float(rng.choice([-1, 1]))
    return fac, 0.0


def own_size(row: str, size: float, fac: dict, d: np.ndarray) -> float:
    """The size in the parameter ``diagnose`` states its bound in (stiffness: hypot(κ, κ1)
    on δ_r, the measured displacement's RMS; creep: D in m; asymmetry: a)."""
    if row == "stiffness_nonlinearity":
        D = fac["ratio"] * 5e5 / 1.3e12
        dr = float(np.sqrt(np.mean(d * d)))
        law = fac["law"]
        k1 = size * dr / D if law in ("a2", "a23", "eq17", "p") else 0.0
        k2 = size * (dr / D) ** 2 if law in ("a3", "a23") else 0.0
        return float(math.hypot(k1, k2))
    if row == "creep_drift":
        return abs(size) * fac["ratio"] * 5e5 / 1.3e12
    return abs(size)


def rig_record(effect: str | None, size: float, fac: dict, seed: int):
    """The same draw on the package's rig simulator (:mod:`contactlab.synthetic.rig`):
    tone blocks ramped in from rest (``ramp`` cycles, at least 0.5), the pressure cell and
    the rig's anti-alias filters; δ noise ``noise_d``, pressure noise ``noise_p``."""
    from contactlab.synthetic.rig import rig_recording

    k, p0 = 1.3e12, 5e5
    pa = fac["ratio"] * p0
    D = pa / k
    eff = {}
    if effect == "stiffness_nonlinearity":
        law = fac["law"]
        a2 = size * k / D if law in ("a2", "a23", "eq17", "p") else 0.0
        a3 = size * k / D**2 if law in ("a3", "a23") else 0.0
        eff = {effect: {"a2": a2, "a3": a3}}
    elif effect == "asymmetric_branches":
        eff = {effect: {"a": size}}
    elif effect == "creep_drift":
        eff = {effect: {"D": size * D, "tau_c": fac["tau_c"]}}
    r = rig_recording(eff, "normal", seed=seed, fs=fac["fs"], f=fac["f"],
                      cycles=fac["cycles"], k=k, psi=fac["psi"], p0=p0, pa=pa,
                      x_noise=fac["noise_d"], F_noise=fac["noise_p"],
                      ramp_cycles=max(fac["ramp"], 0.5), bits=fac["bits"])  # fmt: skip
    return r.t, r.channels["p"], r.channels["delta"], None


from contactlab.errors import ContactLabError  # noqa: E402


def run(seed: int, rows: tuple[str, ...], gen: str = "chain", compare: bool = False) -> dict:
    rng = np.random.default_rng((420_000 if gen == "chain" else 520_000) + seed)
    base = factors(rng)
    out = {"seed": seed, "fac": dict(base), "rows": {}}
    for row in ROWS:
        fac, size = row_factors(rng, row, base)
        if row not in rows:
            continue
        effect = row if row != "clean" else None
        t0 = time.process_time()
        make = chain_record if gen == "chain" else rig_record
        t, p, d, _ = make(effect, size, fac, seed * 11 + ROWS.index(row))
        try:
            nm, fl, bd, par, gains, refused = diagnose(t, p, d)
        except ContactLabError as exc:  # a record diagnose refuses (too few cycles)
            out["rows"][row] = {"size": size, "own": 0.0, "law": fac.get("law"),
                                "named": [], "flagged": False, "bound": None, "params": {},
                                "gains": {}, "refused": {"record": str(exc)}, "cpu": 0.0,
                                "before": None, "error": str(exc)}  # fmt: skip
            continue
        before = None
        if compare:  # the rule changed nothing unless one of its hooks refused a candidate
            before = (nm, fl) if not gains["fired"] else diagnose(t, p, d, before=True)[:2]
        per = 1.0 / fac["f"]
        out["rows"][row] = {
            "size": size, "own": own_size(row, size, fac, d), "law": fac.get("law"),
            "tau_c_periods": fac["tau_c"] / per if "tau_c" in fac else None,
            "tau_c_durations": fac["tau_c"] / float(t[-1]) if "tau_c" in fac else None,
            "named": nm, "flagged": fl, "bound": bd.get(row), "params": par, "gains": gains,
            "refused": refused, "cpu": time.process_time() - t0, "before": before,
        }  # fmt: skip
    return out


def verdict(row: str, v: dict) -> str:
    if v.get("error"):
        return "refused record"
    if row == "clean":
        return "named" if v["named"] else ("flagged" if v["flagged"] else "ok")
    return "exact" if v["named"] == [row] else "+".join(v["named"]) or "nothing"


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--seeds", default="0-3")
    ap.add_argument("--rows", default=",".join(ROWS))
    ap.add_argument("--out", default=None)
    ap.add_argument("--gen", default="chain", choices=("chain", "rig"))
    ap.add_argument("--creep", default=None, help="lo_periods,hi_durations,d_lo,d_hi")
    ap.add_argument("--compare", action="store_true", help="also the verdict without the rule")
    a = ap.parse_args()
    if a.creep:
        CREEP.update(zip(("lo_periods", "hi_durations", "d_lo", "d_hi"),
                         (float(v) for v in a.creep.split(",")), strict=True))  # fmt: skip
    lo, hi = (int(s) for s in a.seeds.split("-"))
    rows = tuple(a.rows.split(","))
    res = []
    tally = defaultdict(Counter)
    for s in range(lo, hi + 1):
        r = run(s, rows, a.gen, a.compare)
        res.append(r)
        f = r["fac"]
        print(f"seed {s}: fs {f['fs']:.0f} f {f['f']:.2f} cyc {f['cycles']} ramp {f['ramp']:.1f} "
              f"noise p/d {100 * f['noise_p']:.2f}/{100 * f['noise_d']:.2f} % ψ {f['psi']:.2f}",
              flush=True)  # fmt: skip
        for e, v in r["rows"].items():
            extra = f" law {v['law']}" if v.get("law") else ""
            if v.get("tau_c_periods"):
                extra += f" τc {v['tau_c_periods']:.2f} per {v['tau_c_durations']:.2f} dur"
            b = v.get("bound")
            extra += f" own {v['own']:.3g} bound {b:.3g}" if isinstance(b, float) else ""
            g = {k: round(x, 2) for k, x in v["gains"].items()
                 if not k.endswith(":why") and k != "fired"}  # fmt: skip
            if v.get("before") is not None:
                extra += f" BEFORE {v['before'][0]} flagged {v['before'][1]}"
            print(f"   {e:24s} size {v['size']:+.3f}{extra} named {v['named']} "
                  f"flagged {v['flagged']} cpu {v['cpu']:.0f}s gains {g} "
                  f"refused {v['refused']}", flush=True)  # fmt: skip
            tally[e][verdict(e, v)] += 1
            if v.get("before") is not None:
                was = {"named": v["before"][0], "flagged": v["before"][1]}
                tally[e + " (before)"][verdict(e, was)] += 1
    print()
    for e, c in tally.items():
        print(f"{e:24s} " + ", ".join(f"{k} {n}" for k, n in c.most_common()))
    if a.out:
        Path(a.out).write_text(json.dumps(res, indent=1, default=str))


if __name__ == "__main__":
    main()
