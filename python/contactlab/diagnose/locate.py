"""Where the residual lives: short statements with numbers about a model's residual.

The residual ``e = measured - model`` is broken down by position in the branch (right after
a reversal or mid-branch), by branch (input rising or falling), by input velocity, by time,
by cycle amplitude, and into harmonics of the excitation phase (the phase of the analytic
signal of the input, so a stepped or swept excitation is handled). Each breakdown gives
the share of the residual power and a short statement; the numbers are kept in a dict for
plots and programs.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ._family import Prepared
from ._filters import hilbert, uniform_filter1d

N_HARMONICS = 7


def _share(mask: np.ndarray, p: np.ndarray) -> float:
    tot = float(p.sum())
    return float(p[mask].sum() / tot) if tot > 0 else 0.0


def excitation_phase(d: Prepared) -> np.ndarray:
    """Instantaneous phase of the input (analytic signal of the input minus its local mean)."""
    win = max(3, round(d.cycles.period_samples))
    uc = d.u - uniform_filter1d(d.u, win, mode="nearest")
    return np.unwrap(np.angle(hilbert(uc)))


def harmonic_shares(phase: np.ndarray, e: np.ndarray) -> dict[str, Any]:
    """Least-squares split of ``e`` into a mean and harmonics ``n = 1..7`` of ``phase``."""
    cols = [np.ones_like(phase)]
    for n in range(1, N_HARMONICS + 1):
        cols += [np.cos(n * phase), np.sin(n * phase)]
    A = np.column_stack(cols)
    coef, *_ = np.linalg.lstsq(A, e, rcond=None)
    tot = float(np.sum(e * e)) or 1.0
    power = [float(np.sum((A[:, :1] @ coef[:1]) ** 2)) / tot]
    for n in range(1, N_HARMONICS + 1):
        comp = A[:, 2 * n - 1 : 2 * n + 1] @ coef[2 * n - 1 : 2 * n + 1]
        power.append(float(np.sum(comp * comp)) / tot)
    odd = sum(power[1::2])
    even = sum(power[2::2])
    return {"mean": power[0], "per_harmonic": power[1:], "odd": odd, "even": even}


def locate(
    d: Prepared, residual_model_minus_meas: np.ndarray, family: Any
) -> tuple[list[str], dict]:
    """Statements (with numbers) on where the residual lives, and the numbers themselves."""
    e = -residual_model_minus_meas  # measured minus model
    p = e * e
    # display units: tangential F in N, x in µm; normal δ in nm, p in MPa
    if family.kind == "tangential":
        unit, ys, uunit, us = "N", 1.0, "µm", 1e6
    else:
        unit, ys, uunit, us = "nm", 1e9, "MPa", 1e-6
    uname = family.input_name
    rms = float(np.sqrt(p.mean()))
    ph = d.cycles.phase_in_branch
    nums: dict[str, Any] = {"rms": rms}
    out: list[str] = []

    after = ph < 0.05
    mid = (ph >= 0.25) & (ph < 0.75)
    nums["after_reversal"] = (_share(after, p), float(after.mean()))
    nums["mid_branch"] = (_share(mid, p), float(mid.mean()))
    out.append(
        f"{100 * nums['after_reversal'][0]:.0f} % of the residual power is in the "
        f"{100 * nums['after_reversal'][1]:.0f} % of samples right after a reversal; "
        f"{100 * nums['mid_branch'][0]:.0f} % is mid-branch "
        f"({100 * nums['mid_branch'][1]:.0f} % of samples)"
    )

    rising = d.ud > 0
    m_up = float(e[rising].mean()) if rising.any() else 0.0
    m_dn = float(e[~rising].mean()) if (~rising).any() else 0.0
    nums["branch_mean"] = (m_up, m_dn)
    nums["rising_share"] = _share(rising, p)
    out.append(
        f"{100 * nums['rising_share']:.0f} % of the residual power is on branches with "
        f"{uname} rising; mean residual {m_up * ys:+.3g} {unit} while {uname} rises, "
        f"{m_dn * ys:+.3g} {unit} while it falls"
    )

    speed = np.abs(d.ud)
    q75, q25 = np.quantile(speed, [0.75, 0.25])
    nums["fast_quarter"] = _share(speed >= q75, p)
    nums["slow_quarter"] = _share(speed <= q25, p)
    out.append(
        f"{100 * nums['fast_quarter']:.0f} % of the residual power is in the fastest quarter "
        f"of samples (|d{uname}/dt| >= {q75 * us:.3g} {uunit}/s), "
        f"{100 * nums['slow_quarter']:.0f} % in the "
        "slowest quarter"
    )

    n = e.size
    thirds = [slice(0, n // 3), slice(n // 3, 2 * n // 3), slice(2 * n // 3, n)]
    tr = [float(np.sqrt(np.mean(e[s] ** 2))) for s in thirds]
    tm = [float(np.mean(e[s])) for s in thirds]
    nums["time_thirds_rms"] = tr
    nums["time_thirds_mean"] = tm
    out.append(
        f"residual RMS {tr[0] * ys:.3g} / {tr[1] * ys:.3g} / {tr[2] * ys:.3g} {unit} in the "
        f"first / middle / last third of the recording (mean {tm[0] * ys:+.3g} / "
        f"{tm[1] * ys:+.3g} / {tm[2] * ys:+.3g} {unit})"
    )

    cyc = d.cycles.cycle
    ids = np.unique(cyc[cyc >= 0])
    if ids.size >= 3:
        amp = np.array([np.ptp(d.u[cyc == k]) / 2 for k in ids])
        crms = np.array([np.sqrt(np.mean(e[cyc == k] ** 2)) for k in ids])
        lo, hi = np.quantile(amp, [1 / 3, 2 / 3])
        groups = [amp <= lo, (amp > lo) & (amp <= hi), amp > hi]
        g_rms = [float(np.sqrt(np.mean(crms[g] ** 2))) if g.any() else float("nan") for g in groups]
        g_amp = [float(np.mean(amp[g])) if g.any() else float("nan") for g in groups]
        nums["amplitude_groups"] = {"amplitude": g_amp, "rms": g_rms}
        out.append(
            "residual RMS by cycle amplitude: "
            + ", ".join(
                f"{r * ys:.3g} {unit} at {uname} amplitude {a * us:.3g} {uunit}"
                for a, r in zip(g_amp, g_rms, strict=True)
            )
        )

    h = harmonic_shares(excitation_phase(d), e)
    nums["harmonics"] = h
    top = int(np.argmax(h["per_harmonic"])) + 1
    out.append(
        f"{100 * h['odd']:.0f} % of the residual power is in odd harmonics of the excitation "
        f"(strongest: harmonic {top}, {100 * h['per_harmonic'][top - 1]:.0f} %), "
        f"{100 * h['even']:.0f} % in even harmonics, {100 * h['mean']:.0f} % is a constant offset"
    )
    return out, nums
