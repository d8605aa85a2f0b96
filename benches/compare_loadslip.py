"""Before/after tables of ``benches/eval_loadslip.py`` runs (issue 29, helper loadslip).

A miss is "above the bound" when the diagnosis stated a bound for the true effect and the
true size exceeds it (a miss by its own statement), "honest" when the truth lies below the
stated bound or no bound is stated ("not separable ..." on that record).

    python benches/compare_loadslip.py before.json after.json
"""

from __future__ import annotations

import itertools
import json
import sys
from collections import Counter, defaultdict

TRUE_SIZE = {
    "normal_load": ("eps",),
    "stick_slip": ("b",),
    "stribeck": ("s",),
    "parallel_stiffness": ("k_p",),
    "position_friction": ("a", "eps"),
}


def true_size(r):
    p = r["truth"]["params"]
    for k in TRUE_SIZE.get(r["effect"], ()):
        if k in p:
            return abs(float(p[k]))
    return None


def outcome(r):
    if r.get("error"):
        return "error"
    named, e = set(r["named"]), r["effect"]
    if e is None:
        return "ok" if not named and not r["flagged"] else ("named" if named else "flagged")
    if named == {e}:
        return "exact"
    if e in named:
        return "extra"
    if named:
        return "wrong"
    b = (r.get("bound") or {}).get("detectable_above")
    size = true_size(r)
    if b is not None and size is not None and size > b:
        return "missed>bound"
    return "missed(honest)"


def table(runs):
    rows = defaultdict(dict)
    confusions = defaultdict(Counter)
    for label, res in runs:
        by = defaultdict(list)
        for r in res:
            by[r["effect"] or "clean"].append(r)
            if outcome(r) == "wrong":
                confusions[(label, r["effect"])]["+".join(sorted(r["named"]))] += 1
        for e, rs in by.items():
            rows[e][label] = Counter(outcome(r) for r in rs), len(rs)
    out = [
        "| effect | run | n | exact | extra | wrong | missed > stated bound | missed, honest "
        "| clean: nothing named or flagged |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for e in sorted(rows, key=lambda k: (k == "clean", k)):
        for label, _ in runs:
            if label not in rows[e]:
                continue
            c, n = rows[e][label]
            if e == "clean":
                out.append(
                    f"| clean | {label} | {n} | | | named {c['named']} | flagged "
                    f"{c['flagged']} | | **{c['ok']}/{n}** |"
                )
            else:
                out.append(
                    f"| {e} | {label} | {n} | **{c['exact']}** | {c['extra']} | "
                    f"{c['wrong']} | {c['missed>bound']} | {c['missed(honest)']} | |"
                )
    out.append("")
    for (label, e), c in sorted(confusions.items()):
        out.append(f"- {label}, {e} named as: " + ", ".join(f"{k} ×{v}" for k, v in c.items()))
    return "\n".join(out)


BANDS = {
    "x noise [%]": (lambda f: 100 * f["x_noise"], (0, 0.5, 1, 1.5, 2.01)),
    "ac·A": (lambda f: f["acA"], (0.3, 1, 2.5, 5.01)),
    "fs [kHz]": (lambda f: f["fs"] / 1000, (1, 2, 5, 10.01)),
}


def bands(runs):
    """Exact named / single-effect records, and clean records with nothing named or flagged,
    by band of each factor."""
    out = []
    for name, (get, edges) in BANDS.items():
        out += [
            f"| {name} | " + " | ".join(lab for lab, _ in runs) + " |",
            "|---|" + "---|" * len(runs),
        ]
        for lo, hi in itertools.pairwise(edges):
            cells = []
            for _, res in runs:
                sel = [r for r in res if lo <= get(r["truth"]["factors"]) < hi]
                eff = [r for r in sel if r["effect"]]
                clean = [r for r in sel if not r["effect"]]
                ex = sum(outcome(r) == "exact" for r in eff)
                ok = sum(outcome(r) == "ok" for r in clean)
                cells.append(f"effects {ex}/{len(eff)}, clean {ok}/{len(clean)}")
            out.append(f"| {lo:g}-{hi:g} | " + " | ".join(cells) + " |")
        out.append("")
    return "\n".join(out)


def main(argv=None):
    argv = sys.argv[1:] if argv is None else argv
    runs = []
    for path in argv:
        label, _, file = path.rpartition("=")
        res = json.loads(open(file or path).read())
        runs.append((label or file, res))
    for gen in ("chain", "rig"):
        sub = [(lab, [r for r in res if r["gen"] == gen]) for lab, res in runs]
        print(f"### {gen}\n")
        print(table(sub))
        print()
    print("### both\n")
    print(table(runs))
    print("\n### by factor (both generators)\n")
    print(bands(runs))


if __name__ == "__main__":
    main()
