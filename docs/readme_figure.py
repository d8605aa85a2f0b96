"""Make ``docs/_static/readme-loop.png``, the README's picture, from data bundled with the
package (never from measured files): one bundled tangential recording through
``analyze_tangential``, its averaged loop with the fitted Masing loop, and the loops of the
three amplitudes at one load.

Run ``.venv/bin/python docs/readme_figure.py`` after changing the analysis or the plots; the
PNG is committed so that the README shows it without a build.
"""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

from contactlab.data import data_dir
from contactlab.io import read_recording
from contactlab.report.tangential import plot_loop
from contactlab.tangential import analyze_tangential

OUT = Path(__file__).resolve().parent / "_static" / "readme-loop.png"


def main() -> Path:
    fig, axes = plt.subplots(1, 2, figsize=(9.0, 3.4), layout="constrained")
    files = sorted(data_dir().glob("tangential/Al-Al_W109N_A*um.csv"),
                   key=lambda p: float(p.stem.split("_A")[1][:-2]))  # fmt: skip
    for f in files:
        res = analyze_tangential(read_recording(f), warn=False)
        loop = res.loop
        assert loop is not None
        axes[1].plot(1e6 * loop.x, loop.F, lw=1.0, label=f.stem.split("_")[-1])
        if f.stem.endswith("A10um"):
            plot_loop(res, ax=axes[0])
            d = res.to_dict()
            axes[0].set_title(f"{f.name}: h0 = {d['h0']:.1f} ± {d['h0_stderr']:.1f} N, "
                              f"ac = {d['ac']:.3g} 1/m", fontsize=9)  # fmt: skip
    axes[1].set_xlabel("x [µm]")
    axes[1].set_ylabel("F [N]")
    axes[1].set_title("Al/Al at 109 N: averaged loops at three amplitudes", fontsize=9)
    axes[1].legend(fontsize=8)
    fig.savefig(OUT, dpi=90)
    plt.close(fig)
    return OUT


if __name__ == "__main__":
    print(main())
