"""The bundled example data: reproducible from the documented seeded script, readable, tagged,
and made with the documented parameters."""

from __future__ import annotations

import numpy as np
import pytest

from contactlab.data import data_dir, manifest_path
from contactlab.io import read_recording
from contactlab.studies.manifest import read_manifest
from contactlab.studies.study import run_study
from contactlab.synthetic.bundled import MATERIALS, NORMAL_P0, generate, truth


@pytest.fixture(scope="module")
def regenerated(tmp_path_factory):
    out = tmp_path_factory.mktemp("regen")
    generate(out)
    return out


@pytest.mark.parametrize(("kind", "channels"), [("tangential", "xF"), ("normal", ("p", "delta"))])
def test_bundled_files_equal_a_fresh_run_of_the_script(regenerated, kind, channels):
    shipped = sorted((data_dir() / kind).iterdir())
    fresh = sorted((regenerated / kind).iterdir())
    assert [p.name for p in shipped] == [p.name for p in fresh]
    if kind == "tangential":
        assert len(shipped) == sum(len(m.loads) * len(m.amplitudes) for m in MATERIALS)
    else:
        assert len(shipped) == len(NORMAL_P0)
    for a, b in zip(shipped, fresh, strict=True):
        if a.suffix == ".csv":
            assert a.read_bytes() == b.read_bytes(), a.name
        ra, rb = read_recording(a, kind=kind), read_recording(b, kind=kind)
        np.testing.assert_array_equal(ra.t, rb.t)
        for c in channels:
            np.testing.assert_array_equal(ra[c], rb[c])
    assert (data_dir() / "manifest.csv").read_bytes() == (regenerated / "manifest.csv").read_bytes()


@pytest.fixture(scope="module")
def bundle_study():
    return run_study(manifest_path(), progress=False)


def _check_truth(r):
    k_true = r["true_h0"] * r["true_ac"]
    # the initial stiffness h0·ac is always identified (to 0.1-3 %), and within 5 σ
    assert r["h0_ac"] == pytest.approx(k_true, rel=0.05)
    assert abs(r["h0_ac"] - k_true) < 5 * r["h0_ac_stderr"]
    if r["identifiable"]:
        assert abs(r["h0"] - r["true_h0"]) < 5 * r["h0_stderr"], r["file"]
        assert abs(r["ac"] - r["true_ac"]) < 5 * r["ac_stderr"], r["file"]
    else:
        assert r["h0"] is None and r["ac"] is None  # not arbitrary numbers


def test_study_of_the_bundle_recovers_the_truth(bundle_study):
    """End to end on the shipped files: readers, fits and identifiability as documented."""
    res = bundle_study
    assert not res.failures
    rows = res.table("tangential")
    assert _counts(rows) == _expected_counts()  # every recording is in the table
    for r in rows:
        if r["material"] != "steel/steel":
            assert r["identifiable"], r["file"]
            _check_truth(r)
    steel = [r for r in rows if r["material"] == "steel/steel"]
    assert sum(not r["identifiable"] for r in steel) >= len(steel) // 2


def test_study_of_the_bundle_normal(bundle_study):
    res = bundle_study
    normal = res.table("normal")
    assert [r["p0"] for r in normal] == pytest.approx(NORMAL_P0, rel=1e-3)
    k = [r["k_tan"] for r in sorted(normal, key=lambda r: r["p0"])]
    assert np.all(np.diff(k) > 0)  # the joint stiffens with the static pressure


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


def test_steel_loops_identified_only_when_right(bundle_study):
    steel = [r for r in bundle_study.table("tangential") if r["material"] == "steel/steel"]
    assert len(steel) == _expected_counts()["steel/steel"] > 0
    for r in steel:
        _check_truth(r)


def _counts(rows):
    out: dict[str, int] = {}
    for r in rows:
        out[r["material"]] = out.get(r["material"], 0) + 1
    return out


def _expected_counts():
    return {m.material: len(m.loads) * len(m.amplitudes) for m in MATERIALS}
