"""contactlab.io: readers and writers for CSV, TDMS, HDF5 and MAT, units and bad input."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from contactlab import InputError
from contactlab.io import (
    Recording,
    RecordingError,
    UnknownUnitError,
    read_recording,
    split_name,
    to_si,
    write_recording,
)

FORMATS = ["csv", "txt", "tsv", "tdms", "h5", "hdf5", "mat", "mat73"]


def _rec(n=500, fs=1000.0):
    t = np.arange(n) / fs
    x = 5e-6 * np.sin(2 * np.pi * 3 * t)
    F = 2.0 * np.cos(2 * np.pi * 3 * t) + 0.1
    return Recording(t, {"x": x, "F": F}, {"x": "m", "F": "N"}, source="test")


def _path(tmp_path, fmt):
    return tmp_path / ("r.mat" if fmt == "mat73" else f"r.{fmt}")


def _write(tmp_path, fmt, rec):
    p = _path(tmp_path, fmt)
    write_recording(p, rec, **({"version": "7.3"} if fmt == "mat73" else {}))
    return p


@pytest.mark.parametrize("fmt", FORMATS)
def test_round_trip_every_format(tmp_path, fmt):
    rec = _rec()
    p = _write(tmp_path, fmt, rec)
    back = read_recording(p)
    assert back.kind == "tangential"
    np.testing.assert_allclose(back.t, rec.t, rtol=0, atol=1e-15)
    np.testing.assert_array_equal(back["x"], rec["x"])
    np.testing.assert_array_equal(back["F"], rec["F"])
    assert back.units == {"x": "m", "F": "N"}
    assert back.source == str(p)
    assert not list(tmp_path.glob("*.part"))


@pytest.mark.parametrize("fmt", FORMATS)
def test_normal_recording_round_trip(tmp_path, fmt):
    t = np.arange(200) / 100.0
    rec = Recording(
        t,
        {"p": 5e5 + 4e5 * np.sin(t), "delta": 1e-6 * np.sin(t - 0.1)},
        {"p": "Pa", "delta": "m"},
    )
    back = read_recording(_write(tmp_path, fmt, rec))
    assert back.kind == "normal"
    np.testing.assert_array_equal(back["p"], rec["p"])
    np.testing.assert_array_equal(back["delta"], rec["delta"])


def test_csv_units_in_brackets_are_converted(tmp_path):
    p = tmp_path / "run.csv"
    p.write_text("# rig 3, W = 109 N\nt [ms];x [um];F [kN]\n0;1.5;0.002\n1;2.5;0.003\n2;3;0.001\n")
    rec = read_recording(p)
    np.testing.assert_allclose(rec.t, [0, 1e-3, 2e-3])
    np.testing.assert_allclose(rec["x"], [1.5e-6, 2.5e-6, 3e-6])
    np.testing.assert_allclose(rec["F"], [2.0, 3.0, 1.0])
    assert rec.meta["comments"] == ["rig 3, W = 109 N"]
    assert rec.meta["file_units"] == {"t": "ms", "x": "um", "F": "kN"}


def test_csv_whitespace_and_pressure_units(tmp_path):
    p = tmp_path / "normal.txt"
    p.write_text("time [s]\tp [MPa]\tdelta [µm]\n0\t0.5\t0\n0.01\t0.6\t0.1\n0.02\t0.7\t0.2\n")
    rec = read_recording(p)
    assert rec.kind == "normal"
    np.testing.assert_allclose(rec["p"], [5e5, 6e5, 7e5])
    np.testing.assert_allclose(rec["delta"], [0, 1e-7, 2e-7])
    p2 = tmp_path / "ws.dat"
    p2.write_text("t [ms]   disp [mm]   force [N]\n0 1 2\n1 2 3\n")
    rec2 = read_recording(p2)
    np.testing.assert_allclose(rec2["x"], [1e-3, 2e-3])


def test_column_mapping_and_sampling_rate(tmp_path):
    p = tmp_path / "m.csv"
    p.write_text("LVDT1 [um],load cell [N],other\n1,2,3\n2,3,4\n3,4,5\n")
    with pytest.raises(RecordingError, match="cannot tell"):
        read_recording(p)
    with pytest.raises(RecordingError, match="fs="):
        read_recording(p, columns={"x": "LVDT1", "F": "load cell [N]"})
    rec = read_recording(p, columns={"x": "LVDT1", "F": "load cell [N]"}, fs=100.0)
    np.testing.assert_allclose(rec.t, [0, 0.01, 0.02])
    np.testing.assert_allclose(rec["x"], [1e-6, 2e-6, 3e-6])
    assert rec.meta["columns"] == {"x": "LVDT1 [um]", "F": "load cell [N]"}


def test_units_assumed_si_are_recorded(tmp_path):
    p = tmp_path / "plain.csv"
    p.write_text("t,x,F\n0,1e-6,1\n0.001,2e-6,2\n")
    rec = read_recording(p)
    assert sorted(rec.meta["units_assumed_si"]) == ["F", "t", "x"]


def test_csv_reads_only_needed_columns(tmp_path):
    # a junk text column that is not asked for does not break the read
    p = tmp_path / "extra.csv"
    p.write_text("t [s],note,x [m],F [N]\n0,start,0,0\n1,mid,1e-6,1\n2,end,2e-6,2\n")
    rec = read_recording(p)
    assert set(rec.data) == {"x", "F"}


@pytest.mark.parametrize(
    ("text", "match", "column", "row"),
    [
        ("t [s],x [m],F [N]\n0,0,0\n1,abc,1\n2,0,0\n", "'abc' is not a number", "x [m]", 3),
        ("t [s],x [m],F [N]\n0,0,0\n1,,1\n2,0,0\n", "'' is not a number", "x [m]", 3),
        ("t [s],x [furlong],F [N]\n0,0,0\n1,1,1\n", "unknown unit 'furlong'", "x [furlong]", None),
        ("t [s],x [N],F [N]\n0,0,0\n1,1,1\n", "is a force unit", "x [N]", None),
        ("t [s],x [m],F [N]\n0,0,0\n2,1,1\n1,1,1\n", "unsorted", "t [s]", 4),
        ("t [s],x [m],F [N]\n0,0,0\n1,1,1\n1,1,1\n", "duplicated", "t [s]", 4),
        ("t [s],x [m],F [N]\n0,0,0\n1,1,1\n2,1,1\n5,1,1\n6,0,0\n", "gap in time", "t [s]", 5),
        ("t [s],x [m],Fz [N]\n0,0,0\n1,1,1\n", "no column for 'F'", "F", None),
        ("t [s],x [m],F [N]\n0,0,0\n1,nan,1\n", "not a finite number", "x [m]", 3),
    ],
)
def test_csv_errors_name_file_column_and_row(tmp_path, text, match, column, row):
    p = tmp_path / "bad.csv"
    p.write_text(text)
    with pytest.raises(RecordingError, match=match) as info:
        read_recording(p, kind="tangential")
    err = info.value
    assert str(p) in str(err)
    assert err.file == str(p)
    assert err.column == column
    assert err.row == row
    if row is not None:
        assert f"(line {row} of bad.csv)" in str(err) and f"sample {row - 2} " in str(err)
    assert isinstance(err, InputError)


def test_missing_explicit_column_is_named(tmp_path):
    p = tmp_path / "r.csv"
    write_recording(p, _rec(20))
    with pytest.raises(RecordingError, match="'Fx'") as info:
        read_recording(p, columns={"F": "Fx"})
    assert info.value.column == "Fx"


@pytest.mark.parametrize(
    ("real", "claimed"),
    [("h5", "csv"), ("csv", "tdms"), ("tdms", "h5"), ("csv", "mat"), ("mat", "h5")],
)
def test_wrong_content_for_extension(tmp_path, real, claimed):
    src = tmp_path / f"a.{real}"
    write_recording(src, _rec(20))
    dst = tmp_path / f"b.{claimed}"
    dst.write_bytes(src.read_bytes())
    with pytest.raises(RecordingError, match="content is") as info:
        read_recording(dst)
    assert str(dst) in str(info.value)


def test_missing_file_and_unknown_extension(tmp_path):
    with pytest.raises(RecordingError, match="no such file"):
        read_recording(tmp_path / "nope.csv")
    p = tmp_path / "r.xyz"
    p.write_text("t,x,F\n")
    with pytest.raises(RecordingError, match="unknown extension"):
        read_recording(p)
    with pytest.raises(RecordingError, match="unknown extension"):
        write_recording(tmp_path / "out.xyz", _rec(10))


def test_tdms_unit_and_increment_from_properties(tmp_path):
    nptdms = pytest.importorskip("nptdms")
    p = tmp_path / "rig.tdms"
    with nptdms.TdmsWriter(p) as w:
        w.write_segment(
            [
                nptdms.GroupObject("Rig"),
                nptdms.ChannelObject(
                    "Rig",
                    "displacement",
                    np.array([1.0, 2.0, 3.0]),
                    properties={"unit_string": "um", "wf_increment": 0.5e-3},
                ),
                nptdms.ChannelObject(
                    "Rig", "force", np.array([0.1, 0.2, 0.3]), properties={"unit_string": "kN"}
                ),
            ]
        )
    rec = read_recording(p)
    np.testing.assert_allclose(rec.t, [0, 5e-4, 1e-3])
    np.testing.assert_allclose(rec["x"], [1e-6, 2e-6, 3e-6])
    np.testing.assert_allclose(rec["F"], [100, 200, 300])
    rec2 = read_recording(p, columns={"x": "Rig/displacement"}, fs=10.0)
    np.testing.assert_allclose(rec2.t, [0, 0.1, 0.2])


def test_hdf5_attributes_and_nested_datasets(tmp_path):
    h5py = pytest.importorskip("h5py")
    p = tmp_path / "rig.h5"
    with h5py.File(p, "w") as f:
        g = f.create_group("run1")
        g.create_dataset("x", data=[1.0, 2.0, 4.0]).attrs["units"] = b"mm"
        g.create_dataset("F", data=[1.0, 2.0, 3.0]).attrs["unit"] = "N"
        f.attrs["fs"] = 2.0
    rec = read_recording(p)
    np.testing.assert_allclose(rec.t, [0, 0.5, 1.0])
    np.testing.assert_allclose(rec["x"], [1e-3, 2e-3, 4e-3])
    with h5py.File(p, "a") as f:
        f["run1/x"].attrs["units"] = "parsec"
    with pytest.raises(UnknownUnitError, match="parsec"):
        read_recording(p)


def test_mat_name_suffix_units_and_dt(tmp_path):
    import scipy.io

    p = tmp_path / "m.mat"
    scipy.io.savemat(p, {"x_um": np.array([1.0, 2.0]), "F_N": np.array([3.0, 4.0]), "dt": 0.01})
    rec = read_recording(p)
    np.testing.assert_allclose(rec["x"], [1e-6, 2e-6])
    np.testing.assert_allclose(rec.t, [0, 0.01])


def test_recording_validation():
    with pytest.raises(InputError, match="samples"):
        Recording(np.arange(3.0), {"x": np.zeros(2)}, {"x": "m"})
    with pytest.raises(InputError, match="no unit"):
        Recording(np.arange(3.0), {"x": np.zeros(3)}, {})
    rec = _rec(10)
    with pytest.raises(KeyError, match="channels"):
        rec["p"]
    assert "x" in rec and "t" in rec and len(rec) == 10


@pytest.mark.parametrize(
    ("unit", "factor", "dim"),
    [
        ("s", 1, "time"),
        ("ms", 1e-3, "time"),
        ("us", 1e-6, "time"),
        ("µs", 1e-6, "time"),
        ("m", 1, "length"),
        ("mm", 1e-3, "length"),
        ("um", 1e-6, "length"),
        ("μm", 1e-6, "length"),
        ("N", 1, "force"),
        ("kN", 1e3, "force"),
        ("Pa", 1, "pressure"),
        ("kPa", 1e3, "pressure"),
        ("MPa", 1e6, "pressure"),
        ("N/mm2", 1e6, "pressure"),
    ],
)
def test_unit_table(unit, factor, dim):
    assert to_si(unit) == (factor, dim)


def test_unknown_unit_raises():
    with pytest.raises(UnknownUnitError, match="furlong"):
        to_si("furlong")


@settings(max_examples=50, deadline=None)
@given(
    name=st.text(st.characters(whitelist_categories=("L",)), min_size=1, max_size=8),
    unit=st.sampled_from(["s", "ms", "um", "mm", "N", "kN", "MPa", "Pa"]),
    style=st.sampled_from(["{} [{}]", "{} ({})", "{}[{}]"]),
)
def test_split_name_property(name, unit, style):
    assert split_name(style.format(name, unit)) == (name, unit)


def test_csv_decimal_comma(tmp_path):
    p = tmp_path / "eu.csv"
    p.write_text("Zeit [ms];Weg [µm];Kraft [N]\n0;1,5;-0,25\n1;2,5;1e-1\n2;3;0,5\n")
    rec = read_recording(p, columns={"t": "Zeit", "x": "Weg", "F": "Kraft"})
    np.testing.assert_allclose(rec["x"], [1.5e-6, 2.5e-6, 3e-6])
    np.testing.assert_allclose(rec["F"], [-0.25, 0.1, 0.5])
    assert rec.meta["decimal"] == ","
    p.write_text("Zeit [ms];Weg [µm];Kraft [N]\n0;1,5;-0,25\n1;2,x5;1e-1\n")
    with pytest.raises(RecordingError, match="'2,x5'") as info:
        read_recording(p, columns={"t": "Zeit", "x": "Weg", "F": "Kraft"})
    assert info.value.row == 3


@pytest.mark.parametrize("fmt", ["h5", "mat", "tdms"])
def test_binary_formats_name_the_bad_sample(tmp_path, fmt):
    rec = _rec(50)
    rec.data["F"][17] = np.inf
    p = tmp_path / f"r.{fmt}"
    write_recording(p, rec)
    with pytest.raises(RecordingError, match="not a finite number") as info:
        read_recording(p)
    assert info.value.row == 17
    assert info.value.column == "F"


@pytest.mark.parametrize("fmt", ["h5", "mat", "tdms"])
def test_binary_formats_missing_channel(tmp_path, fmt):
    rec = Recording(np.arange(5.0), {"x": np.zeros(5)}, {"x": "m"})
    p = tmp_path / f"r.{fmt}"
    write_recording(p, rec)
    with pytest.raises(RecordingError, match="no column for 'F'") as info:
        read_recording(p, kind="tangential")
    assert str(p) in str(info.value)


@settings(max_examples=25, deadline=None)
@given(
    xunit=st.sampled_from([("m", 1.0), ("mm", 1e-3), ("um", 1e-6), ("nm", 1e-9)]),
    funit=st.sampled_from([("N", 1.0), ("kN", 1e3), ("mN", 1e-3)]),
    tunit=st.sampled_from([("s", 1.0), ("ms", 1e-3), ("us", 1e-6)]),
    values=st.lists(st.floats(-1e6, 1e6, allow_nan=False), min_size=2, max_size=20),
    delim=st.sampled_from([",", ";", "\t"]),
)
def test_csv_units_property(tmp_path_factory, xunit, funit, tunit, values, delim):
    n = len(values)
    t = np.arange(n) * 3.0
    header = delim.join([f"t [{tunit[0]}]", f"x [{xunit[0]}]", f"F [{funit[0]}]"])
    rows = [delim.join(repr(float(v)) for v in (t[i], values[i], -values[i])) for i in range(n)]
    p = tmp_path_factory.mktemp("u") / "r.csv"
    p.write_text(header + "\n" + "\n".join(rows) + "\n")
    rec = read_recording(p)
    np.testing.assert_allclose(rec.t, t * tunit[1], rtol=1e-15)
    np.testing.assert_allclose(rec["x"], np.array(values) * xunit[1], rtol=1e-15)
    np.testing.assert_allclose(rec["F"], -np.array(values) * funit[1], rtol=1e-15)


def test_csv_rows_count_blank_and_comment_lines(tmp_path):
    p = tmp_path / "gaps.csv"
    p.write_text("t [s],x [m],F [N]\n0,0,0\n\n# pause\n1,1,1\n1,2,2\n")
    with pytest.raises(RecordingError, match="duplicated") as info:
        read_recording(p)
    assert info.value.row == 6  # the 6th line of the file


@pytest.mark.parametrize("fmt", ["csv", "h5", "mat", "tdms"])
def test_failed_write_leaves_nothing_behind(tmp_path, monkeypatch, fmt):
    import contactlab._io_atomic as atomic

    real = atomic.os.replace

    def boom(src, dst):  # fail at the very end, after the data went to the temporary file
        raise KeyboardInterrupt

    monkeypatch.setattr(atomic.os, "replace", boom)
    p = tmp_path / f"out.{fmt}"
    with pytest.raises(KeyboardInterrupt):
        write_recording(p, _rec(50))
    monkeypatch.setattr(atomic.os, "replace", real)
    assert list(tmp_path.iterdir()) == []


def test_mat_v4_is_read(tmp_path):
    import scipy.io

    p = tmp_path / "v4.mat"
    scipy.io.savemat(p, {"t": np.arange(3.0), "x": np.ones(3), "F": np.zeros(3)}, format="4")
    rec = read_recording(p)
    np.testing.assert_array_equal(rec["x"], np.ones(3))


def test_recording_window():
    rec = _rec(100, fs=100.0)
    w = rec.window(0.2, 0.5)
    np.testing.assert_allclose(w.t, rec.t[20:50])
    np.testing.assert_array_equal(w["F"], rec["F"][20:50])
    assert w.meta["window"] == (0.2, 0.5) and w.units == rec.units
    assert len(rec.window(t0=0.9)) == 10 and len(rec.window(t1=0.1)) == 10
    with pytest.raises(InputError, match="holds 0 samples"):
        rec.window(5.0, 6.0)


@pytest.mark.parametrize("chunked", [False, True])
def test_csv_without_header_row(tmp_path, chunked):
    """A file whose first line holds numbers has no header row: that line is data, and the
    columns are named by the last comment when it lists them (remarks in parentheses dropped,
    as exporters write ``# u_N,y_m (fs=750 Hz, 5 periods)``), else by position."""
    from contactlab.io import read_chunks

    def read(p, **kw):
        if not chunked:
            return read_recording(p, **kw)
        parts = list(read_chunks(p, chunk_size=2, **kw))
        return Recording(
            np.concatenate([c.t for c in parts]),
            {k: np.concatenate([c[k] for c in parts]) for k in parts[0].data},
            dict(parts[0].units),
            source="chunks",
        )

    named = tmp_path / "named.csv"
    named.write_text("# rig 2\n# u_N,y_m (fs=750 Hz, 5 periods x 8 samples, 50 N rms)\n"
                     "-2.5,1e-6\n3.5,2e-6\n4.5,-1e-6\n")  # fmt: skip
    rec = read(named, columns={"x": "y_m", "F": "u_N"}, fs=750.0)
    np.testing.assert_array_equal(rec["x"], [1e-6, 2e-6, -1e-6])  # the first line is data
    np.testing.assert_array_equal(rec["F"], [-2.5, 3.5, 4.5])
    np.testing.assert_allclose(rec.t, np.arange(3) / 750.0)

    bare = tmp_path / "bare.txt"
    bare.write_text("# no names here\n1 10\n2 20\n3 30\n")
    rec = read(bare, columns={"x": "1", "F": "0"}, fs=10.0)
    np.testing.assert_array_equal(rec["x"], [10, 20, 30])
    np.testing.assert_array_equal(rec["F"], [1, 2, 3])
    with pytest.raises(RecordingError, match=r"columns are \['0', '1'\]"):
        read(bare, columns={"x": "disp", "F": "0"}, fs=10.0)

    comma = tmp_path / "comma.csv"  # decimal commas with ';' are numbers, not names
    comma.write_text("1,5;2,5\n3,5;4,5\n")
    rec = read(comma, columns={"x": "0", "F": "1"}, fs=1.0)
    np.testing.assert_array_equal(rec["x"], [1.5, 3.5])
