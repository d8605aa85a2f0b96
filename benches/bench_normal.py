"""Benchmark: the nonlinear contact model (eq. 17) over a long sampled pressure, contactlab's
Rust integrator against ``scipy.integrate.solve_ivp(method="LSODA")``, side by side.

Problem: k_s(δ) from the Table 2 centre curve, ψ = 0.0887, ω = 1 rad/s, p = 0.4 MPa sin ω t
sampled at 256 points per period (the paper's rate), continued between samples by the same
cubic Hermite for both solvers (slopes ``numpy.gradient(p, t, edge_order=2)``; scipy gets
``CubicHermiteSpline``'s piecewise coefficients and an analytic Jacobian).

Accuracy: both are measured against a reference solved by contactlab at rtol 1e-12 on the
samples scipy integrated; the speed-up is quoted at the same rtol and, if contactlab were the
less accurate there, at the contactlab tolerance that matches LSODA's error.

    python benches/bench_normal.py                 # 1e7 samples for both (LSODA: ~15 min)
    python benches/bench_normal.py --scipy-n 1e6   # LSODA on the first 1e6 samples only
"""

from __future__ import annotations

import argparse
import bisect
import json
import sys
import time

import numpy as np

from contactlab.normal import NonlinearContact

A_T2 = np.array([1.32596e12, 1.59811e18, 2.92127e24, 2.87416e30])
PSI, OMEGA, PA = 0.0887, 1.0, 0.4e6


def problem(n: int, spc: int) -> tuple[np.ndarray, np.ndarray]:
    t = np.arange(n) * (2 * np.pi / OMEGA / spc)
    return t, PA * np.sin(OMEGA * t)


def run_contactlab(model: NonlinearContact, t, p, rtol: float, atol: float):
    t0 = time.perf_counter()
    res = model.simulate(t, p, rtol=rtol, atol=atol, delta0=0.0)
    el = time.perf_counter() - t0
    if not res.success:
        raise SystemExit(f"contactlab failed: {res.message}")
    return res, el


def run_lsoda(t, p, ns: int, rtol: float, atol: float):
    """LSODA over the first ``ns`` samples, on the interpolant of the whole record."""
    from scipy.integrate import solve_ivp
    from scipy.interpolate import CubicHermiteSpline

    m = min(ns + 8, t.size)  # slopes as in the full record (interior formula at sample ns-1)
    t, p = t[:m], p[:m]
    spl = CubicHermiteSpline(t, p, np.gradient(p, t, edge_order=2))
    c3, c2, c1, c0 = (np.asarray(c).tolist() for c in spl.c)
    x = np.asarray(spl.x).tolist()
    a1, a2, a3, a4 = A_T2.tolist()
    r = 2 * np.pi * OMEGA / PSI
    last = len(x) - 2

    def seg(tt):
        i = bisect.bisect_right(x, tt) - 1
        i = 0 if i < 0 else (last if i > last else i)
        s = tt - x[i]
        return ((c3[i] * s + c2[i]) * s + c1[i]) * s + c0[i]

    def rhs(tt, y):
        d = y[0]
        k = ((a4 * d + a3) * d + a2) * d + a1
        return [r * (seg(tt) / k - d)]

    def jac(tt, y):
        d = y[0]
        k = ((a4 * d + a3) * d + a2) * d + a1
        dk = (3 * a4 * d + 2 * a3) * d + a2
        return [[-r * (1 + seg(tt) * dk / (k * k))]]

    t0 = time.perf_counter()
    sol = solve_ivp(
        rhs,
        (t[0], t[ns - 1]),
        [0.0],
        method="LSODA",
        t_eval=t[:ns],
        rtol=rtol,
        atol=atol,
        jac=jac,
    )
    el = time.perf_counter() - t0
    if not sol.success:
        raise SystemExit(f"LSODA failed: {sol.message}")
    return sol, el


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    ap.add_argument("--n", type=float, default=1e7, help="samples for contactlab (default 1e7)")
    ap.add_argument("--scipy-n", type=float, default=None, help="samples for LSODA (default: --n)")
    ap.add_argument("--rtol", type=float, default=1e-8)
    ap.add_argument("--spc", type=int, default=256, help="samples per period (default 256)")
    ap.add_argument("--json", default=None, help="also write the figures to this JSON file")
    args = ap.parse_args(argv)
    n = int(args.n)
    ns = n if args.scipy_n is None else min(int(args.scipy_n), n)
    rtol = args.rtol

    t, p = problem(n, args.spc)
    model = NonlinearContact(k_s_delta=A_T2, psi=PSI, omega=OMEGA)
    scale = PA / A_T2[0]  # displacement scale, m
    atol = rtol * scale
    print(f"nonlinear contact model, {n:.3g} samples ({n / args.spc:.4g} periods), rtol {rtol:g}")

    ours, t_ours = run_contactlab(model, t, p, rtol, atol)
    print(
        f"contactlab RODAS4 : {t_ours:8.3f} s  ({t_ours / n * 1e9:7.1f} ns/sample, "
        f"{ours.n_steps / n:.2f} steps/sample, {ours.n_rejected} rejected)"
    )
    m = min(ns + 8, n)  # same interpolant as the full record up to sample ns-1
    ref, t_ref = run_contactlab(model, t[:m], p[:m], 1e-12, 1e-12 * scale)
    dref = ref.delta[:ns]
    dscale = float(np.max(np.abs(dref)))

    def err(d):
        return float(np.max(np.abs(d[:ns] - dref)) / dscale)

    e_ours = err(ours.delta)
    print(f"  max error vs reference (rtol 1e-12, {t_ref:.1f} s): {e_ours:.3g} of max|δ|")

    sol, t_lsoda = run_lsoda(t, p, ns, rtol, atol)
    e_lsoda = err(sol.y[0])
    t_lsoda_full = t_lsoda * n / ns
    note = "" if ns == n else f" (on {ns:.3g} samples; ×{n / ns:g} → {t_lsoda_full:.1f} s)"
    print(
        f"scipy LSODA       : {t_lsoda:8.3f} s{note}  ({t_lsoda / ns * 1e9:9.1f} ns/sample, "
        f"nfev {sol.nfev}, njev {sol.njev})"
    )
    print(f"  max error vs reference: {e_lsoda:.3g} of max|δ|")

    # Same accuracy: the loosest contactlab rtol (half-decade steps) whose error is still no
    # larger than LSODA's; tighter than `rtol` if contactlab were the less accurate.
    rt, t_match, e_match = rtol, t_ours, e_ours
    while e_match > e_lsoda and rt > 1e-12:
        rt /= 10
        res, t_match = run_contactlab(model, t, p, rt, rt * scale)
        e_match = err(res.delta)
    for k in range(1, 7):
        if e_ours > e_lsoda:
            break  # contactlab had to be tightened: nothing to loosen
        trial = rtol * 10 ** (k / 2)
        res, t_try = run_contactlab(model, t, p, trial, trial * scale)
        e_try = err(res.delta)
        if e_try > e_lsoda:
            break
        rt, t_match, e_match = trial, t_try, e_try
    speed_same_rtol = t_lsoda_full / t_ours
    speed_same_acc = t_lsoda_full / t_match
    print(f"speed-up at the same rtol      : {speed_same_rtol:7.1f}×")
    print(
        f"speed-up at the same accuracy  : {speed_same_acc:7.1f}×  (contactlab rtol {rt:.3g}, "
        f"{t_match:.3f} s, error {e_match:.3g} <= LSODA {e_lsoda:.3g})"
    )
    out = {
        "n": n,
        "scipy_n": ns,
        "rtol": rtol,
        "contactlab_s": t_ours,
        "contactlab_error": e_ours,
        "contactlab_steps_per_sample": ours.n_steps / n,
        "lsoda_s": t_lsoda,
        "lsoda_s_scaled_to_n": t_lsoda_full,
        "lsoda_error": e_lsoda,
        "speedup_same_rtol": speed_same_rtol,
        "speedup_same_accuracy": speed_same_acc,
        "matched_rtol": rt,
        "matched_contactlab_s": t_match,
        "matched_contactlab_error": e_match,
    }
    if args.json:
        with open(args.json, "w", encoding="utf-8") as fh:
            json.dump(out, fh, indent=2)
    return 0 if speed_same_acc >= 30 else 1


if __name__ == "__main__":
    sys.exit(main())
