"""Fuzz target: the Rust kernels through the binding (``contactlab._core``).

Random and adversarial arrays (lengths 0/1/2 often, 1e-300…1e300, denormals, NaN/inf at any
index) and every scalar parameter at, inside and beyond its bounds (0, negative, denormal,
huge, non-finite). Arrays reach the binding as contiguous float64, as the Python layer hands
them over; odd layouts (non-contiguous, big-endian, float32) are the ``models`` target's.

Invariants: a ``ContactLabError`` or a result; no panic (caught or not); when every input is
finite and the call succeeds (``status == 0`` for the ODE), no NaN in the result.
"""

from __future__ import annotations

import math
import warnings

import numpy as np
from _harness import Bytes, check, instrumented, main, no_nan

with instrumented(("contactlab",)):
    from contactlab import _core

TARGET = "kernels"
_NAMES = ["push", "cycles", "backbone/slope/chord_area", "set_state+push", "fresh+get_state",
          "push(out=)", "loop_area", "normal_simulate", "normal_equilibrium", "kv", "poly_fit",
          "poly_roots_in", "poly_min_on", "fold_cycles"]  # fmt: skip


def _f64(a: np.ndarray) -> np.ndarray:
    with np.errstate(all="ignore"):
        return np.ascontiguousarray(a, dtype=np.float64)


def _finite(*xs: object) -> bool:
    for x in xs:
        if x is None:
            continue
        if isinstance(x, np.ndarray):
            if not np.all(np.isfinite(x)):
                return False
        elif isinstance(x, float) and not math.isfinite(x):
            return False
    return True


def _call(b: Bytes) -> tuple[object, tuple]:
    op = b.int(0, 13)
    x = _f64(b.array())
    if op <= 5:
        if b.int(0, 1):
            h0, ac = b.positive(40.0, 200.0), b.positive(4e4, 200.0)
            sc = b.choice((2.0, 1.0, b.float(-3.0, 5.0), b.positive(2.0)))
            args = (h0, ac, sc)

            def make():
                return _core.MasingCore.exponential(h0, ac, sc)

        else:
            xp, fp = _f64(b.array(16)), _f64(b.array(16))
            if b.int(0, 1):  # mostly a valid monotone table
                n = b.int(2, 16)
                xp = np.cumsum(np.abs(_f64(b.array(n))) + b.positive(1e-6, 6.0))
                fp = np.cumsum(np.abs(_f64(b.array(n))))
            sc = b.choice((2.0, b.float(-3.0, 5.0)))
            args = (xp, fp, sc)

            def make():
                return _core.MasingCore.tabulated(xp, fp, sc)

        again, st, repeat = b.int(0, 1), _f64(b.array(8)), b.int(0, 3)

        def run():
            core = make()
            if op == 0:
                out = core.push(x)
                if again:
                    out = core.push(x[::-1].copy())
                return out
            if op == 1:
                return core.cycles(x)
            if op == 2:
                return (core.backbone(x), core.slope(x), core.chord_area(np.abs(x)))
            if op == 3:
                core.set_state(st)
                return core.push(x)
            if op == 4:
                core.push(x)
                fresh = core.fresh()
                fresh.set_state(core.get_state())
                return fresh.push(x)
            # the output-buffer path (`out=`), in pieces as a streaming caller uses it
            buf = np.empty_like(x)
            cut = x.size // (repeat + 1)
            core.push(x[:cut], out=buf[:cut])
            core.push(x[cut:], out=buf[cut:])
            return buf

        return run, (x, *args)
    if op == 6:
        f = _f64(b.array())
        if b.int(0, 1) and x.size:
            f = _f64(np.resize(f, x.size)) if f.size else np.zeros_like(x)
        return (lambda: _core.loop_area(x, f)), (x, f)
    if op == 7:
        n = x.size
        t = np.cumsum(np.abs(_f64(b.array(n))) + b.positive(1e-3, 4.0)) if n else x
        if b.int(0, 3) == 0:
            t = x
        p = _f64(b.array(max(n, 1)))[: max(n, 0)] if n else x
        if p.size != t.size:
            p = np.resize(p, t.size) if p.size else np.zeros_like(t)
        law = b.choice(("constant", "delta", "pressure", "bogus"))
        coeffs = _f64(b.array(5))
        psi, omega = b.positive(0.5, 6.0), b.positive(1.0, 6.0)
        d0 = b.float(-1e-5, 1e-5)
        rtol, atol = b.positive(1e-8, 6.0), b.positive(1e-12, 6.0)
        interp = b.choice(("cubic", "linear", "spline"))
        dpdt = None if b.int(0, 1) else np.resize(_f64(b.array()), t.size)
        first = None if b.int(0, 1) else b.positive(1e-4, 6.0)
        steps = b.choice((0, 1, 10, 10_000))

        def run():
            out = _core.normal_simulate(
                t, p, law, coeffs, psi, omega, d0, rtol, atol, interp, dpdt, first, steps
            )
            return out if out.status == 0 else None

        return run, (t, p, coeffs, psi, omega, d0, rtol, atol, dpdt, first)
    if op == 8:
        law = b.choice(("constant", "delta", "pressure"))
        coeffs = _f64(b.array(5))
        args = (coeffs, b.positive(0.5), b.positive(1.0), b.float(-1e7, 1e7))
        return (lambda: _core.normal_equilibrium(law, *args)), args
    if op == 9:
        args = (b.positive(1e11, 20.0), b.positive(0.5), b.positive(1.0), b.float(-1e7, 1e7))
        if b.int(0, 1):
            return (lambda: _core.kv_steady_state(*args, x)), (*args, x)
        return (lambda: _core.kv_analytic(*args)), args
    if op == 10:
        y = _f64(np.resize(b.array(), x.size)) if x.size else x
        deg = b.choice((0, 1, 2, 3, 5, b.int(0, 40)))
        w = None if b.int(0, 1) else (_f64(np.resize(b.array(), x.size)) if x.size else x)
        return (lambda: _core.poly_fit(x, y, deg, w)), (x, y, w)
    if op == 11:
        lo, hi = b.float(-1e3, 1e3), b.float(-1e3, 1e3)
        return (lambda: _core.poly_roots_in(x[:12].copy(), lo, hi)), (x, lo, hi)
    if op == 12:
        lo, hi = b.float(-1e3, 1e3), b.float(-1e3, 1e3)
        return (lambda: _core.poly_min_on(x[:12].copy(), lo, hi)), (x, lo, hi)
    start, period = b.float(-10.0, 100.0), b.float(-1.0, 50.0)
    nc, nb = b.choice((0, 1, 2, b.int(0, 50))), b.choice((0, 1, 2, b.int(0, 200)))
    return (lambda: _core.fold_cycles(x, start, period, nc, nb)), (x, start, period)


def one_input(data: bytes) -> None:
    b = Bytes(data)
    with np.errstate(all="ignore"), warnings.catch_warnings():
        warnings.simplefilter("ignore")
        fn, inputs = _call(b)
    out = check(fn)
    if out is not None and _finite(*inputs):
        no_nan(out, f"{_NAMES[data[0] % 14 if data else 0]} output")


if __name__ == "__main__":
    main(one_input)
