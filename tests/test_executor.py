"""Executor-agnostic studies and tracking: thread and process pools and a Dask LocalCluster
give the serial run's results, in order."""

from __future__ import annotations

from concurrent.futures import ProcessPoolExecutor, ThreadPoolExecutor

import numpy as np
import pytest

from contactlab import InputError
from contactlab.data import data_dir
from contactlab.studies import ordered_map, run_study, track_many
from contactlab.tangential import synthetic_recording


def _square(v: int) -> int:
    return v * v


def _fails_at_3(v: int) -> int:
    if v == 3:
        raise InputError("three")
    return v


@pytest.fixture(scope="module")
def files():
    return (
        sorted(data_dir().glob("tangential/Al-Al_W50N_*"))[:3]
        + sorted(data_dir().glob("normal/*"))[:1]
    )


@pytest.fixture(scope="module")
def serial(files):
    return run_study(files, progress=False, keep_recordings=False)


def _same(a, b) -> None:
    for kind in ("tangential", "normal"):
        assert a.to_csv(kind) == b.to_csv(kind)
    assert [r.entry.path for r in a.results] == [r.entry.path for r in b.results]


def test_ordered_map_keeps_order_and_bounds_in_flight():
    with ThreadPoolExecutor(2) as ex:
        assert list(ordered_map(_square, range(20), ex, in_flight=3)) == [v * v for v in range(20)]
        with pytest.raises(InputError, match="three"):
            list(ordered_map(_fails_at_3, range(10), ex))
    with pytest.raises(InputError, match="submit"):
        list(ordered_map(_square, [1], executor=object()))


@pytest.mark.parametrize("pool", [ThreadPoolExecutor, ProcessPoolExecutor])
def test_study_on_pools_equals_serial(files, serial, pool):
    with pool(2) as ex:
        par = run_study(files, progress=False, executor=ex)
    _same(serial, par)
    assert all(r.recording is None for r in par.results)  # results only, not the samples


def _tracks():
    return [
        synthetic_recording(h0=40.0, ac=4e4, amplitude=20e-6, n_cycles=9, fs=800.0,
                            noise=0.01, seed=s)
        for s in (8101, 8102, 8103)
    ]  # fmt: skip


def test_dask_local_cluster_equals_serial(files, serial):
    distributed = pytest.importorskip("distributed", reason="distributed is not installed")
    recs = _tracks()
    want = list(track_many(recs, "4cycles"))
    with (
        distributed.LocalCluster(
            n_workers=1, threads_per_worker=2, processes=False, dashboard_address=None
        ) as cluster,
        distributed.Client(cluster) as client,
    ):
        par = run_study(files, progress=False, executor=client)
        got = list(track_many(recs, "4cycles", executor=client))
    _same(serial, par)
    assert len(got) == len(want)
    for a, b in zip(got, want, strict=True):
        assert a.rows == b.rows
        np.testing.assert_array_equal(a.cycles["energy"], b.cycles["energy"])


@pytest.mark.parametrize("pool", [ThreadPoolExecutor, ProcessPoolExecutor])
def test_track_windows_in_parallel_equal_serial(pool):
    from contactlab.studies import track

    rec = _tracks()[0]
    want = track(rec, "3cycles")
    with pool(2) as ex:
        got = track(rec, "3cycles", executor=ex)
    assert got.rows == want.rows and len(got.rows) == 2
    np.testing.assert_array_equal(got.cycles["energy"], want.cycles["energy"])
