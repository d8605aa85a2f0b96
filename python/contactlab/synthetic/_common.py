"""Pieces shared by the tangential and normal hidden-effect generators: the recording type
that carries the truth, the smooth block excitation and the effect-size bookkeeping."""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..errors import InputError
from ..io import Recording


@dataclass
class HiddenEffectRecording(Recording):
    """A generated :class:`contactlab.io.Recording` (SI units; write it with
    :func:`contactlab.io.write_recording`) that also carries the ``truth``: base parameters,
    active effects with their parameters, magnitudes and noise levels."""

    truth: dict[str, Any] = field(default_factory=dict)
    model: str = "tangential"

    def arrays(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        keys = ("x", "F") if self.model == "tangential" else ("p", "delta")
        return self.t, self.data[keys[0]], self.data[keys[1]]


class Profile:
    """A piecewise-constant level smoothed by cubic steps of width ``w``, with its integral."""

    def __init__(self, levels: Iterable[float], starts: Iterable[float], w: float) -> None:
        self.levels = np.asarray(list(levels), float)
        self.starts = np.asarray(list(starts), float)
        self.w = float(w)

    def __call__(self, t: np.ndarray) -> np.ndarray:
        out = np.full_like(t, self.levels[0], dtype=float)
        for lv_prev, lv, ts in zip(self.levels[:-1], self.levels[1:], self.starts, strict=True):
            u = np.clip((t - ts) / self.w, 0.0, 1.0)
            out += (lv - lv_prev) * u * u * (3.0 - 2.0 * u)
        return out

    def integral(self, t: np.ndarray) -> np.ndarray:
        out = self.levels[0] * t
        for lv_prev, lv, ts in zip(self.levels[:-1], self.levels[1:], self.starts, strict=True):
            u = (t - ts) / self.w
            uc = np.clip(u, 0.0, 1.0)
            part = np.where(u > 1.0, 0.5 + (u - 1.0), uc**3 - uc**4 / 2.0)
            out += (lv - lv_prev) * self.w * np.where(u < 0.0, 0.0, part)
        return out


def block_excitation(
    amplitudes: Iterable[float], freqs: Iterable[float], cycles_per_block: int
) -> tuple[Callable[[np.ndarray], np.ndarray], float, float]:
    """Closed-form excitation ``x(t)`` (zero for ``t < 0``), its duration and max frequency."""
    A = list(amplitudes)
    f = list(freqs)
    durations = [cycles_per_block / fi for fi in f]
    starts = np.cumsum(durations)[:-1]
    w = 1.0 / min(f)
    # amplitude ramps in from zero over the first cycle, so x(t) = 0 for t < 0 joins smoothly
    amp = Profile([0.0, *A], [0.0, *(starts - w / 2)], w)
    fr = Profile(f, starts - w / 2, w)
    total = float(np.sum(durations))

    def x(t: np.ndarray) -> np.ndarray:
        tt = np.asarray(t, float)
        val = amp(tt) * np.sin(2.0 * np.pi * fr.integral(tt))
        return np.where(tt < 0.0, 0.0, val)

    return x, total, max(f)


#: frequencies of the three amplitude blocks, relative to the reference frequency
BLOCK_FREQUENCIES = (1.0, 1.7, 0.6)


def block_frequencies(frequencies: Sequence[float] | None) -> np.ndarray:
    """The three blocks' relative frequencies: the default, one value for all, or three."""
    if frequencies is None:
        return np.array(BLOCK_FREQUENCIES)
    f = np.asarray(list(frequencies), dtype=float)
    if f.size == 1:
        f = np.repeat(f, 3)
    if f.size != 3 or not np.all(np.isfinite(f)) or not np.all(f > 0):
        raise InputError(
            f"frequencies must be one or three positive numbers (relative to f0), got {f.tolist()}"
        )
    return f


def rms(a: np.ndarray) -> float:
    return float(np.sqrt(np.mean(a * a)))


def effect_sizes(
    effects: Iterable[str] | Mapping[str, float], magnitude: float, known: tuple[str, ...]
) -> dict[str, float]:
    sizes = dict(effects) if isinstance(effects, Mapping) else dict.fromkeys(effects, magnitude)
    for n, m in sizes.items():
        if n not in known:
            raise InputError(f"unknown effect {n!r}; choose from {', '.join(known)}")
        if not (0.0 < float(m) < 1.0):
            raise InputError(f"magnitude of {n} must be in (0, 1), got {m}")
    return {n: float(m) for n, m in sizes.items()}


ANTI_ALIAS_ORDER = 4


def measure(
    t: np.ndarray,
    u: np.ndarray,
    y: np.ndarray,
    rng: np.random.Generator,
    *,
    u_noise: float,
    y_noise: float,
    anti_alias: tuple[float, float] | None,
    bits: int | None,
    f_ref: float,
) -> tuple[np.ndarray, np.ndarray, dict[str, Any]]:
    """What a rig's two channels record of the true input ``u`` and output ``y``.

    Each channel passes its own causal anti-alias filter (Butterworth of order
    :data:`ANTI_ALIAS_ORDER`, cut-offs ``anti_alias = (input, output)`` as fractions of the
    Nyquist frequency; started at rest at the first value), gets white sensor noise of RMS
    ``u_noise`` / ``y_noise`` (absolute) and is quantised to ``bits`` over ±1.25 × its peak.
    Different cut-offs delay one channel against the other: ``info["filter_skew"]`` is the
    output's group delay minus the input's at ``f_ref`` (seconds; positive: the output lags).
    """
    from scipy.signal import butter, group_delay, lfilter, lfilter_zi

    dt = float(t[1] - t[0])
    info: dict[str, Any] = {"filter_skew": 0.0}
    chans = []
    delays = []
    for k, (v, sd) in enumerate(((u, u_noise), (y, y_noise))):
        out = np.asarray(v, float)
        if anti_alias is not None:
            fc = float(anti_alias[k])
            if not 0.0 < fc < 1.0:
                raise InputError(f"anti-alias cut-offs are fractions of Nyquist, got {fc}")
            b, a = butter(ANTI_ALIAS_ORDER, fc)
            out, _ = lfilter(b, a, out, zi=lfilter_zi(b, a) * out[0])
            _, gd = group_delay((b, a), w=[2.0 * np.pi * f_ref * dt])
            delays.append(float(gd[0]) * dt)
        if sd > 0:
            out = out + rng.normal(0.0, sd, out.size)
        if bits is not None:
            lsb = 2.5 * float(np.max(np.abs(out))) / 2.0**bits
            out = np.round(out / lsb) * lsb
        chans.append(out)
    if delays:
        info["filter_skew"] = delays[1] - delays[0]
    return chans[0], chans[1], info


def start_index(start: str, t: np.ndarray, f0: float, f_min: float) -> int:
    """First sample kept: 0 from rest; after the amplitude ramp (one period of the slowest
    block) and 1.5 reference cycles more for a steady start."""
    if start == "rest":
        return 0
    if start != "steady":
        raise InputError(f"start must be 'rest' or 'steady', got {start!r}")
    return int(np.searchsorted(t, 1.0 / f_min + 1.5 / f0))
