"""``contactlab.diagnose(..., delay=)`` (issue 32: the README's promise; the command line
only parses ``--delay`` into it): the same diagnosis as on the recording shifted by hand."""

from __future__ import annotations

import numpy as np
import pytest

import contactlab
from contactlab import InputError
from contactlab.synthetic.diagnosis import hidden_effect_recording
from contactlab.tangential.lag import delayed_recording, shifted_recording


def test_delay_equals_the_recording_shifted_by_hand():
    rec = hidden_effect_recording(["force_offset"], seed=11)
    d = 0.7 / 1000
    kw = {"model": "tangential", "candidates": ["force_offset", "viscous_damping"]}
    a = contactlab.diagnose(rec, delay=d, **kw)
    b = contactlab.diagnose(shifted_recording(rec, d)[0], **kw)
    assert a.to_dict() == b.to_dict()
    assert a.location["samples"]["recording"] < rec.t.size  # the shifted-out tail is dropped


def test_every_form_of_recording_is_shifted_alike():
    t = np.arange(400) * 1e-3
    x = np.sin(2 * np.pi * t)
    F = np.cos(2 * np.pi * t)
    tt, xs, Fs = delayed_recording((t, x, F), 2.5e-3)
    d = delayed_recording({"t": t, "x": x, "F": F, "T": 20.0 + 0 * t, "rig": "A"}, 2.5e-3)
    np.testing.assert_array_equal(d["F"], Fs)
    np.testing.assert_array_equal(d["T"], np.full(xs.size, 20.0))
    assert d["rig"] == "A" and tt.size == xs.size == Fs.size == d["t"].size < t.size
    # a whole number of samples is an exact shift of the force
    np.testing.assert_array_equal(delayed_recording((t, x, F), 3e-3)[2], F[3:])


def test_delay_on_a_normal_recording_is_refused():
    t = np.linspace(0.0, 8 * np.pi, 2000)
    rec = {"t": t, "p": 1e6 + 0.4e6 * np.sin(t), "delta": 1e-7 * np.sin(t - 0.1)}
    with pytest.raises(InputError, match="delay= is for tangential recordings"):
        contactlab.diagnose(rec, model="normal", delay=1e-3)
