"""Bad metadata (sampling rate, time step, start time) and damaged files give a typed error
naming file and attribute in every reader, whole-file and chunked, and a one-line CLI error."""

from __future__ import annotations

import logging

import numpy as np
import pytest

import contactlab
from contactlab.cli import main
from contactlab.io.chunked import read_chunks
from contactlab.io.recording import RecordingError, metadata_scalar

h5py = pytest.importorskip("h5py")
scipy_io = pytest.importorskip("scipy.io")

N = 200


def _xf() -> tuple[np.ndarray, np.ndarray]:
    t = np.arange(N) / 1000.0
    return 1e-6 * np.sin(2 * np.pi * 20 * t), 5.0 * np.sin(2 * np.pi * 20 * t + 0.3)


def _h5(path, *, attrs=None, extra=None):
    x, f = _xf()
    with h5py.File(path, "w") as h:
        h.create_dataset("x", data=x).attrs["unit"] = "m"
        h.create_dataset("F", data=f).attrs["unit"] = "N"
        for k, v in (attrs or {}).items():
            h.attrs[k] = v
        for k, v in (extra or {}).items():
            h.create_dataset(k, data=v)
    return str(path)


def _mat(path, **meta):
    x, f = _xf()
    scipy_io.savemat(str(path), {"x": x, "F": f, **meta})
    return str(path)


def _mat73(path, **meta):
    x, f = _xf()
    with h5py.File(path, "w", userblock_size=512) as h:
        for k, v in {"x": x, "F": f}.items():
            h.create_dataset(k, data=v.reshape(1, -1)).attrs["MATLAB_class"] = np.bytes_("double")
        for k, v in meta.items():
            if isinstance(v, str) and v == "group":
                h.create_group(k)
            else:
                h.create_dataset(k, data=v)
    with open(path, "r+b") as fh:
        fh.write(b"MATLAB 7.3 MAT-file, Platform: GLNXA64".ljust(116, b" "))
        fh.write(b"\x00" * 8 + b"\x00\x02" + b"IM")
    return str(path)


def _expect(path, match, capsys):
    """Whole-file and chunked readers raise RecordingError matching ``match``; the CLI prints
    one line and returns 1."""
    with pytest.raises(RecordingError, match=match):
        contactlab.read_recording(path)
    with pytest.raises(RecordingError, match=match):
        list(read_chunks(path, chunk_size=64))
    capsys.readouterr()
    assert main(["track", path]) == 1
    err = capsys.readouterr().err
    assert "Traceback" not in err
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert len(lines) == 1, err
    assert lines[0].startswith("contactlab track: error:")
    assert path in lines[0]


@pytest.mark.filterwarnings("error")
@pytest.mark.parametrize(
    ("attrs", "match"),
    [
        ({"fs": 0.0}, "attribute 'fs' is 0: a sampling rate must be a positive number"),
        ({"fs": np.zeros(0)}, "attribute 'fs' is empty"),
        ({"fs": "fast"}, "attribute 'fs' is 'fast', not a number"),
        ({"fs": np.complex128(1000 + 0j)}, "attribute 'fs' is complex"),
        ({"fs": -5.0}, "attribute 'fs' is -5"),
        ({"fs": np.nan}, "attribute 'fs' is nan"),
        ({"dt": "abc"}, "attribute 'dt' is 'abc', not a number: a time step"),
        ({"dt": 0.0}, "attribute 'dt' is 0"),
        ({"fs": 1e-320}, "attribute 'fs' .*beyond any data acquisition"),
    ],
)
def test_hdf5_bad_rate(tmp_path, capsys, attrs, match):
    _expect(_h5(tmp_path / "r.h5", attrs=attrs), match, capsys)


def test_hdf5_valid_rate_still_read(tmp_path):
    p = _h5(tmp_path / "ok.h5", attrs={"fs": np.array([1000.0])})
    rec = contactlab.read_recording(p)
    assert rec.fs == pytest.approx(1000.0)
    p = _h5(tmp_path / "ok2.h5", attrs={"fs": "1000"})
    assert contactlab.read_recording(p).fs == pytest.approx(1000.0)


@pytest.mark.parametrize(
    ("meta", "match"),
    [
        ({"fs": 0.0}, "variable 'fs' is 0"),
        ({"fs": np.zeros(0)}, "variable 'fs' is empty"),
        ({"dt": np.zeros(0)}, "variable 'dt' is empty"),
        ({"dt": "abc"}, "variable 'dt' is 'abc', not a number"),
        ({"fs": 1 + 1j}, "variable 'fs' is complex"),
    ],
)
def test_mat_bad_rate(tmp_path, capsys, meta, match):
    _expect(_mat(tmp_path / "r.mat", **meta), match, capsys)


@pytest.mark.parametrize(
    ("meta", "match"),
    [
        ({"fs": np.zeros((1, 1))}, "variable 'fs' is 0"),
        ({"dt": np.zeros(0)}, "variable 'dt' is empty"),
        ({"dt": "group"}, "variable 'dt' is a group"),
    ],
)
def test_mat73_bad_rate(tmp_path, capsys, meta, match):
    _expect(_mat73(tmp_path / "r.mat", **meta), match, capsys)


def test_hdf5_complex_channel_named(tmp_path, capsys):
    x, f = _xf()
    p = str(tmp_path / "c.h5")
    with h5py.File(p, "w") as h:
        h.create_dataset("t", data=np.arange(N) / 1000.0)
        h.create_dataset("x", data=x)
        h.create_dataset("F", data=f.astype(np.complex128))
    _expect(p, "'F' is complex: a channel must hold real numbers", capsys)


def test_hdf5_damaged_object_header(tmp_path, capsys):
    x, f = _xf()
    p = tmp_path / "d.h5"
    with h5py.File(p, "w") as h:
        g = h.create_group("g")
        g.create_dataset("x", data=x)
        g.create_dataset("F", data=f)
        g.attrs["fs"] = 1000.0
        addr = h["g/x"].id.get_offset()
    # find an object header (version-1 headers start with byte 1 at 8-aligned addresses
    # after the superblock) by damaging bytes until libhdf5 refuses the visit
    data = bytearray(p.read_bytes())
    assert addr is not None
    for at in range(96, min(len(data), addr), 8):
        bad = bytearray(data)
        bad[at] = 0xFF
        q = tmp_path / f"d{at}.h5"
        q.write_bytes(bytes(bad))
        try:
            with h5py.File(q, "r") as h:
                h.visititems(lambda *_: None)
        except (RuntimeError, OSError, KeyError):
            break
        except Exception:
            continue
    else:
        pytest.skip("no byte found whose damage fails the visit")
    with pytest.raises(RecordingError, match="not a readable HDF5 file"):
        contactlab.read_recording(str(q))
    with pytest.raises(RecordingError, match="not a readable HDF5 file"):
        list(read_chunks(str(q)))
    capsys.readouterr()
    assert main(["track", str(q)]) == 1
    err = capsys.readouterr().err
    assert "Traceback" not in err and len(err.strip().splitlines()) == 1


@pytest.mark.parametrize("fs", ["1e308", "1e-308"])
def test_user_fs_extremes(tmp_path, capsys, fs):
    x, f = _xf()
    p = tmp_path / "no_t.csv"
    p.write_text("x [m],F [N]\n" + "".join(f"{a!r},{b!r}\n" for a, b in zip(x, f, strict=True)))
    with pytest.raises(RecordingError, match="fs"):
        contactlab.read_recording(p, fs=float(fs))
    with pytest.raises(RecordingError, match="fs"):
        list(read_chunks(p, fs=float(fs)))
    capsys.readouterr()
    assert main(["track", str(p), "--fs", fs]) == 1
    err = capsys.readouterr().err
    assert "Traceback" not in err and len(err.strip().splitlines()) == 1


@pytest.mark.parametrize(
    ("value", "kind", "ok"),
    [
        (1000.0, "rate", 1000.0),
        (np.array([[2.0]]), "step", 2.0),
        (b"3.5", "offset", 3.5),
        (-1.0, "offset", -1.0),
        (-1.0, "step", None),
        (np.inf, "offset", None),
        (np.True_, "rate", None),
        (np.array([1 + 0j]), "rate", None),
    ],
)
def test_metadata_scalar(value, kind, ok):
    if ok is None:
        with pytest.raises(RecordingError, match=r"f\.h5: the thing is"):
            metadata_scalar(value, file="f.h5", label="the thing", kind=kind)
    else:
        assert metadata_scalar(value, file="f.h5", label="the thing", kind=kind) == ok


def _tdms(path, props):
    nt = pytest.importorskip("nptdms")
    x, f = _xf()
    with nt.TdmsWriter(str(path)) as w:
        w.write_segment(
            [
                nt.GroupObject("g"),
                nt.ChannelObject("g", "x", x, properties={"unit_string": "m", **props}),
                nt.ChannelObject("g", "F", f, properties={"unit_string": "N", **props}),
            ]
        )
    return str(path)


@pytest.mark.parametrize(
    ("props", "match"),
    [
        ({"wf_increment": "abc"}, "property 'wf_increment' of channel 'x' is 'abc'"),
        (
            {"wf_increment": 0.001, "wf_start_offset": "abc"},
            "property 'wf_start_offset' of channel 'x' is 'abc'",
        ),
    ],
)
def test_tdms_bad_increment(tmp_path, capsys, props, match):
    _expect(_tdms(tmp_path / "r.tdms", props), match, capsys)


def test_tdms_truncated_quiet(tmp_path, capsys):
    nt = pytest.importorskip("nptdms")
    x, f = _xf()
    p = tmp_path / "full.tdms"
    with nt.TdmsWriter(str(p)) as w:
        w.write_segment(
            [
                nt.GroupObject("g"),
                nt.ChannelObject("g", "x", x, properties={"wf_increment": 0.001}),
                nt.ChannelObject("g", "F", f, properties={"wf_increment": 0.001}),
            ]
        )
    data = p.read_bytes()
    q = tmp_path / "trunc.tdms"
    q.write_bytes(data[: len(data) - 8 * (N // 2)])
    levels = {n: logging.getLogger(n).level for n in ("nptdms", "nptdms.reader")}
    filters = {n: list(logging.getLogger(n).filters) for n in levels}
    with pytest.raises(RecordingError, match="truncated file\\? channels differ in length"):
        contactlab.read_recording(str(q))
    with pytest.raises(RecordingError, match="truncated file\\? channels differ in length"):
        list(read_chunks(str(q)))
    capsys.readouterr()
    assert main(["track", str(q)]) == 1
    err = capsys.readouterr().err
    assert "nptdms" not in err and "WARNING" not in err
    assert len(err.strip().splitlines()) == 1, err
    assert {n: logging.getLogger(n).level for n in levels} == levels
    assert {n: list(logging.getLogger(n).filters) for n in levels} == filters


@pytest.mark.parametrize("fs", ["1e200", "1e13", "1e-10"])
def test_sampling_rate_beyond_any_acquisition(tmp_path, capsys, fs):
    """fs = 1e200 Hz passed the reader and divided by zero in the drift's trend."""
    p = tmp_path / "no_t.csv"
    x = 1e-5 * np.sin(np.linspace(0, 12 * np.pi, 600))
    p.write_text("x [m],F [N]\n" + "\n".join(f"{v:.9g},{1e6 * v:.9g}" for v in x))
    assert main(["analyze", str(p), "--model", "tangential", "--fs", fs]) == 1
    err = capsys.readouterr().err
    assert "beyond any data acquisition" in err and "Traceback" not in err


def test_hdf5_declaring_more_than_it_stores(tmp_path):
    """A long dataset with no chunk written is refused by the whole-file reader before it
    allocates the declared length (8 GB a channel for 1e9 samples)."""
    import h5py

    p = tmp_path / "empty.h5"
    with h5py.File(p, "w") as f:
        for name in ("t", "x", "F"):
            f.create_dataset(name, shape=(10**9,), dtype="f8", chunks=(65536,))
    with pytest.raises(RecordingError, match="stores 0 bytes: none of it was written"):
        contactlab.read_recording(p, kind="tangential")


def test_matlab_struct_variables_are_named_with_the_way_out(tmp_path):
    """Channels saved inside a struct inside a struct (`data.run.x`) are not read: the message
    says so and how to save them as variables, for MAT v5 and v7.3 (it said 'columns are []').
    One level of struct (`data.x`) is read: tests/io/test_mat_struct.py."""
    import h5py
    import scipy.io

    x = 1e-5 * np.sin(np.linspace(0, 12 * np.pi, 600))
    v5 = tmp_path / "s5.mat"
    scipy.io.savemat(v5, {"data": {"run": {"x": x, "F": 1e6 * x}}})
    v73 = tmp_path / "s73.mat"
    with h5py.File(v73, "w", userblock_size=512) as f:
        g = f.create_group("data")
        g.attrs["MATLAB_class"] = np.bytes_("struct")
        g = g.create_group("run")
        g.attrs["MATLAB_class"] = np.bytes_("struct")
        for k, v in (("x", x), ("F", 1e6 * x)):
            d = g.create_dataset(k, data=v.reshape(-1, 1))
            d.attrs["MATLAB_class"] = np.bytes_("double")
    with open(v73, "r+b") as fh:  # MATLAB's header in the user block
        fh.write(b"MATLAB 7.3 MAT-file".ljust(128, b" "))
    for p in (v5, v73):
        with pytest.raises(RecordingError, match=r"'data.run' is a MATLAB struct.*'-struct', 's'"):
            contactlab.read_recording(p)
