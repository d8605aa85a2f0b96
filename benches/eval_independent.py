"""Evaluate ``contactlab diagnose --json`` on an independently written generator (issue 29).

The generator (benches/independent/) was written from docs/effects.md and PHYSICS.md only,
without reading the package's diagnosis or its generators. For every effect record a clean
twin (same chain, same noise streams, effect off) is diagnosed too: the twins are the clean
records of the false-alarm table, and the bound the diagnosis states on the twin for the
effect ("detectable_above") is one of the two visibility judgements; the other is the
generator's own noncentrality criterion (benches/independent/visibility.py).

Usage::

    nice .venv/bin/python benches/eval_independent.py --quick
    nice .venv/bin/python benches/eval_independent.py --n 2 --label before --seed-base 123

Seeds come from the clock unless ``--seed-base`` is given (printed either way). Results go to
benches/results/eval_independent_<label>.md (markdown tables) and a JSON of every record.
"""

from __future__ import annotations

import argparse
import itertools
import json
import math
import os
import subprocess
import sys
import tempfile
import time
from collections import Counter, defaultdict
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE / "independent"))

from generator import MISFITS, NORMAL_EFFECTS, TANGENTIAL_EFFECTS, tangential_record  # noqa: E402
from sizes import make_pair  # noqa: E402

ROOT = HERE.parent
CLI = ROOT / ".venv" / "bin" / "contactlab"

# diagnose's bound parameter for each effect whose units match the document's magnitude
SAME_UNITS = {
    "viscous_damping": ("c", lambda p, T: p["c"]),
    "inertia": ("m", lambda p, T: p["m"]),
    "parallel_stiffness": ("k_p", lambda p, T: p["k_p"]),
    "series_compliance": ("C_s", lambda p, T: p["C_s"]),
    "force_offset": ("F0", lambda p, T: p["F0"]),
    "displacement_offset": ("x0", lambda p, T: p["x0"]),
    "channel_delay": ("tau", lambda p, T: p["tau"]),
    "asymmetry": ("alpha", lambda p, T: p["a"]),
    "non_masing_scaling": ("lam", lambda p, T: p["lam"] - 2.0),
    "stribeck": ("s", lambda p, T: p["s"]),
    "stick_slip": ("s_b", lambda p, T: p["b"]),
    "creep_drift": ("D", lambda p, T: p["D"]),
    # diagnose normalises these by the record's length (checked on named values: 1.02-1.03)
    "force_drift": ("F1", lambda p, T: p["Fdot"] * T["cycles"] / T["f"]),
    "parameter_drift": ("beta", lambda p, T: p["beta"] * T["cycles"] / T["f"]),
}


def run_diagnose(csv: Path, kind: str) -> tuple[dict | None, float, str]:
    out = csv.with_suffix(".json")
    env = dict(
        os.environ, CONTACTLAB_DIAGNOSE_THREADS="1", OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1"
    )
    t0 = os.times()
    proc = subprocess.run(
        ["nice", str(CLI), "diagnose", str(csv), "--json", str(out), "--model", kind],
        capture_output=True,
        text=True,
        env=env,
        timeout=600,
    )
    t1 = os.times()
    cpu = (t1.children_user - t0.children_user) + (t1.children_system - t0.children_system)
    if proc.returncode != 0 or not out.exists():
        return (
            None,
            cpu,
            (proc.stderr or proc.stdout).strip().splitlines()[-1:][0]
            if (proc.stderr or proc.stdout)
            else "no output",
        )
    return json.loads(out.read_text()), cpu, ""


def _summary(d: dict | None) -> dict:
    if d is None:
        return {"failed": True, "named": [], "flagged": False}
    un = d.get("unexplained") or {}
    return {
        "failed": False,
        "named": sorted(e["name"] for e in d.get("effects", [])),
        "params": {e["name"]: e.get("parameters", {}) for e in d.get("effects", [])},
        "flagged": bool(un.get("flagged", False)),
        "flag_where": un.get("where", []),
        "not_detected": {n["effect"]: n for n in d.get("not_detected", [])},
    }


def _ideal_relative_change(rec) -> float:
    """RMS of the effect's change of the output over the output's RMS (noise-free)."""
    from generator import masing_series, virgin_function
    from visibility import kv_from_rest

    T, sig = rec.truth, rec.ideal
    if rec.kind == "tangential":
        base = masing_series(sig["x_rep"], virgin_function("exponential", T["h0"], T["ac"]))
        y = sig["F"]
    else:
        w = 2 * math.pi * T["f"]
        base = kv_from_rest(sig["t"], T["t_pre"], T["pa"], T["k"], T["c"], w)
        y = sig["delta"]
    return float(np.sqrt(np.mean((y - base) ** 2)) / np.sqrt(np.mean(base**2)))


def job(spec: dict) -> dict:
    """Generate one record (and its clean twin), diagnose both, return the summary."""
    kind, label, seed = spec["kind"], spec["label"], spec["seed"]
    rng = np.random.default_rng(seed + 7919)
    t0 = time.process_time()
    out = {"kind": kind, "label": label, "seed": seed, "size_class": spec.get("size_class")}
    with tempfile.TemporaryDirectory(prefix="diageval_") as tmp:
        tmp = Path(tmp)
        if label in MISFITS:
            rec = tangential_record(seed, label)
            twin = None
            from visibility import THRESHOLD, tangential_visibility

            lam_d, lam_i, near, _ = tangential_visibility(rec.ideal, rec.truth, label)
            info = {
                "lam_detect": lam_d,
                "lam_identify": lam_i,
                "nearest": near,
                "visible_own": bool(lam_i >= THRESHOLD),
            }
        else:
            twin, rec, info = make_pair(kind, label, seed, spec["size_class"], rng)
        gen_cpu = time.process_time() - t0
        rec.write_csv(tmp / "rec.csv")
        d, cpu, err = run_diagnose(tmp / "rec.csv", kind)
        out["rec"] = _summary(d)
        out["rec"]["error"] = err
        out["cpu_diagnose"] = cpu
        if twin is not None:
            twin.write_csv(tmp / "twin.csv")
            dt, cpu2, err2 = run_diagnose(tmp / "twin.csv", kind)
            out["twin"] = _summary(dt)
            out["twin"]["error"] = err2
            out["cpu_diagnose"] += cpu2
            out["twin_truth"] = _truth_factors(twin.truth, kind)
            if out["twin"]["named"] or out["twin"]["flagged"]:
                # attribute a false alarm: the same twin with x noise 0.5 %, no hum, no jitter
                out["twin_ablation"] = _ablate(twin, seed, kind, tmp)
                out["cpu_diagnose"] += out["twin_ablation"].pop("cpu")
            # the bound diagnose states on the clean twin for this effect
            nd = out["twin"].get("not_detected", {}).get(label)
            out["bound"] = None
            if nd is not None:
                rel = _ideal_relative_change(rec)
                out["bound"] = {
                    "parameter": nd.get("parameter"),
                    "detectable_above": nd.get("detectable_above"),
                    "relative_size": nd.get("relative_size"),
                    "true_relative_change": rel,
                }
            # compact twin: drop the long not_detected map
            out["twin"].pop("not_detected", None)
        out["rec"].pop("not_detected", None)
    out["truth"] = _truth_factors(rec.truth, kind)
    out["params"] = rec.truth["params"]
    out["info"] = info
    out["cpu_generate"] = gen_cpu
    if "twin" in out:
        out["visible_bound"] = visible_by_bound(out)
    return out


def _ablate(twin, seed: int, kind: str, tmp: Path) -> dict:
    import dataclasses

    from generator import normal_record

    T = twin.truth
    ch = dataclasses.replace(twin.chain, hum_x=0.0, hum_y=0.0, jitter=0.0, noise_x=0.005)
    if kind == "tangential":
        base = {"h0": T["h0"], "ac": T["ac"], "A": T["A_target"]}
        rec = tangential_record(seed, "clean", chain=ch, base=base)
    else:
        base = {"p0": T["p0"], "pa": T["pa"], "k": T["k"], "psi": T["psi"]}
        rec = normal_record(seed, "clean", chain=ch, base=base)
    rec.write_csv(tmp / "ablate.csv")
    d, cpu, _ = run_diagnose(tmp / "ablate.csv", kind)
    s = _summary(d)
    return {"named": s["named"], "flagged": s["flagged"], "cpu": cpu}


def visible_by_bound(r: dict) -> bool:
    """True size above the bound diagnose states on the clean twin (same units, or RMS)."""
    b = r.get("bound")
    if not b or b.get("detectable_above") is None:
        return False
    label, p, T = r["label"], r["params"], r["truth"]
    if label in SAME_UNITS:
        return abs(SAME_UNITS[label][1](p, T)) > b["detectable_above"]
    if b.get("relative_size") is not None:
        return b["true_relative_change"] > b["relative_size"]
    return False


def _bound_over_own(r: dict) -> float | None:
    """Diagnose's bound / the size at which lam_identify reaches the threshold (linear)."""
    b, info = r.get("bound"), r.get("info", {})
    lam = info.get("lam_identify")
    if not b or b.get("detectable_above") is None or not lam or lam <= 0:
        return None
    k = math.sqrt(44.8 / lam)
    label = r["label"]
    if label in SAME_UNITS:
        m = abs(SAME_UNITS[label][1](r["params"], r["truth"]))
        return b["detectable_above"] / (m * k) if m else None
    if b.get("relative_size") and b.get("true_relative_change"):
        return b["relative_size"] / (b["true_relative_change"] * k)
    return None


def _truth_factors(T: dict, kind: str) -> dict:
    keys = ["fs", "f", "cycles", "noise_x", "noise_y"]
    f = {k: T[k] for k in keys}
    if kind == "tangential":
        f["acA"] = T["acA"]
        f["h0"] = T["h0"]
    else:
        f["pa_p0"] = T["pa_p0"]
    return f


# --------------------------------------------------------------------------- plan
def plan(n: int, n_misfit: int, seed_base: int, effects_t, effects_n) -> list[dict]:
    """Records to run; each seed depends on (kind, label, size class, repeat) only, so a run
    with a smaller ``n`` on the same seed base replays a subset of a larger one."""
    specs = []
    for kind, effects, all_effects in (
        ("tangential", effects_t, TANGENTIAL_EFFECTS),
        ("normal", effects_n, NORMAL_EFFECTS),
    ):
        off = 0 if kind == "tangential" else 2000
        for e in effects:
            j = all_effects.index(e)
            for c, size_class in enumerate(("visible", "near")):
                for rep in range(n):
                    idx = off + j * 100 + c * 50 + rep
                    specs.append(
                        {
                            "kind": kind,
                            "label": e,
                            "seed": seed_base * 10000 + idx,
                            "size_class": size_class,
                        }
                    )
    for j, m in enumerate(MISFITS):
        for rep in range(n_misfit):
            idx = 4000 + j * 100 + rep
            specs.append({"kind": "tangential", "label": m, "seed": seed_base * 10000 + idx})
    return specs


# --------------------------------------------------------------------------- tables
def _band(v, edges, fmt):
    for lo, hi in itertools.pairwise(edges):
        if lo <= v < hi:
            return fmt.format(lo, hi)
    return fmt.format(edges[-2], edges[-1])


def _pct(k, n):
    return f"{k}/{n} ({100.0 * k / n:.0f} %)" if n else "–"


def outcome(named: list[str], label: str) -> str:
    if not named:
        return "missed"
    if named == [label]:
        return "exact"
    if label in named:
        return "extra"
    return "wrong"


def tables(results: list[dict], header: str) -> str:
    for r in results:
        if "twin" in r:
            r["visible_bound"] = visible_by_bound(r)
    L = [header, ""]
    ok = [
        r for r in results if not r["rec"]["failed"] and not r.get("twin", {}).get("failed", False)
    ]
    failed = [r for r in results if r not in ok]
    L.append(f"Records: {len(results)} ({len(failed)} with a failed diagnose run).")
    if failed:
        for r in failed[:10]:
            err = r["rec"].get("error") or r.get("twin", {}).get("error")
            L.append(f"- failed: {r['kind']} {r['label']} seed {r['seed']}: {err}")
    cpu = sum(r["cpu_diagnose"] for r in results)
    gen = sum(r["cpu_generate"] for r in results)
    n_diag = sum(1 + ("twin" in r) for r in results)
    L.append(
        f"CPU: diagnose {cpu:.0f} s over {n_diag} runs (mean {cpu / max(n_diag, 1):.1f} s), "
        f"generator {gen:.0f} s."
    )
    L.append("")

    # ---- false alarms on clean twins
    clean = [(r["kind"], r["twin"], r["twin_truth"]) for r in ok if "twin" in r]
    for kind in ("tangential", "normal"):
        cl = [(s, t) for k, s, t in clean if k == kind]
        if not cl:
            continue
        L.append(f"### False alarms on clean {kind} records (the clean twins)")
        L.append("")
        L.append("| factor | band | n | effect named | misfit flagged | either |")
        L.append("|---|---|---|---|---|---|")
        facs = [
            ("all", lambda t: "all"),
            ("fs", lambda t: f"{t['fs'] / 1000:g} kHz"),
            ("cycles", lambda t: str(t["cycles"])),
            (
                "x noise",
                lambda t: _band(100 * t["noise_x"], [0.5, 1.0, 1.5, 2.0001], "{:g}-{:g} %"),
            ),
            (
                "y noise",
                lambda t: _band(100 * t["noise_y"], [0.5, 1.0, 1.5, 2.0001], "{:g}-{:g} %"),
            ),
        ]
        if kind == "tangential":
            facs.append(("ac·A", lambda t: _band(t["acA"], [0.0, 1.0, 2.5, 100.0], "{:g}-{:g}")))
        else:
            facs.append(
                ("pa/p0", lambda t: _band(t["pa_p0"], [0.2, 0.4, 0.6, 0.8001], "{:g}-{:g}"))
            )
        for name, key in facs:
            groups = defaultdict(list)
            for s, t in cl:
                groups[key(t)].append(s)
            for band in sorted(groups, key=lambda b: (len(b), b)):
                g = groups[band]
                n = len(g)
                nm = sum(bool(s["named"]) for s in g)
                fl = sum(s["flagged"] for s in g)
                ei = sum(bool(s["named"]) or s["flagged"] for s in g)
                L.append(
                    f"| {name} | {band} | {n} | {_pct(nm, n)} | {_pct(fl, n)} | {_pct(ei, n)} |"
                )
        alarms = [r for r in ok if r["kind"] == kind and "twin_ablation" in r]
        if alarms:
            gone = sum(
                not a["twin_ablation"]["named"] and not a["twin_ablation"]["flagged"]
                for a in alarms
            )
            L.append("")
            L.append(
                f"Attribution: of the {len(alarms)} clean {kind} records with an alarm, {gone} are "
                "clean again when the same record is regenerated with x noise 0.5 % (hum and "
                "jitter off, everything else equal)."
            )
        names = Counter(e for s, _ in cl for e in s["named"])
        L.append("")
        L.append(
            f"Named on clean {kind} records: "
            + (", ".join(f"{k} {v}" for k, v in names.most_common()) or "nothing")
        )
        L.append("")

    # ---- by effect
    eff = [r for r in ok if r["label"] not in MISFITS]
    for kind in ("tangential", "normal"):
        rs = [r for r in eff if r["kind"] == kind]
        if not rs:
            continue
        L.append(f"### By effect, {kind}: exact / extra / missed / wrong")
        L.append("")
        L.append(
            "Visible (own): the generator's noncentrality lam_identify >= 44.8; visible "
            "(bound): the true size "
            "exceeds the bound `diagnose` states for that effect on the clean twin "
            "(`not_detected`)."
        )
        L.append("")
        L.append(
            "| effect | n | all: exact/extra/missed/wrong | visible (own): n, exact, extra, "
            "missed, wrong | visible (bound): n, exact, extra, missed, wrong | invisible by "
            "both: n, named wrong | named/true (median, range) |"
        )
        L.append("|---|---|---|---|---|---|---|")
        tot = defaultdict(Counter)
        for e in sorted({r["label"] for r in rs}):
            g = [r for r in rs if r["label"] == e]
            cells = []
            for sel_name, sel in (
                ("all", lambda r: True),
                ("own", lambda r: r["info"].get("visible_own")),
                ("bound", lambda r: r.get("visible_bound")),
            ):
                sub = [r for r in g if sel(r)]
                c = Counter(outcome(r["rec"]["named"], e) for r in sub)
                tot[sel_name].update(c)
                tot[sel_name]["n"] += len(sub)
                if sel_name == "all":
                    cells.append(f"{c['exact']}/{c['extra']}/{c['missed']}/{c['wrong']}")
                else:
                    cells.append(
                        f"{len(sub)}: {c['exact']}, {c['extra']}, {c['missed']}, {c['wrong']}"
                    )
            ratios = []
            if e in SAME_UNITS:
                pname, true_of = SAME_UNITS[e]
                for r in g:
                    named_p = r["rec"].get("params", {}).get(e, {})
                    if pname in named_p:
                        v = named_p[pname] - (2.0 if e == "non_masing_scaling" else 0.0)
                        tv = true_of(r["params"], r["truth"])
                        if tv:
                            ratios.append(v / tv)
            rcell = (
                f"{np.median(ratios):.2f} ({min(ratios):.2f}-{max(ratios):.2f}, n {len(ratios)})"
                if ratios
                else "–"
            )
            inv = [r for r in g if not r["info"].get("visible_own") and not r.get("visible_bound")]
            wrong = sum(outcome(r["rec"]["named"], e) == "wrong" for r in inv)
            tot["inv"]["n"] += len(inv)
            tot["inv"]["wrong"] += wrong
            L.append(
                f"| {e} | {len(g)} | {cells[0]} | {cells[1]} | {cells[2]} | {len(inv)}, {wrong} "
                f"| {rcell} |"
            )
        c = tot["all"]
        cells = [f"{c['exact']}/{c['extra']}/{c['missed']}/{c['wrong']}"]
        for s in ("own", "bound"):
            c = tot[s]
            cells.append(
                f"{c['n']}: {c['exact']} ({100 * c['exact'] / max(c['n'], 1):.0f} %), "
                f"{c['extra']}, {c['missed']}, {c['wrong']}"
            )
        L.append(
            f"| **total** | {len(rs)} | {cells[0]} | {cells[1]} | {cells[2]} | "
            f"{tot['inv']['n']}, {tot['inv']['wrong']} | |"
        )
        L.append("")
        # diagnose's stated bound against the size the independent criterion calls visible
        ratio_rows = []
        for e in sorted({r["label"] for r in rs}):
            q = [x for x in (_bound_over_own(r) for r in rs if r["label"] == e) if x is not None]
            if q:
                ratio_rows.append(f"{e} {np.median(q):.2g} ({min(q):.2g}-{max(q):.2g})")
        if ratio_rows:
            L.append(
                "Bound stated on the clean twin over the size the independent criterion needs "
                "(lam_identify = 44.8), median (range): " + "; ".join(ratio_rows) + "."
            )
            L.append("")
        # agreement of the two visibility judgements
        agree = Counter(
            (bool(r["info"].get("visible_own")), bool(r.get("visible_bound"))) for r in rs
        )
        L.append(
            f"Visibility judgements (own, bound): both {agree[(True, True)]}, own only "
            f"{agree[(True, False)]}, "
            f"bound only {agree[(False, True)]}, neither {agree[(False, False)]}."
        )
        L.append("")
        # splits of the visible (own) by x noise and ac·A
        L.append(f"#### {kind}, visible (own) single effects: exact rate by factor")
        L.append("")
        L.append("| factor | band | n | exact | extra | missed | wrong |")
        L.append("|---|---|---|---|---|---|---|")
        vis = [r for r in rs if r["info"].get("visible_own")]
        facs = [
            (
                "x noise",
                lambda t: _band(100 * t["noise_x"], [0.5, 1.0, 1.5, 2.0001], "{:g}-{:g} %"),
            ),
            ("fs", lambda t: f"{t['fs'] / 1000:g} kHz"),
            ("cycles", lambda t: _band(t["cycles"], [0, 10, 25, 51], "{:g}-{:g}")),
        ]
        if kind == "tangential":
            facs.append(("ac·A", lambda t: _band(t["acA"], [0.0, 1.0, 2.5, 100.0], "{:g}-{:g}")))
        else:
            facs.append(
                ("pa/p0", lambda t: _band(t["pa_p0"], [0.2, 0.4, 0.6, 0.8001], "{:g}-{:g}"))
            )
        for name, key in facs:
            groups = defaultdict(list)
            for r in vis:
                groups[key(r["truth"])].append(r)
            for band in sorted(groups):
                g = groups[band]
                c = Counter(outcome(r["rec"]["named"], r["label"]) for r in g)
                L.append(
                    f"| {name} | {band} | {len(g)} | {_pct(c['exact'], len(g))} | "
                    f"{c['extra']} | {c['missed']} | {c['wrong']} |"
                )
        L.append("")
        # confusion pairs
        conf = Counter()
        for r in rs:
            o = outcome(r["rec"]["named"], r["label"])
            if o in ("extra", "wrong"):
                others = [n for n in r["rec"]["named"] if n != r["label"]]
                conf[(r["label"], o, "+".join(others))] += 1
        if conf:
            L.append(
                f"Confusion pairs ({kind}; true → named besides or instead): "
                + "; ".join(
                    f"{a} → {'+' if o == 'extra' else ''}{b} ×{k}"
                    for (a, o, b), k in conf.most_common()
                )
            )
            L.append("")
        miss_vis = [r for r in vis if outcome(r["rec"]["named"], r["label"]) == "missed"]
        if miss_vis:
            L.append(
                f"Missed though visible (own), {kind}: "
                + "; ".join(
                    f"{r['label']} (lam {r['info']['lam_identify']:.0f}, bound-visible "
                    f"{r.get('visible_bound')})"
                    for r in miss_vis
                )
            )
            L.append("")
        # misfit flags on effect records
        fl = sum(r["rec"]["flagged"] for r in rs)
        L.append(f"Effect records ({kind}) also flagged 'systematic misfit': {_pct(fl, len(rs))}.")
        L.append("")

    # ---- unnameable misfits
    mis = [r for r in ok if r["label"] in MISFITS]
    if mis:
        L.append("### Unnameable misfits (tangential)")
        L.append("")
        L.append(
            "| misfit | n | flagged 'systematic misfit' | visible vs base: n, flagged | "
            "visible (own): n, flagged | nothing named | named (counts) |"
        )
        L.append("|---|---|---|---|---|---|---|")
        for m in MISFITS:
            g = [r for r in mis if r["label"] == m]
            if not g:
                continue
            fl = sum(r["rec"]["flagged"] for r in g)
            nothing = sum(not r["rec"]["named"] for r in g)
            names = Counter(n for r in g for n in r["rec"]["named"])
            vis = [r for r in g if r["info"].get("visible_own")]
            vfl = sum(r["rec"]["flagged"] for r in vis)
            vb = [r for r in g if r["info"].get("lam_detect", 0) >= 44.8]
            vbf = sum(r["rec"]["flagged"] for r in vb)
            L.append(
                f"| {m} | {len(g)} | {_pct(fl, len(g))} | {len(vb)}, {vbf} | {len(vis)}, {vfl} "
                f"| {nothing} | "
                f"{', '.join(f'{k} {v}' for k, v in names.most_common()) or '–'} |"
            )
        fl = sum(r["rec"]["flagged"] for r in mis)
        vis = [r for r in mis if r["info"].get("visible_own")]
        vfl = sum(r["rec"]["flagged"] for r in vis)
        vb = [r for r in mis if r["info"].get("lam_detect", 0) >= 44.8]
        vbf = sum(r["rec"]["flagged"] for r in vb)
        L.append(
            f"| **total** | {len(mis)} | {_pct(fl, len(mis))} | {len(vb)}, {_pct(vbf, len(vb))} | "
            f"{len(vis)}, {_pct(vfl, len(vis))} | | |"
        )
        L.append("")
        L.append(
            "Visible vs base: the weighted residual of the noise-free misfit after refitting the "
            "base (h0, ac) is >= 44.8 noise variances; visible (own): also after projecting off "
            "the nearest candidate's linearised direction (a misfit one candidate absorbs to "
            "within the noise cannot be told from that candidate)."
        )
        L.append("")
    return "\n".join(L)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true", help="a few records (<= 3 CPU-min)")
    ap.add_argument("--n", type=int, default=1, help="records per (effect, size class) cell")
    ap.add_argument("--n-misfit", type=int, default=None, help="records per misfit (default 2n)")
    ap.add_argument(
        "--seed-base", type=int, default=None, help="replay a run (default: from the clock)"
    )
    ap.add_argument("--jobs", type=int, default=2, help="parallel records (at most 2)")
    ap.add_argument("--label", default=None, help="results file suffix")
    ap.add_argument("--effects", default=None, help="comma-separated subset of effects")
    ap.add_argument("--tables-from", default=None, help="re-render the tables of a results JSON")
    args = ap.parse_args(argv)
    if args.tables_from:
        path = Path(args.tables_from)
        results = json.loads(path.read_text())
        md_path = path.with_suffix(".md")
        first = md_path.read_text().split("\n\n")[:2] if md_path.exists() else [path.stem, ""]
        md = tables(results, "\n\n".join(first))
        md_path.write_text(md + "\n")
        print(md)
        return 0
    seed_base = args.seed_base if args.seed_base is not None else int(time.time()) % 100000
    jobs = max(1, min(args.jobs, 2))
    et, en = TANGENTIAL_EFFECTS, NORMAL_EFFECTS
    if args.effects:
        want = set(args.effects.split(","))
        et = tuple(e for e in et if e in want)
        en = tuple(e for e in en if e in want)
    n_mis = args.n_misfit if args.n_misfit is not None else 2 * args.n
    if args.quick:
        et = ("channel_delay", "parallel_stiffness", "force_offset", "stribeck")
        en = ("channel_delay", "creep_drift")
        specs = [
            s for s in plan(1, 1, seed_base, et, en) if s.get("size_class", "visible") == "visible"
        ]
    else:
        specs = plan(args.n, n_mis, seed_base, et, en)
    label = args.label or ("quick" if args.quick else f"seed{seed_base}")
    head = git_head()
    print(
        f"eval_independent: seed base {seed_base}, {len(specs)} records (+ clean twins), jobs "
        f"{jobs}, tree {head}",
        flush=True,
    )
    t0 = time.time()
    results = []
    with ProcessPoolExecutor(max_workers=jobs) as ex:
        res_dir = HERE / "results"
        res_dir.mkdir(exist_ok=True)
        partial = res_dir / f"eval_independent_{label}.json"
        for k, r in enumerate(ex.map(job, specs), 1):
            results.append(r)
            # written as it goes: an interrupted run can be tabled with --tables-from
            partial.write_text(json.dumps(results, indent=1, default=float))
            o = (
                outcome(r["rec"]["named"], r["label"])
                if r["label"] not in MISFITS
                else ("flagged" if r["rec"]["flagged"] else "not flagged")
            )
            tw = ""
            if "twin" in r:
                tw = f" | twin named {r['twin']['named'] or '-'} flagged {r['twin']['flagged']}"
            print(
                f"[{k}/{len(specs)}] {r['kind'][:4]} {r['label']:<22} "
                f"{r.get('size_class') or '':<7} "
                f"own-vis {r['info'].get('visible_own')!s:<5} bound-vis "
                f"{r.get('visible_bound')!s:<5} "
                f"-> {o:<8} named {r['rec']['named'] or '-'} flagged {r['rec']['flagged']}{tw}",
                flush=True,
            )
    wall = time.time() - t0
    header = (
        f"## eval_independent: {label}\n\n"
        f"Tree {head}; seed base {seed_base} (replay: `--seed-base {seed_base}`"
        f"{' --quick' if args.quick else f' --n {args.n} --n-misfit {n_mis}'}); wall "
        f"{wall:.0f} s with {jobs} jobs."
    )
    md = tables(results, header)
    print(md)
    res_dir = HERE / "results"
    res_dir.mkdir(exist_ok=True)
    (res_dir / f"eval_independent_{label}.md").write_text(md + "\n")
    (res_dir / f"eval_independent_{label}.json").write_text(
        json.dumps(results, indent=1, default=float)
    )
    return 0


def git_head() -> str:
    try:
        return subprocess.run(
            ["git", "-C", str(ROOT), "rev-parse", "--short", "HEAD"], capture_output=True, text=True
        ).stdout.strip()
    except OSError:
        return "?"


if __name__ == "__main__":
    raise SystemExit(main())
