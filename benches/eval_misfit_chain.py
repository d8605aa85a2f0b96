"""The misfit flag (issue 29, item 3) on the measurement chain of ``benches/misfit_chain.py``:
false alarms on clean records (exponential virgin curve) and the flag rate on virgin curves
no candidate draws (tanh, rational, gamma), by factor.

``--corner`` draws the hard corner only (ac·A 2.5-5, 35-50 cycles, x noise 1-2 % of the
range); otherwise every factor is drawn over its whole range (fs 1-10 kHz, 5-50 cycles, x
noise 0-2 %, ac·A 0.3-5). Seeds 0-999 were used for tuning (diagflag); report on others.

Run: ``nice .venv/bin/python benches/eval_misfit_chain.py --n 30 --misfits 12 --seed0 5000``
(about 10 CPU-minutes). Not part of the test suite.
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

UNNAMEABLE = ("tanh", "rational", "gamma")


def _over(corner: bool, rng: np.random.Generator) -> dict[str, Any]:
    if not corner:
        return {}
    return {
        "acA": float(rng.uniform(2.5, 5.0)),
        "cycles": int(rng.integers(35, 51)),
        "x_noise": float(rng.uniform(0.01, 0.02)),
    }


def run_one(job: tuple[int, str, bool]) -> dict[str, Any]:
    import warnings

    from contactlab.diagnose import assessment
    from contactlab.diagnose.workflow import diagnose
    from contactlab.errors import ContactLabError
    from misfit_chain import chain_record

    warnings.simplefilter("ignore")
    seed, virgin, corner = job
    over = _over(corner, np.random.default_rng([seed, 99]))
    rec, fac = chain_record(seed, virgin, **over)
    seen: dict[str, Any] = {}
    orig = assessment.assess

    def spy(family: Any, d: Any, current: Any, sigma: float, **kw: Any) -> Any:
        out = orig(family, d, current, sigma, **kw)
        seen.update(
            u_noise=float(d.extra.get("u_noise", 0.0)),
            kept="knots" in d.extra,
            sigma=float(sigma),
            n=int(d.u.size),
        )
        return out

    assessment.assess = spy
    t0 = time.process_time()
    out: dict[str, Any] = {"seed": seed, **fac}
    try:
        rep = diagnose(rec, model="tangential")
    except ContactLabError as exc:
        out.update(refused=str(exc)[:120], named=[], flagged=False)
    else:
        u = rep.unexplained
        bb = None if u is None else u.backbone
        out.update(
            refused=None,
            named=rep.effect_names,
            flagged=bool(u is not None and u.flagged),
            bins_flag=bool(u is not None and u.statistic > u.threshold),
            ratio=None if u is None else u.statistic / u.threshold,
            bb_t=None if bb is None else bb["t"],
            bb_flag=bool(bb is not None and bb["flagged"]),
            detectable_rms=None if u is None else u.detectable_rms,
            rms=None if u is None else u.rms,
            eiv=None if u is None else u.eiv_bias_rms,
            flag_route=rep.location.get("flag_route"),
            **seen,
        )
        # the true input noise RMS (the chain scales it to x_noise of the range)
        out["u_noise_true"] = fac["x_noise"] * float(np.ptp(rec[1]))
    out["cpu"] = time.process_time() - t0
    return out


def _g(v: Any) -> str:
    return "-" if v is None else (f"{v:.3g}" if isinstance(v, float) else str(v))


def table(rs: list[dict[str, Any]], title: str) -> str:
    ok = [r for r in rs if r["refused"] is None]
    lines = [f"\n{title}: {len(ok)} diagnosed ({len(rs) - len(ok)} refused)"]
    bands = {
        "fs": lambda r: f"{r['fs']:g}",
        "cycles": lambda r: "5-20" if r["cycles"] <= 20 else "21-34" if r["cycles"] < 35
        else "35-50",
        "x noise %": lambda r: ("0-0.5" if r["x_noise"] < 0.005 else "0.5-1" if r["x_noise"] < 0.01
                                else "1-1.5" if r["x_noise"] < 0.015 else "1.5-2"),
        "ac·A": lambda r: "0.3-1" if r["acA"] < 1 else ("1-2.5" if r["acA"] < 2.5 else "2.5-5"),
        "virgin": lambda r: r["virgin"],
    }  # fmt: skip
    lines.append(f"{'factor':<12}{'level':>8}{'n':>5}{'named':>7}{'flagged':>9}{'rate':>7}")
    for name, key in bands.items():
        g: dict[str, list] = defaultdict(list)
        for r in ok:
            g[key(r)].append(r)
        for lvl in sorted(g):
            k = sum(bool(r["named"]) for r in g[lvl])
            f = sum(r["flagged"] for r in g[lvl])
            lines.append(
                f"{name:<12}{lvl:>8}{len(g[lvl]):>5}{k:>7}{f:>9}{100 * f / len(g[lvl]):>6.0f}%"
            )
    f = sum(r["flagged"] for r in ok)
    nb = sum(r["bins_flag"] for r in ok)
    nv = sum(r["bb_flag"] for r in ok)
    clean = sum(1 for r in ok if not r["named"] and not r["flagged"])
    lines.append(
        f"all: flagged {f}/{len(ok)} (phase bins {nb}, virgin curve {nv}); nothing named or "
        f"flagged {clean}/{len(ok)}"
    )
    for r in ok:
        lines.append(
            f"  seed {r['seed']} {r['virgin']}: named {r['named']} flag {r['flagged']} "
            f"(T/thr {_g(r['ratio'])}, virgin t {_g(r['bb_t'])}) σu est/true "
            f"{_g(r.get('u_noise', 0) / r['u_noise_true'] if r['u_noise_true'] else None)} "
            f"kept {r.get('kept')} eiv {_g(r['eiv'])} det {_g(r['detectable_rms'])} "
            f"(fs {r['fs']:g}, f {r['f']:.3g}, cyc {r['cycles']}, xn {100 * r['x_noise']:.2g} %, "
            f"acA {r['acA']:.3g}, cell {r['cell']}, cpu {r['cpu']:.0f})"
        )
    return "\n".join(lines)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--n", type=int, default=30, help="clean records")
    ap.add_argument("--misfits", type=int, default=12, help="unnameable-virgin records")
    ap.add_argument("--seed0", type=int, default=5000)
    ap.add_argument("--corner", action="store_true")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--dump", default=None, help="append every record's result (JSON lines)")
    ap.add_argument("--first", type=int, default=0, help="skip the first clean seeds")
    a = ap.parse_args()
    jobs = [(a.seed0 + k, "exp", a.corner) for k in range(a.first, a.n)]
    jobs += [(a.seed0 + 500 + k, UNNAMEABLE[k % 3], a.corner) for k in range(a.misfits)]
    res = []
    with ProcessPoolExecutor(a.jobs) as ex:
        for r in ex.map(run_one, jobs):  # each row written as it comes (a long run's part)
            res.append(r)
            if a.dump:
                with open(a.dump, "a") as fh:
                    fh.write(json.dumps(r, default=str) + "\n")
    print(table([r for r in res if r["virgin"] == "exp"], "clean (exponential virgin curve)"))
    print(table([r for r in res if r["virgin"] != "exp"], "unnameable virgin curves"))


if __name__ == "__main__":
    main()
