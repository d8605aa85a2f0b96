"""A sensor glitch (one sample orders of magnitude outside the rest of its channel) is refused
by diagnose, naming channel, sample, time, value and the way on; found by audit: a normal
recording whose displacement read -2.17 m at one sample (~0.1 µm elsewhere) was fitted."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import contactlab
from contactlab.cli import main
from contactlab.io import Recording, write_recording
from contactlab.io.checks import GlitchError, check_glitches
from contactlab.synthetic.normal import synthetic_recording as normal_recording


def _normal(n_glitch: int = 1) -> Recording:
    t, p, delta = normal_recording(0.5e6, 0.4e6, 1.0, 5, 400, seed=1)
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
    from contactlab.synthetic.tangential import synthetic_recording

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


def test_analyze_refuses_a_glitch_from_the_cli(tmp_path: Path, capsys) -> None:
    """``analyze`` of the audit's file (a normal record whose displacement reads -2.17 m at one
    sample) said "the centre curve does not store positive strain energy ..."; it now names
    the glitch, as diagnose does, and writes nothing."""
    path = tmp_path / "n_glitch.csv"
    write_recording(path, _normal())
    out = tmp_path / "a.json"
    assert main(["analyze", "--model", "normal", str(path), "--json", str(out)]) != 0
    err = capsys.readouterr().err
    assert "channel 'delta' reads -2.17 m at sample 1234" in err and "Traceback" not in err
    assert not out.exists()


@pytest.mark.parametrize("kind", ["normal", "tangential"])
def test_track_names_the_glitch_in_its_window(tmp_path: Path, kind: str) -> None:
    """``track``: the window holding the glitch fails with the glitch named, its sample
    counted in the file; the other windows are analysed."""
    if kind == "normal":
        t, p, delta = normal_recording(0.5e6, 0.4e6, 1.0, 12, 400, seed=3)
        delta = delta.copy()
        i = 2600
        delta[i] = -2.17
        rec = Recording(t, {"p": p, "delta": delta}, {"p": "Pa", "delta": "m"}, "g")
        every, what = "4cycles", "channel 'delta' reads -2.17 m"
    else:
        from contactlab.synthetic.tangential import synthetic_recording

        base = synthetic_recording(40.0, 4e4, 20e-6, n_cycles=12, fs=2000.0, seed=4)
        F = base["F"].copy()
        i = 2600
        F[i] = 4e6
        rec = Recording(base.t, {"x": base["x"], "F": F}, dict(base.units), "g")
        every, what = "4cycles", "channel 'F' reads 4e+06 N"
    path = tmp_path / f"{kind}.csv"
    write_recording(path, rec)
    res = contactlab.track(path, every=every)
    bad = [r for r in res.rows if r.get("error")]
    assert len(bad) == 1, [r.get("error") for r in res.rows]
    assert what in bad[0]["error"] and f"at sample {i} " in bad[0]["error"]
    assert bad[0]["t_start"] <= rec.t[i] <= bad[0]["t_end"]
    assert len(res.rows) - len(bad) >= 1
    assert all(np.isfinite(r["energy_per_cycle" if kind == "tangential" else "E_d"])
               for r in res.rows if not r.get("error"))  # fmt: skip


def test_glitch_suspect_is_a_safe_prefilter() -> None:
    """The cheap pre-check never misses what the full check finds (random records with 0-3
    glitches of random size and place)."""
    from contactlab.io.checks import GLITCH_SCALE, glitch_suspect

    rng = np.random.default_rng(11)
    for _ in range(300):
        n = int(rng.integers(8, 5000))
        v = np.sin(np.linspace(0, 20, n)) + 0.01 * rng.standard_normal(n)
        for _k in range(int(rng.integers(0, 4))):
            v[rng.integers(0, n)] = rng.choice([-1, 1]) * 10 ** rng.uniform(0, 5)
        med = np.median(v)
        scale = 1.4826 * np.median(np.abs(v - med))
        full = bool(np.any(np.abs(v - med) > GLITCH_SCALE * scale))
        if full:
            assert glitch_suspect(v)
