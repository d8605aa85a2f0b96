"""``track(cycles=False)`` and ``block_cycles(quantities=False)``: the crossings alone (what
an auto-streamed ``analyze --json`` cuts its windows at, issue 33 item 4) are the crossings
of the per-cycle pass, the windows and their rows are the same, and a stream cut so refuses
to give per-cycle quantities later."""

from __future__ import annotations

import itertools
import json

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import contactlab.studies.pooled as pooled
import contactlab.studies.tracking as tracking
from contactlab import InputError
from contactlab.cli import main
from contactlab.io import write_recording
from contactlab.studies.cycles import CycleState, block_cycles
from contactlab.synthetic.normal import synthetic_recording as normal_recording
from contactlab.synthetic.tangential import synthetic_recording


@settings(max_examples=40, deadline=None)
@given(
    seed=st.integers(0, 10_000),
    cuts=st.lists(st.integers(1, 2999), max_size=5),
    drive_is_x=st.booleans(),
    band=st.floats(-0.5, 1.5),
)
def test_crossings_alone_are_the_per_cycle_passes_crossings(seed, cuts, drive_is_x, band):
    rng = np.random.default_rng(seed)
    n = 3000
    ph = np.arange(n) * 2 * np.pi / rng.uniform(40, 400)
    x = np.sin(ph) + 0.2 * rng.standard_normal(n)
    F = np.cos(ph) + 0.1 * rng.standard_normal(n)
    d = x if drive_is_x else np.sin(ph - 0.3)
    t = np.arange(n) * 1e-3
    levels = (-0.3, -0.3 + band)  # band <= 0: no crossing can count
    full, alone, known = CycleState(), CycleState(), CycleState()
    got_full, got_alone, got_known = [], [], []
    edges = [0, *sorted(cuts), n]
    for a, b in itertools.pairwise(edges):
        dd = x[a:b] if drive_is_x else d[a:b]
        c1 = block_cycles(t[a:b], x[a:b], F[a:b], dd, a, full, levels)
        c2 = block_cycles(t[a:b], x[a:b], F[a:b], dd, a, alone, levels, quantities=False)
        # samples known finite (a checked reader's): the same crossings without the scans
        c3 = block_cycles(
            t[a:b], x[a:b], F[a:b], dd, a, known, levels, quantities=False, finite=True
        )
        got_full.append(c1.crossings)
        got_alone.append(c2.crossings)
        got_known.append(c3.crossings)
        assert c2.energy.size == c2.start.size == c2.amplitude.size == 0
    np.testing.assert_array_equal(np.concatenate(got_alone), np.concatenate(got_full))
    np.testing.assert_array_equal(np.concatenate(got_known), np.concatenate(got_full))


def test_a_stream_cut_by_its_crossings_gives_no_per_cycle_quantities_later():
    x = np.sin(np.arange(500) * 0.1)
    s = CycleState()
    block_cycles(np.arange(500.0), x, x, x, 0, s, (-0.3, 0.3), quantities=False)
    with pytest.raises(InputError, match="push_crossings"):
        block_cycles(np.arange(500.0), x, x, x, 500, s, (-0.3, 0.3))
    bad = x.copy()
    bad[7] = np.nan
    with pytest.raises(InputError, match=r"x\[7\]|x.*7"):
        block_cycles(np.arange(500.0), bad, x, bad, 0, CycleState(), (-0.3, 0.3), quantities=False)


@pytest.mark.parametrize("threads", [0, 1])
def test_track_without_the_cycle_table_has_the_same_windows(threads):
    rec = synthetic_recording(
        h0=28.0, ac=6e4, amplitude=11e-6, n_cycles=14, fs=1200.0, noise=0.01, seed=7331
    )
    a = tracking.track(rec, every="4cycles", keep_documents=True, threads=threads)
    b = tracking.track(rec, every="4cycles", keep_documents=True, threads=threads, cycles=False)
    assert len(a.rows) >= 2 and a.cycles["energy"].size >= 10
    assert a.rows == b.rows and a.window_docs == b.window_docs
    assert all(v.size == 0 for v in b.cycles.values())
    ca, cb = a.combined(), b.combined()
    assert "cycle_energy_mean" in ca and "cycle_energy_mean" not in cb
    assert {k: v for k, v in ca.items() if not k.startswith("cycle_") and k != "n_cycles"} == {
        k: v for k, v in cb.items() if k != "n_cycles"
    }


def test_a_normal_track_without_the_cycle_table_has_the_same_windows():
    from contactlab.io import Recording

    t, p, d = normal_recording(p0=0.5e6, pa=0.4e6, omega=1.0, n_cycles=14, seed=7332)
    rec = Recording(t, {"p": p, "delta": d}, {"p": "Pa", "delta": "m"})
    a = tracking.track(rec, every="5cycles", kind="normal", threads=0)
    b = tracking.track(rec, every="5cycles", kind="normal", threads=0, cycles=False)
    assert len(a.rows) >= 2 and a.rows == b.rows


def test_auto_streamed_analyze_json_is_the_same_with_or_without_a_report(tmp_path, monkeypatch):
    """``analyze --json`` of a long file skips the per-cycle table (the pooled document does
    not read it); with ``--report`` it is computed for the figures: the same JSON."""
    rec = synthetic_recording(
        h0=30.0, ac=5e4, amplitude=12e-6, n_cycles=16, fs=1000.0, noise=0.01, seed=7333
    )
    f = tmp_path / "long.h5"
    write_recording(f, rec)
    monkeypatch.setattr(pooled, "STREAM_ABOVE", 4000)  # the file holds 16 000 samples
    seen = []
    real = tracking.track

    def spy(*args, **kwargs):
        seen.append(kwargs.get("cycles", True))
        return real(*args, **kwargs)

    monkeypatch.setattr(tracking, "track", spy)
    j1, j2 = tmp_path / "a.json", tmp_path / "b.json"
    assert main(["analyze", str(f), "--model", "tangential", "--json", str(j1),
                 "--no-progress"]) == 0  # fmt: skip
    assert main(["analyze", str(f), "--model", "tangential", "--json", str(j2), "--report",
                 str(tmp_path / "rep"), "--no-progress"]) == 0  # fmt: skip
    assert seen == [False, True]
    a, b = json.loads(j1.read_text()), json.loads(j2.read_text())
    assert a["streamed"] is True and a == b
