"""
A normal-contact loop and its Table 2
=====================================

Konowalski's normal contact under ``p = p0 + pa sin(ωt)``: the loop's loading, centre and
unloading polynomials (the paper's Table 2, in its units: MPa against µm), the energy
dissipated per cycle ``E_d`` and the energy dissipation coefficient ``ψ``.
"""

import matplotlib.pyplot as plt

import contactlab.normal as cn
from contactlab.synthetic.normal import synthetic_recording

t, p, delta = synthetic_recording(p0=0.5e6, pa=0.4e6, omega=1.0, n_cycles=4, seed=0)
loop = cn.analyze_loop(t, p, delta)
print(f"E_d = {loop.E_d:.4g} J/m², psi = {loop.psi:.4f}, k_tan = {loop.k_tan:.4g} Pa/m")
for curve, coeffs in loop.table2().items():
    print(curve, ", ".join(f"{c:.4g}" for c in coeffs))

fig, ax = plt.subplots()
ax.plot(1e6 * delta, 1e-6 * p, lw=0.8)
ax.set_xlabel("δ [µm]")
ax.set_ylabel("p [MPa]")
ax.set_title("normal contact loop, p0 = 0.5 MPa, pa = 0.4 MPa")
