"""A small, independent pure-Python Masing operator (PHYSICS.md §1) for cross-checking the Rust
core. Written from the rules, not from the Rust code: it keeps the list of turning points and
re-derives the active branch from scratch at every sample, using math.expm1 throughout.
"""

from __future__ import annotations

import math


def virgin(u: float, h0: float, ac: float) -> float:
    return math.copysign(-h0 * math.expm1(-ac * abs(u)), u)


def reference_force(x, h0: float, ac: float, lam: float = 2.0) -> list[float]:
    turning: list[tuple[float, float]] = []  # (x_r, h_r), oldest first
    xp, hp, direction = 0.0, 0.0, 0
    out = []
    for xi in x:
        xi = float(xi)
        if xi != xp:
            d = 1 if xi > xp else -1
            if direction != 0 and d != direction:
                turning.append((xp, hp))
            direction = d
            # Rule 3 / 4: wipe out every loop the step closes.
            changed = True
            while changed and turning:
                changed = False
                if len(turning) == 1:
                    mirror = -turning[0][0]
                    if (d > 0 and xi >= mirror) or (d < 0 and xi <= mirror):
                        turning.clear()
                        changed = True
                else:
                    older = turning[-2][0]
                    if (d > 0 and xi >= older) or (d < 0 and xi <= older):
                        del turning[-2:]
                        changed = True
            if turning:
                xr, hr = turning[-1]
                hp = hr + lam * virgin((xi - xr) / lam, h0, ac)
            else:
                hp = virgin(xi, h0, ac)
            xp = xi
        out.append(hp)
    return out


def reference_energy(A: float, h0: float, ac: float) -> float:
    """E(A) exactly as printed (corrected) in PHYSICS.md §1."""
    hm = virgin(A, h0, ac)
    return 8.0 * (h0 * (A - (1.0 - math.exp(-ac * A)) / ac) - A * hm / 2.0)
