"""Displacement-noise estimates of :func:`contactlab.tangential.frame.difference_noise` on
simulated friction frames (tests/frame_sim.py: Coulomb frame from rest, plain Python) whose
displacement channels carry white noise, optionally through a causal 2nd-order Butterworth
anti-alias filter with its cut-off at 0.2 or 0.5 of Nyquist (1.0: no filter).

Per case (drawn from the seed: sampling 250/500/1000 Hz, Fk 0.5-1.2 N, Fs/Fk 1-1.5, white
noise 0.2-1.5 µm on both channels) the truth is the standard deviation of the noise as it is
on the channel (after the filter); the table gives estimated/true for the top plate ``x`` and
the base ``y``, for the estimator before issue 8's fix (``old``: the lag-1 value when the
lag search finds no plateau) and now (``new``), by filter and sampling rate: median, min, max,
and the share within [0.5, 2].

    python benches/eval_difference_noise.py [first_seed] [count]
"""

from __future__ import annotations

import itertools
import sys
from pathlib import Path

import numpy as np
from scipy.signal import butter, lfilter

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

from contactlab.tangential.frame import _lag_noise, difference_noise
from frame_sim import simulate_frame

CUTS = (0.2, 0.5, 1.0)


def old_difference_noise(v: np.ndarray, order: int = 4) -> float:
    """The estimator before the fix: lag-1 value when no plateau is found."""
    lags = [lag for lag in (1, 2, 4, 8, 16) if v.size > order * lag + 10]
    est = [_lag_noise(v, lag, order) for lag in lags]
    ratios = [b / a if a > 0 else np.inf for a, b in itertools.pairwise(est)]
    k = int(np.argmin(ratios))
    return float(est[k + 1] if ratios[k] < 4.0 else est[0])


def cases(seed: int):
    rng = np.random.default_rng(seed)
    fs = float(rng.choice([250.0, 500.0, 1000.0]))
    fk = float(rng.uniform(0.5, 1.2))
    ratio = float(rng.choice([1.0, 1.1, 1.25, 1.5]))
    sigma = float(rng.uniform(2e-7, 1.5e-6))
    _t, x, y, _f = simulate_frame(Fk=fk, Fs=ratio * fk, fs=fs)
    for cut in CUTS:
        out = {"seed": seed, "fs": fs, "cut": cut, "sigma_white": sigma}
        for name, v in (("x", x), ("y", y)):
            noise = rng.normal(0, sigma, v.size)
            if cut < 1.0:
                noise = lfilter(*butter(2, cut), noise)
            true = float(np.std(noise))
            out[name] = (true, old_difference_noise(v + noise), difference_noise(v + noise))
        yield out


def main() -> None:
    first = int(sys.argv[1]) if len(sys.argv) > 1 else 7301
    count = int(sys.argv[2]) if len(sys.argv) > 2 else 24
    rows = [c for s in range(first, first + count) for c in cases(s)]
    print(f"seeds {first}..{first + count - 1}: estimated / true noise std (after the filter)")
    cols = f"{'med':>7s} {'min':>6s} {'max':>6s} {'in[.5,2]':>8s}"
    print(f"{'chan':4s} {'cut':>4s} {'fs':>6s} {'n':>3s} | old {cols} | new {cols}")
    for chan in ("x", "y"):
        for cut in CUTS:
            for fs in (250.0, 500.0, 1000.0, None):
                sel = [r for r in rows if r["cut"] == cut and (fs is None or r["fs"] == fs)]
                if not sel:
                    continue
                old = np.array([r[chan][1] / r[chan][0] for r in sel])
                new = np.array([r[chan][2] / r[chan][0] for r in sel])

                def stats(a: np.ndarray) -> str:
                    ok = np.mean((a >= 0.5) & (a <= 2.0))
                    return (f"{np.median(a):7.3f} {a.min():6.3f} {a.max():6.3f} "
                            f"{100 * ok:7.0f}%")  # fmt: skip

                label = "all" if fs is None else f"{fs:.0f}"
                print(
                    f"{chan:4s} {cut:4.1f} {label:>6s} {len(sel):3d} | {stats(old)} | {stats(new)}"
                )


if __name__ == "__main__":
    main()
