"""Plain-Python reference of the joint laws: one sample at a time, scalar ``math`` only.

This is the independent route the Rust kernels are tested against (to 1e-12): every law is
written out here as a loop over samples with a mutable state, without numpy and without
sharing code with the Rust core. It is slow (about 1 µs a sample per element) and meant for
tests and for checking a new law, never for production runs.

Conventions shared with the Rust core (``rust/core/src/joints``):

- the displacement path between two samples is a straight line in time (piecewise-linear
  ``x(t)``), so the velocity over a step is ``(x_n - x_{n-1}) / (t_n - t_{n-1})``, constant;
  every law is integrated exactly along that path (closed forms) except Bouc-Wen (RK4 on a
  fixed sub-step rule) and the implicit splits of ``Series`` / ``Backlash`` (a bracketed
  Illinois root search);
- the operator starts relaxed (force 0, no history) at displacement ``x0``; the first sample
  is reached from ``x0`` by a quasi-static step (``dt = None``: velocity 0 in the rate terms,
  the rate-dependent internal variables relaxed to their zero-velocity limit);
- a step with ``dx == 0`` changes no rate-independent state.
"""

from __future__ import annotations

import copy
import math
from typing import Any

EPS = 2.220446049250313e-16


def sign(v: float) -> float:
    return 1.0 if v > 0 else (-1.0 if v < 0 else 0.0)


class RefLaw:
    """Base class: ``start(x0)`` returns a state, ``step(st, dt, x)`` advances it to ``x``."""

    rate_dependent = False

    def start(self, x0: float) -> Any:
        raise NotImplementedError

    def step(self, st: Any, dt: float | None, x: float) -> float:
        raise NotImplementedError


# --------------------------------------------------------------------------------------------
class RefJenkins(RefLaw):
    def __init__(self, k: float, fs: float) -> None:
        self.k, self.fs = k, fs

    def start(self, x0: float) -> Any:
        return {"z": x0}

    def step(self, st: Any, dt: float | None, x: float) -> float:
        f = self.k * (x - st["z"])
        if f > self.fs:
            f = self.fs
            st["z"] = x - self.fs / self.k
        elif f < -self.fs:
            f = -self.fs
            st["z"] = x + self.fs / self.k
        return f


class RefMaxwellSlip(RefLaw):
    def __init__(self, k: list[float], fs: list[float]) -> None:
        self.k, self.fs = list(k), list(fs)

    def start(self, x0: float) -> Any:
        return {"z": [x0] * len(self.k)}

    def step(self, st: Any, dt: float | None, x: float) -> float:
        total = 0.0
        z = st["z"]
        for i in range(len(self.k)):
            k, fs = self.k[i], self.fs[i]
            f = k * (x - z[i])
            if f > fs:
                f = fs
                z[i] = x - fs / k
            elif f < -fs:
                f = -fs
                z[i] = x + fs / k
            total += f
        return total


# --------------------------------------------------------------------------------------------
class RefMasingStack(RefLaw):
    """Masing's rules (branch ``F_r + 2 f((x - x_r) / 2)``) with the wiping-out memory of
    reversal points, on an odd virgin curve ``f``: the exact response of a continuous Iwan
    (parallel-series) model whose virgin curve is ``f``."""

    def f(self, u: float) -> float:
        raise NotImplementedError

    def start(self, x0: float) -> Any:
        return {"x0": x0, "xp": x0, "fp": 0.0, "dir": 0.0, "stack": []}

    def step(self, st: Any, dt: float | None, x: float) -> float:
        x0 = st["x0"]
        dx = x - st["xp"]
        if dx == 0.0:
            return st["fp"]
        s = sign(dx)
        stack = st["stack"]
        if st["dir"] != 0.0 and s != st["dir"]:
            stack.append((st["xp"], st["fp"]))
        st["dir"] = s
        while True:
            n = len(stack)
            if n >= 2 and (x - stack[n - 2][0]) * s >= 0.0:
                stack.pop()
                stack.pop()
                continue
            if n == 1 and (x - (2.0 * x0 - stack[0][0])) * s >= 0.0:
                stack.pop()
                continue
            break
        if stack:
            xr, fr = stack[-1]
            f = fr + 2.0 * self.f(0.5 * (x - xr))
        else:
            f = self.f(x - x0)
        st["xp"], st["fp"] = x, f
        return f


class RefSegalman(RefMasingStack):
    """Segalman's 4-parameter Iwan model (J. Appl. Mech. 72, 2005): slip-displacement density
    ``ρ(φ) = R φ^χ [H(φ) - H(φ - φmax)] + S δ(φ - φmax)``."""

    def __init__(self, F_S: float, K_T: float, chi: float, beta: float) -> None:
        self.F_S, self.K_T = F_S, K_T
        self.phi_max = F_S * (1.0 + beta) / (K_T * (beta + (chi + 1.0) / (chi + 2.0)))
        self.R = (
            F_S * (chi + 1.0) / (self.phi_max ** (chi + 2.0) * (beta + (chi + 1.0) / (chi + 2.0)))
        )
        self.c = self.R / ((chi + 1.0) * (chi + 2.0))
        self.n = chi + 2.0

    def f(self, u: float) -> float:
        a = abs(u)
        if a >= self.phi_max:
            v = self.F_S
        else:
            v = self.K_T * a - self.c * a**self.n
        return v if u >= 0 else -v


class RefMasingExp(RefMasingStack):
    def __init__(self, h0: float, ac: float) -> None:
        self.h0, self.ac = h0, ac

    def f(self, u: float) -> float:
        v = self.h0 * (1.0 - math.exp(-self.ac * abs(u)))
        return v if u >= 0 else -v


# --------------------------------------------------------------------------------------------
class RefDahl(RefLaw):
    """``dF/dx = σ0 |1 - F/Fc sgn(dx)|^α sgn(1 - F/Fc sgn(dx))``, solved in closed form along
    each monotone step."""

    def __init__(self, sigma0: float, Fc: float, alpha: float) -> None:
        self.sigma0, self.Fc, self.alpha = sigma0, Fc, alpha

    def start(self, x0: float) -> Any:
        return {"xp": x0, "f": 0.0}

    def step(self, st: Any, dt: float | None, x: float) -> float:
        dx = x - st["xp"]
        st["xp"] = x
        if dx == 0.0:
            return st["f"]
        s = sign(dx)
        a = self.sigma0 / self.Fc
        u = abs(dx)
        y = 1.0 - s * st["f"] / self.Fc
        al = self.alpha
        if y <= 0.0:
            yn = y
        elif al == 1.0:
            yn = y * math.exp(-a * u)
        elif al < 1.0:
            w = y ** (1.0 - al) - (1.0 - al) * a * u
            yn = w ** (1.0 / (1.0 - al)) if w > 0.0 else 0.0
        else:
            yn = (y ** (1.0 - al) + (al - 1.0) * a * u) ** (-1.0 / (al - 1.0))
        st["f"] = s * self.Fc * (1.0 - yn)
        return st["f"]


def stribeck(Fc: float, Fs: float, vs: float, delta: float, v: float) -> float:
    return Fc + (Fs - Fc) * math.exp(-((abs(v) / vs) ** delta))


class RefLuGre(RefLaw):
    """``dz/dt = v - σ0 |v| z / g(v)``, ``F = σ0 z + σ1 dz/dt + σ2 v``; with ``v`` constant
    over a step, ``z`` relaxes exponentially in the travelled distance (exact)."""

    rate_dependent = True

    def __init__(self, sigma0, sigma1, sigma2, Fc, Fs, vs, delta) -> None:
        self.s0, self.s1, self.s2 = sigma0, sigma1, sigma2
        self.Fc, self.Fs, self.vs, self.delta = Fc, Fs, vs, delta

    def start(self, x0: float) -> Any:
        return {"xp": x0, "z": 0.0}

    def step(self, st: Any, dt: float | None, x: float) -> float:
        dx = x - st["xp"]
        st["xp"] = x
        if dt is None:
            v = 0.0
            g = self.Fs
        else:
            v = dx / dt
            g = stribeck(self.Fc, self.Fs, self.vs, self.delta, v)
        if dx != 0.0:
            zss = sign(dx) * g / self.s0
            st["z"] = zss + (st["z"] - zss) * math.exp(-self.s0 * abs(dx) / g)
        z = st["z"]
        zdot = v - self.s0 * abs(v) * z / g
        return self.s0 * z + self.s1 * zdot + self.s2 * v


class RefGMS(RefLaw):
    """Generalised Maxwell-slip (Al-Bender, Lampaert & Swevers 2005): element ``i`` sticks
    (``dF_i = k_i dx``) until ``|F_i|`` reaches ``α_i s(v)``, then slips with
    ``dF_i/dt = sgn(v) C (1 - F_i / (α_i s(v) sgn v))`` until the motion reverses."""

    rate_dependent = True

    def __init__(self, k, alpha, Fc, Fs, vs, C, delta, sigma2) -> None:
        self.k, self.alpha = list(k), list(alpha)
        self.Fc, self.Fs, self.vs, self.C, self.delta, self.s2 = Fc, Fs, vs, C, delta, sigma2

    def start(self, x0: float) -> Any:
        n = len(self.k)
        return {"xp": x0, "f": [0.0] * n, "slip": [0.0] * n}

    def step(self, st: Any, dt: float | None, x: float) -> float:
        dx = x - st["xp"]
        st["xp"] = x
        if dt is None:
            v = 0.0
            g = self.Fs
        else:
            v = dx / dt
            g = stribeck(self.Fc, self.Fs, self.vs, self.delta, v)
        fs, slip = st["f"], st["slip"]
        total = 0.0
        if dx != 0.0:
            s = sign(dx)
            for i in range(len(self.k)):
                lim = self.alpha[i] * g
                target = s * lim
                if slip[i] != 0.0 and slip[i] != s:
                    slip[i] = 0.0
                if slip[i] == 0.0:
                    fn = fs[i] + self.k[i] * dx
                    if s * fn <= lim:
                        fs[i] = fn
                    else:
                        # sticks for the part of the step that brings it to the limit, then
                        # slips at the limit for the rest (v constant: the limit is constant)
                        fs[i] = target
                        slip[i] = s
                elif dt is None:
                    fs[i] = target
                else:
                    fs[i] = target + (fs[i] - target) * math.exp(-self.C * dt / lim)
                total += fs[i]
        else:
            for f in fs:
                total += f
        return total + self.s2 * v


# --------------------------------------------------------------------------------------------
class RefBoucWen(RefLaw):
    """``F = z``, ``dz/dx = α - β (γ s |z|^(ν-1) z + δ |z|^ν)``, ``s = sgn(dx)``: RK4 in ``x``
    with ``n = ceil(|dx| max(ν, 1) / (0.05 x_c))`` sub-steps (``x_c = z_c / α``,
    ``z_c = (α / (β (|γ| + |δ|)))^(1/ν)``, the saturation scale), at most 100000."""

    def __init__(self, alpha, beta, gamma, delta, nu) -> None:
        self.a, self.b, self.g, self.d, self.nu = alpha, beta, gamma, delta, nu
        q = beta * (abs(gamma) + abs(delta))
        self.h = 0.05 * ((alpha / q) ** (1.0 / nu)) / alpha / max(nu, 1.0) if q > 0 else math.inf

    def start(self, x0: float) -> Any:
        return {"xp": x0, "z": 0.0}

    def rate(self, z: float, s: float) -> float:
        p = abs(z) ** self.nu
        return self.a - self.b * (self.g * s * sign(z) * p + self.d * p)

    def step(self, st: Any, dt: float | None, x: float) -> float:
        dx = x - st["xp"]
        st["xp"] = x
        if dx == 0.0:
            return st["z"]
        s = sign(dx)
        n = 1 if math.isinf(self.h) else min(max(math.ceil(abs(dx) / self.h), 1), 100000)
        hs = dx / n
        z = st["z"]
        for _ in range(n):
            k1 = self.rate(z, s)
            k2 = self.rate(z + 0.5 * hs * k1, s)
            k3 = self.rate(z + 0.5 * hs * k2, s)
            k4 = self.rate(z + hs * k3, s)
            z = z + hs / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
        st["z"] = z
        return z


class RefKelvinVoigt(RefLaw):
    def __init__(self, k: float, c: float) -> None:
        self.k, self.c = k, c
        self.rate_dependent = c > 0

    def start(self, x0: float) -> Any:
        return {"x0": x0, "xp": x0}

    def step(self, st: Any, dt: float | None, x: float) -> float:
        v = 0.0 if dt is None else (x - st["xp"]) / dt
        st["xp"] = x
        return self.k * (x - st["x0"]) + self.c * v


# --------------------------------------------------------------------------------------------
def illinois(phi: Any, a: float, fa: float, b: float, fb: float, ftol: float) -> float:
    """A root of the non-decreasing ``phi`` in ``[a, b]`` with ``fa <= 0 <= fb`` (Illinois
    false position, bisection when the secant leaves the bracket); deterministic."""
    if fa == 0.0:
        return a
    if fb == 0.0:
        return b
    side = 0
    c = a
    for _ in range(200):
        c = b - fb * (b - a) / (fb - fa)
        if not (a < c < b):
            c = 0.5 * (a + b)
            if not (a < c < b):
                return c
        fc = phi(c)
        if abs(fc) <= ftol:
            return c
        if fc > 0.0:
            b, fb = c, fc
            if side == 1:
                fa *= 0.5
            side = 1
        else:
            a, fa = c, fc
            if side == -1:
                fb *= 0.5
            side = -1
        if b - a <= 4.0 * EPS * max(abs(a), abs(b)):
            return c
    return c


def bracket(phi: Any, lo: float, hi: float, width: float) -> tuple[float, float, float, float]:
    """Widen ``[lo, hi]`` until ``phi(lo) <= 0 <= phi(hi)`` (``phi`` non-decreasing)."""
    flo, fhi = phi(lo), phi(hi)
    w = width
    for _ in range(200):
        if flo <= 0.0 <= fhi:
            return lo, flo, hi, fhi
        if flo > 0.0:
            lo -= w
            flo = phi(lo)
        if fhi < 0.0:
            hi += w
            fhi = phi(hi)
        w *= 2.0
    raise ArithmeticError("no sign change of the force balance: the law is not monotone")


class RefSeries(RefLaw):
    """Two laws in series: ``x = x_a + x_b`` with ``F_a(x_a) = F_b(x_b)``, the split found
    by a root search on ``x_a`` (``F_a(x_a) - F_b(x - x_a)`` is non-decreasing)."""

    def __init__(self, a: RefLaw, b: RefLaw) -> None:
        self.a, self.b = a, b
        self.rate_dependent = a.rate_dependent or b.rate_dependent

    def start(self, x0: float) -> Any:
        return {"xp": x0, "xa": 0.0, "sa": self.a.start(0.0), "sb": self.b.start(x0), "f": 0.0}

    def step(self, st: Any, dt: float | None, x: float) -> float:
        dx = x - st["xp"]
        xa0 = st["xa"]
        trial = {}

        def phi(xa: float) -> float:
            sa, sb = copy.deepcopy(st["sa"]), copy.deepcopy(st["sb"])
            fa = self.a.step(sa, dt, xa)
            fb = self.b.step(sb, dt, x - xa)
            trial["r"] = (sa, sb, fa, fb)
            return fa - fb

        lo, hi = xa0 + min(dx, 0.0), xa0 + max(dx, 0.0)
        width = max(abs(dx), EPS * (abs(x) + abs(xa0)), 1e-300)
        lo, flo, hi, fhi = bracket(phi, lo, hi, width)
        ftol = 1e-14 * max(abs(st["f"]), abs(flo), abs(fhi))
        xa = illinois(phi, lo, flo, hi, fhi, ftol)
        phi(xa)
        sa, sb, _fa, fb = trial["r"]
        st.update(xp=x, xa=xa, sa=sa, sb=sb, f=fb)
        return fb


class RefBacklash(RefLaw):
    """A clearance of total width ``gap`` in series with a law: the law's displacement
    ``y`` obeys ``|x - y| <= gap/2``, with force 0 while the gap is open, ``F >= 0`` in
    contact at ``x - y = gap/2``, ``F <= 0`` at ``x - y = -gap/2``."""

    def __init__(self, gap: float, law: RefLaw) -> None:
        self.h, self.law = 0.5 * gap, law
        self.rate_dependent = law.rate_dependent

    def start(self, x0: float) -> Any:
        return {"y": x0, "s": self.law.start(x0), "f": 0.0}

    def step(self, st: Any, dt: float | None, x: float) -> float:
        trial = {}

        def phi(y: float) -> float:
            s = copy.deepcopy(st["s"])
            f = self.law.step(s, dt, y)
            trial["r"] = (s, f)
            return f

        lo, hi = x - self.h, x + self.h
        f_lo = phi(lo)
        if f_lo >= 0.0:
            y = lo
        else:
            f_hi = phi(hi)
            if f_hi <= 0.0:
                y = hi
            else:
                ftol = 1e-14 * max(abs(st["f"]), abs(f_lo), abs(f_hi))
                y = illinois(phi, lo, f_lo, hi, f_hi, ftol)
        f = phi(y)
        st.update(y=y, s=trial["r"][0], f=f)
        return f


class RefParallel(RefLaw):
    def __init__(self, laws: list[RefLaw], k: float, c: float) -> None:
        self.laws, self.k, self.c = laws, k, c
        self.rate_dependent = c > 0 or any(law.rate_dependent for law in laws)

    def start(self, x0: float) -> Any:
        return {"x0": x0, "xp": x0, "s": [law.start(x0) for law in self.laws]}

    def step(self, st: Any, dt: float | None, x: float) -> float:
        v = 0.0 if dt is None else (x - st["xp"]) / dt
        st["xp"] = x
        f = self.k * (x - st["x0"]) + self.c * v
        for law, s in zip(self.laws, st["s"], strict=True):
            f += law.step(s, dt, x)
        return f


# --------------------------------------------------------------------------------------------
def run(
    law: RefLaw,
    t: list[float] | None,
    x: list[float],
    state: Any = None,
    x0: float = 0.0,
    t_prev: float | None = None,
) -> tuple[list[float], Any, float | None]:
    """Forces for ``x`` (at times ``t``, or None for a rate-independent law) continuing
    ``state`` (None: a fresh start at ``x0``); returns ``(F, state, last time)``."""
    st = law.start(x0) if state is None else state
    out = []
    for i, xi in enumerate(x):
        ti = None if t is None else t[i]
        dt = None if (ti is None or t_prev is None) else ti - t_prev
        out.append(law.step(st, dt, float(xi)))
        t_prev = ti
    return out, st, t_prev
