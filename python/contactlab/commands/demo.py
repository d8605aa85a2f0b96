"""``contactlab demo``: analyse the bundled example study and write its report.

1. Masing loops at several amplitudes with energy, equivalent damping and stiffness against
   amplitude (PHYSICS.md §1): ``loops.png`` and ``amplitude_table.csv``.
2. The bundled example recordings (:mod:`contactlab.data`: three material pairs over loads
   and amplitudes, normal-contact tests over p0; CSV/TDMS/HDF5/MAT) go through the study
   (:func:`contactlab.studies.run_study`): ``report.html`` (self-contained), ``figures/*.png``,
   ``study_tangential.csv``/``.parquet`` and ``study_normal.*``.

All outputs are rendered first and written all or nothing into the output folder.
"""

from __future__ import annotations

import argparse
import csv
import io
import time
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    import numpy as np

    from ..masing import Masing

# Illustrative aluminium-on-aluminium values of the order the paper reports.
DEMO_H0 = 40.0  # N
DEMO_AC = 4.0e4  # 1/m
DEMO_AMPLITUDES = (5e-6, 10e-6, 20e-6, 40e-6, 80e-6)  # m


def amplitude_table(model: Masing, amplitudes: np.ndarray, samples: int = 4001) -> list[dict]:
    """Energy (analytic and from the simulated loop), c_e·ω and stiffness per amplitude."""
    import numpy as np

    from ..masing import loop_area

    rows = []
    for A in amplitudes:
        x = A * np.sin(np.linspace(0.0, 4.0 * np.pi, 2 * samples - 1))
        F = model.force(x)
        second = slice(samples - 1, None)  # the second, steady cycle
        rows.append(
            {
                "amplitude_m": float(A),
                "energy_J": float(model.loop_energy(A)),
                "energy_numeric_J": loop_area(x[second], F[second]),
                "equivalent_damping_N_per_m": float(model.equivalent_damping(A)),
                "k_local_N_per_m": float(model.local_stiffness(A)),
                "k_global_N_per_m": float(model.global_stiffness(A)),
                "force_amplitude_N": float(model.virgin(A)),
            }
        )
    return rows


def masing_outputs() -> dict[str, bytes]:
    """``loops.png`` and ``amplitude_table.csv`` of the illustrative Masing model."""
    import matplotlib.pyplot as plt
    import numpy as np

    from ..masing import Masing
    from ..report import figure_png

    model = Masing(DEMO_H0, DEMO_AC)
    amps = np.asarray(DEMO_AMPLITUDES)
    rows = amplitude_table(model, amps)

    fig, ax = plt.subplots(figsize=(6.4, 4.8), constrained_layout=True)
    for A in amps:
        x = A * np.sin(np.linspace(0.0, 4.0 * np.pi, 4001))
        F = model.force(x)
        ax.plot(x[1000:] * 1e6, F[1000:], lw=1.2, label=f"A = {A * 1e6:g} µm")
    xv = np.linspace(0, amps.max(), 400)
    ax.plot(xv * 1e6, model.virgin(xv), "k--", lw=0.8, label="virgin curve")
    ax.set_xlabel("tangential displacement x [µm]")
    ax.set_ylabel("friction force h [N]")
    ax.set_title(f"Masing loops, h0 = {DEMO_H0:g} N, ac = {DEMO_AC:g} 1/m")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    try:
        png = figure_png(fig, dpi=120)
    finally:
        plt.close(fig)

    buf = io.StringIO()
    w = csv.DictWriter(buf, fieldnames=list(rows[0]))
    w.writeheader()
    w.writerows(rows)
    return {"loops.png": png, "amplitude_table.csv": buf.getvalue().encode("utf-8")}


def demo_entries(quick: bool = False) -> list:
    """Entries of the bundled study; ``quick`` keeps one recording per material and kind."""
    from ..data import manifest_path
    from ..studies.manifest import read_manifest

    entries = read_manifest(manifest_path())
    if not quick:
        return entries
    seen: set[tuple[str, str]] = set()
    out = []
    for e in entries:
        if (e.kind, e.material) not in seen:
            seen.add((e.kind, e.material))
            out.append(e)
    normal = [e for e in entries if e.kind == "normal"]
    if len(normal) > 1 and normal[-1] not in out:
        out.append(normal[-1])  # two p0 values, so the normal study plots have a line
    return out


def run_demo(
    out: Path,
    *,
    quick: bool = False,
    progress: bool | None = None,
    workers: int | None = None,
    auto: bool = False,
    command: str | None = None,
) -> list[Path]:
    """Run the demo and write every output into ``out``; returns the written paths.

    ``command``: the command line that ran it, quoted at the top of the report.

    ``workers``: processes that analyse the recordings and draw the report's figures (None:
    all in this process; ``auto``: the count was not asked for, so a machine that cannot
    start processes runs serially); the outputs are the same.
    """
    import matplotlib

    matplotlib.use("Agg")
    from ..report import commit_outputs
    from ..report.study_report import build_report
    from ..studies import run_study
    from .common import process_pool

    files = masing_outputs()
    intro = (f"Made by: {command}. " if command else "") + (
        "Example study bundled with contactlab (synthetic recordings with realistic sensor "
        "noise, offsets, quantisation and drift; see contactlab.data.generate). The table's "
        "true_h0 / true_ac columns are the values the recordings were made with."
    )
    with process_pool(workers, auto=auto) as ex:
        result = run_study(
            demo_entries(quick), progress=progress, executor=ex, keep_recordings=True
        )
        rep = build_report(
            result, "contactlab demo: example study", intro=intro, progress=progress, executor=ex
        )
    files.update(rep.files())
    files.update(result.table_files())
    return commit_outputs(out, files)


def _handler(args: argparse.Namespace) -> int:
    t0 = time.perf_counter()
    from .common import made_by, resolve_workers

    workers = resolve_workers(args.workers)
    paths = run_demo(
        Path(args.out),
        quick=args.quick,
        progress=args.progress,
        workers=workers,
        auto=args.workers is None,
        command=made_by(args, "demo", "--out", args.out),
    )
    for p in paths:
        if p.parent == Path(args.out):
            print(f"wrote {p}")
    n_fig = sum(p.suffix == ".png" and p.parent.name == "figures" for p in paths)
    took = time.perf_counter() - t0
    print(f"(and {n_fig} figures under {Path(args.out) / 'figures'}; {took:.1f} s)")
    return 0


def add_parser(sub: argparse._SubParsersAction) -> None:
    from .common import add_progress_flags

    p = sub.add_parser(
        "demo",
        help="run the bundled demonstration and write its outputs",
        description="Analyse the example study bundled with contactlab (synthetic recordings "
        "of three material pairs over loads and amplitudes, tangential and normal, in CSV, "
        "TDMS, HDF5 and MAT files) and write report.html, figures/*.png, loops.png and the "
        "study tables into --out. Nothing is read from outside the package.",
    )
    p.add_argument("--out", default="demo-output", help="output folder (default: demo-output)")
    p.add_argument("--quick", action="store_true", help="a reduced set (one file per material)")
    p.add_argument(
        "--workers",
        type=int,
        default=None,
        metavar="N",
        help="analyse the recordings and draw the figures in N processes (default: "
        "one per core, at most 8; 0: serially in this process)",
    )
    add_progress_flags(p)
    p.set_defaults(handler=_handler)
