"""``track`` of a normal recording: only the first window drops a start-up cycle; the others
start mid-record at an upward crossing of the pressure and keep every whole cycle."""

from __future__ import annotations

import contactlab
from contactlab.io import Recording
from contactlab.synthetic.normal import synthetic_recording as normal_recording


def test_later_windows_keep_their_first_cycle(tmp_path):
    t, p, delta = normal_recording(0.5e6, 0.4e6, 1.0, 24, 400, seed=5)
    rec = Recording(t, {"p": p, "delta": delta}, {"p": "Pa", "delta": "m"}, "n")
    res = contactlab.track(rec, every="6cycles")
    assert len(res.rows) >= 3
    _first, *later = res.rows
    full = [r for r in later if r["n_samples"] >= 6 * 400 - 1]  # not the record's remainder
    assert len(full) >= 2
    for r in full:
        assert r.get("error") is None
        assert r["n_cycles"] >= 5, r  # of 6: all whole cycles, none dropped as start-up
    # an explicit choice is kept
    res2 = contactlab.track(rec, every="6cycles", options={"discard_cycles": 2})
    for a, b in zip(res.rows[1:], res2.rows[1:], strict=True):
        assert b["n_cycles"] == a["n_cycles"] - 2
