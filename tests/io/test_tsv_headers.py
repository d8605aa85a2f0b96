"""Tab-separated headers with units in brackets, as tribometers write them, mapped to t/x/F
(and the normal force kept as channel N), automatically and with --columns (issue 31)."""

from __future__ import annotations

import json

import numpy as np
import pytest

from contactlab.cli import main
from contactlab.io import read_chunks, read_recording
from contactlab.io.recording import RecordingError

HEADER = "Time [s]\tNormal [uN]\tPosition [mm]\tFriction [uN]\n"


def _write(path, n=1200, header=HEADER):
    t = np.arange(n) * 5e-3
    pos = -110.0 + 0.1 * np.sin(2 * np.pi * t)  # mm
    fric = np.zeros(n)  # uN: a Jenkins element (stiffness 1e8 uN/mm) slipping at 2 N
    for i in range(1, n):
        fric[i] = np.clip(fric[i - 1] + 1e8 * (pos[i] - pos[i - 1]), -2.0e6, 2.0e6)
    normal = np.full(n, 5.0e6)
    rows = "".join(f"{a:.17g}\t{b:.17g}\t{c:.17g}\t{d:.17g}\n" for a, b, c, d in
                   zip(t, normal, pos, fric, strict=True))  # fmt: skip
    path.write_text(header + rows)
    return t, pos, fric, normal


def test_tribometer_header_maps_automatically(tmp_path):
    p = tmp_path / "tribo.txt"
    _t, pos, fric, _normal = _write(p)
    rec = read_recording(p)
    assert rec.kind == "tangential"
    assert rec.meta["columns"] == {"x": "Position [mm]", "F": "Friction [uN]", "t": "Time [s]",
                                   "N": "Normal [uN]"}  # fmt: skip
    np.testing.assert_allclose(rec["x"], pos * 1e-3, rtol=1e-12)
    np.testing.assert_allclose(rec["F"], fric * 1e-6, rtol=1e-12)
    np.testing.assert_allclose(rec["N"], 5.0, rtol=1e-12)
    assert rec.units == {"x": "m", "F": "N", "N": "N"}
    chunks = list(read_chunks(p, chunk_size=100))
    np.testing.assert_array_equal(np.concatenate([c["N"] for c in chunks]), rec["N"])


def test_columns_flag_maps_names_with_or_without_units(tmp_path):
    p = tmp_path / "renamed.txt"
    _write(p, header="Zeit [s]\tLast [uN]\tWeg [mm]\tReibung [uN]\n")
    with pytest.raises(RecordingError, match="cannot tell a tangential"):
        read_recording(p)
    rec = read_recording(p, columns={"x": "Weg", "F": "Reibung [uN]", "N": "Last", "t": "Zeit"})
    assert rec.channels == ["x", "F", "N"]
    out = tmp_path / "r.json"
    code = main(["analyze", str(p), "--columns", "x=Weg,F=Reibung,N=Last,t=Zeit", "--json",
                 str(out)])  # fmt: skip
    assert code == 0
    doc = json.loads(out.read_text())
    assert doc["normal_load"] == pytest.approx(5.0, rel=1e-12)
    assert doc["mu"] == pytest.approx(0.4, rel=1e-9)  # 2 N / 5 N on every sliding stroke


def test_normal_force_in_wrong_unit_is_refused(tmp_path):
    p = tmp_path / "bad.txt"
    _write(p, header="Time [s]\tNormal [mm]\tPosition [mm]\tFriction [uN]\n")
    with pytest.raises(RecordingError, match=r"'Normal \[mm\]'.*length unit but 'N' is a force"):
        read_recording(p)
