"""Typed options per contact kind (issue 32): ``contactlab.tangential.Options`` and
``contactlab.normal.Options`` are taken the same way as the keywords (and dicts) they stand
for, by the analyses, ``diagnose``, ``track`` and the studies."""

from __future__ import annotations

import numpy as np
import pytest

import contactlab
from contactlab import InputError
from contactlab.normal import Options as NormalOptions
from contactlab.normal import analyze_loop
from contactlab.synthetic.normal import synthetic_recording as normal_recording
from contactlab.synthetic.tangential import synthetic_recording
from contactlab.tangential import Options, analyze_tangential


@pytest.fixture(scope="module")
def rec():
    return synthetic_recording(h0=40.0, ac=4e4, amplitude=20e-6, n_cycles=8, fs=2000.0,
                               noise=0.01, seed=3)  # fmt: skip


def test_options_equal_the_keywords_they_stand_for(rec):
    a = analyze_tangential(rec, options=Options(delay=1e-3, force_sign=1), warn=False)
    b = analyze_tangential(rec, delay=1e-3, force_sign=1, warn=False)
    assert a.to_dict() == b.to_dict()
    t, p, d = normal_recording(p0=0.5e6, pa=0.4e6, omega=1.0, n_cycles=4, seed=2)
    la = analyze_loop(t, p, d, options=NormalOptions(p0=0.5e6, pa=0.4e6))
    lb = analyze_loop(t, p, d, p0=0.5e6, pa=0.4e6)
    assert la.to_dict() == lb.to_dict()


def test_track_and_studies_take_options_as_dicts(rec):
    a = contactlab.track(rec, "3cycles", options=Options(force_sign=1, delay=0.5e-3))
    b = contactlab.track(rec, "3cycles", options={"force_sign": 1, "delay": 0.5e-3})
    assert a.rows == b.rows


def test_a_field_the_function_does_not_take_is_named(rec):
    with pytest.raises(InputError, match="analyze_tangential\\(\\) takes no option output_filter"):
        analyze_tangential(rec, options=Options(output_filter=np.ones(3) / 3))
    with pytest.raises(InputError, match="delay given both as options and as a keyword"):
        analyze_tangential(rec, options=Options(delay=1e-3), delay=2e-3)
    with pytest.raises(InputError, match="options must be"):
        analyze_tangential(rec, options=42)
