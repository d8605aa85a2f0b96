"""Detection calibrated to coloured noise on both channels (issue 29, item 1), hum left next to
a drive harmonic, and the channel delay's plausible range: the pieces checked against
independent routes (the noise's known RMS, a line put in by hand)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import signal

from contactlab.diagnose._family import Prepared
from contactlab.diagnose._mains import kept_hum
from contactlab.diagnose._prepare import input_seen
from contactlab.diagnose.candidates_tangential import TangentialFamily
from contactlab.diagnose.detection import output_noise_rms
from contactlab.diagnose.effects import registry
from contactlab.diagnose.effects.tangential.normal_load import hum_sideband
from contactlab.masing import Masing


def _prepared(f=5.0, fs=2000.0, cycles=12, xn=0.0, colour=None, seed=0, hum=0.0, f_hum=50.0):
    rng = np.random.default_rng(seed)
    t = np.arange(int(cycles * fs / f)) / fs
    A = 1e-5
    x = A * np.sin(2 * np.pi * f * t)
    F = Masing(40.0, 2e5).force(x)
    n = rng.standard_normal(t.size)
    if colour is not None:  # an LVDT demodulator's low-pass (2nd order) on the noise
        n = signal.sosfiltfilt(signal.butter(2, colour, fs=fs, output="sos"), n)
    n *= xn * A / np.std(n)
    xm = x + n + hum * A * np.sin(2 * np.pi * f_hum * t + 0.3)
    Fm = F + rng.normal(0.0, 0.2, t.size) + hum * 40.0 * np.sin(2 * np.pi * f_hum * t + 1.9)
    return t, x, F, xm, Fm


def _d(t, xm, Fm):
    d = Prepared.build(t, xm, Fm)
    TangentialFamily().prepare(d)
    return d


def test_white_input_noise_is_seen_as_the_white_estimate_says():
    t, _, _, xm, Fm = _prepared(xn=0.02)
    d = _d(t, xm, Fm)
    from contactlab.diagnose._filters import savgol_coeffs

    wlen = int(d.extra["u_filter"])
    white = d.extra["u_noise"] * np.sqrt(np.sum(savgol_coeffs(wlen, 3) ** 2))
    assert input_seen(d) == pytest.approx(white)


def test_low_passed_input_noise_is_seen_from_its_spectrum():
    # behind a demodulator at 5 % of fs, neighbouring samples hardly differ: the white
    # estimate reads a fraction of the noise, which the candidates' filter then passes whole
    t, x, _, xm, Fm = _prepared(xn=0.02, colour=100.0)
    d = _d(t, xm, Fm)
    from contactlab.diagnose._filters import savgol_filter

    wlen = int(d.extra["u_filter"])
    true_seen = float(np.std(savgol_filter(xm - x, wlen, 3, mode="interp")))
    white = float(d.extra["u_noise"])
    assert white < 0.5 * true_seen
    assert input_seen(d) == pytest.approx(true_seen, rel=0.35)


def test_output_noise_behind_an_anti_alias_filter_is_read_from_the_spectrum():
    rng = np.random.default_rng(3)
    t, _, F, xm, _ = _prepared()
    d = _d(t, xm, F)
    # a periodic misfit on the drive's harmonics (the model's) is no noise
    misfit = 0.5 * np.sin(2 * np.pi * 15.0 * t) + 0.3 * np.sin(2 * np.pi * 25.0 * t)
    white = rng.normal(0.0, 0.3, t.size)
    assert output_noise_rms(d, white + misfit, None, 0.3) is None  # white: not replaced
    sos = signal.bessel(4, 0.1 * 2000.0, fs=2000.0, norm="phase", output="sos")
    col = signal.sosfilt(sos, rng.standard_normal(t.size))
    col *= 0.3 / np.std(col)
    from contactlab.diagnose._signal import noise_rms

    est_white = noise_rms(col + misfit)
    assert est_white < 0.5 * 0.3  # what third differences see of it
    got = output_noise_rms(d, col + misfit, None, est_white)
    assert got is not None and got == pytest.approx(0.3, rel=0.2)


def test_hum_next_to_a_drive_harmonic_on_both_channels_is_found():
    # 50 Hz, 1.5 bins (of 1/0.75 s) above the 3rd harmonic of a 16 Hz drive over 12 cycles
    f = 50.0 / (3.0 + 1.5 / 12.0)
    t, _, _, xm, Fm = _prepared(f=f, fs=2000.0, xn=0.005, hum=0.01)
    lines, note = kept_hum(t, xm, Fm)
    assert len(lines) == 1 and abs(lines[0]["f"] - 50.0) <= 0.31 and lines[0]["harmonic"] == 3
    assert lines[0]["F"] == pytest.approx(0.4, rel=0.25)
    assert "left in place" in note and "unexplained" in note
    # on the force alone (a line the joint could make), or with no hum, nothing
    t, _, F, xm0, _ = _prepared(f=f, fs=2000.0, xn=0.005)
    assert kept_hum(t, xm0, F)[0] == []
    Fh = F + 0.4 * np.sin(2 * np.pi * 50.0 * t)
    assert kept_hum(t, xm0, Fh)[0] == []


def test_a_load_fluctuation_whose_sideband_is_the_hum_is_refused():
    f = 50.0 / (3.0 + 1.5 / 12.0)
    t, _, _, xm, Fm = _prepared(f=f, fs=2000.0, xn=0.005, hum=0.01)
    d = _d(t, xm, Fm)
    lines, _ = kept_hum(t, xm, Fm)
    d.extra["hum_kept"] = lines
    f_exc = 1.0 / (d.cycles.period_samples * d.dt)
    eff = registry("tangential")["normal_load"]
    p = {"eps_c": 0.01, "eps_s": 0.0, "f_n": lines[0]["f"] - f_exc, "h0": 40.0}
    assert hum_sideband(d, p["f_n"]) is not None
    ok, why = eff.plausible(d, p)
    assert not ok and "mains line" in why and "unexplained" in why
    # a fluctuation elsewhere is judged as before
    assert hum_sideband(d, 1.37 * f_exc) is None
    d.extra.pop("hum_kept")
    assert hum_sideband(d, p["f_n"]) is None


def test_a_skew_of_a_millisecond_or_two_is_plausible_at_any_drive_frequency():
    eff = registry("tangential")["channel_delay"]
    t, _, F, xm, _ = _prepared(f=20.0, fs=5000.0, cycles=8)
    d = _d(t, xm, F)
    period = 1.0 / 20.0
    assert eff.plausible(d, {"tau": 1.5e-3, "h0": 40.0}).ok  # 3 % of the period
    ok, why = eff.plausible(d, {"tau": 2.5e-3, "h0": 40.0})  # 5 %, above 2 ms
    assert not ok and "5.0 % of the excitation period" in why and "2 ms" in why
    assert 2.5e-3 > 0.02 * period
