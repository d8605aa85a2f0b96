"""Executor-agnostic studies and tracking: thread and process pools and a Dask LocalCluster
give the serial run's results, in order."""

from __future__ import annotations

import threading
import time
from concurrent.futures import ProcessPoolExecutor, ThreadPoolExecutor

import numpy as np
import pytest

from contactlab import InputError
from contactlab.data import data_dir
from contactlab.studies import ordered_map, run_study, track_many
from contactlab.synthetic.tangential import synthetic_recording


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


def _waits_for_last(item):
    """Item 0 waits until the last item has started: only a map that keeps the free worker
    busy past the oldest task lets it through."""
    pos, started, last = item
    if pos == last:
        started.set()
        return pos, True
    if pos == 0:
        return pos, started.wait(timeout=20)
    return pos, True


def test_ordered_map_does_not_stall_behind_a_slow_task():
    # 2 workers, 4 in flight: the old map (new tasks only when the oldest was collected) never
    # submitted item 9 while item 0 ran, so item 0 timed out
    started = threading.Event()
    items = [(i, started, 9) for i in range(10)]
    with ThreadPoolExecutor(2) as ex:
        got = list(ordered_map(_waits_for_last, items, ex, in_flight=4))
    assert got == [(i, True) for i in range(10)]


class _Counting:
    """An executor that checks ordered_map's bounds at every submit."""

    def __init__(self, inner, limit, held):
        self.inner, self.limit, self.held = inner, limit, held
        self.futures: list = []
        self.yielded = 0
        self.most_running = self.most_outstanding = 0
        self._max_workers = 2

    def submit(self, fn, *args):
        running = sum(not f.done() for f in self.futures) + 1
        self.most_running = max(self.most_running, running)
        self.most_outstanding = max(self.most_outstanding, len(self.futures) + 1 - self.yielded)
        fut = self.inner.submit(fn, *args)
        self.futures.append(fut)
        return fut


def _sleepy(v):
    time.sleep(0.001 * (v * 7 % 5))
    return v


class _Plain:
    """Futures with result() only (no add_done_callback): the map waits for the oldest."""

    def __init__(self, value):
        self.value = value

    def result(self):
        return self.value

    def cancel(self):
        return False


class _PlainExecutor:
    _max_workers = 2

    def submit(self, fn, *args):
        return _Plain(fn(*args))


@pytest.mark.parametrize(("in_flight", "max_held"), [(1, 0), (2, 0), (3, 2), (4, 16)])
def test_ordered_map_bounds_running_and_held_tasks(in_flight, max_held):
    with ThreadPoolExecutor(3) as ex:
        counting = _Counting(ex, in_flight, max_held)
        got = []
        for v in ordered_map(_sleepy, range(40), counting, in_flight=in_flight,
                             max_held=max_held):  # fmt: skip
            got.append(v)
            counting.yielded += 1
    assert got == list(range(40))
    assert counting.most_running <= in_flight
    assert counting.most_outstanding <= in_flight + max_held
    assert list(ordered_map(_square, range(7), _PlainExecutor(), in_flight=2)) == [
        v * v for v in range(7)
    ]
    with pytest.raises(InputError, match="max_held"):
        list(ordered_map(_square, [1], ex, max_held=-1))


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
