"""Mains hum on a tangential record's channels: found, and taken out before the diagnosis.

A 50 or 60 Hz line picked up by both the displacement and the force channel is no part of
the joint, but the model carries the displacement's hum into its force (``k·hum`` on a steep
branch) while the force channel holds its own: a channel delay then fits the phase between
the two lines (2π·50 Hz·τ is a large lever), and takes the dashpot's share with it (rig:
1 % hum on both channels gave a 0.44 ms delay and c at 0.68 of the truth; on either channel
alone, c at 0.99-1.01). A line is taken out of a channel when it is significant there
(:data:`LINE_SIGMAS` standard errors of its amplitude) and no harmonic of the drive lies
within :data:`GUARD_BINS` frequency bins of it (there the drive's own content and the hum
cannot be told apart, and the channels are left as recorded).
"""

from __future__ import annotations

import numpy as np

from ._signal import dominant_period_samples, noise_rms

#: the mains frequencies looked for (Hz), each searched within ±MAINS_DRIFT
MAINS = (50.0, 60.0)
MAINS_DRIFT = 0.3
#: a line is removed when its amplitude is this many standard errors (white noise of the
#: channel, Hann-weighted least squares)
LINE_SIGMAS = 8.0
#: ... and every drive harmonic (of the force: all up to the line; of the displacement: the
#: first HARMONICS_X) is at least this many bins (1 / record length) away: a Hann window's
#: leakage from a line 4 bins off is below 0.3 % of it
GUARD_BINS = 4.0
HARMONICS_X = 3
#: the record must hold this many periods of the line and of the drive
MIN_PERIODS = 8.0


def _fit_line(t: np.ndarray, s: np.ndarray, f: float, w: np.ndarray) -> tuple[float, float, float]:
    """Hann-weighted least squares of ``s`` on a constant, a slope and ``cos``, ``sin`` at
    ``f``: ``(a_cos, a_sin, var_factor)``, ``var_factor`` the amplitude's variance per unit
    white-noise variance."""
    ph = 2.0 * np.pi * f * (t - t[0])
    tt = (t - t[0]) / max(float(t[-1] - t[0]), 1e-300)
    X = np.column_stack([np.ones_like(t), tt, np.cos(ph), np.sin(ph)])
    Xw = X * w[:, None]
    G = X.T @ Xw
    try:
        Gi = np.linalg.inv(G)
    except np.linalg.LinAlgError:
        return 0.0, 0.0, np.inf
    beta = Gi @ (Xw.T @ s)
    cov = Gi @ (Xw.T @ Xw) @ Gi  # sandwich: white noise through the weights
    return float(beta[2]), float(beta[3]), float(0.5 * (cov[2, 2] + cov[3, 3]))


#: a hum holds through the record: its amplitude in each third within this factor of the
#: whole record's, its phase within STEADY_PHASE rad (a drive in blocks of other frequencies
#: has content near 50 Hz in one block only: the package's generator at 7.3 Hz, 60.34 Hz)
STEADY_FACTOR, STEADY_PHASE = 1.5, 0.5


def _steady(t: np.ndarray, s: np.ndarray, f: float, a: float, b: float) -> bool:
    """Whether the line ``(a, b)`` at ``f`` found on the whole record is there, alike, in
    each third of it."""
    amp, ph = float(np.hypot(a, b)), float(np.arctan2(b, a))
    n = t.size // 3
    for k in range(3):
        sl = slice(k * n, (k + 1) * n if k < 2 else t.size)
        tk = t[sl]
        ak, bk, _ = _fit_line(tk, s[sl], f, np.hanning(tk.size))
        # (the phase is referred to the record's start, as (a, b) are)
        rot = 2.0 * np.pi * f * (tk[0] - t[0])
        c, sn = np.cos(rot), np.sin(rot)
        ak, bk = ak * c - bk * sn, ak * sn + bk * c
        amp_k = float(np.hypot(ak, bk))
        if not (amp / STEADY_FACTOR <= amp_k <= amp * STEADY_FACTOR):
            return False
        dph = float(np.angle(np.exp(1j * (np.arctan2(bk, ak) - ph))))
        if abs(dph) > STEADY_PHASE:
            return False
    return True


def _clear(f_line: float, f_drive: float, duration: float, harmonics: int | None) -> bool:
    """Whether no drive harmonic lies within :data:`GUARD_BINS` bins of ``f_line``."""
    if not (f_drive > 0 and duration > 0):
        return False
    top = harmonics if harmonics is not None else int(f_line / f_drive) + 2
    k = np.arange(1, max(top, 1) + 1)
    return bool(np.min(np.abs(f_line - k * f_drive)) * duration >= GUARD_BINS)


#: a line left in place (a drive harmonic within GUARD_BINS) counts as hum, not as the
#: drive's own harmonic, when it is at least this many bins from every harmonic
HUM_APART_BINS = 1.0


def _apart(f_line: float, f_drive: float, duration: float) -> bool:
    """Whether ``f_line`` is at least :data:`HUM_APART_BINS` bins from every drive harmonic."""
    k = max(round(f_line / f_drive), 1)
    near = min(abs(f_line - j * f_drive) for j in (k - 1, k, k + 1) if j >= 1)
    return bool(near * duration >= HUM_APART_BINS)


def _one_channel(
    t: np.ndarray, s: np.ndarray, f_drive: float, harmonics: int | None
) -> tuple[np.ndarray, list[tuple[float, float]]]:
    """``s`` with each significant mains line removed, and the lines ``(f, amplitude)``."""
    duration = float(t[-1] - t[0])
    dt = duration / max(t.size - 1, 1)
    w = np.hanning(t.size)
    try:
        sigma = noise_rms(s)
    except Exception:  # (a too-short channel: nothing to remove)
        return s, []
    out, found = s, []
    for f0 in MAINS:
        if f0 >= 0.45 / dt or duration * f0 < MIN_PERIODS:
            continue
        # coarse (a tenth of a bin, at most ~61 trials), then a hundredth of a bin around
        # the best: a line off by a tenth of a bin drifts by 0.3 rad over the record
        coarse = max(0.1 / duration, 2 * MAINS_DRIFT / 60)
        grid = np.arange(f0 - MAINS_DRIFT, f0 + MAINS_DRIFT + 0.5 * coarse, coarse)
        best = None
        for stage in (grid, None):
            if stage is None:
                stage = best[0] + np.linspace(-1.0, 1.0, 21) * coarse
            for f in stage:
                a, b, v = _fit_line(t, out, float(f), w)
                if best is None or a * a + b * b > best[1] ** 2 + best[2] ** 2:
                    best = (float(f), a, b, v)
        if best is None:
            continue
        f, a, b, v = best
        amp = float(np.hypot(a, b))
        if not (sigma > 0 and np.isfinite(v)) or amp < LINE_SIGMAS * sigma * np.sqrt(v):
            continue
        if not _clear(f, f_drive, duration, harmonics) or not _steady(t, out, f, a, b):
            continue
        ph = 2.0 * np.pi * f * (t - t[0])
        out = out - (a * np.cos(ph) + b * np.sin(ph))
        found.append((f, amp))
    return out, found


def drive_frequency(t: np.ndarray, u: np.ndarray) -> float:
    """The drive's frequency (Hz): the strongest spectral line of ``u``
    (:func:`~contactlab.diagnose._signal.dominant_period_samples`, one bin of resolution)
    refined to a twentieth of a bin by the largest Hann-weighted Fourier amplitude nearby
    (the guard around each harmonic k·f needs f to better than a bin over k)."""
    dt = float(t[1] - t[0])
    duration = float(t[-1] - t[0])
    f0 = 1.0 / (dominant_period_samples(u) * dt)
    if not duration > 0:
        return f0
    s = (u - float(np.mean(u))) * np.hanning(u.size)
    grid = f0 + np.linspace(-1.5, 1.5, 61) / duration
    grid = grid[grid > 0]
    tt = t - t[0]
    amps = [abs(np.dot(s, np.exp(-2j * np.pi * f * tt))) for f in grid]
    return float(grid[int(np.argmax(amps))]) if grid.size else f0


def _beside_harmonics(t: np.ndarray, s: np.ndarray, f_drive: float) -> list[tuple[float, float]]:
    """Significant mains lines of ``s`` within :data:`GUARD_BINS` of a drive harmonic (those
    :func:`remove_mains` leaves) and at least :data:`HUM_APART_BINS` from every one:
    ``(f, amplitude)``. Each line is fitted beside the three drive harmonics nearest it
    (Hann-weighted least squares): a Hann window's main lobe spans two bins either side,
    so the line alone would carry a near harmonic's leakage."""
    duration = float(t[-1] - t[0])
    dt = duration / max(t.size - 1, 1)
    w = np.hanning(t.size)
    try:
        sigma = noise_rms(s)
    except Exception:  # (a too-short channel)
        return []
    tt = t - t[0]
    out = []
    for f0 in MAINS:
        if f0 >= 0.45 / dt or duration * f0 < MIN_PERIODS:
            continue
        k = max(round(f0 / f_drive), 1)
        ks = [j for j in (k - 1, k, k + 1) if j >= 1]
        cols = [np.ones_like(tt), tt / max(duration, 1e-300)]
        for j in ks:
            ph = 2.0 * np.pi * j * f_drive * tt
            cols += [np.cos(ph), np.sin(ph)]
        base = np.column_stack(cols)
        best = None
        for f in np.arange(f0 - MAINS_DRIFT, f0 + MAINS_DRIFT + 1e-9, 0.1 / duration):
            if _clear(f, f_drive, duration, None) or not _apart(f, f_drive, duration):
                continue
            ph = 2.0 * np.pi * f * tt
            X = np.column_stack([base, np.cos(ph), np.sin(ph)])
            Xw = X * w[:, None]
            try:
                Gi = np.linalg.inv(X.T @ Xw)
            except np.linalg.LinAlgError:
                continue
            beta = Gi @ (Xw.T @ s)
            amp = float(np.hypot(beta[-2], beta[-1]))
            if best is None or amp > best[1]:
                cov = Gi @ (Xw.T @ Xw) @ Gi
                best = (float(f), amp, float(0.5 * (cov[-2, -2] + cov[-1, -1])))
        if best is None:
            continue
        f, amp, v = best
        if sigma > 0 and np.isfinite(v) and amp >= LINE_SIGMAS * sigma * np.sqrt(v):
            out.append((f, amp))
    return out


def kept_hum(
    t: np.ndarray, u: np.ndarray, y: np.ndarray, units: tuple[str, str] = ("m", "N")
) -> tuple[list[dict[str, float]], str | None]:
    """Mains lines on both channels that :func:`remove_mains` leaves in place because a
    drive harmonic lies within :data:`GUARD_BINS` bins, and a sentence saying so (None:
    there are none).

    A line significant (:data:`LINE_SIGMAS`) at the same frequency (within a bin) on the
    displacement and on the force, at least :data:`HUM_APART_BINS` bins from every drive
    harmonic, is hum picked up by both channels: no effect of the joint moves the
    displacement sensor at the mains frequency. It stays in the residual, unexplained; an
    effect whose fit draws a line there (a normal-load fluctuation whose sideband falls on
    it: :class:`~contactlab.diagnose.effects.tangential.normal_load.NormalLoad`) is refused.
    Returns ``[{"f": Hz, "x": amplitude, "F": amplitude, "harmonic": k}]``.
    """
    if t.size < 64:
        return [], None
    f_drive = drive_frequency(t, u)
    duration = float(t[-1] - t[0])
    if duration * f_drive < 2:
        return [], None
    on_x = _beside_harmonics(t, u, f_drive)
    on_y = _beside_harmonics(t, y, f_drive)
    out = []
    for fx, ax in on_x:
        for fy, ay in on_y:
            if abs(fx - fy) * duration <= 1.0:
                f = 0.5 * (fx + fy)
                out.append({"f": f, "x": ax, "F": ay, "harmonic": round(f / f_drive)})
    if not out:
        return [], None
    parts = [
        f"{h['x']:.3g} {units[0]} and {h['F']:.3g} {units[1]} at {h['f']:.2f} Hz, "
        f"{abs(h['f'] - h['harmonic'] * f_drive) * duration:.1f} bins from drive harmonic "
        f"{h['harmonic']}"
        for h in out
    ]
    return out, (
        "mains hum on both channels left in place (a drive harmonic too near to tell them "
        "apart): " + "; ".join(parts) + "; it stays in the residual unexplained, and no "
        "normal-load fluctuation is named for it"
    )


def remove_mains(
    t: np.ndarray, u: np.ndarray, y: np.ndarray, units: tuple[str, str] = ("m", "N")
) -> tuple[np.ndarray, np.ndarray, str | None]:
    """The input and output with significant mains lines (50, 60 Hz) removed where no
    drive harmonic is near them, and a sentence saying what was removed (None: nothing).

    Parameters
    ----------
    t : ndarray
        Uniform sample times (s).
    u, y : ndarray
        The displacement and force channels.
    units : tuple of str
        The channels' units, for the sentence.

    Returns
    -------
    tuple
        ``(u, y, sentence or None)``.
    """
    if t.size < 64:
        return u, y, None
    f_drive = drive_frequency(t, u)
    if (t[-1] - t[0]) * f_drive < 2:
        return u, y, None
    u2, lines_u = _one_channel(t, u, f_drive, HARMONICS_X)
    y2, lines_y = _one_channel(t, y, f_drive, None)
    if not (lines_u or lines_y):
        return u, y, None
    parts = []
    for name, lines, s, unit in (("x", lines_u, u, units[0]), ("F", lines_y, y, units[1])):
        for f, amp in lines:
            parts.append(
                f"{amp:.3g} {unit} at {f:.2f} Hz on {name} "
                f"({100 * amp / max(float(np.ptp(s)), 1e-300):.2g} % of its range)"
            )
    return (
        u2,
        y2,
        (
            "mains hum taken out before the diagnosis (a line no harmonic of the drive comes "
            "near; the model would carry the displacement's hum into its force and a delay "
            "would fit the phase between the channels' lines): " + "; ".join(parts)
        ),
    )
