"""A sensor glitch (one sample orders of magnitude outside the rest of its channel) is refused
by diagnose, naming channel, sample, time, value and the way on; found by audit: a normal
recording whose displacement read -2.17 m at one sample (~0.1 µm elsewhere) was fitted."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import contactlab
from contactlab.cli import main
from contactlab.diagnose._inputs import GlitchError, check_glitches
from contactlab.io import Recording, write_recording


def _normal(n_glitch: int = 1) -> Recording:
    t, p, delta = contactlab.normal.synthetic_recording(0.5e6, 0.4e6, 1.0, 5, 400, seed=1)
    delta = delta.copy()
    for k in range(n_glitch):
        delta[1234 + 7 * k] = -2.17
    return Recording(t, {"p": p, "delta": delta}, {"p": "Pa", "delta": "m"}, "glitch")


def test_normal_glitch_refused_by_diagnose() -> None:
    rec = _normal()
    with pytest.raises(GlitchError) as e:
        contactlab.diagnose(rec, model="normal")
    msg = str(e.value)
    assert "channel 'delta' reads -2.17 m at sample 1234" in msg
    assert f"(t = {rec.t[1234]:.9g} s)" in msg
    assert "sensor glitch" in msg and "remove or replace" in msg
    assert isinstance(e.value, contactlab.InputError)
    assert (e.value.channel, e.value.sample, e.value.value) == ("delta", 1234, -2.17)


def test_glitch_cli_one_line(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "n_glitch.csv"
    write_recording(path, _normal(n_glitch=2))
    out = tmp_path / "d.json"
    assert main(["diagnose", "--model", "normal", str(path), "--json", str(out)]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "Traceback" not in err[0]
    assert err[0].startswith(f"contactlab diagnose: error: {path}: channel 'delta'")
    assert "(and 1 more such sample(s))" in err[0]
    assert not out.exists()


def test_tangential_glitch_refused_too() -> None:
    from contactlab.tangential import synthetic_recording

    rec = synthetic_recording(40.0, 4e4, 20e-6, n_cycles=5, seed=0)
    F = rec["F"].copy()
    F[321] = 4e6  # N, against a ±40 N loop
    bad = Recording(rec.t, {"x": rec["x"], "F": F}, dict(rec.units), "glitch")
    with pytest.raises(GlitchError, match=r"channel 'F' reads 4e\+06 N at sample 321"):
        contactlab.diagnose(bad, model="tangential")


def test_not_glitches() -> None:
    """A record at rest before it loads (many samples far from a small median spread), an
    amplitude step and a quantised channel (MAD 0) are signals, not glitches."""
    t = np.arange(20000) * 1e-3
    rest = np.where(t < 12, 1e-9 * np.sin(t * 50), 1e-4 * np.sin(2 * np.pi * t))
    step = np.where(t < 15, 1e-6, 1e-4) * np.sin(2 * np.pi * t)
    quant = np.round(np.sin(2 * np.pi * t) * 0.3)
    for v in (rest, step, quant):
        check_glitches(t, {"x": (v, "m")})
