"""What a pooled track result says about its windows, and records with no loop at all:
window warnings grouped and shown (console, report, JSON), windows that disagree beyond their
errors flagged, a track whose every window failed refused, and a noise-only record analysed
in bounded time without an overflow."""

from __future__ import annotations

import json

import numpy as np
import pytest

from contactlab import Masing, Recording
from contactlab.cli import main
from contactlab.io import write_recording
from contactlab.studies.tracking import track
from contactlab.tangential import regime
from contactlab.tangential.model import steady_loop_force


def _step_recording(seed: int) -> Recording:
    """h0 40 N for 10 cycles then 50 N (ac 4e4 1/m, 20 µm, 1 kHz, 0.5 % noise on F)."""
    fs, f, n_cyc = 1000.0, 1.0, 20
    t = np.arange(int(n_cyc * fs / f)) / fs
    x = 20e-6 * np.sin(2 * np.pi * f * t)
    half = t.size // 2
    F = np.concatenate([Masing(40.0, 4e4).force(x[:half]), Masing(50.0, 4e4).force(x[half:])])
    rng = np.random.default_rng(seed)
    F = F + rng.normal(0, 0.005 * 40, F.size)
    return Recording(t, {"x": x, "F": F}, {"x": "m", "F": "N"}, "step")


def test_windows_that_disagree_are_noted(tmp_path, capsys):
    res = track(_step_recording(4711), every="4cycles")
    comb = res.combined()
    assert comb["h0_birge"] > 3
    notes = res.notes(comb)
    assert any("Birge ratio h0 " in n and "not constants" in n for n in notes)
    p = tmp_path / "step.h5"
    write_recording(p, _step_recording(4712))
    assert main(["track", str(p), "--every", "4cycles", "--json", str(tmp_path / "t.json"),
                 "--report", str(tmp_path / "rep")]) == 0  # fmt: skip
    err = capsys.readouterr().err
    assert "warning: the windows scatter beyond their standard errors" in err
    doc = json.loads((tmp_path / "t.json").read_text())
    assert any("Birge ratio" in n for n in doc["notes"])
    assert "not constants" in (tmp_path / "rep" / "report.html").read_text()


def test_window_warnings_grouped_once_per_kind():
    res = track(_step_recording(4713), every="4cycles")
    res.rows[0]["warnings"] = "amplitude ended at a bound (1.5e-05); its error is not reliable"
    res.rows[2]["warnings"] = "amplitude ended at a bound (1.7e-05); its error is not reliable"
    notes = [n for n in res.notes() if "ended at a bound" in n]
    assert notes == [f"2 of {len(res.rows)} windows warn (window 1: amplitude ended at a bound "
                     "(1.5e-05); its error is not reliable)"]  # fmt: skip


def test_every_window_failing_is_an_error_and_writes_nothing(tmp_path, capsys):
    t = np.arange(8000) / 1000.0
    rec = Recording(t, {"x": 1e-5 * np.sin(2 * np.pi * t), "F": np.full(t.size, 3.0)},
                    {"x": "m", "F": "N"}, "const")  # fmt: skip
    p = tmp_path / "const.csv"
    write_recording(p, rec)
    out = tmp_path / "t.json"
    assert main(["track", str(p), "--every", "3cycles", "--json", str(out),
                 "--report", str(tmp_path / "rep")]) == 1  # fmt: skip
    err = capsys.readouterr().err
    assert "none of the" in err and "F is constant" in err and "Traceback" not in err
    assert not out.exists() and not (tmp_path / "rep").exists()


def test_one_window_prints_no_nan_error(tmp_path, capsys):
    """ψ and k_tan have no error per window: with one window there is no scatter either."""
    p = tmp_path / "normal.csv"
    assert main(["simulate", "normal", str(p), "--cycles", "10"]) == 0
    capsys.readouterr()
    assert main(["track", str(p), "--every", "100cycles"]) == 0
    out = capsys.readouterr().out
    assert "± nan" not in out and "1 window," in out
    assert "psi = " in out and "one window: no error from their scatter" in out


def test_noise_only_record(tmp_path, capsys):
    """Pure noise on both channels (no loop): the fit stays finite (ac bounded; the
    curvature term cannot overflow) and the breakaway search stays within reach of each
    'stick' (it ran to the record's end: minutes for 1e4 samples)."""
    rng = np.random.default_rng(99)
    n = 6000
    t = np.arange(n) / 1000.0
    rec = Recording(t, {"x": rng.normal(0, 1e-6, n), "F": rng.normal(0, 1.0, n)},
                    {"x": "m", "F": "N"}, "noise")  # fmt: skip
    p = tmp_path / "noise.csv"
    write_recording(p, rec)
    code = main(["track", str(p), "--every", "10cycles", "--json", str(tmp_path / "n.json")])
    err = capsys.readouterr().err
    assert "Traceback" not in err and "OverflowError" not in err
    if code == 0:
        doc = json.loads((tmp_path / "n.json").read_text())
        assert doc["notes"]  # the windows' warnings (not identifiable, ...) are passed on
    else:
        assert code == 1 and "error:" in err


def test_breakaway_search_stops_at_reach():
    """A 'stick' with no sliding after it within reach: no break search, the peak."""
    n = 4000
    f = np.linspace(0.0, 1.0, n)
    x = np.zeros(n)
    v = np.zeros(n)
    calls = []
    orig = regime._break_time
    try:
        regime._break_time = lambda *a: calls.append(a) or orig(*a)
        got = regime._breakaway(f, x, v, (100, 200), 10, 1.0, 1e-9, reach=50)
    finally:
        regime._break_time = orig
    assert not calls
    assert got == pytest.approx(1.0 * 250 / (n - 1), rel=0.05)


def test_curvature_term_bounded_for_a_huge_ac():
    x = np.linspace(-1e-5, 1e-5, 8)
    xb = np.concatenate([x[::-1][:4], x[:4]])  # bins: a descending then ascending half
    with np.errstate(over="raise", invalid="raise", divide="raise"):
        F = steady_loop_force(Masing(1.0, 1e200), xb, 0.0, 1e-5, np.full(8, 1e-12))
    assert np.isfinite(F).all() and np.abs(F).max() <= 2.0 + 1e-12


def test_time_windows_widened_to_whole_cycles_are_noted():
    res = track(_step_recording(4715), every="100ms")
    assert any("hold at least 3 cycles" in n and "not 0.1 s" in n for n in res.notes())


def test_every_must_be_finite():
    from contactlab.errors import InputError
    from contactlab.studies.tracking import parse_every

    with pytest.raises(InputError, match="finite"):
        parse_every("1e400s")
