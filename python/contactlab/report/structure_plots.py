"""Plots of the structure analyses: natural frequency and damping ratio against amplitude
(one degree of freedom, or one line per mode); each accepts ``ax=`` and returns the axes."""

from __future__ import annotations

from typing import Any

from ..structure.amplitude import AmplitudeDependence
from ..structure.amplitude_mdof import ModalAmplitudeDependence


def plot_amplitude_dependence(ad: AmplitudeDependence, ax: Any = None) -> Any:
    """Frequency and damping ratio versus amplitude (two axes); returns the axes."""
    import matplotlib.pyplot as plt

    if ax is None:
        _, ax = plt.subplots(1, 2, figsize=(9, 3.5), layout="constrained")
    ax[0].semilogx(ad.amplitude, ad.frequency_hz, "o-")
    ax[0].set_xlabel("amplitude [m]")
    ax[0].set_ylabel("natural frequency [Hz]")
    ax[1].semilogx(ad.amplitude, 100 * ad.damping_ratio, "o-")
    ax[1].set_xlabel("amplitude [m]")
    ax[1].set_ylabel("damping ratio [%]")
    for a in ax:
        a.grid(True, alpha=0.3)
    return ax


def plot_modal_amplitude_dependence(ads: list[ModalAmplitudeDependence], ax: Any = None) -> Any:
    """Frequency and damping ratio against amplitude, one line per mode; returns the axes."""
    import matplotlib.pyplot as plt

    if ax is None:
        _, ax = plt.subplots(1, 2, figsize=(9, 3.5), layout="constrained")
    for ad in ads:
        lab = f"mode {ad.mode + 1} (x{ad.ref_dof})"
        ax[0].semilogx(ad.amplitude, ad.frequency_hz, "o-", label=lab)
        ax[1].semilogx(ad.amplitude, 100 * ad.damping_ratio, "o-", label=lab)
    ax[0].set_ylabel("natural frequency [Hz]")
    ax[1].set_ylabel("damping ratio [%]")
    for a in ax:
        a.set_xlabel("amplitude of the reference DOF [m]")
        a.grid(True, alpha=0.3)
        a.legend(fontsize=8)
    return ax
