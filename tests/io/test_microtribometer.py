"""The micro-tribometer record of ../shared/data analysed as published (tab-separated,
``Time [s] Normal [uN] Position [mm] Friction [uN]``, 5 ms steps with some 10 ms ones): no
conversion by hand, and μ within 5 % of its sliding plateau F/N (issue 31)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from contactlab.cli import main
from contactlab.io import read_recording
from contactlab.io.recording import RecordingError

FILE = (Path(__file__).resolve().parents[2].parent / "shared" / "data" / "microtribometer"
        / "test_data_2.txt")  # fmt: skip


@pytest.fixture(scope="module")
def published():
    if not FILE.exists():
        pytest.skip("../shared/data absent")
    return FILE


def _plateau_mu(path: Path) -> float:
    """The reference, from the raw columns by plain numpy (not the package's reader nor its
    stroke logic): |F|/N over the samples where the stage slides at speed (over half its
    largest) in the outer 40 % of its stroke, loaded (N above half its largest)."""
    t, normal, pos, fric = np.loadtxt(path, skiprows=1, unpack=True)
    v = np.gradient(pos, t)
    loaded = normal > 0.5 * normal.max()
    lo, hi = np.percentile(pos[loaded], [1, 99])
    fast = np.abs(v) > 0.5 * np.abs(v[loaded]).max()
    up = loaded & fast & (v > 0) & (pos > lo + 0.6 * (hi - lo))
    down = loaded & fast & (v < 0) & (pos < hi - 0.6 * (hi - lo))
    mu = np.r_[np.abs(fric[up]) / normal[up], np.abs(fric[down]) / normal[down]]
    assert up.sum() > 500 and down.sum() > 500
    return float(np.mean(mu))


def test_read_as_published(published):
    with pytest.raises(RecordingError, match="--resample"):
        read_recording(published)  # 9-10 ms steps among 5 ms ones: refused, with the way out
    rec = read_recording(published, resample=True)
    assert rec.meta["columns"] == {"x": "Position [mm]", "F": "Friction [uN]",
                                   "t": "Time [s]", "N": "Normal [uN]"}  # fmt: skip
    info = rec.meta["resampled"]
    assert info["n_read"] == 42579
    assert 0.009 <= info["largest_step"] <= 0.0101
    loaded = rec["N"] > 2.5
    assert np.median(rec["N"][loaded]) == pytest.approx(5.0, rel=1e-3)  # 5.000 N, in N
    stroke = np.subtract(*np.percentile(rec["x"][loaded], [99, 1]))
    assert stroke == pytest.approx(228e-6, rel=0.05)  # a 228 um stroke, in m


def test_mu_within_5_percent_of_the_sliding_plateau(published, tmp_path, capsys):
    ref = _plateau_mu(published)
    out = tmp_path / "tribo.json"
    assert main(["analyze", str(published), "--resample", "--json", str(out)]) == 0
    said = capsys.readouterr()
    assert "model tangential, inferred from the columns" in " ".join(said.out.split())
    assert "largest gap bridged" in " ".join(said.err.split())
    doc = json.loads(out.read_text())
    assert doc["normal_load"] == pytest.approx(5.0, rel=1e-3)
    assert doc["mu"] == pytest.approx(ref, rel=0.05), (doc["mu"], ref)
    assert doc["mu_strokes"] >= 90  # 50 cycles: ~100 strokes, all sliding
