"""The rig's contact laws: Masing with exact non-local memory (PHYSICS.md §1, rules 1-4),
backlash, LuGre and breakaway friction.

Part of the rig simulator :mod:`contactlab.synthetic.rig`, written from ``docs/effects.md``
only: it shares no code with the diagnosis or its generators.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from contactlab.errors import InputError

__all__ = ["Virgin", "masing_force", "play_operator", "segalman_parameters"]


@dataclass(frozen=True)
class Virgin:
    """An odd virgin curve f(u) with its derivative.

    Parameters
    ----------
    f, df : callable
        f(u) for u ≥ 0 (N) and its derivative (N/m); odd-extended here.
    name : str
        Shown in the truth.
    """

    f: Callable[[np.ndarray], np.ndarray]
    df: Callable[[np.ndarray], np.ndarray]
    name: str = "custom"

    def __call__(self, u: np.ndarray) -> np.ndarray:
        u = np.asarray(u, dtype=float)
        return np.sign(u) * self.f(np.abs(u))

    def slope(self, u: np.ndarray) -> np.ndarray:
        return self.df(np.abs(np.asarray(u, dtype=float)))

    @staticmethod
    def exponential(h0: float, ac: float) -> Virgin:
        """f(u) = h0 (1 − exp(−ac u)) (the tangential seed paper, eq. 3)."""
        return Virgin(
            lambda u: -h0 * np.expm1(-ac * u), lambda u: h0 * ac * np.exp(-ac * u), "exponential"
        )

    @staticmethod
    def tanh(h0: float, ac: float) -> Virgin:
        """f(u) = h0 tanh(ac u): same initial slope and saturation, another shape."""
        return Virgin(
            lambda u: h0 * np.tanh(ac * u), lambda u: h0 * ac / np.cosh(ac * u) ** 2, "tanh"
        )

    @staticmethod
    def segalman(F_S: float, K_T: float, chi: float, beta: float) -> Virgin:
        """Segalman's (2005) four-parameter Iwan virgin curve (power-law micro-slip)."""
        phi_max, R, _S = segalman_parameters(F_S, K_T, chi, beta)

        def f(u: np.ndarray) -> np.ndarray:
            w = np.minimum(u, phi_max)
            return np.where(
                u < phi_max, K_T * w - R * w ** (chi + 2) / ((chi + 1) * (chi + 2)), F_S
            )

        def df(u: np.ndarray) -> np.ndarray:
            w = np.minimum(u, phi_max)
            return np.where(u < phi_max, K_T - R * w ** (chi + 1) / (chi + 1), 0.0)

        return Virgin(f, df, "segalman")


def segalman_parameters(F_S: float, K_T: float, chi: float, beta: float) -> tuple[float, ...]:
    """φ_max (m), R and S of Segalman's density from (F_S, K_T, χ, β).

    Parameters
    ----------
    F_S : float
        Force at macro-slip (N).
    K_T : float
        Initial tangential stiffness (N/m).
    chi : float
        Power-law exponent, −1 < χ < 0 (dissipation ∝ A^(3+χ)).
    beta : float
        Weight of the Dirac at φ_max, ≥ 0.

    Returns
    -------
    tuple of float
        (φ_max, R, S).
    """
    if not (-1.0 < chi < 0.0) or beta < 0 or F_S <= 0 or K_T <= 0:
        raise InputError(
            f"Segalman parameters: need -1 < chi < 0, beta >= 0, F_S > 0, K_T > 0 "
            f"(got chi={chi}, beta={beta}, F_S={F_S}, K_T={K_T})"
        )
    q = beta + (chi + 1) / (chi + 2)
    phi_max = F_S * (1 + beta) / (K_T * q)
    R = F_S * (chi + 1) / (phi_max ** (chi + 2) * q)
    S = F_S * beta / (phi_max * q)
    return phi_max, R, S


def _directions(x: np.ndarray) -> np.ndarray:
    """Direction of motion into each sample (+1/−1), zeros carried forward."""
    d = np.sign(np.diff(x))
    if d.size == 0:
        return np.zeros(0)
    idx = np.where(d != 0, np.arange(d.size), 0)
    np.maximum.accumulate(idx, out=idx)
    d = d[idx]
    nz = np.flatnonzero(d)
    if nz.size:
        d[: nz[0]] = d[nz[0]]
    return d


def _runs(d: np.ndarray) -> list[tuple[int, int, float]]:
    """Monotone runs (first sample, end sample exclusive, direction) of samples 1..n-1."""
    if d.size == 0:
        return []
    cuts = np.flatnonzero(np.diff(d) != 0) + 1
    starts = np.concatenate([[0], cuts])
    ends = np.concatenate([cuts, [d.size]])
    return [(int(a) + 1, int(b) + 1, float(d[a])) for a, b in zip(starts, ends, strict=True)]


def _branch(
    virgin: Virgin,
    lam: float,
    k_s: float,
    fsup: float,
    anchor: tuple[float, float] | None,
    xs: np.ndarray,
) -> tuple[np.ndarray, ...]:
    """``(u, F)`` on one branch of :func:`masing_force` over monotone samples ``xs``: the
    virgin curve (``anchor`` None) or ``F_r + λ f((u − u_r)/λ)`` from the turning point
    ``anchor = (u_r, F_r)``; with a series stiffness ``k_s``, u solves ``x = u + F(u)/k_s``
    (``fsup`` = sup f bounds the root)."""
    series = math.isfinite(k_s)
    if anchor is None:

        def fb(u: np.ndarray) -> np.ndarray:
            return virgin(u)

        def dfb(u: np.ndarray) -> np.ndarray:
            return virgin.slope(u)
    else:
        ur, Fr = anchor

        def fb(u: np.ndarray) -> np.ndarray:
            return Fr + lam * virgin((u - ur) / lam)

        def dfb(u: np.ndarray) -> np.ndarray:
            return virgin.slope((u - ur) / lam)

    if not series:
        return xs, fb(xs)
    # x = u + F(u)/k_s on this branch: monotone in u (slope 1 + F'/k_s ≥ 1), and
    # |F| ≤ |F_r| + λ sup f, which brackets the root.
    bound = fsup * (1.0 if anchor is None else lam) + (abs(anchor[1]) if anchor else 0.0)
    lo = xs - 1.01 * bound / k_s
    hi = xs + 1.01 * bound / k_s
    u = np.clip(xs - fb(xs) / k_s, lo, hi)
    scale = float(np.max(np.abs(xs))) + bound / k_s
    for _ in range(100):
        g = u + fb(u) / k_s - xs
        lo = np.where(g < 0, u, lo)
        hi = np.where(g > 0, u, hi)
        un = u - g / (1.0 + dfb(u) / k_s)
        bad = (un <= lo) | (un >= hi)
        un = np.where(bad, 0.5 * (lo + hi), un)
        done = float(np.max(np.abs(un - u), initial=0.0)) <= 1e-14 * scale
        u = un
        if done:
            break
    return u, fb(u)


def masing_force(
    x: np.ndarray,
    virgin: Virgin,
    *,
    lam: float = 2.0,
    k_s: float = math.inf,
) -> tuple[np.ndarray, np.ndarray]:
    """Masing hysteresis with exact non-local memory (PHYSICS.md §1), from rest at u = 0.

    Parameters
    ----------
    x : ndarray
        Displacement the operator sees (m).
    virgin : Virgin
        The virgin curve f.
    lam : float
        Branch scale: a branch from the turning point (u_r, F_r) is F_r + λ f((u − u_r)/λ).
        λ = 2 is Masing (memory with wiping-out and the return to the virgin curve); any other
        λ anchors each branch at the last actual turning point (docs/effects.md).
    k_s : float
        Stiffness (N/m) of an element in series with the contact: x = u + F/k_s.

    Returns
    -------
    (F, u) : tuple of ndarray
        Force (N) and contact slip (m); u equals x without series compliance.
    """
    x = np.asarray(x, dtype=float)
    n = x.size
    F = np.empty(n)
    U = np.empty(n)
    if n == 0:
        return F, U
    if not lam > 0:
        raise InputError(f"masing_force: branch scale lam must be > 0, got {lam}")
    memory = lam == 2.0
    fsup = float(virgin.f(np.array([np.inf]))[0])
    if math.isfinite(k_s) and not k_s > 0:
        raise InputError(f"masing_force: series stiffness k_s must be > 0, got {k_s}")

    u0, F0 = _branch(virgin, lam, k_s, fsup, None, x[:1])
    U[0], F[0] = float(u0[0]), float(F0[0])
    d = _directions(x)
    stack: list[tuple[float, float]] = []
    anchor: tuple[float, float] | None = None  # non-memory mode
    prev_dir = 0.0
    if d.size and d[0] * U[0] < 0:  # the first motion returns towards rest
        stack.append((U[0], F[0]))
        anchor = (U[0], F[0])
    for i, j, di in _runs(d):
        # samples i..j-1 move in direction di; sample i-1 is the turning point
        if prev_dir != 0 and di != prev_dir:
            stack.append((float(U[i - 1]), float(F[i - 1])))
            anchor = stack[-1]
        prev_dir = di
        k = i
        while k < j:
            lim: float | None
            if memory:
                cur = stack[-1] if stack else None
                if len(stack) >= 2:
                    lim = stack[-2][0]
                elif len(stack) == 1:
                    lim = -stack[0][0]
                else:
                    lim = None
            else:
                cur, lim = anchor, None
            u, Fk = _branch(virgin, lam, k_s, fsup, cur, x[k:j])
            if lim is not None:
                hit = np.flatnonzero(di * (u - lim) >= 0)
                if hit.size:
                    h = int(hit[0])
                    U[k : k + h], F[k : k + h] = u[:h], Fk[:h]
                    if len(stack) >= 2:
                        del stack[-2:]
                    else:
                        stack.clear()
                    k += h
                    continue
            U[k:j], F[k:j] = u, Fk
            k = j
    return F, U


def play_operator(x: np.ndarray, b: float, u0: float = 0.0) -> np.ndarray:
    """Backlash (lost motion): u stands still until ``|x − u| = b``, then follows at distance b.

    Parameters
    ----------
    x : ndarray
        Input (m).
    b : float
        Half-width of the dead band (m), ≥ 0.
    u0 : float
        Initial output.

    Returns
    -------
    ndarray
        The output u (m).
    """
    x = np.asarray(x, dtype=float)
    if b < 0:
        raise InputError(f"backlash: half-width b must be >= 0, got {b}")
    u = np.empty_like(x)
    if x.size == 0:
        return u
    u[0] = min(max(u0, x[0] - b), x[0] + b)
    cur = float(u[0])
    for i, j, di in _runs(_directions(x)):
        seg = x[i:j]
        out = np.maximum(cur, seg - b) if di > 0 else np.minimum(cur, seg + b)
        u[i:j] = out
        cur = float(out[-1])
    return u


def _lugre(
    t: np.ndarray, v: np.ndarray, sigma0: float, sigma1: float, Fc: float, Fs: float, vs: float
) -> np.ndarray:
    """LuGre friction (Canudas de Wit et al. 1995) without σ2, exact per step for constant v."""
    z = 0.0
    F = np.empty_like(v)
    dt = np.diff(t, prepend=t[0])
    for i in range(v.size):
        vi = v[i]
        g = Fc + (Fs - Fc) * math.exp(-((vi / vs) ** 2))
        if vi != 0.0:
            zss = math.copysign(g / sigma0, vi)
            z = zss + (z - zss) * math.exp(-sigma0 * abs(vi) * dt[i] / g)
        zdot = vi - sigma0 * abs(vi) * z / g
        F[i] = sigma0 * z + sigma1 * zdot
    return F


def _breakaway(x: np.ndarray, dc: float) -> np.ndarray:
    """sgn(ẋ)·(s/d_c)·e^(1 − s/d_c), s the travel since the last turning point."""
    d = np.concatenate([[0.0], _directions(x)]) if x.size > 1 else np.zeros_like(x)
    if d.size > 1:
        d[0] = d[1]
    turn = np.zeros(x.size, dtype=bool)
    turn[1:] = d[1:] != d[:-1]
    idx = np.where(turn, np.arange(x.size) - 1, 0)
    idx[0] = 0
    np.maximum.accumulate(idx, out=idx)
    s = np.abs(x - x[idx])
    # before the first turning point there is no breakaway (first loading from rest)
    first = np.flatnonzero(turn)
    out = d * (s / dc) * np.exp(1 - s / dc)
    if first.size:
        out[: first[0]] = 0.0
    else:
        out[:] = 0.0
    return out
