"""Time of the bundled example study (``contactlab demo``): analysis, figures, HTML, tables.

Each stage is reported per item and as a ratio to a same-run reference: one plain matplotlib
line figure of the same size and resolution rendered to PNG (the floor any report with
figures pays). The analysis and the figures are then timed on ``--workers`` processes (as
``contactlab study`` and ``demo`` run them) in interleaved pairs with the serial run (the
order alternating): median speed-up and range; the pooled outputs are checked to be the
serial ones.
Run: ``.venv/bin/python benches/bench_study.py [--repeat 3] [--workers 2]``.
"""

from __future__ import annotations

import argparse
import os
import time
from concurrent.futures import ProcessPoolExecutor

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from contactlab.data import manifest_path
from contactlab.report import figure_png
from contactlab.report.study_report import build_report
from contactlab.studies import run_study


def best_of(f, repeat: int) -> tuple[float, object]:
    best, out = np.inf, None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = f()
        best = min(best, time.perf_counter() - t0)
    return best, out


def reference_figure() -> bytes:
    fig, ax = plt.subplots(figsize=(9.0, 3.4), constrained_layout=True)
    ax.plot(np.sin(np.linspace(0, 6.28, 400)))
    try:
        return figure_png(fig, dpi=90)
    finally:
        plt.close(fig)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--workers", type=int, default=os.cpu_count() or 1)
    args = ap.parse_args()
    t_ref, _ = best_of(reference_figure, args.repeat * 3)
    t_study, res = best_of(lambda: run_study(manifest_path(), progress=False), args.repeat)
    n_rec = len(res.results)
    t_rep, rep = best_of(lambda: build_report(res, "bench"), args.repeat)
    n_fig = len(rep.figures)
    t_html, _ = best_of(lambda: rep.files(), args.repeat)
    t_tab, _ = best_of(lambda: res.table_files(), args.repeat)
    print(f"reference: one 9×3.4 in line figure to PNG at 90 dpi: {1e3 * t_ref:.0f} ms")
    rows = [
        ("read + analyse", t_study, n_rec, "recording"),
        ("figures (report)", t_rep, n_fig, "figure"),
        ("HTML assembly", t_html, 1, "report"),
        ("tables CSV+Parquet", t_tab, 1, "study"),
    ]
    print(f"{'stage':<20}{'total [s]':>10}{'per item [ms]':>15}{'× reference':>13}")
    for name, t, n, unit in rows:
        print(f"{name:<20}{t:>10.2f}{1e3 * t / n:>15.1f}{t / n / t_ref:>13.2f}  per {unit}")
    print(f"total {t_study + t_rep + t_html + t_tab:.1f} s for {n_rec} recordings, {n_fig} figures")
    if args.workers < 2:
        return
    import statistics

    def serial_run():
        r = run_study(manifest_path(), progress=False)
        return r, build_report(r, "bench")

    with ProcessPoolExecutor(args.workers) as ex:

        def pooled_run():
            r = run_study(manifest_path(), progress=False, executor=ex, keep_recordings=True)
            return r, build_report(r, "bench", executor=ex)

        pooled_run()  # start and warm up the workers
        ratios, same = [], True
        for k in range(max(args.repeat, 2)):  # interleaved pairs, the order alternating
            times = {}
            for name, f in (("s", serial_run), ("p", pooled_run))[:: 1 if k % 2 == 0 else -1]:
                t0 = time.perf_counter()
                r, rp = f()
                times[name] = time.perf_counter() - t0
                if name == "p":
                    same = same and r.table_files() == res.table_files()
                    same = same and rp.figures == rep.figures
            ratios.append(times["s"] / times["p"])
    ratios.sort()
    print(
        f"analysis and figures on {args.workers} processes, {len(ratios)} interleaved pairs "
        f"with the serial run: x{statistics.median(ratios):.2f} median (range "
        f"{ratios[0]:.2f}-{ratios[-1]:.2f}); outputs identical to the serial ones: {same}"
    )


if __name__ == "__main__":
    main()
