"""Inertia and channel delay through a realistic sensor chain (issue 29): what ``diagnose``
names, what it states it would have seen, on :mod:`chain_inertia_delay` records (start from
rest, load-cell resonance, Butterworth anti-alias filters of order 2-4, quantisation,
displacement noise 0.5-2 % and drift).

Per record: the named set, the misfit flag, the verdicts on ``inertia`` and
``channel_delay``, the bound the diagnosis states for the effect ("would be seen above"),
and an independent visibility figure: the noncentrality ``Σ Δ² / σ_F²`` of the noise-free
force the effect adds at the ADC over the steady cycles (after the first two).

    nice .venv/bin/python benches/eval_inertia_delay_chain.py --base 100 --n 8 \
        --out benches/results/inertia_delay_chain_x.md
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

EFFECTS = ("inertia", "channel_delay", "clean", "backlash")


def _size_of(effect: str, info: dict[str, Any]) -> float:
    return {"inertia": info["m"], "channel_delay": info["tau"],
            "backlash": info.get("b", 0.0)}.get(effect, 0.0)  # fmt: skip


def run_job(job: tuple[int, str, dict[str, Any]]) -> dict[str, Any]:
    import warnings

    from chain_inertia_delay import draw, effect_signal, record
    from contactlab.diagnose.workflow import diagnose
    from contactlab.errors import ContactLabError

    warnings.simplefilter("ignore")
    seed, effect, over = job
    (t, x, F), fac, info = record(seed, effect, **over)
    out: dict[str, Any] = {"seed": seed, "effect": effect, "factors": fac, "size": 0.0}
    if effect != "clean":
        d = effect_signal(draw(seed, effect, **over) | {"seed": seed}, effect)
        steady = t >= 2.0 / fac["f"]
        out["nc"] = float(np.sum(d[steady] ** 2) / info["sigma_F"] ** 2)
        out["rms_over_noise"] = float(np.sqrt(np.mean(d[steady] ** 2)) / info["sigma_F"])
        out["size"] = _size_of(effect, info)
    t0 = time.process_time()
    try:
        rep = diagnose((t, x, F), model="tangential")
    except ContactLabError as exc:
        out.update(error=str(exc)[:200], named=[], flagged=False)
        return out
    out["named"] = list(rep.effect_names)
    out["params"] = {e.name: dict(e.parameters) for e in rep.effects}
    un = rep.unexplained
    out["flagged"] = bool(un is not None and un.flagged)
    for name in ("inertia", "channel_delay", "backlash"):
        vs = [v for st in rep.steps for v in st.candidates if v.name == name]
        out[f"{name}_verdicts"] = [
            {"gain": v.gain, "t": v.t_stat, "accepted": v.accepted,
             "reason": (v.reason or "")[:300]}
            for v in vs
        ]  # fmt: skip
        nd = {x.effect: x for x in rep.not_detected}.get(name)
        out[f"{name}_bound"] = None if nd is None else nd.detectable_above
        out[f"{name}_nd"] = "" if nd is None else (nd.reason or "")[:300]
    out["where"] = [w[:240] for w in rep.where]
    out["cpu"] = time.process_time() - t0
    return json.loads(json.dumps(out, default=float))


def _visible(r: dict[str, Any]) -> bool | None:
    """Above the bound the diagnosis stated (None: it stated none)."""
    b = r.get(f"{r['effect']}_bound")
    if b is None or not np.isfinite(b):
        return None
    return abs(r["size"]) >= b


def tables(res: list[dict[str, Any]]) -> str:
    lines = ["| effect | n | exact | with extra | nothing | wrong | flagged | errors |",
             "|---|---|---|---|---|---|---|---|"]  # fmt: skip
    by = defaultdict(list)
    for r in res:
        by[r["effect"]].append(r)
    for e in EFFECTS:
        rows = by.get(e, [])
        if not rows:
            continue
        if e == "clean":
            ok = sum(not r["named"] for r in rows)
            extra, missed, wrong = 0, 0, sum(bool(r["named"]) for r in rows)
        else:
            ok = sum(r["named"] == [e] for r in rows)
            extra = sum(e in r["named"] and r["named"] != [e] for r in rows)
            missed = sum(not r["named"] for r in rows)
            wrong = sum(bool(r["named"]) and e not in r["named"] for r in rows)
        fl = sum(r["flagged"] for r in rows)
        er = sum(bool(r.get("error")) for r in rows)
        lines.append(f"| {e} | {len(rows)} | {ok} | {extra} | {missed} | {wrong} | {fl} | {er} |")
    clean = by.get("clean", [])
    n_ok = sum(not r["named"] and not r["flagged"] for r in clean)
    n_id = sum(bool({"inertia", "channel_delay"} & set(r["named"])) for r in clean)
    lines += ["", f"clean: nothing named and nothing flagged {n_ok}/{len(clean)}; "
              f"inertia or delay named {n_id}/{len(clean)}", ""]  # fmt: skip
    lines += ["| effect | outcome against the stated bound | n |", "|---|---|---|"]
    for e in ("inertia", "channel_delay", "backlash"):
        bb: dict[str, int] = defaultdict(int)
        for r in by.get(e, []):
            v = _visible(r)
            if r["named"] == [e]:
                k = "named exactly"
            elif e in r["named"]:
                k = "named with others"
            elif v is None:
                k = "not named, no bound stated"
            else:
                k = (
                    "not named, ABOVE its stated bound (a miss)"
                    if v
                    else ("not named, below its stated bound (honest)")
                )
            bb[k] += 1
        for k in sorted(bb):
            lines.append(f"| {e} | {k} | {bb[k]} |")
    lines += ["", "| seed | effect | fs | f | cyc | ac·A | start | aa | x noise | size | nc | "
              "bound | named | flag | verdict (last) |",
              "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]  # fmt: skip
    for r in sorted(res, key=lambda r: (EFFECTS.index(r["effect"]), r["seed"])):
        fac = r["factors"]
        e = r["effect"]
        vname = e if e != "clean" else "inertia"
        v = (r.get(f"{vname}_verdicts") or [{}])[-1]
        vt = ""
        if v:
            vt = (f"{'acc' if v['accepted'] else 'no'} g={v['gain']:.3g} t={v['t']:.3g} "
                  f"{v['reason'][:100]}").replace("|", "/")  # fmt: skip
        b = r.get(f"{vname}_bound")
        bt = "-" if b is None or not np.isfinite(b) else f"{b:.3g}"
        named = "+".join(r["named"]) or "-"
        if r.get("error"):
            named = "ERROR " + r["error"][:60]
        lines.append(
            f"| {r['seed']} | {e} | {fac['fs']:g} | {fac['f']:g} | {fac['cycles']} | "
            f"{fac['acA']:g} | {fac['start']} | {fac['aa_order']}@{fac['aa_ratio']:.2f} | "
            f"{100 * fac['x_noise']:.2f} % | {r['size']:.3g} | {r.get('nc', 0):.3g} | {bt} | "
            f"{named} | {'F' if r['flagged'] else ''} | {vt} |"
        )
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--base", type=int, default=0)
    ap.add_argument("--n", type=int, default=6)
    ap.add_argument("--n-clean", type=int, default=None)
    ap.add_argument("--effects", default=",".join(EFFECTS))
    ap.add_argument("--over", default="{}", help="factors fixed for every record (JSON)")
    ap.add_argument("--jobs", type=int, default=1)
    ap.add_argument("--out", default=None)
    ap.add_argument("--tables", default=None, help="print the tables of a saved .json only")
    a = ap.parse_args(argv)
    if a.tables:
        print(tables(json.loads(Path(a.tables).read_text())))
        return
    over = json.loads(a.over)
    jobs = []
    for e in a.effects.split(","):
        n = a.n_clean if (e == "clean" and a.n_clean) else a.n
        jobs += [(a.base + i, e, over) for i in range(n)]
    t0 = time.time()
    res = []
    if a.jobs > 1:
        with ProcessPoolExecutor(a.jobs) as ex:
            res = list(ex.map(run_job, jobs))
    else:
        for j in jobs:
            res.append(run_job(j))
            r = res[-1]
            print(j[:2], r["named"], "F" if r["flagged"] else "", f"{r.get('cpu', 0):.0f}s",
                  file=sys.stderr, flush=True)  # fmt: skip
    text = f"base {a.base}, n {a.n}, over {over}, {time.time() - t0:.0f} s\n\n" + tables(res)
    print(text)
    if a.out:
        Path(a.out).write_text(text + "\n")
        Path(a.out).with_suffix(".json").write_text(json.dumps(res, indent=1))


if __name__ == "__main__":
    main()
