"""``Masing.force`` at every SIMD level: the same forces bit for bit as the generic build."""

from __future__ import annotations

import contextlib
import io
import os
import subprocess
import sys

import numpy as np
import pytest

import contactlab
from contactlab import _core

# Sine (long monotone runs), band-limited noise (runs of ~6 samples), a random walk (runs of
# ~2), and held values with jumps (zero-length steps, several loops closed at once).
CODE = """
import hashlib, numpy as np, contactlab
r = np.random.default_rng(33)
n = 20_000
sine = np.sin(np.arange(n) * (2 * np.pi / 700))
e = r.uniform(-1, 1, (2, n)).tolist()
a1, b, w = 2 * 0.95 * np.cos(2 * np.pi / 40), [0.0, 0.0], [0.0]
for i in range(2, n):
    b.append(a1 * b[-1] - 0.9025 * b[-2] + 0.06 * e[0][i])
for i in range(1, n):
    w.append(0.999 * w[-1] + 0.05 * e[1][i])
band, walk = np.array(b), np.array(w)
held = np.repeat(r.standard_normal(n // 4).cumsum() * 0.01, 4)
held[::997] += 3 * r.standard_normal(held[::997].size)
m = contactlab.Masing(h0=1.0, ac=3.0)
digests = []
for x in (sine, band, walk, held):
    buf = np.empty_like(x)
    op = m.operator()
    op.push(x[:12_345], out=buf[:12_345])
    op.push(x[12_345:], out=buf[12_345:])
    digests.append(hashlib.sha256(m.force(x).tobytes() + buf.tobytes()).hexdigest())
print(" ".join(digests))
"""


def here() -> list[str]:
    """The digests at this process's level (the best this CPU has)."""
    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        exec(CODE, {})
    return buf.getvalue().split()


def run_at(level: str) -> list[str]:
    env = dict(os.environ)
    env["CONTACTLAB_SIMD"] = level
    out = subprocess.run(
        [sys.executable, "-c", CODE], env=env, capture_output=True, text=True, check=True
    )
    return out.stdout.split()


@pytest.mark.skipif(_core.simd_level() == "generic", reason="this CPU has no wider level")
def test_every_simd_level_gives_the_generic_forces():
    want = run_at("generic")
    assert len(want) == 4
    assert here() == want, _core.simd_level()
    if _core.simd_level() == "avx512":
        assert run_at("avx2") == want


def test_force_matches_the_plain_loop():
    """Against a plain loop of the rules with libm exp (independent code), to 1e-12."""
    r = np.random.default_rng(5)
    x = np.concatenate([np.sin(np.arange(3000) / 40.0), r.standard_normal(3000).cumsum() * 0.05])
    h = contactlab.Masing(h0=1.0, ac=3.0).force(x)
    xr: list[float] = []
    hr: list[float] = []
    xp = hp = d = 0.0
    want = np.empty_like(x)
    for i, xi in enumerate(x):
        if xi != xp:
            s = 1.0 if xi > xp else -1.0
            if s != d:
                if d != 0.0:
                    xr.append(xp)
                    hr.append(hp)
                d = s
            while xr:
                t = xr[-2] if len(xr) >= 2 else -xr[0]
                if s * (xi - t) < 0.0:
                    break
                del xr[-2:]
                del hr[-2:]
            if xr:
                u = (xi - xr[-1]) / 2.0
                hp = hr[-1] + 2.0 * np.copysign(-np.expm1(-3.0 * abs(u)), u)
            else:
                hp = np.copysign(-np.expm1(-3.0 * abs(xi)), xi)
            xp = xi
        want[i] = hp
    assert np.max(np.abs(h - want)) <= 1e-12
