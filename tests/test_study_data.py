"""The bundled example data: reproducible from the documented seeded script, readable, tagged,
and made with the documented parameters."""

from __future__ import annotations

import numpy as np
import pytest

from contactlab.data import data_dir, manifest_path
from contactlab.data.generate import MATERIALS, generate, truth
from contactlab.io import read_recording
from contactlab.manifest import read_manifest


@pytest.fixture(scope="module")
def regenerated(tmp_path_factory):
    out = tmp_path_factory.mktemp("regen")
    generate(out, normal=False)
    return out


def test_bundled_tangential_files_equal_a_fresh_run_of_the_script(regenerated):
    shipped = sorted((data_dir() / "tangential").iterdir())
    fresh = sorted((regenerated / "tangential").iterdir())
    assert [p.name for p in shipped] == [p.name for p in fresh]
    assert len(shipped) == sum(len(m.loads) * len(m.amplitudes) for m in MATERIALS)
    for a, b in zip(shipped, fresh, strict=True):
        if a.suffix == ".csv":
            assert a.read_bytes() == b.read_bytes(), a.name
        ra, rb = read_recording(a, kind="tangential"), read_recording(b, kind="tangential")
        np.testing.assert_array_equal(ra.t, rb.t)
        np.testing.assert_array_equal(ra["x"], rb["x"])
        np.testing.assert_array_equal(ra["F"], rb["F"])


def test_bundle_is_small_and_mixed_format():
    files = [p for p in data_dir().rglob("*") if p.is_file() and p.suffix != ".py"]
    assert sum(p.stat().st_size for p in files) < 3e6
    assert {p.suffix for p in files} >= {".csv", ".tdms", ".h5", ".mat"}


def test_manifest_tags_and_truth():
    entries = read_manifest(manifest_path())
    tang = [e for e in entries if e.kind == "tangential"]
    assert {e.material for e in tang} == {"Al/Al", "PVC/steel", "steel/steel"}
    for e in tang:
        pair = next(m for m in MATERIALS if m.material == e.material)
        h0, ac = truth(pair, e.tags["normal_load"])
        assert e.tags["true_h0"] == pytest.approx(h0, rel=1e-5)
        assert e.tags["true_ac"] == pytest.approx(ac, rel=1e-5)
        assert e.units["true_h0"] == "N" and e.units["amplitude_nominal"] == "m"
        assert e.path.is_file()
    # realistic: h0 grows with load, the initial stiffness h0·ac like W^(2/3) (Mindlin)
    pair = MATERIALS[0]
    k = [np.prod(truth(pair, w)) for w in pair.loads]
    np.testing.assert_allclose(np.diff(np.log(k)) / np.diff(np.log(pair.loads)), 2 / 3)
    # steel: only a tiny part of the loop is reached (ac·A < 0.1)
    steel = next(m for m in MATERIALS if m.material == "steel/steel")
    assert max(truth(steel, w)[1] * a for w in steel.loads for a in steel.amplitudes) < 0.1


def test_recordings_carry_sensor_imperfections():
    e = read_manifest(manifest_path())[0]
    rec = read_recording(e.path, kind="tangential")
    F = rec["F"]
    lsb = np.diff(np.unique(np.round(F, 9)))
    assert lsb.min() == pytest.approx(2 * 200.0 / 2**16, rel=1e-3)  # 16-bit ADC steps
    assert abs(np.mean(rec["x"])) > 1e-8  # a zero offset, not a perfectly centred signal
