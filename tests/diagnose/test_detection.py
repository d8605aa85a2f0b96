"""Both channels' noise estimated separately, and the effective variance (issue 29 item 1)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from contactlab.diagnose._family import Prepared
from contactlab.diagnose.candidates_tangential import TangentialFamily
from contactlab.diagnose.detection import ChannelNoise, channel_noise, effective_variance
from contactlab.synthetic.diagnosis import hidden_effect_recording


@pytest.mark.parametrize("xn", [0.005, 0.02])
def test_channel_noise_recovers_both_channels(xn: float) -> None:
    rec = hidden_effect_recording([], seed=11, input_noise=xn, noise=0.01)
    t, x, F = rec.arrays()
    d = Prepared.build(t, x, F)
    fam = TangentialFamily()
    fam.prepare(d)
    p = {"h0": 50.0, "ac": 5e4}  # the truth: its residual is the noise
    r = fam.predict(p, (), d) - d.y
    cn = channel_noise(d, r, slope=fam.slope(p, d), input_unit="m", output_unit="N")
    assert cn.input == pytest.approx(rec.truth["noise_rms"]["x"], rel=0.1)
    assert cn.output == pytest.approx(rec.truth["noise_rms"]["F"], rel=0.1)
    assert 0 < cn.input_seen < cn.input
    js = cn.to_dict()
    assert set(js) == {"input", "output", "input_seen", "output_declared", "units"}
    assert js["units"] == {"input": "m", "output": "N", "input_seen": "m"}


def test_declared_output_noise_is_kept() -> None:
    rec = hidden_effect_recording([], seed=2)
    d = Prepared.build(*rec.arrays())
    cn = channel_noise(d, np.zeros(d.y.size) + np.arange(d.y.size) % 3, declared_output=0.25)
    assert cn.output == 0.25 and cn.output_declared


@settings(max_examples=50, deadline=None)
@given(
    sy=st.floats(1e-6, 1e3),
    su=st.floats(0.0, 1e-2),
    s=st.lists(st.floats(0.0, 1e6), min_size=1, max_size=20),
)
def test_effective_variance_is_the_sum_of_both_channels(sy: float, su: float, s: list) -> None:
    cn = ChannelNoise(input=su, output=sy, input_seen=0.5 * su)
    k = np.asarray(s)
    v = effective_variance(k, cn)
    # plain-Python reference, term by term
    ref = [sy * sy + (ki * su) ** 2 for ki in s]
    assert np.allclose(v, ref, rtol=1e-12)
    per_sample = effective_variance(k, cn, smooth=False)
    assert np.all(per_sample <= v + 1e-300) and np.all(per_sample >= sy * sy)
    assert effective_variance(None, cn) == sy * sy
