"""Amplitude dependence of a 2-DOF structure's modes (issue 10): the equivalent
linearisation (:func:`contactlab.structure.modal_amplitude_dependence`) against the time
integration's phase resonance (:func:`contactlab.structure.phase_resonance`, periodic steady
state of a stepped sine) at several amplitudes, for a Jenkins joint to the ground and a
Masing joint between the two masses. Prints the table (relative differences in %) and the
times; ``--plot FILE`` saves the curves with the measured points.

    python benches/eval_structure_amplitude.py [--plot amplitude.png]
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from contactlab.structure import Structure, modal_amplitude_dependence, phase_resonance


def two_dof(joint: str) -> Structure:
    s = Structure(np.diag([1.0, 0.5]), [[3.0, -1.0], [-1.0, 1.0]], [[6e3, -2e3], [-2e3, 2e3]])
    if joint == "jenkins to ground":
        s.add_joint("jenkins", 0, None, k=2e3, fs=1.0)
    else:
        s.add_joint("masing", 0, 1, h0=1.5, ac=1500.0)
    return s


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--plot", help="save the curves and the measured points to this PNG")
    args = ap.parse_args()
    amps = (3e-4, 1e-3, 3e-3, 1e-2, 3e-2)
    print(f"{'joint':<20} {'mode':>4} {'amplitude':>10} {'f sim':>9} {'f EQL':>9} {'df %':>6} "
          f"{'zeta sim %':>10} {'zeta EQL %':>10} {'dz %':>6}")  # fmt: skip
    worst_f = worst_z = 0.0
    t_eql = t_sim = 0.0
    points = []
    for joint in ("jenkins to ground", "masing between"):
        s = two_dof(joint)
        for mode in (0, 1):
            for a in amps:
                t0 = time.perf_counter()
                pr = phase_resonance(s, a, mode, samples_per_period=256, rel_tol=1e-6)
                t1 = time.perf_counter()
                ad = modal_amplitude_dependence(s, [pr.amplitude], mode=mode)
                t2 = time.perf_counter()
                t_sim += t1 - t0
                t_eql += t2 - t1
                df = 100 * (pr.frequency_hz / ad.frequency_hz[0] - 1)
                dz = 100 * (pr.damping_ratio / ad.damping_ratio[0] - 1)
                worst_f, worst_z = max(worst_f, abs(df)), max(worst_z, abs(dz))
                points.append((joint, mode, pr))
                print(f"{joint:<20} {mode + 1:>4} {pr.amplitude:>10.3g} {pr.frequency_hz:>9.4f} "
                      f"{ad.frequency_hz[0]:>9.4f} {df:>+6.2f} {100 * pr.damping_ratio:>10.3f} "
                      f"{100 * ad.damping_ratio[0]:>10.3f} {dz:>+6.2f}")  # fmt: skip
    n = len(points)
    print(
        f"worst |df| {worst_f:.2f} %, worst |dzeta| {worst_z:.2f} % over {n} points; "
        f"EQL {1e3 * t_eql / n:.1f} ms per point, phase resonance {t_sim / n:.2f} s per point"
    )
    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        from contactlab.report.structure_plots import plot_modal_amplitude_dependence

        fig, ax = plt.subplots(2, 2, figsize=(10, 7))
        for row, joint in enumerate(("jenkins to ground", "masing between")):
            s = two_dof(joint)
            grid = np.geomspace(1e-4, 5e-2, 40)
            ads = [modal_amplitude_dependence(s, grid, mode=m) for m in (0, 1)]
            plot_modal_amplitude_dependence(ads, ax[row])
            for j, _mode, pr in points:
                if j == joint:
                    ax[row][0].plot(pr.amplitude, pr.frequency_hz, "kx")
                    ax[row][1].plot(pr.amplitude, 100 * pr.damping_ratio, "kx")
            ax[row][0].set_title(joint)
        fig.tight_layout()
        fig.savefig(args.plot, dpi=110)
        print(f"wrote {args.plot}")


if __name__ == "__main__":
    main()
