"""A rig simulator of the whole measurement chain, written from ``docs/effects.md`` only.

It is the second, independent generator of issue 29: it shares no code with the diagnosis or
its generators. The chain, from the command to the stored samples:

tangential
    actuator (a position servo, second order, driven from rest by a ramped sine) → the contact
    (its own Masing operator with exact non-local memory, or another contact law) with the
    effects of ``docs/effects.md`` → load cell (second-order dynamics) → anti-alias filters on
    both channels (4th-order Butterworth, corner tolerances → a small channel skew) →
    sampling → quantisation; displacement-sensor noise and drift, force noise, each from its
    own random stream. Optionally (``rig_recording`` arguments): the displacement sensor's
    own low-pass (an LVDT demodulator), a piezoelectric (high-pass) force cell, Bessel
    anti-alias filters, mains hum, clock jitter and the actuator's drive harmonics.
normal
    pressure actuator (ramped tone blocks from the static preload) → the joint (Kelvin-Voigt
    with the normal effects, solved for δ by an implicit integrator) → pressure cell
    (second-order dynamics) → the same filters, sampling, quantisation and noise.

Everything analogue runs on an internal grid ``oversample`` times finer than the sampling
rate; the filters are discretised exactly for piecewise-linear input (first-order hold).
"""

from .chain import bessel, butterworth, discretise, group_delay, highpass, load_cell
from .contact import Virgin, masing_force, play_operator, segalman_parameters
from .recording import NEW_EFFECTS, NORMAL_EFFECTS, TANGENTIAL_EFFECTS, RigRecording, rig_recording

__all__ = [
    "NEW_EFFECTS",
    "NORMAL_EFFECTS",
    "TANGENTIAL_EFFECTS",
    "RigRecording",
    "Virgin",
    "bessel",
    "butterworth",
    "discretise",
    "group_delay",
    "highpass",
    "load_cell",
    "masing_force",
    "play_operator",
    "rig_recording",
    "segalman_parameters",
]
