"""Pieces shared by the tangential and normal hidden-effect generators: the recording type
that carries the truth, the smooth block excitation and the effect-size bookkeeping."""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping
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


def _rms(a: np.ndarray) -> float:
    return float(np.sqrt(np.mean(a * a)))


def _sizes(
    effects: Iterable[str] | Mapping[str, float], magnitude: float, known: tuple[str, ...]
) -> dict[str, float]:
    sizes = dict(effects) if isinstance(effects, Mapping) else dict.fromkeys(effects, magnitude)
    for n, m in sizes.items():
        if n not in known:
            raise InputError(f"unknown effect {n!r}; choose from {', '.join(known)}")
        if not (0.0 < float(m) < 1.0):
            raise InputError(f"magnitude of {n} must be in (0, 1), got {m}")
    return {n: float(m) for n, m in sizes.items()}
