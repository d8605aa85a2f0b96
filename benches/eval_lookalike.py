"""What ``diagnose`` names on the look-alike records of :mod:`chain_lookalike` (issue 29,
helper lookalike): per record the named set, the misfit flag, the bound the diagnosis states
for the true effect ("would be seen above"), the true size, and the held-out gains of the
true effect and its look-alikes at every step they were tried; then a table by pair
(exact / look-alike named / other / nothing), split at the stated bound, and the clean
records' rate of nothing named and nothing flagged.

    nice .venv/bin/python benches/eval_lookalike.py --base 41000 --n 4 --out /tmp/x.json
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from collections import defaultdict
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from chain_lookalike import EFFECTS, RIVALS, TRUE_NAME

#: the true effect's size in the diagnosis's own parameter
SIZE = {"channel_delay": ("channel_delay", "tau"), "stribeck": ("stribeck", "s"),
        "stick_slip": ("stick_slip", "b"), "normal_load": ("normal_load", "eps"),
        "displacement_offset": ("displacement_offset", "x0"),
        "backlash": ("backlash", "b"), "asymmetry": ("asymmetry", "a"),
        "normal_load_2f": ("normal_load", "eps"), "parallel_stiffness": ("parallel_stiffness",
        "k_p"), "force_offset": ("force_offset", "F0"), "viscous_damping": ("viscous_damping",
        "c"), "position_friction": ("position_friction", "eps")}  # fmt: skip


def true_name(kind: str) -> str | None:
    """The diagnosis's name of a record kind's true effect (None: a clean record)."""
    return TRUE_NAME.get(kind, kind)


#: the discriminators of this helper, by effect: ``--without`` takes them off (the "before" of
#: a before/after comparison on one tree)
HOOKS = {"backlash": ("yields_to_tried", None), "asymmetry": ("yields_to_tried", None),
         "displacement_offset": ("input_noise_share", 1.0)}  # fmt: skip


def _without(names: tuple[str, ...]) -> None:
    from contactlab.diagnose.effects import registry

    reg = registry("tangential")
    for n in names:
        cls = type(reg[n])
        attr, before = HOOKS[n]
        if before is not None:
            setattr(cls, attr, before)
        elif attr in cls.__dict__:
            delattr(cls, attr)


def run_job(job: tuple[str, int, str, tuple[str, ...]]) -> dict[str, Any]:
    import warnings

    from chain_lookalike import record
    from contactlab.diagnose.workflow import diagnose
    from contactlab.errors import ContactLabError

    warnings.simplefilter("ignore")
    effect, seed, chain, without = job
    _without(without)
    data, case = record(effect, seed, chain)
    out: dict[str, Any] = {"effect": effect, "seed": seed, "chain": chain,
                           "factors": case["factors"],
                           "truth": case["effects"], "A": case["A"]}  # fmt: skip
    if effect in SIZE:
        e, k = SIZE[effect]
        out["size"] = abs(float(case["effects"][e][k]))
        out["size"] = effective_size(effect, chain, case["factors"], out["size"])
    t0 = time.process_time()
    try:
        rep = diagnose(data, model="tangential")
    except ContactLabError as exc:
        out.update(error=str(exc)[:200], named=[], flagged=False)
        return out
    out["cpu"] = time.process_time() - t0
    out["named"] = list(rep.effect_names)
    out["params"] = {e.name: dict(e.parameters) for e in rep.effects}
    un = rep.unexplained
    out["flagged"] = bool(un is not None and un.flagged)
    nd = {x.effect: x for x in rep.not_detected}.get(true_name(effect) or "")
    out["bound"] = None if nd is None else nd.detectable_above
    out["bound_reason"] = None if nd is None else (nd.reason or "")[:200]
    out["bound_before"] = bound_before(rep, true_name(effect) or "")
    watch = (true_name(effect), *RIVALS.get(effect, ()))
    steps = []
    for st in rep.steps:
        row = {v.name: [float(v.gain), bool(v.accepted), (v.reason or "")[:200]]
               for v in st.candidates if v.name in watch or v.accepted}  # fmt: skip
        steps.append({"added": getattr(st, "added", None), "cands": row})
    out["steps"] = steps
    out["where"] = [w[:300] for w in rep.where]
    return json.loads(json.dumps(out, default=float))


def effective_size(
    effect: str, chain: str, fac: dict[str, Any], size: float | None
) -> float | None:
    """The true size the record shows: for a channel delay through the sensor chain, the
    skew between the channels, ``|τ - τ_x|``, ``τ_x`` the low-frequency group delay of the
    LVDT's low-pass on x (second-order Butterworth at ``x_lowpass``): it lags x as the
    delay lags the force (at 350-730 Hz, 0.48-0.73 ms: most of a 0.2-1 ms delay)."""
    if effect != "channel_delay" or chain != "sensors" or not fac.get("x_lowpass") or size is None:
        return size
    from contactlab.synthetic.rig.chain import butterworth, group_delay

    return abs(size - group_delay(butterworth(float(fac["x_lowpass"]), 2)))


def bound_before(rep: Any, name: str) -> float | None:
    """The bound stated for ``name`` without stop 42's honest-bound rules (the look-alikes not
    told apart, an effect seen and withdrawn, a normal load's bound at 2f beside a dashpot
    and a spring, their rivals):
    the report's bounds recomputed with them taken off (the named set does not depend on
    them). None when ``name`` is named or has no bound."""
    from contactlab.diagnose import search
    from contactlab.diagnose.effects import registry
    from contactlab.diagnose.power import stated_power

    if not name or name in rep.effect_names or rep.prepared is None:
        return None
    reg = registry("tangential")
    nl, ps, vd = (type(reg[n]) for n in ("normal_load", "parallel_stiffness", "viscous_damping"))
    saved = {c: {k: c.__dict__[k] for k in ("rivals", "power_shape", "power_note")
                 if k in c.__dict__} for c in (nl, ps, vd)}  # fmt: skip
    ties = rep.prepared.extra.pop(search.NOT_TOLD_APART, None)
    gone = rep.prepared.extra.pop("withdrawn", None)
    kept = rep.not_detected
    try:
        for c in (nl, ps):
            for k in saved[c]:
                if k != "power_note" or c is nl:
                    delattr(c, k)
        vd.rivals = ("channel_delay",)
        rep.not_detected = []
        det = rep.location.setdefault("detection", {})
        had = det.get("candidates")
        det["candidates"] = [name]  # the true effect's bound only
        try:
            nd = {x.effect: x for x in stated_power(rep)}.get(name)
        finally:
            det["candidates"] = had
        return None if nd is None else nd.detectable_above
    finally:
        for c, attrs in saved.items():
            for k, v in attrs.items():
                setattr(c, k, v)
        rep.not_detected = kept
        if ties is not None:
            rep.prepared.extra[search.NOT_TOLD_APART] = ties
        if gone is not None:
            rep.prepared.extra["withdrawn"] = gone


def verdict(r: dict[str, Any]) -> str:
    named = set(r.get("named", []))
    e = true_name(r["effect"])
    if e is None:
        return "quiet" if not named and not r.get("flagged") else ("named" if named else "flagged")
    if named == {e}:
        return "exact"
    if e in named:
        return "extra"
    if named & set(RIVALS[r["effect"]]):
        return "rival"
    return "other" if named else "nothing"


def above(r: dict[str, Any], key: str = "bound") -> bool | None:
    """Whether the true size exceeds the bound diagnose states for the true effect: None
    when it is named (no bound: it was seen); False when no bound is stated (no promise:
    not detectable, not separable, not told apart from a named look-alike)."""
    b = r.get(key)
    if true_name(r["effect"]) in r.get("named", []):
        return None
    if b is None or not np.isfinite(b):
        return False
    return r["size"] > b


def table(rows: list[dict[str, Any]]) -> str:
    lines = [
        "| effect | n | exact | extra | look-alike | other | nothing | above bound: "
        "exact / n | look-alike above bound | before stop 42's bounds: above bound exact / n, "
        "look-alike above |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    by = defaultdict(list)
    for r in rows:
        by[r["effect"]].append(r)
    for e in EFFECTS:
        rs = by.get(e, [])
        if not rs or true_name(e) is None:
            continue
        v = [verdict(r) for r in rs]
        ab = [r for r in rs if above(r) is not False]
        ab0 = [r for r in rs if above(r, "bound_before" if "bound_before" in r else "bound")
               is not False]  # fmt: skip
        lines.append(
            f"| {e} | {len(rs)} | {v.count('exact')} | {v.count('extra')} | {v.count('rival')} "
            f"| {v.count('other')} | {v.count('nothing')} | "
            f"{sum(verdict(r) == 'exact' for r in ab)}/{len(ab)} | "
            f"{sum(verdict(r) == 'rival' for r in ab)} | "
            f"{sum(verdict(r) == 'exact' for r in ab0)}/{len(ab0)}, "
            f"{sum(verdict(r) == 'rival' for r in ab0)} |"
        )
    for c in ("clean", "clean_wide"):
        cl = by.get(c, [])
        if not cl:
            continue
        v = [verdict(r) for r in cl]
        lines.append(f"\n{c}: nothing named or flagged {v.count('quiet')}/{len(cl)} "
                     f"(named {v.count('named')}, flagged only {v.count('flagged')})")  # fmt: skip
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--base", type=int, required=True)
    ap.add_argument("--n", type=int, default=4)
    ap.add_argument("--n-clean", type=int, default=None)
    ap.add_argument("--effects", default=",".join(EFFECTS))
    ap.add_argument("--jobs", type=int, default=1)
    ap.add_argument("--chain", default="sensors,plain", help="sensors, plain or both")
    ap.add_argument("--without", default="", help="effects whose new hook is taken off")
    ap.add_argument("--out", type=Path, default=None)
    a = ap.parse_args(argv)
    jobs = []
    for e in a.effects.split(","):
        n = a.n_clean if (true_name(e) is None and a.n_clean is not None) else a.n
        off = tuple(w for w in a.without.split(",") if w)
        jobs += [(e, a.base + i, c, off) for i in range(n) for c in a.chain.split(",")]
    rows = []
    with ProcessPoolExecutor(a.jobs) as ex:
        for r in ex.map(run_job, jobs):
            rows.append(r)
            fac = r["factors"]
            print(f"{r['effect']:20s} {r['seed']} {r['chain'][0]} f {fac['f']:.3g} "
                  f"acA {fac['acA']:.2f} xn {100 * fac['x_noise_range']:.2f}% "
                  f"size {r.get('size', 0):.3g} "
                  f"bound {r.get('bound_before')} -> {r.get('bound')} -> {r.get('named')} "
                  f"flag {r.get('flagged')} "
                  f"[{verdict(r)}] cpu {r.get('cpu', 0):.1f}", flush=True)  # fmt: skip
            if a.out:
                a.out.write_text(json.dumps(rows, indent=1))
    print(table(rows))


if __name__ == "__main__":
    main()
