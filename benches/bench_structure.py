"""Speed of the structure integrator (issue 10): an SDOF oscillator with a Masing joint,
1e6 Newmark steps in the Rust core, against a straightforward pure-Python implementation of
the same scheme (Newmark average acceleration in the acceleration form, Newton on the joint
force with its tangent) measured in the same run: a scalar pure-Python version specialised to
one DOF (steps split at velocity reversals, as the core does), and the straightforward numpy
version written for n DOFs as the core is (matrices, ``np.linalg.solve`` per Newton update).

The Python reference is timed on fewer steps (default 20000) and scaled linearly to 1e6 (its
cost per step is constant); both runs are checked to agree on the common steps. Rust and the
scalar reference are timed in ``--repeat`` interleaved pairs, in wall and process-CPU time;
the ratio is the median of the pairs' ratios (on a loaded machine the CPU ratio is the
steadier one). The Rust run returns what the reference returns, the displacement
(``outputs=("x",)``); the run with all eight outputs is timed and reported too. Target: the
Rust core ≥ 100× the reference.

``--stepping`` prints instead the error-controlled stepping table (issue 33 item 6): for SDOF
and MDOF structures with Bouc-Wen, Masing and Jenkins joints, the default run
(error-controlled, ``tol = DEFAULT_TOL``) against the old default (``substeps=1``: one Newmark
step per sample, the same code path as before) — their CPU-time ratio (medians of
``--repeat`` interleaved pairs) and each one's relative RMS error of ``x`` against tight
references: scipy ``solve_ivp`` LSODA and Radau at ``rtol = 1e-11`` where the joint law is an
ODE (Bouc-Wen), ``solve_ivp`` DOP853 at ``rtol = 1e-10`` with the Masing memory and Jenkins
stick-slip handled by terminal events (``structure_reference.py``, written apart from the
core; the reference of the Masing and Jenkins cases), fixed Newmark with 64 steps per sample
(second order, an independent route) and the error-controlled run at ``tol / 100``.
OpenSeesPy is compared when installed. ``--only TEXT`` runs the cases whose name has TEXT.
Run: ``.venv/bin/python benches/bench_structure.py [--stepping]``.
"""

from __future__ import annotations

import argparse
import math
import os
import statistics
import time
from functools import partial

import numpy as np

from contactlab.structure import Structure

M, C, K = 1.0, 0.5, 1.0e4
H0, AC, LAM = 40.0, 4.0e4, 2.0
DT = 1e-4


def excitation(n: int) -> tuple[np.ndarray, np.ndarray]:
    t = np.arange(n) * DT
    rng = np.random.default_rng(3)
    f = 60.0 * np.sin(2 * np.pi * 7.0 * t) + 20.0 * np.sin(2 * np.pi * 31.0 * t + rng.uniform())
    return t, f


class PyMasing:
    """The Masing operator with non-local memory, in plain Python (trial / commit)."""

    def __init__(self) -> None:
        self.x = 0.0
        self.h = 0.0
        self.dir = 0.0
        self.stack: list[tuple[float, float]] = []

    @staticmethod
    def f(u: float) -> float:
        return math.copysign(H0 * (1.0 - math.exp(-AC * abs(u))), u)

    @staticmethod
    def df(u: float) -> float:
        return H0 * AC * math.exp(-AC * abs(u))

    def _walk(self, x: float) -> tuple[list[tuple[float, float]], float]:
        dx = x - self.x
        s = 1.0 if dx > 0 else (-1.0 if dx < 0 else self.dir)
        stack = list(self.stack)
        if dx != 0.0 and self.dir != 0.0 and s != self.dir:
            stack.append((self.x, self.h))
        while stack and dx != 0.0:
            target = -stack[0][0] if len(stack) == 1 else stack[-2][0]
            if (x - target) * s >= 0.0:
                del stack[-(1 if len(stack) == 1 else 2) :]
            else:
                break
        return stack, s

    def trial(self, x: float) -> tuple[float, float]:
        stack, _ = self._walk(x)
        if not stack:
            return self.f(x), self.df(x)
        xa, ha = stack[-1]
        u = (x - xa) / LAM
        return ha + LAM * self.f(u), self.df(u)

    def commit(self, x: float) -> None:
        stack, s = self._walk(x)
        h, _ = self.trial(x)
        if x != self.x:
            self.dir = s
        self.stack, self.x, self.h = stack, x, h


def python_reference(
    t: np.ndarray, f: np.ndarray, rtol: float = 1e-10, linear_predictor: bool = False
) -> np.ndarray:
    """The scheme in plain Python. Newton starts from the last acceleration (the
    straightforward choice), or with ``linear_predictor`` from the step of the equation
    linearised at the start of the step, as the Rust core does (fewer iterations)."""
    joint = PyMasing()
    x, v, a = 0.0, 0.0, f[0] / M
    fj0, kt0 = 0.0, H0 * AC  # joint force and tangent at the start of the step
    out = np.empty(t.size)
    out[0] = 0.0

    def step(h: float, f1: float) -> tuple[float, float, float, float, float]:
        b, g = 0.25 * h * h, 0.5 * h
        a1 = a
        if linear_predictor:
            rhs = f1 - C * (v + g * a) - K * (x + h * v + b * a) - fj0 - kt0 * (h * v + b * a)
            a1 = rhs / (M + g * C + b * (K + kt0))
        for _ in range(30):
            x1 = x + h * v + b * (a + a1)
            v1 = v + g * (a + a1)
            fj, kt = joint.trial(x1)
            r = M * a1 + C * v1 + K * x1 + fj - f1
            scale = abs(f1) + abs(M * a1) + abs(C * v1) + abs(K * x1)
            if abs(r) <= rtol * max(scale, abs(fj)):
                return x1, v1, a1, fj, kt
            a1 -= r / (M + g * C + b * (K + kt))
        raise RuntimeError("Newton failed")

    for i in range(t.size - 1):
        big_h = t[i + 1] - t[i]
        tau = 0.0
        while tau < 1.0:
            frac = 1.0 - tau
            f1 = f[i] + (f[i + 1] - f[i]) * (tau + frac)
            x1, v1, a1, fj1, kt1 = step(frac * big_h, f1)
            if v * v1 < 0.0:
                theta = v / (v - v1)
                if theta * frac * big_h > 1e-3 * big_h and (1 - theta) * frac > 1e-3:
                    frac *= theta
                    f1 = f[i] + (f[i + 1] - f[i]) * (tau + frac)
                    x1, v1, a1, fj1, kt1 = step(frac * big_h, f1)
            joint.commit(x1)
            x, v, a, fj0, kt0 = x1, v1, a1, fj1, kt1
            tau = 1.0 if tau + frac >= 1.0 - 1e-15 else tau + frac
        out[i + 1] = x
    return out


def numpy_reference(t: np.ndarray, f: np.ndarray, rtol: float = 1e-10) -> np.ndarray:
    """The same scheme written for an n-DOF structure with numpy matrices (as the core is):
    ``np.linalg.solve`` for each Newton update, joint forces scattered by index."""
    Mm, Cm, Km = np.array([[M]]), np.array([[C]]), np.array([[K]])
    joint = PyMasing()
    x, v = np.zeros(1), np.zeros(1)
    a = np.linalg.solve(Mm, np.array([f[0]]))
    out = np.empty(t.size)
    out[0] = 0.0
    for i in range(t.size - 1):
        h = t[i + 1] - t[i]
        b, g = 0.25 * h * h, 0.5 * h
        f1 = np.array([f[i + 1]])
        a1 = a.copy()
        for _ in range(30):
            x1 = x + h * v + b * (a + a1)
            v1 = v + g * (a + a1)
            fj, kt = joint.trial(float(x1[0]))
            G = np.array([fj])
            r = Mm @ a1 + Cm @ v1 + Km @ x1 + G - f1
            scale = np.abs(f1) + np.abs(Mm) @ np.abs(a1) + np.abs(Cm) @ np.abs(v1)
            scale = scale + np.abs(Km) @ np.abs(x1)
            if np.max(np.abs(r)) <= rtol * max(float(np.max(scale)), abs(fj)):
                break
            Kt = np.array([[kt]])
            a1 = a1 - np.linalg.solve(Mm + g * Cm + b * (Km + Kt), r)
        joint.commit(float(x1[0]))
        x, v, a = x1, v1, a1
        out[i + 1] = x[0]
    return out


def _timed(fn):  # type: ignore[no-untyped-def]
    """Wall and process-CPU time of one call of ``fn()``, and its result."""
    w0, c0 = time.perf_counter(), time.process_time()
    out = fn()
    return time.perf_counter() - w0, time.process_time() - c0, out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=1_000_000)
    ap.add_argument("--n-python", type=int, default=20_000)
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--stepping", action="store_true", help="the error-control table")
    ap.add_argument("--only", default="", help="--stepping: the cases whose name has this")
    ap.add_argument("--seed", type=int, default=1, help="--stepping: the multisine's seed")
    a = ap.parse_args()
    if a.stepping:
        stepping_table(a.n, a.repeat, a.only, a.seed)
        return
    t, f = excitation(a.n)
    s = Structure(M, C, K)
    s.add_joint("masing", 0, h0=H0, ac=AC, scale=LAM)
    np_ = a.n_python
    scale = (a.n - 1) / (np_ - 1)
    load0 = os.getloadavg()[0]
    # Interleaved (Rust run, the scalar Python reference), so that both sides of each pair see
    # the same machine load; the ratio reported is the median over the pairs. The Rust run
    # returns what the reference returns (the displacement: outputs=("x",)); the run with all
    # eight outputs (velocity, acceleration, joint force and energies) is timed alongside.
    rust_w, rust_c, py_w, py_c, all_w, all_c = [], [], [], [], [], []
    r = ref = full = None
    for _ in range(a.repeat):
        w, c, r = _timed(lambda: s.simulate(t, force=f, outputs=("x",)))
        rust_w.append(w)
        rust_c.append(c)
        w, c, full = _timed(lambda: s.simulate(t, force=f))
        all_w.append(w)
        all_c.append(c)
        w, c, ref = _timed(lambda: python_reference(t[:np_], f[:np_]))
        py_w.append(w * scale)
        py_c.append(c * scale)
    assert r is not None and r.success, r
    assert ref is not None and full is not None and np.array_equal(full.x, r.x)
    nw, nc, ref2 = _timed(lambda: numpy_reference(t[:np_], f[:np_]))
    nw, nc = nw * scale, nc * scale
    lw, lc, ref3 = _timed(lambda: python_reference(t[:np_], f[:np_], linear_predictor=True))
    lw, lc = lw * scale, lc * scale
    med = statistics.median
    ratio_w = med(p / q for p, q in zip(py_w, rust_w, strict=True))
    ratio_c = med(p / q for p, q in zip(py_c, rust_c, strict=True))
    ratio_all_w = med(p / q for p, q in zip(py_w, all_w, strict=True))
    ratio_all_c = med(p / q for p, q in zip(py_c, all_c, strict=True))
    rw, rc, pw, pc = med(rust_w), med(rust_c), med(py_w), med(py_c)
    diff = float(np.max(np.abs(ref - r.x[:np_])) / np.max(np.abs(ref)))
    diff2 = float(np.max(np.abs(ref2 - r.x[:np_])) / np.max(np.abs(ref2)))
    diff3 = float(np.max(np.abs(ref3 - r.x[:np_])) / np.max(np.abs(ref3)))
    print(f"Rust core, displacement only: {a.n} steps, median of {a.repeat}: {rw:.3f} s wall, "
          f"{rc:.3f} s CPU "
          f"({1e9 * rw / a.n:.0f} ns/step wall, {1e9 * rc / a.n:.0f} ns/step CPU; fastest "
          f"{1e9 * min(rust_c) / a.n:.0f} ns/step CPU; {r.n_iter / r.n_steps:.2f} Newton "
          "iterations/step)")  # fmt: skip
    print(f"Rust core, all eight outputs: {1e9 * med(all_w) / a.n:.0f} ns/step wall, "
          f"{1e9 * med(all_c) / a.n:.0f} ns/step CPU (fastest {1e9 * min(all_c) / a.n:.0f}); "
          f"ratio {ratio_all_w:.0f}x wall, {ratio_all_c:.0f}x CPU")  # fmt: skip
    print(f"scalar pure-Python reference: {np_} steps, scaled to {a.n}: {pw:.2f} s wall, "
          f"{pc:.2f} s CPU ({1e6 * pc / a.n:.2f} us/step CPU); max relative difference on the "
          f"common steps {diff:.2e}")  # fmt: skip
    print(f"numpy n-DOF reference: {np_} steps, scaled to {a.n}: {nw:.1f} s wall, {nc:.1f} s "
          f"CPU; max relative difference {diff2:.2e} (no reversal sub-steps); ratio "
          f"{nw / rw:.0f}x wall, {nc / rc:.0f}x CPU")  # fmt: skip
    print(f"scalar pure-Python with the core's linearised predictor: {lw:.1f} s wall, "
          f"{lc:.1f} s CPU (scaled); max relative difference {diff3:.2e}; ratio "
          f"{lw / rw:.0f}x wall, {lc / rc:.0f}x CPU")  # fmt: skip
    print(f"ratio vs scalar Python, both returning the displacement (median of {a.repeat} "
          f"interleaved pairs): {ratio_w:.0f}x "
          f"wall, {ratio_c:.0f}x CPU (per pair, CPU: "
          f"{', '.join(f'{p / q:.0f}' for p, q in zip(py_c, rust_c, strict=True))}; target "
          f">= 100x); load average {load0:.1f} -> {os.getloadavg()[0]:.1f}")  # fmt: skip


# ----------------------------------------------------------------- error-controlled stepping
BW = {"alpha": 5e4, "beta": 1e3, "gamma": 0.8, "delta": -1.1}  # the hysteretic benchmark's


def multisine(n: int, fs: float, cols: int = 1, seed: int = 1) -> np.ndarray:
    """Random-phase multisine, 5-150 Hz, 50 N RMS, period 8192 samples, ``(n, cols)``."""
    rng = np.random.default_rng(seed)
    freq = np.fft.rfftfreq(8192, 1 / fs)
    band = (freq >= 5) & (freq <= 150)
    out = np.empty((n, cols))
    for c in range(cols):
        spec = np.zeros(freq.size, complex)
        spec[band] = np.exp(2j * np.pi * rng.uniform(size=band.sum()))
        u = np.fft.irfft(spec, 8192)
        out[:, c] = np.resize(u * 50.0 / np.sqrt(np.mean(u**2)), n)
    return out


def bouc_wen_ode(s: Structure, t: np.ndarray, f: np.ndarray, method: str) -> np.ndarray:
    """``x`` of a structure whose joints are all Bouc-Wen (ν = 1) by scipy ``solve_ivp`` at
    rtol 1e-11 (the joint law as the ODE ``ż = α ḋ − β (γ |ḋ| z + δ ḋ |z|)``; the force linear
    between samples, as the core takes it)."""
    from scipy.integrate import solve_ivp

    n, js = s.n, s.joints
    minv = np.linalg.inv(s.M)

    def rhs(tt: float, y: np.ndarray) -> np.ndarray:
        x, v, z = y[:n], y[n : 2 * n], y[2 * n :]
        i = min(int(np.searchsorted(t, tt, side="right")) - 1, t.size - 2)
        w = (tt - t[i]) / (t[i + 1] - t[i])
        g = np.zeros(n)
        dz = np.empty(len(js))
        for k, j in enumerate(js):
            p = j.params
            dv = v[j.dof] - (v[j.dof2] if j.dof2 is not None else 0.0)
            g[j.dof] += z[k]
            if j.dof2 is not None:
                g[j.dof2] -= z[k]
            dz[k] = p["alpha"] * dv - p["beta"] * (
                p["gamma"] * abs(dv) * z[k] + p["delta"] * dv * abs(z[k])
            )
        a = minv @ ((1 - w) * f[i] + w * f[i + 1] - s.C @ v - s.K @ x - g)
        return np.concatenate([v, a, dz])

    y0 = np.zeros(2 * n + len(js))
    sol = solve_ivp(rhs, (t[0], t[-1]), y0, method=method, t_eval=t, rtol=1e-11, atol=1e-15,
                    max_step=float(t[1] - t[0]))  # fmt: skip
    return sol.y[:n].T


def stepping_cases() -> list[tuple[str, Structure, float, int, bool]]:
    """(name, structure, sample rate, samples for the accuracy check, Bouc-Wen only)."""
    out = []
    for fs in (3000.0, 750.0):
        s = Structure(2.0, 10.0, 5e4)
        s.add_joint("bouc_wen", 0, **BW)
        out.append((f"SDOF Bouc-Wen, {fs:g} Hz", s, fs, int(fs), True))
    s = Structure(2.0, 10.0, 5e4)
    s.add_joint("masing", 0, h0=40.0, ac=2e4, scale=2.0)
    out.append(("SDOF Masing, 3000 Hz", s, 3000.0, 9000, False))
    s = Structure(2.0, 10.0, 5e4)
    s.add_joint("jenkins", 0, k=5e4, fs=30.0)
    out.append(("SDOF Jenkins, 3000 Hz", s, 3000.0, 9000, False))
    m, k = np.diag([2.0, 1.0, 1.5]), 5e4 * np.array([[2, -1, 0], [-1, 2, -1], [0, -1, 1.0]])
    c = 1e-4 * k + 2.0 * m
    s = Structure(m, c, k)
    s.add_joint("bouc_wen", 0, **BW)
    s.add_joint("bouc_wen", 2, 1, **BW)
    out.append(("3-DOF Bouc-Wen x2, 3000 Hz", s, 3000.0, 1500, True))
    s = Structure(m, c, k)
    s.add_joint("masing", 0, h0=40.0, ac=2e4, scale=2.0)
    s.add_joint("jenkins", 2, 1, k=3e4, fs=20.0)
    out.append(("3-DOF Masing + Jenkins, 3000 Hz", s, 3000.0, 6000, False))
    return out


def _cpu(fn):  # type: ignore[no-untyped-def]
    c0 = time.process_time()
    out = fn()
    return time.process_time() - c0, out


def stepping_table(n_time: int, repeat: int, only: str = "", seed: int = 1) -> None:
    """The error-control table: cost ratio and relative RMS errors, per case (see the
    module's docstring); ``seed``: the multisine's (1: the bench's own; others: fresh
    forcing for the accuracy check)."""
    from contactlab.structure.model import DEFAULT_TOL
    from structure_reference import hysteretic_ode

    def rrms(x: np.ndarray, ref: np.ndarray) -> float:
        return float(np.sqrt(np.mean((x - ref) ** 2) / np.mean(ref**2)))

    try:
        import openseespy  # noqa: F401

        print("OpenSeesPy is installed but not wired into this table")
    except ImportError:
        print("OpenSeesPy: not installed (no comparison row)")
    print(f"default tol = {DEFAULT_TOL:g}; CPU-time medians of {repeat} interleaved pairs on "
          f"{n_time} samples; errors: relative RMS of x on the accuracy record; multisine seed "
          f"{seed}; load average {os.getloadavg()[0]:.1f}")  # fmt: skip
    print("| case | old default (substeps=1) | new default | cost new/old | pieces/sample "
          "(Newton it./piece) | old err vs ref | new err vs ref | references (max pairwise "
          "diff) |")  # fmt: skip
    print("|---|---|---|---|---|---|---|---|")
    for name, s, fs, n_acc, bw_only in stepping_cases():
        if only not in name:
            continue
        f = multisine(max(n_acc, n_time), fs, s.n, seed)
        t = np.arange(f.shape[0]) / fs
        ta, fa = t[:n_acc], f[:n_acc]
        fa1 = fa[:, 0] if s.n == 1 else fa
        refs = {
            "fixed x64": s.simulate(ta, force=fa1, substeps=64).x,
            "tol/100": s.simulate(ta, force=fa1, tol=DEFAULT_TOL / 100).x,
        }
        if bw_only:
            for meth in ("LSODA", "Radau"):
                x = bouc_wen_ode(s, ta, fa, meth)
                refs[meth] = x[:, 0] if s.n == 1 else x
        else:
            x = hysteretic_ode(s, ta, fa)
            refs["DOP853 events"] = x[:, 0] if s.n == 1 else x
        ref = refs["LSODA"] if bw_only else refs["DOP853 events"]
        spread = max(rrms(a, ref) for a in refs.values())
        old = rrms(s.simulate(ta, force=fa1, substeps=1).x, ref)
        new_r = s.simulate(ta, force=fa1)
        new = rrms(new_r.x, ref)
        others = ", ".join(f"{k} {rrms(new_r.x, v):.1e}" for k, v in refs.items())
        ft = f[:n_time, 0] if s.n == 1 else f[:n_time]
        tt = t[:n_time]
        c_old, c_new = [], []
        run = new_r
        for _ in range(repeat):
            c_old.append(_cpu(partial(s.simulate, tt, force=ft, substeps=1))[0])
            c, run = _cpu(partial(s.simulate, tt, force=ft))
            c_new.append(c)
        pieces = f"{run.n_steps / (run.t.size - 1):.3f} ({run.n_iter / run.n_steps:.2f})"
        mo, mn = statistics.median(c_old), statistics.median(c_new)
        ratio = statistics.median(b / a for a, b in zip(c_old, c_new, strict=True))
        print(f"| {name} | {1e3 * mo:.0f} ms | {1e3 * mn:.0f} ms | {ratio:.2f} | {pieces} | "
              f"{old:.1e} | "
              f"{new:.1e} (vs {others}) | {spread:.1e} |", flush=True)  # fmt: skip
    print(f"load average at the end {os.getloadavg()[0]:.1f}")


if __name__ == "__main__":
    main()
