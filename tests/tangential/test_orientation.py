"""Force sign from physics (issue 8): a passive joint dissipates, ∮F dx > 0."""

from __future__ import annotations

import json

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from contactlab import InputError, Masing
from contactlab.cli import main
from contactlab.io import Recording
from contactlab.tangential import analyze_tangential
from contactlab.tangential.orientation import orient, signed_area


def _coulomb(seed: int, fs: float = 250.0, n_cycles: int = 10, phase: float = 0.0):
    """A rectangular (gross-sliding) loop with a wavy plateau: F ≈ 0.8 N sign(ẋ), x ~ 1.6 mm.
    Its correlation with x is ≈ 0, the decision that failed on the measured frame."""
    rng = np.random.default_rng(seed)
    t = np.arange(int(n_cycles * fs)) / fs
    x = 1.6e-3 * np.sin(2 * np.pi * t + phase)
    v = np.cos(2 * np.pi * t + phase)
    F = 0.8 * np.tanh(v / 0.05) * (1 + 0.1 * np.sin(2 * np.pi * x / 1e-3))
    return t, x + rng.normal(0, 3e-6, t.size), F + rng.normal(0, 0.03, t.size)


def test_rectangular_loop_keeps_its_sign_and_a_flipped_one_is_inverted():
    t, x, F = _coulomb(101)
    xc = x - x.mean()
    assert abs(np.corrcoef(xc, F)[0, 1]) < 0.1  # the old test had nothing to go on
    o = orient(x, F, t)
    assert (o.sign, o.by) == (1, "loop area")
    # ∮F dx ≈ 4 μN A per cycle, 9 complete cycles between the first and last peak
    assert o.loop_area == pytest.approx(9 * 4 * 0.8 * 1.6e-3, rel=0.1)
    assert orient(x, -F, t).sign == -1


def test_thin_elastic_loop_falls_back_to_the_stiffness_sign():
    t = np.linspace(0, 6, 6001)
    x = 1e-6 * np.sin(2 * np.pi * t)
    F = Masing(40.0, 1e3).force(x) + np.random.default_rng(5).normal(0, 1e-5, t.size)
    o = orient(x, -F, t)
    assert o.sign == -1 and o.by in ("stiffness", "loop area")


def test_noise_only_is_kept_as_recorded_and_says_so():
    rng = np.random.default_rng(7)
    t = np.linspace(0, 6, 3001)
    x = np.sin(2 * np.pi * t)
    o = orient(x, rng.normal(size=t.size), t)
    assert o.sign == 1 and o.by == "default" and "kept as recorded" in o.reason


def test_user_sign_is_respected_and_an_impossible_area_is_named():
    t, x, F = _coulomb(3)
    o = orient(x, F, t, force_sign=-1)
    assert o.sign == -1 and o.by == "user" and "cannot produce" in o.reason
    with pytest.raises(InputError, match="force_sign"):
        orient(x, F, t, force_sign=2)


@settings(max_examples=15, deadline=None)
@given(seed=st.integers(0, 10_000), fs=st.sampled_from([100.0, 250.0, 1000.0]),
       phase=st.floats(0, 6.2))  # fmt: skip
def test_flipping_the_force_flips_the_decided_sign(seed, fs, phase):
    t, x, F = _coulomb(seed, fs=fs, n_cycles=4, phase=phase)
    a, b = orient(x, F, t), orient(x, -F, t)
    assert a.sign == 1 and b.sign == -1
    area, err = signed_area(x, F, t)
    assert area > 3 * err > 0


def test_analysis_reports_the_sign_and_the_reason():
    t, x, F = _coulomb(11)
    rec = Recording(t, {"x": x, "F": -F}, {"x": "m", "F": "N"})
    res = analyze_tangential(rec, warn=False)
    d = res.to_dict()
    assert d["force_sign"] == -1 and "passive joint dissipates" in d["orientation_reason"]
    assert d["loop_area_recorded"] < 0
    assert d["energy_per_cycle_numeric"] > 0


def test_cli_force_sign_flag(tmp_path, capsys):
    t, x, F = _coulomb(12)
    f = tmp_path / "loop.csv"
    rows = "\n".join(f"{a:.6f},{b:.9e},{c:.6e}" for a, b, c in zip(t, x, F, strict=True))
    f.write_text("t [s],x [m],F [N]\n" + rows + "\n")
    out = tmp_path / "a.json"
    assert main(["analyze", str(f), "--model", "tangential", "--json", str(out)]) == 0
    assert json.loads(out.read_text())["force_sign"] == 1
    assert main(["analyze", str(f), "--model", "tangential", "--force-sign", "-1",
                 "--json", str(out)]) == 0  # fmt: skip
    d = json.loads(out.read_text())
    assert d["force_sign"] == -1 and "given by the user" in d["orientation_reason"]
    capsys.readouterr()
