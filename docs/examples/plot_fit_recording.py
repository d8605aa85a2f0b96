"""
Fitting a tangential recording
==============================

A synthetic recording with 1 % force noise goes through the analysis a measured file gets
(``contactlab analyze FILE`` on the command line): the cycles are averaged, ``h0`` and
``ac`` fitted with standard errors, and the energy per cycle computed in closed form and
from the loop area.
"""

import matplotlib.pyplot as plt

from contactlab.report.tangential import plot_loop
from contactlab.synthetic.tangential import synthetic_recording
from contactlab.tangential import analyze_tangential

rec = synthetic_recording(
    h0=40.0, ac=4e4, amplitude=20e-6, n_cycles=6, fs=2000.0, noise=0.01, seed=1
)
res = analyze_tangential(rec, warn=False)
d = res.to_dict()
for key in ("h0", "ac", "energy_per_cycle", "energy_per_cycle_numeric", "equivalent_damping"):
    print(f"{key} = {d[key]:.5g} ± {d[key + '_stderr']:.2g} {d['units'][key]}")

fig, ax = plt.subplots()
plot_loop(res, ax=ax)
ax.set_title("averaged loop (±1σ across cycles) and the fitted Masing loop")
