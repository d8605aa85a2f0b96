"""Model evaluations of ``contactlab diagnose`` per candidate (issue 9: where a long
diagnosis spends its fits).

Runs the CLI path in this process on each recording (``--model normal`` for files whose
name starts with ``n_``, tangential otherwise) with every candidate fit counted: per
candidate (the last effect of the fitted model; ``(base)`` for the base model) the model
evaluations (the fits' ``nfev``, a family's start search included), the number of fits and
their time; then the total, the wall and CPU time and the effects named. ``--detail`` also
lists every fit (its effects, samples, evaluations, seconds, converged).

Run: ``CONTACTLAB_DIAGNOSE_THREADS=1 .venv/bin/python benches/count_diagnose_evaluations.py
FILE [FILE ...] [--detail]``; with ``PYTHONPATH=DIR`` (another version's ``contactlab``
package in DIR) for the figures before a change. Recordings: e.g. those
``benches/bench_diagnose.py --workdir DIR`` writes.
"""

from __future__ import annotations

import argparse
import collections
import json
import os
import tempfile
import time
from pathlib import Path


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("files", nargs="+")
    ap.add_argument("--detail", action="store_true", help="list every fit")
    args = ap.parse_args()

    from contactlab.cli import main as cli
    from contactlab.diagnose import search, select, workflow

    plain = select.fit
    log: list[tuple[tuple[str, ...], int, int, float, bool]] = []

    def counted(family, effects, d, mask, start, scales):  # type: ignore[no-untyped-def]
        t0 = time.perf_counter()
        f = plain(family, effects, d, mask, start, scales)
        log.append((effects, int(mask.sum()), f.nfev, time.perf_counter() - t0, f.success))
        return f

    select.fit = counted  # evaluate() calls it from select, the workflow by its own name
    workflow.fit = counted  # type: ignore[attr-defined]
    search.fit = counted  # type: ignore[attr-defined]  (the search's moves)
    with tempfile.TemporaryDirectory() as tmp:
        for path in args.files:
            log.clear()
            out = str(Path(tmp) / "report.json")
            model = "normal" if Path(path).name.startswith("n_") else "tangential"
            t0, c0 = time.perf_counter(), time.process_time()
            cli(["diagnose", path, "--model", model, "--json", out])
            wall, cpu = time.perf_counter() - t0, time.process_time() - c0
            named = [e["name"] for e in json.loads(Path(out).read_text())["effects"]]
            evals: collections.Counter[str] = collections.Counter()
            fits: collections.Counter[str] = collections.Counter()
            secs: collections.Counter[str] = collections.Counter()
            for eff, _, nfev, dt, _ in log:
                key = eff[-1] if eff else "(base)"
                evals[key] += nfev
                fits[key] += 1
                secs[key] += dt
            print(
                f"{os.path.basename(path)}: wall {wall:.2f} s, CPU {cpu:.2f} s, {len(log)} fits, "
                f"{sum(evals.values())} model evaluations, named {named}"
            )
            for k, v in evals.most_common():
                print(f"   {k:22s} {v:6d} evaluations in {fits[k]:3d} fits  {secs[k]:6.2f} s")
            if args.detail:
                for eff, n, nfev, dt, ok in log:
                    print(f"      {eff} on {n} samples: {nfev} evaluations, {dt:.2f} s, {ok}")


if __name__ == "__main__":
    main()
