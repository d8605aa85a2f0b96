"""What ``diagnose`` names on Coulomb friction frames (issue 8): the friction_frame rig's
physics simulated from rest (tests/frame_sim.py: base-excited frame, static ``Fs`` and
kinetic ``Fk`` friction, plain Python, no contactlab code), white noise on both measured
displacements, the friction force reconstructed by :func:`contactlab.tangential.
frame_friction_force` as a user would from measured frames.

A Coulomb frame's only effect beyond Masing is static above kinetic friction (Fs > Fk);
every other name is spurious (an inertia term on a reconstructed force is the frame's own
``M x''``: ``diagnose`` reports it as a reading of M, printed apart). Each case is diagnosed
four ways:

- ``true``: the simulation's own friction force with white noise of the reconstruction's
  level (what a force sensor would give), the diagnosis as it was before issue 8's fix
  (no sticking samples weighted out: ``TangentialFamily.sticking`` disabled);
- ``true_stick``: the same force, the sticking samples weighted out;
- ``recon``: the reconstructed force passed as plain arrays (no declared filter, the noise
  estimated from the residual);
- ``declared``: ``FrameForce.recording()``, whose meta declares the reconstruction's kernel
  and noise (``output_filter``, ``output_noise``).

Cases are drawn per seed: sampling 250/500/1000 Hz, Fk 0.5-1.2 N, Fs/Fk in {1, 1.1, 1.25,
1.5}, displacement noise 0.2-1.5 µm; with ``filters``, both displacement channels also pass
causal 2nd-order Butterworth anti-alias filters, cut-offs drawn per seed from 0.2/0.2,
0.3/0.3 and 0.2/0.4 of Nyquist (x/y). Prints one JSON line per case, then the tables.

    python benches/eval_frame_diagnose.py [first_seed] [count] [modes] [filters]
"""

from __future__ import annotations

import collections
import json
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

import contactlab
from contactlab.diagnose.candidates_tangential import TangentialFamily
from contactlab.tangential import frame_friction_force
from frame_sim import simulate_frame

M, C, K = 3.08, 0.669, 1191.0


def case(seed: int) -> tuple[float, float, float, float]:
    rng = np.random.default_rng(seed)
    fs = float(rng.choice([250.0, 500.0, 1000.0]))
    fk = float(rng.uniform(0.5, 1.2))
    ratio = float(rng.choice([1.0, 1.1, 1.25, 1.5]))
    sigma = float(rng.uniform(2e-7, 1.5e-6))
    return fs, fk, ratio * fk, sigma


def run(seed: int, modes: list[str], filters: bool = False) -> dict:
    fs, fk, fsx, sigma = case(seed)
    rng = np.random.default_rng(seed + 1000)
    t, x, y, F = simulate_frame(Fk=fk, Fs=fsx, fs=fs)
    xm = x + rng.normal(0, sigma, x.size)
    ym = y + rng.normal(0, sigma, x.size)
    cuts = None
    if filters:
        from scipy.signal import butter, lfilter

        cuts = [(0.2, 0.2), (0.3, 0.3), (0.2, 0.4)][int(rng.integers(3))]
        xm = lfilter(*butter(2, cuts[0]), xm)
        ym = lfilter(*butter(2, cuts[1]), ym)
    r = frame_friction_force(t, xm, ym, M=M, C=C, K=K)
    Fn = F + rng.normal(0, r.force_noise, F.size)
    row = {"seed": seed, "fs": fs, "Fk": round(fk, 3), "Fs": round(fsx, 3),
           "sigma_um": round(sigma * 1e6, 2), "window": r.window, "filters": cuts}  # fmt: skip
    for m in modes:
        t0 = time.process_time()
        if m == "true":
            keep = TangentialFamily.sticking
            TangentialFamily.sticking = lambda self, d: np.zeros(d.t.size, bool)  # type: ignore[method-assign]
            try:
                rep = contactlab.diagnose((t, xm, Fn))
            finally:
                TangentialFamily.sticking = keep  # type: ignore[method-assign]
        elif m == "true_stick":
            rep = contactlab.diagnose((t, xm, Fn))
        elif m == "recon":
            rep = contactlab.diagnose((t, xm, r.F))
        else:
            rep = contactlab.diagnose(r.recording())
        row[m] = rep.effect_names
        row[m + "_params"] = {e.name: {k: float(f"{v:.4g}") for k, v in e.parameters.items()}
                              for e in rep.effects}  # fmt: skip
        fc = rep.location.get("frame_constants") or {}
        if fc:  # an inertia term read as the frame's own mass (not named as a joint effect)
            row[m + "_M_read"] = round(fc["M_read"], 5)
        row[m + "_h0"] = round(rep.final_model.params["h0"], 4)
        row[m + "_gap"] = round(rep.steps[-1].heldout_rms / rep.noise_rms, 2)
        row[m + "_cpu_s"] = round(time.process_time() - t0, 2)
    return row


def main() -> None:
    first = int(sys.argv[1]) if len(sys.argv) > 1 else 63001
    count = int(sys.argv[2]) if len(sys.argv) > 2 else 12
    modes = sys.argv[3].split(",") if len(sys.argv) > 3 else ["true", "true_stick", "recon",
                                                               "declared"]  # fmt: skip
    filters = len(sys.argv) > 4 and sys.argv[4] == "filters"
    rows = []
    for seed in range(first, first + count):
        row = run(seed, modes, filters)
        rows.append(row)
        print(json.dumps(row), flush=True)
    print()
    for m in modes:
        names = collections.Counter(n for r in rows for n in r[m])
        clean = sum(1 for r in rows if not set(r[m]) - {"stick_slip", "stribeck"})
        h0 = [abs(r[m + "_h0"] / r["Fk"] - 1) for r in rows]
        mass = [r[m + "_M_read"] for r in rows if m + "_M_read" in r]
        if mass:
            print(f"{m:11s} the frame's M read from an inertia term in {len(mass)} case(s): "
                  f"{', '.join(f'{v:.4g}' for v in mass)} kg (given {M} kg)")  # fmt: skip
        print(f"{m:11s} only Fs>Fk effects (stick_slip/stribeck) or nothing: {clean}/{len(rows)};"
              f" names {dict(names)}; |h0/Fk - 1| median {100 * np.median(h0):.2f} % max "
              f"{100 * np.max(h0):.2f} %")  # fmt: skip


if __name__ == "__main__":
    main()
