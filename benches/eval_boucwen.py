"""Hold-out evaluation on the hysteretic benchmark's training record (Noël & Schoukens).

Trains each joint model on periods 1-4 of ``../shared/data/boucwen/train_multisine.csv``
(32768 samples, start-up transient included, from rest), simulates the whole record with the
identified model (band-limited input between samples) and reports the simulation error
e_RMS = sqrt(mean((ŷ − y)²)) in metres on the held-out period 5, the training RMS and the
identification wall time. The benchmark's own validation signals are not used (we do not
have them); the published validation-multisine results are about 1e-5 to 5e-5 m.

    python benches/eval_boucwen.py [joint ...] [--json out.json]
"""

from __future__ import annotations

import argparse
import json
import os
import time
from pathlib import Path

import numpy as np

from contactlab.structure.identify import identify

DATA = Path(__file__).resolve().parents[1].parent / "shared" / "data" / "boucwen"
N = 8192
FS = 750.0


def load() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    d = np.loadtxt(DATA / "train_multisine.csv", delimiter=",", comments="#")
    u, y = d[:, 0], d[:, 1]
    return np.arange(u.size) / FS, u, y


def evaluate(joint: str, substeps: int = 4) -> dict[str, float]:
    t, u, y = load()
    ntr = 4 * N
    t0, c0 = time.perf_counter(), time.process_time()
    m = identify(t[:ntr], u[:ntr], y[:ntr], joint=joint, substeps=substeps)
    elapsed, cpu = time.perf_counter() - t0, time.process_time() - c0
    r = m.simulate(t, force=u, x0=[m.x0], v0=[m.v0], interpolation="fourier")
    e = r.x - y
    return {
        "joint": joint,
        "holdout_e_rms_m": float(np.sqrt(np.mean(e[4 * N :] ** 2))),
        "train_rms_m": float(m.rms),
        "identify_s": elapsed,
        "identify_cpu_s": cpu,
        "nfev": m.fit.nfev,
        "load_avg": os.getloadavg()[0],
        "params": {k: p.value for k, p in m.fit.params.items()},
        # reported (residual-autocorrelation-corrected) and white-noise standard errors
        "stderr": {k: m.fit.params[k].stderr for k in m.fit.var_names},
        "noise": m.noise,
        "stderr_white": dict(zip(m.fit.var_names, white_stderr(m.fit), strict=True)),
    }


def white_stderr(fit) -> np.ndarray:
    """``sqrt(diag((JᵀJ)⁻¹) χ²/ν)``: the errors were the residuals white."""
    J, r = fit.jac, fit.residual
    nrm = np.linalg.norm(J, axis=0)
    A = np.linalg.pinv((J / nrm).T @ (J / nrm), rcond=1e-16)
    return np.sqrt(np.diag(A) * (r @ r) / (r.size - J.shape[1])) / nrm


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("joints", nargs="*", default=["bouc_wen", "masing", "iwan", "jenkins",
                                                  "normal", "kelvin_voigt"])  # fmt: skip
    ap.add_argument("--json")
    a = ap.parse_args()
    if not DATA.exists():
        raise SystemExit(f"{DATA} absent")
    rows = []
    for j in a.joints:
        row = evaluate(j)
        rows.append(row)
        print(f"{j:14s} hold-out e_RMS {row['holdout_e_rms_m']:.3e} m   train "
              f"{row['train_rms_m']:.3e} m   identify {row['identify_s']:.1f} s wall, "
              f"{row['identify_cpu_s']:.1f} s CPU "
              f"(load {row['load_avg']:.1f})", flush=True)  # fmt: skip
        print(f"    noise levels behind the standard errors: {row['noise']}")
        for k, se in row["stderr"].items():
            sw = row["stderr_white"][k]
            se = float("nan") if se is None else se
            print(f"    {k:8s} {row['params'][k]:+.6g} ± {se:.3g}"
                  f" (white-noise ± {sw:.3g})")  # fmt: skip
    if a.json:
        Path(a.json).write_text(json.dumps(rows, indent=2))


if __name__ == "__main__":
    main()
