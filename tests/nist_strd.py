"""NIST StRD nonlinear regression problems: the certified data files in tests/data/nist/
(see its README for the source) parsed, with each problem's model written out from its
file's ``Model:`` section.

``load(name)`` gives the data, both start points, the certified parameters and standard
deviations, and the certified residual sum of squares. ``lre(est, cert)`` is the log relative
error NIST and McCullough use to count correct significant digits.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

DATA = Path(__file__).resolve().parent / "data" / "nist"

LOWER = ["Misra1a", "Chwirut2", "Chwirut1", "Lanczos3", "Gauss1", "Gauss2", "DanWood", "Misra1b"]
AVERAGE = ["Kirby2", "Hahn1", "Nelson", "MGH17", "Lanczos1", "Lanczos2", "Gauss3", "Misra1c",
           "Misra1d", "Roszman1", "ENSO"]  # fmt: skip

_TWO_PI = 2.0 * math.pi


def _exp3(b, x):
    return b[0] * np.exp(-b[1] * x) + b[2] * np.exp(-b[3] * x) + b[4] * np.exp(-b[5] * x)


def _gauss(b, x):
    return (
        b[0] * np.exp(-b[1] * x)
        + b[2] * np.exp(-((x - b[3]) ** 2) / b[4] ** 2)
        + b[5] * np.exp(-((x - b[6]) ** 2) / b[7] ** 2)
    )


def _chwirut(b, x):
    return np.exp(-b[0] * x) / (b[1] + b[2] * x)


MODELS = {
    "Misra1a": lambda b, x: b[0] * (1 - np.exp(-b[1] * x)),
    "Misra1b": lambda b, x: b[0] * (1 - (1 + b[1] * x / 2) ** (-2)),
    "Misra1c": lambda b, x: b[0] * (1 - (1 + 2 * b[1] * x) ** (-0.5)),
    "Misra1d": lambda b, x: b[0] * b[1] * x * ((1 + b[1] * x) ** (-1)),
    "Chwirut1": _chwirut,
    "Chwirut2": _chwirut,
    "Lanczos1": _exp3,
    "Lanczos2": _exp3,
    "Lanczos3": _exp3,
    "Gauss1": _gauss,
    "Gauss2": _gauss,
    "Gauss3": _gauss,
    "DanWood": lambda b, x: b[0] * x ** b[1],
    "Kirby2": lambda b, x: (b[0] + b[1] * x + b[2] * x**2) / (1 + b[3] * x + b[4] * x**2),
    "Hahn1": lambda b, x: (
        (b[0] + b[1] * x + b[2] * x**2 + b[3] * x**3) / (1 + b[4] * x + b[5] * x**2 + b[6] * x**3)
    ),
    # log[y] = b1 - b2*x1 * exp[-b3*x2]: the response is log y
    "Nelson": lambda b, x: b[0] - b[1] * x[0] * np.exp(-b[2] * x[1]),
    "MGH17": lambda b, x: b[0] + b[1] * np.exp(-x * b[3]) + b[2] * np.exp(-x * b[4]),
    "Roszman1": lambda b, x: b[0] - b[1] * x - np.arctan(b[2] / (x - b[3])) / math.pi,
    "ENSO": lambda b, x: (
        b[0]
        + b[1] * np.cos(_TWO_PI * x / 12)
        + b[2] * np.sin(_TWO_PI * x / 12)
        + b[4] * np.cos(_TWO_PI * x / b[3])
        + b[5] * np.sin(_TWO_PI * x / b[3])
        + b[7] * np.cos(_TWO_PI * x / b[6])
        + b[8] * np.sin(_TWO_PI * x / b[6])
    ),
}


@dataclass
class Problem:
    name: str
    x: np.ndarray  # (n,) or (k, n) for several predictors
    y: np.ndarray
    start1: np.ndarray
    start2: np.ndarray
    certified: np.ndarray
    certified_stderr: np.ndarray
    rss: float

    def model(self, b, x=None):
        return MODELS[self.name](b, self.x if x is None else x)


_NUM = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"


def load(name: str) -> Problem:
    lines = (DATA / f"{name}.dat").read_text().splitlines()
    rows = [ln for ln in lines if re.match(r"^\s*b\d+\s*=", ln)]
    start1, start2, cert, cstd = [], [], [], []
    for ln in rows:
        nums = [float(v) for v in re.findall(_NUM, ln.split("=", 1)[1])]
        start1.append(nums[0])
        start2.append(nums[1])
        cert.append(nums[2])
        cstd.append(nums[3])
    rss = next(float(re.findall(_NUM, ln)[-1]) for ln in lines if "Residual Sum of Squares" in ln)
    i0 = next(i for i, ln in enumerate(lines) if re.match(r"^Data:\s+y\b", ln))
    data = np.array(
        [[float(v) for v in ln.split()] for ln in lines[i0 + 1 :] if ln.strip()], dtype=float
    )
    y = data[:, 0]
    x = data[:, 1] if data.shape[1] == 2 else data[:, 1:].T
    if name == "Nelson":
        y = np.log(y)
    return Problem(name, x, y, np.array(start1), np.array(start2), np.array(cert),
                   np.array(cstd), rss)  # fmt: skip


def lre(est: float, cert: float) -> float:
    """Log relative error: the number of correct significant digits (capped at 15)."""
    if not math.isfinite(est):
        return 0.0
    if est == cert:
        return 15.0
    rel = abs(est - cert) / abs(cert) if cert != 0 else abs(est)
    return max(0.0, min(15.0, -math.log10(rel)))
