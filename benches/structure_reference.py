"""An independent reference for structures with Masing (exponential curve) and Jenkins joints:
scipy ``solve_ivp`` (DOP853, rtol 1e-10) on the equations of motion, the joints' memory
handled by terminal events instead of by the core's step logic.

Between events every joint's force is a smooth function of the state:

- a Masing joint moving in the direction ``s`` is on the branch anchored at its last
  reversal ``(x_a, h_a)``, ``F = h_a + λ h0 (1 − e^(−ac |d − x_a| / λ)) sgn(d − x_a)`` (the
  virgin curve ``h0 (1 − e^(−ac |d|)) sgn d`` with no reversal), until ``d`` reaches the
  branch's closure target (the reversal before the anchor, or the mirror point ``−x_a`` of a
  lone reversal), where the two reversals are dropped (one for a lone reversal: back on the
  virgin curve) — the memory rules of PHYSICS.md §1 written anew here, not taken from the core;
- a Jenkins joint either sticks (its force an ODE variable, ``Ḟ = k ḋ``) or slips
  (``F = ±fs``).

Events: a Masing joint's relative velocity crossing 0 against its direction (a reversal is
pushed at the turning point), its displacement reaching the closure target; a sticking
Jenkins joint's force reaching ``±fs``, a slipping one's velocity crossing 0 (it sticks). The
load is linear between samples, as the core takes it. Each interval between samples is
integrated separately (the load's rate jumps there), so the reference has no kink inside a
step.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.integrate import solve_ivp

from contactlab.structure import Structure


@dataclass
class _MasingMem:
    h0: float
    ac: float
    lam: float
    s: float = 0.0  # direction of motion (0: none yet)
    stack: list[tuple[float, float]] = field(default_factory=list)

    def force(self, d: float) -> float:
        if not self.stack:
            return math.copysign(self.h0 * (1.0 - math.exp(-self.ac * abs(d))), d)
        xa, ha = self.stack[-1]
        u = d - xa
        return ha + math.copysign(
            self.lam * self.h0 * (1.0 - math.exp(-self.ac * abs(u) / self.lam)), u
        )

    def target(self) -> float | None:
        if not self.stack:
            return None
        if len(self.stack) == 1:
            return -self.stack[0][0]
        return self.stack[-2][0]


def _rel(j, y: np.ndarray) -> float:  # type: ignore[no-untyped-def]
    return float(y[j.dof] - (y[j.dof2] if j.dof2 is not None else 0.0))


def hysteretic_ode(s: Structure, t: np.ndarray, f: np.ndarray, rtol: float = 1e-10) -> np.ndarray:
    """``x`` at the samples ``t`` of structure ``s`` (Masing on the exponential curve, Jenkins
    joints; zero initial state) under the load ``f`` (``(len(t),)`` or ``(len(t), n)``), by
    the event-driven ``solve_ivp`` route described in the module's docstring."""
    n = s.n
    f = np.asarray(f, float).reshape(len(t), n)
    minv = np.linalg.inv(s.M)
    joints = s.joints
    mem: dict[int, _MasingMem] = {}
    jen: dict[int, list] = {}  # k, fs, sticking, slip sign, force (while slipping)
    for q, j in enumerate(joints):
        p = j.params
        if j.kind == "masing":
            mem[q] = _MasingMem(float(p["h0"]), float(p["ac"]), float(p.get("scale", 2.0)))
        elif j.kind == "jenkins":
            jen[q] = [float(p["k"]), float(p["fs"]), True, 0.0]
        else:
            raise ValueError(f"hysteretic_ode: joint kind {j.kind!r} not handled")
    jq = sorted(jen)  # Jenkins force slots in y after x and v
    slot = {q: 2 * n + i for i, q in enumerate(jq)}

    def forces(y: np.ndarray) -> np.ndarray:
        g = np.zeros(n)
        for q, j in enumerate(joints):
            if q in mem:
                fj = mem[q].force(_rel(j, y))
            else:
                _, fs, stick, sgn = jen[q]
                fj = y[slot[q]] if stick else sgn * fs
            g[j.dof] += fj
            if j.dof2 is not None:
                g[j.dof2] -= fj
        return g

    out = np.empty((len(t), n))
    y = np.zeros(2 * n + len(jq))
    out[0] = 0.0
    # the Masing joints' first direction: the sign of their initial relative acceleration
    a0 = minv @ (f[0] - forces(y))
    for q, m in mem.items():
        j = joints[q]
        da = a0[j.dof] - (a0[j.dof2] if j.dof2 is not None else 0.0)
        m.s = 1.0 if da >= 0 else -1.0
    for i in range(len(t) - 1):
        t0, t1 = float(t[i]), float(t[i + 1])
        f0, fr = f[i], (f[i + 1] - f[i]) / (t1 - t0)

        def rhs(tt: float, yy: np.ndarray, f0=f0, fr=fr, t0=t0) -> np.ndarray:
            x, v = yy[:n], yy[n : 2 * n]
            a = minv @ (f0 + fr * (tt - t0) - s.C @ v - s.K @ x - forces(yy))
            dz = np.empty(len(jq))
            for k_, q in enumerate(jq):
                k, _, stick, _ = jen[q]
                dz[k_] = k * _rel(joints[q], v) if stick else 0.0
            return np.concatenate([v, a, dz])

        tt = t0
        while tt < t1:
            events, kinds = [], []
            for q, m in mem.items():
                j = joints[q]

                def rev(_t, yy, j=j, m=m):  # type: ignore[no-untyped-def]
                    return m.s * _rel(j, yy[n : 2 * n])

                rev.terminal, rev.direction = True, -1
                events.append(rev)
                kinds.append(("rev", q))
                tg = m.target()
                if tg is not None:

                    def close(_t, yy, j=j, m=m, tg=tg):  # type: ignore[no-untyped-def]
                        return m.s * (_rel(j, yy) - tg)

                    close.terminal, close.direction = True, 1
                    events.append(close)
                    kinds.append(("close", q))
            for q in jq:
                j = joints[q]
                _, fs, stick, sgn = jen[q]
                if stick:
                    for sg in (1.0, -1.0):

                        def slip(_t, yy, sg=sg, q=q, fs=fs):  # type: ignore[no-untyped-def]
                            return sg * yy[slot[q]] - fs

                        slip.terminal, slip.direction = True, 1
                        events.append(slip)
                        kinds.append(("slip", q, sg))
                else:

                    def stick_ev(_t, yy, j=j, sgn=sgn):  # type: ignore[no-untyped-def]
                        return sgn * _rel(j, yy[n : 2 * n])

                    stick_ev.terminal, stick_ev.direction = True, -1
                    events.append(stick_ev)
                    kinds.append(("stick", q))
            sol = solve_ivp(rhs, (tt, t1), y, method="DOP853", rtol=rtol, atol=1e-14,
                            events=events)  # fmt: skip
            y = sol.y[:, -1].copy()
            tt = float(sol.t[-1])
            if sol.status != 1:
                break
            hit = [e for e, te in enumerate(sol.t_events) if te.size]
            kind = kinds[min(hit, key=lambda e: sol.t_events[e][0])]
            q = kind[1]
            j = joints[q]
            if kind[0] == "rev":
                m = mem[q]
                d = _rel(j, y)
                m.stack.append((d, m.force(d)))
                m.s = -m.s
            elif kind[0] == "close":
                m = mem[q]
                d = _rel(j, y)
                del m.stack[-(1 if len(m.stack) == 1 else 2) :]
            elif kind[0] == "slip":
                jen[q][2], jen[q][3] = False, kind[2]
            else:
                jen[q][2] = True
                y[slot[q]] = jen[q][3] * jen[q][1]
        out[i + 1] = y[:n]
    return out
