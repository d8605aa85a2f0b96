"""Where a normal load's power is lost (issue 29, helper nload): rig records
(``contactlab.synthetic.rig``) with a ``normal_load`` of two kinds,

- ``beat``: f_N = r·f, r uniform in 0.3-3.7 and not within 0.15 of an integer, eps 0.3-1.2 %;
- ``2f``: f_N = 2f exactly, eps 1-5 %;

fs 1-10 kHz, drive 2-50 Hz, 5-50 cycles (at most ``MAX_SAMPLES`` samples), ac·A 0.35-3.8,
white noise 0.6-2 % of the range on x and 0.8-2 % on F, the rig's identical anti-alias
filters on both channels, 16 bits. Each record is diagnosed once; its oracle noncentrality

    λ = Σ Δ⊥² / V,   V = σF² + (k σx)²,

``Δ`` the load's force signature (noise-free record with minus without the load, less what
the Masing law predicts from the change of the measured x), ``⊥`` after projecting out the
base model's directions (h0, ac), ``k`` the law's local slope, is printed beside the
verdict. A missed record is put at the stage where it is lost, from the diagnosis's first
verdict on ``normal_load`` and the start frequency its search takes from the base's residual:

- ``search``: the start frequency is more than one bin (1/T) from f_N;
- ``in-sample floor``: in-sample gain below ``min_gain`` (the per-sample floor);
- ``min_gain``: held-out gain below ``min_gain``; ``budget``: above ``min_gain``, below
  ``min_gain`` + the input-noise budget;
- ``significance``: t, BIC or the share of the remaining error;
- ``refused``: implausible / look-alike / yields (normal_load.py's rules);
- ``comparison``: accepted but another candidate was named at that step.

    nice .venv/bin/python benches/eval_load_stage.py --seed-base 29900000 --n 12
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np

H0, AC = 40.0, 4.0e4
MAX_SAMPLES = 16_000


#: ``--clean``: clean twins (no load; ``--law`` a rig base law no candidate draws, e.g.
#: ``tanh_virgin``) with the noise of both channels drawn from ``--noise lo,hi`` (% of range)
CLEAN = {"on": False, "law": None, "noise": None, "other": None}
#: ``--other``: records with another effect instead of the load (rotating by seed), at a size
#: the diagnosis sees on most records: are they named normal_load?
OTHERS = ("position_friction", "stribeck", "parallel_stiffness", "channel_delay", "stick_slip")


def other_effect(fac: dict, seed: int) -> dict:
    A = fac["acA"] / AC
    name = fac["other"]
    par = {
        "position_friction": {"eps": 0.04, "L": 1.5 * A, "phi": fac["phi"]},
        "stribeck": {"s": 0.08},
        "parallel_stiffness": {"k_p": 0.1 * H0 / A},
        "channel_delay": {"tau": 0.004 / fac["f"]},
        "stick_slip": {"b": 0.12},
    }[name]
    return {name: par}


def factors(seed: int) -> dict:
    rng = np.random.default_rng(seed)
    kind = "beat" if seed % 2 == 0 else "2f"
    fs = float(np.exp(rng.uniform(np.log(1000.0), np.log(10000.0))))
    f = float(np.exp(rng.uniform(np.log(2.0), np.log(50.0))))
    cycles = int(rng.integers(5, 51))
    cycles = max(5, min(cycles, int(MAX_SAMPLES * f / fs)))
    fac = {
        "kind": kind,
        "fs": round(fs, 1),
        "f": round(f, 3),
        "cycles": cycles,
        "acA": round(float(np.exp(rng.uniform(np.log(0.35), np.log(3.8)))), 3),
        "x_noise": round(float(rng.uniform(0.006, 0.02)), 4),
        "F_noise": round(float(rng.uniform(0.008, 0.02)), 4),
        "phi": float(rng.uniform(0, 2 * math.pi)),
    }
    if kind == "beat":
        while True:
            r = float(rng.uniform(0.3, 3.7))
            if abs(r - round(r)) >= 0.15:
                break
        fac["r"] = r
        fac["eps"] = float(rng.uniform(0.003, 0.012))
    else:
        fac["r"] = 2.0
        fac["eps"] = float(rng.uniform(0.01, 0.05))
    fac["f_n"] = fac["r"] * fac["f"]
    if CLEAN["on"]:
        fac["kind"], fac["eps"] = "clean", 0.0
        if CLEAN["noise"]:
            lo, hi = CLEAN["noise"]
            fac["x_noise"] = round(float(rng.uniform(lo, hi)) / 100, 4)
            fac["F_noise"] = round(float(rng.uniform(lo, hi)) / 100, 4)
        if CLEAN["other"]:
            fac["other"] = OTHERS[seed % len(OTHERS)]
    return fac


def record(fac: dict, seed: int, eps: float | None = None, quiet: bool = False):
    from contactlab.synthetic.rig import rig_recording

    eps = fac["eps"] if eps is None else eps
    eff = {"normal_load": {"eps": eps, "f_n": fac["f_n"], "phi": fac["phi"]}} if eps else {}
    if CLEAN["law"]:
        eff[CLEAN["law"]] = {}
    if CLEAN["other"]:
        eff.update(other_effect(fac, seed))
    kw = {k: fac[k] for k in ("fs", "f", "cycles", "acA", "x_noise", "F_noise")}
    if quiet:
        kw.update(x_noise=0.0, F_noise=0.0, bits=None)
    return rig_recording(eff, "tangential", seed=seed, **kw)


def read(rec):
    import contactlab

    with tempfile.TemporaryDirectory() as tmp:
        return contactlab.read_recording(str(rec.to_csv(Path(tmp) / "r.csv")))


def oracle_lambda(fac: dict, seed: int) -> float:
    from contactlab.masing import Masing

    q0 = record(fac, seed, eps=0.0, quiet=True)
    q1 = record(fac, seed, quiet=True)
    noisy = record(fac, seed, eps=0.0)
    x0, x1, F0, F1 = q0.channels["x"], q1.channels["x"], q0.channels["F"], q1.channels["F"]
    m0 = Masing(H0, AC).force(x0)
    d_ac = (Masing(H0, AC * 1.001).force(x0) - Masing(H0, AC * 0.999).force(x0)) / (0.002 * AC)
    base = np.column_stack([m0 / H0, d_ac])
    dx = np.gradient(x0)
    k = np.abs(np.gradient(m0) / np.where(dx == 0, np.nan, dx))
    k = np.clip(np.nan_to_num(k, nan=H0 * AC), 0, H0 * AC)
    noise = noisy.truth["chain"]["noise_rms"]
    V = noise["F"] ** 2 + (k * noise["x"]) ** 2
    delta = (F1 - F0) - (Masing(H0, AC).force(x1) - m0)
    w = 1.0 / np.sqrt(V)
    a = base * w[:, None]
    beta, *_ = np.linalg.lstsq(a, delta * w, rcond=None)
    r = delta * w - a @ beta
    return float(np.sum(r * r))


def start_offset(rep, fac: dict) -> tuple[float | None, float | None]:
    """The start frequency the load's search takes from the base model's residual, and its
    distance from the true f_N in bins (1/T)."""
    try:
        d = rep.prepared
        base = rep.trials[0]
        fam = rep.final_model.family
        st = fam.start_effect("normal_load", dict(base.full.params), d, -base.full_residual(d))
        fn = float(st["f_n"])
        return fn, abs(fn - fac["f_n"]) * float(d.duration)
    except Exception:
        return None, None


def stage_of(rep, start_bins) -> tuple[str, dict | None]:
    named = list(rep.effect_names)
    if "normal_load" in named:
        return ("exact" if named == ["normal_load"] else "named+"), None
    for st in rep.steps:
        for v in st.candidates:
            if v.name != "normal_load":
                continue
            why = {"gain": v.gain, "t": v.t_stat, "reason": v.reason[:160]}
            rs = v.reason
            if start_bins is not None and start_bins > 1.0 and not v.accepted:
                return "search", why
            if rs.startswith("in-sample gain"):
                return "in-sample floor", why
            if rs.startswith("held-out gain"):
                floor = float(rs.split("below ")[1].split(" ")[0])
                mg = rep.location.get("min_gain")
                if v.gain < 0.05 or (mg is not None and v.gain < mg):
                    return "min_gain", why
                return ("budget" if v.gain < floor else "held-out"), why
            if rs.startswith(("gain not significant", "BIC", "held-out gain share")) or (
                "sliver" in rs
            ):
                return "significance", why
            if v.accepted:
                return "comparison", why
            return "refused", why
    return "not tried", None


def run_seed(seed: int) -> dict:
    import contactlab

    warnings.simplefilter("ignore")
    fac = factors(seed)
    t0 = time.process_time()
    out = {"seed": seed, "factors": fac}
    out["lambda"] = 0.0 if CLEAN["on"] else oracle_lambda(fac, seed)
    rep = contactlab.diagnose(read(record(fac, seed + 1)), model="tangential")
    fn0, bins = start_offset(rep, fac)
    out["start_f_n"], out["start_bins"] = fn0, bins
    out["stage"], out["verdict"] = stage_of(rep, bins)
    out["named"] = list(rep.effect_names)
    b = next((b for b in rep.not_detected if b.effect == "normal_load"), None)
    out["bound"] = None if b is None else b.detectable_above
    out["cpu"] = time.process_time() - t0
    return json.loads(json.dumps(out, default=float))


def summary(res: list[dict]) -> str:
    lines = []
    for kind in ("beat", "2f", "clean"):
        rows = [r for r in res if r["factors"]["kind"] == kind]
        if not rows:
            continue
        det = sum(r["stage"] in ("exact", "named+") for r in rows)
        vis = [r for r in rows if r["lambda"] >= 44.8]
        dv = sum(r["stage"] in ("exact", "named+") for r in vis)
        stages: dict[str, int] = {}
        for r in rows:
            stages[r["stage"]] = stages.get(r["stage"], 0) + 1
        if kind == "clean":
            anyn = sum(bool(r["named"]) for r in rows)
            lines.append(f"clean: normal_load named {det}/{len(rows)}, anything {anyn}")
            continue
        lines.append(
            f"{kind}: named {det}/{len(rows)}; oracle λ >= 44.8: {dv}/{len(vis)}; stages "
            + ", ".join(f"{k} {v}" for k, v in sorted(stages.items()))
        )
    lines.append("")
    for r in res:
        f = r["factors"]
        bound = None if r["bound"] is None else round(r["bound"], 4)
        sb = None if r["start_bins"] is None else round(r["start_bins"], 2)
        lines.append(
            f"{r['seed']} {f['kind']:4s} eps {f['eps']:.4f} r {f['r']:.3f} λ {r['lambda']:.0f} "
            f"{f.get('other', '')} -> {r['stage']} named {r['named']} bound {bound}"
            f" start_bins {sb}"
            f" {r['verdict']} (fs {f['fs']}, f {f['f']}, cyc {f['cycles']}, acA {f['acA']}, "
            f"xn {f['x_noise']}, Fn {f['F_noise']}) cpu {r['cpu']:.0f}s"
        )
    return "\n".join(lines)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seed-base", type=int, required=True)
    ap.add_argument("--n", type=int, default=12)
    ap.add_argument("--raw", type=Path, default=None)
    ap.add_argument("--tables-from", type=Path, default=None)
    ap.add_argument("--clean", action="store_true")
    ap.add_argument("--law", default=None)
    ap.add_argument("--other", action="store_true", help="another effect, no load")
    ap.add_argument("--noise", default=None, help="lo,hi in % of the range (--clean)")
    a = ap.parse_args(argv)
    noise = tuple(float(v) for v in a.noise.split(",")) if a.noise else None
    CLEAN.update(on=a.clean or a.other, law=a.law, noise=noise, other=a.other)
    if a.tables_from:
        print(summary(json.loads(a.tables_from.read_text())))
        return
    res = []
    for s in range(a.seed_base, a.seed_base + a.n):
        try:
            r = run_seed(s)
        except Exception as exc:
            print(f"{s}: error {type(exc).__name__}: {exc}", file=sys.stderr, flush=True)
            continue
        res.append(r)
        print(summary([r]).splitlines()[-1], file=sys.stderr, flush=True)
        if a.raw:
            a.raw.write_text(json.dumps(res, indent=1))
    import contactlab

    print(f"{contactlab.__file__}: seed base {a.seed_base}, n {a.n}, clean {CLEAN}\n")
    print(summary(res))


if __name__ == "__main__":
    main()
