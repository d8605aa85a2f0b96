"""
A Masing loop and its energy
============================

The tangential model: an exponential virgin curve ``f(u) = h0 (1 - exp(-ac u))`` and
Masing's rules. The energy of a symmetric cycle from the closed form equals the area of the
simulated loop.
"""

import matplotlib.pyplot as plt
import numpy as np

import contactlab

m = contactlab.Masing(h0=40.0, ac=4e4)  # N, 1/m
x = 20e-6 * np.sin(np.linspace(0, 4 * np.pi, 4001))
F = m.force(x)
print(
    f"closed form {m.loop_energy(20e-6):.6g} J, loop area "
    f"{contactlab.loop_area(x[-2001:], F[-2001:]):.6g} J"
)

fig, ax = plt.subplots()
ax.plot(1e6 * x, F)
ax.set_xlabel("x [µm]")
ax.set_ylabel("F [N]")
ax.set_title("Masing loop, h0 = 40 N, ac = 4e4 1/m")
