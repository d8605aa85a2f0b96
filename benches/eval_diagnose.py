"""Evaluation of the discrepancy workflow on recordings with hidden effects (issue 5).

For every effect of the candidate library (and for clean data), several magnitudes, noise
levels and seeds, a recording is generated with
:func:`contactlab.diagnose.hidden_effect_recording` and handed to :func:`contactlab.diagnose`
(which sees only the recording). Prints

- the confusion matrix: true effect (rows) against the set of effects named (columns: each
  effect named alone, "none", or "other" for a wrong or longer list);
- the fraction exactly right per magnitude and per noise level;
- the median gap shrink: held-out RMS before / after, in units of the estimated noise, and
  the median ratio of the final held-out RMS to the noise;
- a few two-effect cases.

Run: ``.venv/bin/python benches/eval_diagnose.py [--model tangential|normal] [--seeds 3]``.
Takes minutes; not part of the test suite.
"""

from __future__ import annotations

import argparse
import itertools
import json
import time
from collections import Counter, defaultdict

import numpy as np

import contactlab
from contactlab.diagnose import hidden_effect_recording


def effects_of(model: str) -> tuple[str, ...]:
    if model == "tangential":
        from contactlab.diagnose.generator import TANGENTIAL_EFFECTS

        return TANGENTIAL_EFFECTS
    from contactlab.diagnose.generator_normal import NORMAL_EFFECTS

    return NORMAL_EFFECTS


def run_case(model: str, effects: tuple[str, ...], mag: float, noise: float, seed: int) -> dict:
    rec = hidden_effect_recording(list(effects), model=model, magnitude=mag, noise=noise, seed=seed)
    t0 = time.perf_counter()
    rep = contactlab.diagnose(rec, model=model)
    dt = time.perf_counter() - t0
    return {
        "true": list(effects),
        "named": rep.effect_names,
        "magnitude": mag,
        "noise": noise,
        "seed": seed,
        "before": rep.steps[0].heldout_rms / rep.noise_rms,
        "after": rep.steps[-1].heldout_rms / rep.noise_rms,
        "energy_before": rep.steps[0].energy_error,
        "energy_after": rep.steps[-1].energy_error,
        "seconds": dt,
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--model", default="tangential", choices=["tangential", "normal"])
    ap.add_argument("--seeds", type=int, default=3)
    ap.add_argument("--magnitudes", default="0.02,0.05,0.1")
    ap.add_argument("--noises", default="0.005,0.01,0.02")
    ap.add_argument("--json", help="write all cases to this file")
    args = ap.parse_args()
    mags = [float(v) for v in args.magnitudes.split(",")]
    noises = [float(v) for v in args.noises.split(",")]
    effs = effects_of(args.model)
    cases = []
    t0 = time.perf_counter()
    for eff, mag, noise, seed in itertools.product(
        (None, *effs), mags, noises, range(1000, 1000 + args.seeds)
    ):
        if eff is None and mag != mags[0]:
            continue  # clean data has no magnitude
        cases.append(run_case(args.model, () if eff is None else (eff,), mag, noise, seed))
        c = cases[-1]
        print(
            f"  {len(cases):4d} {eff or 'none':<24} mag {mag:<5g} noise {noise:<6g} seed {seed}"
            f" -> {c['named']}",
            flush=True,
        )
    family = contactlab.diagnose.workflow._family(args.model)[0]
    pairs = [pr for pr in itertools.combinations(effs, 2) if family.check(pr)]
    rng = np.random.default_rng(7)
    two = [pairs[i] for i in rng.choice(len(pairs), size=min(8, len(pairs)), replace=False)]
    two_cases = [
        run_case(args.model, pair, 0.05, 0.01, 2000 + s) for pair in two for s in range(args.seeds)
    ]
    wall = time.perf_counter() - t0

    cols = [*effs, "none", "other"]
    conf: dict[str, Counter] = defaultdict(Counter)
    for c in cases:
        row = c["true"][0] if c["true"] else "none"
        named = c["named"]
        col = "none" if not named else (named[0] if len(named) == 1 else "other")
        conf[row][col] += 1
    short = {e: e[:10] for e in cols}
    print(f"\nConfusion matrix ({args.model}; rows: hidden effect, columns: named)")
    print(f"{'':>20}" + "".join(f"{short[c]:>11}" for c in cols))
    for r in [*effs, "none"]:
        print(f"{r:>20}" + "".join(f"{conf[r][c]:>11d}" for c in cols))
    ok = [c for c in cases if c["named"] == c["true"]]
    print(f"\nexactly right: {len(ok)}/{len(cases)} = {100 * len(ok) / len(cases):.1f} %")
    for m in mags:
        sub = [c for c in cases if c["true"] and c["magnitude"] == m]
        right = sum(c["named"] == c["true"] for c in sub)
        print(f"  magnitude {m:g}: {right}/{len(sub)}")
    for nz in noises:
        sub = [c for c in cases if c["noise"] == nz]
        right = sum(c["named"] == c["true"] for c in sub)
        print(f"  noise {nz:g}: {right}/{len(sub)}")
    eff_cases = [c for c in cases if c["true"]]
    b = np.median([c["before"] for c in eff_cases])
    a = np.median([c["after"] for c in eff_cases])
    print(
        f"\nmedian held-out RMS / noise: before {b:.2f}, after {a:.2f} "
        f"(median shrink ×{np.median([c['before'] / c['after'] for c in eff_cases]):.2f}); "
        f"after <= 1.5 in {sum(c['after'] <= 1.5 for c in eff_cases)}/{len(eff_cases)}"
    )
    eb = np.median([c["energy_before"] for c in eff_cases])
    ea = np.median([c["energy_after"] for c in eff_cases])
    print(f"median loop-energy error: before {100 * eb:.2f} %, after {100 * ea:.2f} %")
    print("\nTwo hidden effects (magnitude 0.05 each, noise 0.01):")
    for c in two_cases:
        mark = "ok" if sorted(c["named"]) == sorted(c["true"]) else "--"
        print(f"  {mark} {' + '.join(c['true']):<45} named {c['named']}  after {c['after']:.2f}")
    right2 = sum(sorted(c["named"]) == sorted(c["true"]) for c in two_cases)
    print(f"two-effect cases right: {right2}/{len(two_cases)}")
    print(
        f"\n{len(cases) + len(two_cases)} diagnoses in {wall:.0f} s "
        f"(median {np.median([c['seconds'] for c in cases + two_cases]):.2f} s each)"
    )
    if args.json:
        with open(args.json, "w", encoding="utf-8") as fh:
            json.dump({"single": cases, "two": two_cases}, fh, indent=1)


if __name__ == "__main__":
    main()
