"""Errors in variables with coloured input noise (issue 29, item 3).

An LVDT's demodulator and an anti-alias filter low-pass a displacement sensor's noise: the
white-noise estimate from neighbouring samples then sees a fraction of it, and the misfit
flag's null (:func:`contactlab.diagnose.eiv.eiv_bias`, the tolerance) was too narrow
(clean records flagged near gross sliding). :func:`contactlab.diagnose.eiv.input_noise_spectrum`
reads the noise from the input's spectrum above the drive.
"""

from __future__ import annotations

import numpy as np

from contactlab.diagnose._family import Prepared
from contactlab.diagnose._prepare import subsample_long
from contactlab.diagnose.candidates_tangential import TangentialFamily
from contactlab.diagnose.eiv import _coloured, _kept_driven, input_noise_spectrum
from contactlab.masing import Masing


def _lowpassed(rng: np.random.Generator, n: int, taps: int) -> np.ndarray:
    """Unit-RMS noise low-passed by a Hann window of ``taps`` samples (correlated over it)."""
    h = np.hanning(taps + 2)[1:-1]
    v = np.convolve(rng.standard_normal(n + taps), h / np.sqrt(np.sum(h * h)), "valid")[:n]
    return v / np.std(v)


def _record(noise: np.ndarray, fs: float = 5000.0, f0: float = 5.0):
    t = np.arange(noise.size) / fs
    x = 1e-5 * np.sin(2 * np.pi * f0 * t) * np.minimum(t * f0, 1.0)
    return t, x + 2e-7 * noise  # 1 % of the range


def test_spectrum_reads_low_passed_noise():
    """Noise correlated over 15 samples (a corner near 5 % of fs): the white estimate sees
    under half of its RMS, the spectrum within 15 %; white noise reads the same both ways."""
    rng = np.random.default_rng(3)
    t, x = _record(_lowpassed(rng, 30000, 15))
    d = Prepared.build(t, x, np.zeros(t.size))
    spec = input_noise_spectrum(d)
    assert spec is not None
    assert d.extra["u_noise"] < 0.5 * 2e-7
    assert abs(spec.rms / 2e-7 - 1.0) < 0.15, spec.rms
    # the candidates' filter (about 40 samples here) leaves most of such noise in
    assert spec.seen > 0.4 * spec.rms
    t, x = _record(rng.standard_normal(30000))
    w = Prepared.build(t, x, np.zeros(t.size))
    sw = input_noise_spectrum(w)
    assert sw is not None and abs(sw.rms / 2e-7 - 1.0) < 0.1, sw.rms
    assert abs(sw.rms / w.extra["u_noise"] - 1.0) < 0.15
    assert sw.seen < 0.3 * sw.rms


def test_coloured_draws_follow_the_spectrum():
    """Draws from the estimated spectrum: unit variance, and the lag-5 correlation of the
    noise they copy (not the white noise's 0)."""
    rng = np.random.default_rng(4)
    noise = _lowpassed(rng, 30000, 15)
    t, x = _record(noise)
    d = Prepared.build(t, x, np.zeros(t.size))
    spec = input_noise_spectrum(d)
    v = _coloured(np.random.default_rng(0), 30000, spec)
    assert abs(np.std(v) - 1.0) < 0.1

    def lag(a: np.ndarray, k: int) -> float:
        return float(np.corrcoef(a[:-k], a[k:])[0, 1])

    assert abs(lag(v, 5) - lag(noise, 5)) < 0.1, (lag(v, 5), lag(noise, 5))
    assert abs(lag(_coloured(np.random.default_rng(0), 30000, None), 5)) < 0.05


def test_kept_record_driven_by_no_noise_is_unchanged():
    """A kept record (every q-th sample with the turning points between them) driven by
    zero added noise predicts exactly what it did; with noise, something else."""
    rng = np.random.default_rng(5)
    t, x = _record(rng.standard_normal(60000) * 0.5)
    y = Masing(50.0, 3e5).force(x)
    d, _ = subsample_long(t, x, y)
    assert "knots" in d.extra and "u_measured" in d.extra
    fam = TangentialFamily()
    fam.prepare(d)
    p = fam.initial_base(d)
    p.update(h0=50.0, ac=3e5)
    base = np.asarray(fam.predict(p, (), d), float)
    raw = d.extra["raw_input"]
    same = _kept_driven(d, np.zeros(raw.u.size))
    assert same is not None
    np.testing.assert_allclose(fam.predict(p, (), same), base, rtol=0, atol=1e-9)
    other = _kept_driven(d, 1e-7 * rng.standard_normal(raw.u.size))
    assert other is None or not np.allclose(fam.predict(p, (), other), base)


def test_effect_floor_keeps_a_tiny_phase_locked_difference_unflagged():
    """200 cycles of a sine: a phase-locked difference of 0.03 of the noise RMS has a t of
    about 2-3 per bin (flagged without the floor), but stays within the effect-size floor
    (0.05); 0.5 of the noise is flagged; the stated power includes the floor."""
    from contactlab.diagnose import misfit

    t = np.arange(200 * 400) / 400.0
    d = Prepared.build(t, np.sin(2 * np.pi * t), np.zeros(t.size), errors_in_input=False)
    e = np.random.default_rng(6).normal(0.0, 0.01, t.size)
    shape = np.sqrt(2.0) * np.cos(2 * np.pi * t)
    small = misfit.unexplained_structure(d, e + 0.0003 * shape, 0.01)
    big = misfit.unexplained_structure(d, e + 0.005 * shape, 0.01)
    assert small is not None and big is not None
    assert not small.flagged and big.flagged
    assert small.detectable_rms is not None and small.detectable_rms > misfit.EFFECT_FLOOR * 0.01
    old = misfit.EFFECT_FLOOR
    try:
        misfit.EFFECT_FLOOR = 0.0
        assert misfit.unexplained_structure(d, e + 0.0003 * shape, 0.01).flagged
    finally:
        misfit.EFFECT_FLOOR = old


def test_reweighted_leaves_out_steep_samples_under_coloured_noise():
    """The weights recomputed for a larger seen input noise fall where the slope is steep
    and stay where it is flat; with no larger noise, ``d`` itself comes back."""
    from contactlab.diagnose.eiv import reweighted

    t = np.arange(2000) / 400.0
    d = Prepared.build(t, np.sin(2 * np.pi * t), np.zeros(t.size), errors_in_input=False)
    d.extra["weight"] = np.ones(t.size)
    slope = np.where(np.arange(t.size) % 2 == 0, 100.0, 0.0)
    out = reweighted(d, slope, 0.01, 1e-5, 1e-3)
    w = out.extra["weight"]
    assert np.all(w[1::2] == 1.0) and np.all(w[::2] < 0.5)
    assert np.all(d.extra["weight"] == 1.0)  # the original untouched
    assert reweighted(d, slope, 0.01, 1e-3, 1e-3) is d
