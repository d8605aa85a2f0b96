"""A streamed window's time axis made by its first pass over the samples (issue 33 item 4):
``analyze_window(axis_filled=False, time_step=...)`` (what ``track`` runs on a sampled
recording) gives every number of the window analysed on ``fill_time``'s axis, and leaves
that axis, bit for bit, in the recording; where the fused pass does not run (a short window,
samples not scanned by a reader, a delay) the axis is made before anything reads it, and the
errors are the same."""

from __future__ import annotations

import numpy as np
import pytest

from contactlab import _core
from contactlab.errors import InputError
from contactlab.io import Recording
from contactlab.synthetic.tangential import synthetic_recording
from contactlab.tangential.window import analyze_window

# fresh seeds: long windows (the fused pass: more than 2^15 samples) with drifts, with
# pre-sliding; a short one (fill_time first)
_CASES = {
    "drifts": dict(h0=25.0, ac=8e4, amplitude=10e-6, n_cycles=40.4, fs=2000.0, noise=0.02,
                   x_noise=0.01, drift=0.3, x_drift=1.5e-7, seed=53101),
    "pre-sliding": dict(h0=30.0, ac=5e4, amplitude=12e-6, n_cycles=35, fs=1500.0, noise=0.02,
                        seed=53102),
    "short": dict(h0=30.0, ac=5e4, amplitude=12e-6, n_cycles=9, fs=800.0, noise=0.02,
                  seed=53103),
}  # fmt: skip

_T0, _OFFSET = 0.375, 3_000_017


def _axis(n: int, dt: float, offset: int = _OFFSET) -> np.ndarray:
    t = np.empty(n)
    _core.fill_time(t, _T0, dt, offset)
    return t


def _unfilled(x: np.ndarray, F: np.ndarray) -> Recording:
    """A recording whose axis holds no time yet (NaN: read before it is made, it would
    fail or change every number)."""
    t = np.full(x.size, np.nan)
    return Recording(t, {"x": x, "F": F}, {"x": "m", "F": "N"}, "w.h5", {})


def _ranges(x: np.ndarray, F: np.ndarray) -> dict[str, tuple[float, float]]:
    return {"x": (float(x.min()), float(x.max())), "F": (float(F.min()), float(F.max()))}


@pytest.mark.parametrize("case", sorted(_CASES))
@pytest.mark.parametrize("invert", [False, True])
def test_the_axis_made_in_the_first_pass_gives_every_number(case, invert):
    src = synthetic_recording(**_CASES[case])
    x, F = src["x"], -src["F"] if invert else src["F"]
    dt = 1.0 / _CASES[case]["fs"]
    filled = Recording(_axis(x.size, dt), {"x": x, "F": F}, {"x": "m", "F": "N"}, "w.h5", {})
    step = (_T0, dt, _OFFSET)
    want = analyze_window(filled, period_means=False, scanned=_ranges(x, F), time_step=step)
    rec = _unfilled(x, F)
    got = analyze_window(
        rec, period_means=False, scanned=_ranges(x, F), time_step=step, axis_filled=False
    )
    assert got.to_dict() == want.to_dict() and got.warnings == want.warnings
    assert rec.t.tobytes() == filled.t.tobytes()  # fill_time's axis, left in the recording


@pytest.mark.parametrize("scanned", [False, True])
def test_the_fused_scan_is_fill_time_then_the_raw_scan(scanned):
    """The kernel itself: its axis is fill_time's and its scan that of the filled axis (the
    order statistics, the period means resumed from its checkpoints), bit for bit, for
    windows across its axis blocks; a bad offset and a short axis are refused."""
    rng = np.random.default_rng(53104)
    for n in (40_000, 4096 * 3 + 1, 100_003):
        t = _axis(n, 1e-4)
        x = np.sin(60.0 * t) + 0.01 * rng.standard_normal(n)
        F = 40.0 * np.sin(60.0 * t + 0.3) + rng.standard_normal(n)
        ranks = [n // 200, n // 200 + 1, n - 2 - n // 200, n - 1 - n // 200]
        out = np.full(n, np.nan)
        got = _core.order_stats_trapezoids_uniform(x, F, _T0, 1e-4, _OFFSET, out, ranks)
        want = _core.order_stats_trapezoids(x, t, F, ranks)
        assert out.tobytes() == t.tobytes()
        assert got.order_stats.tobytes() == want.order_stats.tobytes()
        edges = np.sort(rng.uniform(t[0] - 0.01, t[-1] + 0.01, 200))
        for g, w in zip(
            _core.period_means_pair(t, F, x, edges, got),
            _core.period_means_pair(t, F, x, edges, want),
            strict=True,
        ):
            assert g.tobytes() == w.tobytes()
    with pytest.raises(InputError):
        _core.order_stats_trapezoids_uniform(x, F, 0.0, 1e-4, 1 << 53, out, ranks)
    with pytest.raises(InputError):
        _core.order_stats_trapezoids_uniform(x, F, 0.0, 1e-4, 0, out[:-1], ranks)


def _both(x: np.ndarray, F: np.ndarray, dt: float, scanned: bool) -> tuple[str, str]:
    """The errors of the window analysed on its filled axis and with the axis to make."""
    msgs = []
    for filled in (True, False):
        t = _axis(x.size, dt) if filled else np.full(x.size, np.nan)
        rec = Recording(t, {"x": x, "F": F}, {"x": "m", "F": "N"}, "w.h5", {})
        kw = {"scanned": _ranges(x, F)} if scanned else {}
        with pytest.raises(InputError) as e:
            analyze_window(
                rec, period_means=False, time_step=(_T0, dt, _OFFSET), axis_filled=filled, **kw
            )
        msgs.append(str(e.value))
    return msgs[0], msgs[1]


@pytest.mark.parametrize("where", [0, 777, 39_999])
@pytest.mark.parametrize("bad", [np.nan, np.inf])
def test_a_non_finite_sample_is_named_as_before(where, bad):
    src = synthetic_recording(**_CASES["drifts"])
    x = src["x"].copy()
    x[where] = bad
    a, b = _both(x, src["F"], 1 / 2000.0, scanned=False)
    assert a == b and f"x[{where}]" in a


@pytest.mark.parametrize(
    ("what", "message"),
    [
        ("constant", "x is constant"),
        ("ramp", "cycle"),
        ("tiny", ""),
    ],
)
@pytest.mark.parametrize("scanned", [False, True])
def test_windows_without_a_loop_fail_as_before(what, message, scanned):
    """A constant displacement, a ramp (no reversal) and a window of a few samples fail
    with the same error with or without the axis to make."""
    n = 40_000 if what != "tiny" else 12
    rng = np.random.default_rng(53105)
    if what == "constant":
        x = np.full(n, 2e-6)
    elif what == "ramp":
        x = np.linspace(-1e-5, 1e-5, n) + 1e-9 * rng.standard_normal(n)
    else:
        x = 1e-5 * np.sin(np.arange(n))
    F = rng.standard_normal(n)
    a, b = _both(x, F, 1e-3, scanned)
    assert a == b and message in a


def test_track_rows_equal_those_of_the_axis_made_apart(tmp_path, monkeypatch):
    """``track`` of a sampled HDF5 recording read in chunks that cut cycles (and their
    reversals) anywhere: the rows and window documents with the axis made in the first pass
    equal those with ``fill_time``'s axis made apart and the raw scan run on it (the code
    before issue 33's fused pass)."""
    import h5py

    from contactlab.studies import tracking

    rec = synthetic_recording(
        h0=35.0, ac=6e4, amplitude=15e-6, n_cycles=90, fs=3000.0, frequency=2.0, noise=0.02,
        seed=53106,
    )  # fmt: skip
    path = tmp_path / "rec.h5"
    with h5py.File(path, "w") as f:
        for k, unit in (("x", "m"), ("F", "N")):
            d = f.create_dataset(k, data=rec[k])
            d.attrs["unit"] = unit
            d.attrs["dt"] = 1 / 3000.0
    calls = []
    real = _core.order_stats_trapezoids_uniform

    def counted(*a):
        calls.append(len(a[0]))
        return real(*a)

    def apart(x, F, t0, dt, offset, t_out, ranks):
        _core.fill_time(t_out, t0, dt, offset)
        return _core.order_stats_trapezoids(x, t_out, F, ranks)

    kw = dict(kind="tangential", chunk_size=4099, threads=0, keep_documents=True)
    monkeypatch.setattr(_core, "order_stats_trapezoids_uniform", counted)
    got = tracking.track(path, "30cycles", **kw)
    assert calls and all(n > 1 << 15 for n in calls)  # the fused pass ran on each window
    monkeypatch.setattr(_core, "order_stats_trapezoids_uniform", apart)
    want = tracking.track(path, "30cycles", **kw)
    assert got.rows == want.rows
    assert got.window_docs == want.window_docs
