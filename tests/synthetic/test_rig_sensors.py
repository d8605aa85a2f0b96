"""The rig's optional sensor chain (LVDT low-pass on x, piezo high-pass force cell, Bessel
anti-alias filters, hum, jitter, drive harmonics) against closed forms."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import signal

from contactlab.errors import InputError
from contactlab.synthetic.rig import bessel, butterworth, group_delay, highpass, rig_recording

KW = {"fs": 4000.0, "f": 10.0, "cycles": 6, "x_noise": 0.0, "F_noise": 0.0, "bits": None}


def _phase_at(t, y, f):
    """Phase (rad) of ``y``'s component at ``f`` over the last 3 cycles."""
    keep = t >= t[-1] - 3.0 / f
    w = 2 * math.pi * f
    c = np.dot(y[keep], np.cos(w * t[keep]))
    s = np.dot(y[keep], np.sin(w * t[keep]))
    return math.atan2(c, s)


def test_lvdt_lowpass_lags_x_by_its_phase_at_the_drive():
    plain = rig_recording({}, seed=3, **KW)
    lp = 60.0
    lag = rig_recording({}, seed=3, x_lowpass=lp, **KW)
    _, h = signal.freqs(*butterworth(lp, 2), worN=[2 * math.pi * KW["f"]])
    d_phase = _phase_at(lag.t, lag.x, KW["f"]) - _phase_at(plain.t, plain.x, KW["f"])
    assert d_phase == pytest.approx(np.angle(h[0]), abs=2e-3)
    amp = np.ptp(lag.x[lag.t > 0.3]) / np.ptp(plain.x[plain.t > 0.3])
    assert amp == pytest.approx(abs(h[0]), rel=5e-3)
    # the force is untouched: the skew is the displacement's lag
    np.testing.assert_allclose(lag.F, plain.F, rtol=0, atol=1e-9 * np.ptp(plain.F))
    assert lag.truth["chain"]["channel_skew"] < plain.truth["chain"]["channel_skew"]


def test_piezo_highpass_leads_the_force_and_forgets_a_constant():
    fh = 0.5
    plain = rig_recording({"parallel_stiffness": {"k_p": 1e6}}, seed=4, **KW)
    hp = rig_recording({"parallel_stiffness": {"k_p": 1e6}}, seed=4, F_highpass=fh, **KW)
    # a first-order high-pass s/(s+ωh) leads a sine by atan(fh/f)
    d_phase = _phase_at(hp.t, hp.F, KW["f"]) - _phase_at(plain.t, plain.F, KW["f"])
    assert d_phase == pytest.approx(math.atan(fh / KW["f"]), abs=5e-3)
    b, a = highpass(fh)
    assert b[-1] == 0.0 and a[-1] == pytest.approx(2 * math.pi * fh)  # no DC gain


def test_bessel_has_the_flatter_group_delay():
    fc = 1000.0
    w = 2 * math.pi * np.array([10.0, 400.0])
    gd = {}
    for name, ba in (("bessel", bessel(fc)), ("butter", butterworth(fc))):
        _, h = signal.freqs(*ba, worN=w)
        gd[name] = -np.diff(np.unwrap(np.angle(h))) / np.diff(w)
        _, h3 = signal.freqs(*ba, worN=[2 * math.pi * fc])
        assert abs(h3[0]) == pytest.approx(1 / math.sqrt(2), rel=1e-3)  # -3 dB at fc
    low = group_delay(bessel(fc))
    assert low > 0
    # the Bessel's phase stays linear to 0.4 fc: its mean delay there is its DC delay
    assert gd["bessel"][0] == pytest.approx(low, rel=0.05)


def test_drive_harmonics_and_hum_show_at_their_frequencies():
    kw = {**KW, "cycles": 10}
    r = rig_recording({}, seed=5, drive_harmonics=(0.0, 0.02), hum=0.01, **kw)
    keep = r.t > 0.3
    x = r.x[keep] - r.x[keep].mean()
    spec = np.abs(np.fft.rfft(x * np.hanning(x.size)))
    fr = np.fft.rfftfreq(x.size, r.t[1] - r.t[0])
    at = {k: spec[np.argmin(np.abs(fr - k))] for k in (10.0, 20.0, 30.0, 50.0)}
    assert at[30.0] / at[10.0] == pytest.approx(0.02, rel=0.25)  # the actuator passes 3f
    assert at[20.0] < 0.2 * at[30.0]
    assert at[50.0] / at[10.0] == pytest.approx(0.01, rel=0.3)


def test_defaults_are_the_plain_chain_and_bad_sensor_figures_are_named():
    a = rig_recording({}, seed=6, **KW)
    b = rig_recording({}, seed=6, aa_kind="butterworth", hum=0.0, jitter=0.0, **KW)
    np.testing.assert_array_equal(a.F, b.F)
    with pytest.raises(InputError, match="x_lowpass"):
        rig_recording({}, x_lowpass=-1.0, **KW)
    with pytest.raises(InputError, match="aa_kind"):
        rig_recording({}, aa_kind="chebyshev", **KW)
    with pytest.raises(InputError, match="hum"):
        rig_recording({}, hum=-0.1, **KW)
