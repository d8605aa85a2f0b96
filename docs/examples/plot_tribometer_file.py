"""
A tribometer's file, read as it comes
=====================================

Rigs write their own headers and units: here a tab-separated file with
``Time [s]  Normal [uN]  Position [mm]  Friction [uN]`` and a clock that sometimes skips a
sample. It is read without any conversion by hand: the columns are mapped by name (the
normal force kept as channel ``N``), the units converted to SI, the time stamps resampled
onto a uniform grid (``--resample``) with the largest gap bridged reported, and the friction
coefficient μ = F/N measured on the sliding plateau of every stroke.
"""

import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from contactlab.io import read_recording
from contactlab.io.recording import describe_resampling
from contactlab.tangential.friction import sliding_friction

# a Jenkins element (stiffness 4e7 uN/mm, slipping at 2.3 N) under a 0.2 mm stroke, 5 N load
t = np.arange(3000) * 5e-3
t = np.delete(t, np.arange(7, t.size, 53))  # every 53rd sample lost: a 10 ms step
pos = -110.0 + 0.1 * np.sin(2 * np.pi * 0.5 * t)  # mm
fric = np.zeros(t.size)  # uN
for i in range(1, t.size):
    fric[i] = np.clip(fric[i - 1] + 4e7 * (pos[i] - pos[i - 1]), -2.3e6, 2.3e6)
normal = np.full(t.size, 5.0e6)  # uN
path = Path(tempfile.mkdtemp()) / "tribometer.txt"
path.write_text(
    "Time [s]\tNormal [uN]\tPosition [mm]\tFriction [uN]\n"
    + "".join(
        f"{a:.6f}\t{b:.1f}\t{c:.7f}\t{d:.1f}\n"
        for a, b, c, d in zip(t, normal, pos, fric, strict=True)
    )
)

rec = read_recording(path, resample=True)
print(rec.meta["columns"])
print(describe_resampling(rec.meta["resampled"]))
mu = sliding_friction(rec.t, rec["x"], rec["F"], rec["N"])
print(mu.text())

fig, ax = plt.subplots()
ax.plot(1e6 * (rec["x"] - rec["x"].mean()), rec["F"] / rec["N"], lw=0.8)
ax.axhline(mu.mu, color="C1", ls="--", label=f"μ = {mu.mu:.3f}")
ax.axhline(-mu.mu, color="C1", ls="--")
ax.set_xlabel("x − mean [µm]")
ax.set_ylabel("F / N")
ax.legend()
