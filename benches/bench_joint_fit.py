"""Joint-law fits on 1e5 samples (issue 30: "a fit on 1e5 samples in <= 2 s"): process CPU
time of :func:`contactlab.joints.fit` with the Jacobian from the Rust core's forward
sensitivities (the default where the law has them) against the same fit with
finite-difference Jacobians (the path of laws without sensitivities), in the same run, on
the same records: a synthetic history from a law with known parameters plus 1 % noise.
Columns: CPU seconds of each path, their ratio, the residual RMS of each fit relative to the
noise, and the largest relative error of the fitted law parameters against the truth.

Run: ``.venv/bin/python benches/bench_joint_fit.py [--n 100000] [--laws dahl,lugre]``.
"""

from __future__ import annotations

import argparse
import importlib
import time

import numpy as np

from contactlab.joints import BoucWen, Dahl, Jenkins, LuGre, MaxwellSlip, fit

fit_module = importlib.import_module("contactlab.joints.fit_problem")


def history(n: int) -> tuple[np.ndarray, np.ndarray]:
    """1 Hz sine of slowly varying amplitude at 1 kHz, with small inner reversals."""
    t = np.arange(n) / 1000.0
    x = 1e-3 * np.sin(2 * np.pi * t) * (1 + 0.3 * np.sin(0.2 * t))
    return t, x + 5e-5 * np.sin(2 * np.pi * 7.3 * t)


TRUTH = {
    "jenkins": Jenkins(k=2e4, fs=10.0),
    "dahl": Dahl(sigma0=3e4, Fc=10.0, alpha=1.0),
    "lugre": LuGre(sigma0=2e5, sigma1=30.0, sigma2=5.0, Fc=10.0, Fs=12.0, vs=2e-3),
    "maxwell_slip": MaxwellSlip(k=[1e4, 8e3, 6e3, 4e3], fs=[1.0, 3.0, 4.0, 4.0]),
    "bouc_wen": BoucWen(alpha=2e4, beta=2e3, gamma=0.5, delta=0.5, nu=1.0),
}


def one(law: str, n: int, analytic: bool) -> tuple[float, object]:
    t, x = history(n)
    true = TRUTH[law]
    F = true.force(t, x)
    F = F + np.random.default_rng(1).normal(0, 0.01 * np.std(F), n)
    saved = fit_module.has_sensitivities
    if not analytic:
        fit_module.has_sensitivities = lambda _law: False
    try:
        c0 = time.process_time()
        res = fit(t, x, F, law=law)
        cpu = time.process_time() - c0
    finally:
        fit_module.has_sensitivities = saved
    return cpu, (res, true, F)


def quality(out: object) -> tuple[float, float]:
    res, true, F = out  # type: ignore[misc]
    noise = 0.01 * np.std(F)
    rms = float(np.sqrt(res.result.chisqr / res.n_samples))
    err = 0.0
    if res.law.name != "maxwell_slip":  # its elements are not individually identifiable
        for n, v in true.params.items():
            p = res.params[n]
            if p.vary:
                err = max(err, abs(p.value - v) / abs(v))
    return rms / noise, err


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=100_000)
    ap.add_argument("--laws", default="jenkins,dahl,lugre,maxwell_slip,bouc_wen")
    a = ap.parse_args()
    print(f"fit on {a.n} samples, process CPU s")
    print(f"{'law':<13} {'sens s':>7} {'FD s':>7} {'FD/sens':>8} {'rms/noise sens':>15} "
          f"{'FD':>6} {'max param err sens':>19} {'FD':>8}  converged")  # fmt: skip
    for law in a.laws.split(","):
        has = fit_module.has_sensitivities(TRUTH[law])
        cs, os_ = one(law, a.n, True)
        cf, of = one(law, a.n, False) if has else (cs, os_)
        qs, qf = quality(os_), quality(of)
        conv = f"{os_[0].success}/{of[0].success}"
        print(f"{law:<13} {cs:7.2f} {cf:7.2f} {cf / cs:8.1f} {qs[0]:15.3f} {qf[0]:6.3f} "
              f"{qs[1]:19.2e} {qf[1]:8.2e}  {conv}"
              + ("" if has else "  (no sensitivities: finite differences on both)"))  # fmt: skip


if __name__ == "__main__":
    main()
