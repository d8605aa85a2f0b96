"""How a diagnosis uses the cores: candidate fits on threads, BLAS on one thread each.

The fits of a diagnosis are many small least-squares problems (a few thousand residuals, a
handful of parameters). Their time goes to the model evaluations — the Masing kernel in
Rust and numpy array arithmetic, both of which release the GIL — so independent fits (the
candidates of one step, the folds of one model) run on a thread pool. The BLAS calls of the
solver (an SVD of a 5000 × 3 Jacobian) are far too small to gain from BLAS's own threads; on
a loaded machine those threads spin waiting for each other (measured: the same SVDs and dot
products 20× slower in wall time and CPU with OpenBLAS's default of one thread per core
than with one). :func:`one_blas_thread` limits BLAS to one thread for the duration of a
diagnosis when ``threadpoolctl`` is installed (a dependency of the package), and is a no-op
otherwise; results do not depend on it.
"""

from __future__ import annotations

import functools
import os
import threading
from collections.abc import Callable, Sequence
from concurrent.futures import Future, ThreadPoolExecutor
from contextlib import AbstractContextManager, nullcontext
from typing import Any, TypeVar

F = TypeVar("F", bound=Callable[..., Any])

#: most threads a diagnosis uses for its fits (the fits of one step are a dozen or so)
MAX_WORKERS = 8


def running_elsewhere() -> float | None:
    """Tasks runnable on the machine right now besides the caller (``procs_running`` of
    ``/proc/stat`` less one), or None where the system does not tell."""
    try:
        with open("/proc/stat", "rb") as f:
            for line in f:
                if line.startswith(b"procs_running"):
                    return max(float(line.split()[1]) - 1.0, 0.0)
    except (OSError, ValueError, IndexError):
        return None
    return None


def workers() -> int:
    """Threads for independent fits: one per core this process may run on that is not busy
    already, at least 1 and at most :data:`MAX_WORKERS`; ``CONTACTLAB_DIAGNOSE_THREADS=n``
    sets it. Busy is the smaller of the 1-minute load average and the tasks runnable right
    now (:func:`running_elsewhere`): the average lags, so a diagnosis started just after
    other work ended would otherwise run serially on idle cores for up to a minute. On a
    machine whose cores are all taken, a second thread only adds GIL hand-overs (measured on
    2 cores at a load of 6-10: the same or up to 30 % more wall time than one thread), so
    there a diagnosis runs serially."""
    env = os.environ.get("CONTACTLAB_DIAGNOSE_THREADS", "").strip()
    if env.isdigit() and int(env) >= 1:
        return min(int(env), MAX_WORKERS)
    try:
        n = len(os.sched_getaffinity(0))
    except (AttributeError, OSError):  # not Linux
        n = os.cpu_count() or 1
    try:
        busy = os.getloadavg()[0]
    except (AttributeError, OSError):  # no load average on this system
        busy = 0.0
    now = running_elsewhere()
    if now is not None:
        busy = min(busy, now)
    return max(1, min(n, int(n - busy) + 1, MAX_WORKERS))


def _blas_limit() -> AbstractContextManager[Any]:
    try:
        from threadpoolctl import threadpool_limits
    except ImportError:  # optional at run time: only the speed depends on it
        return nullcontext()
    return threadpool_limits(limits=1, user_api="blas")


def one_blas_thread(fn: F) -> F:
    """Run ``fn`` with BLAS limited to one thread (restored afterwards)."""

    @functools.wraps(fn)
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        with _blas_limit():
            return fn(*args, **kwargs)

    return wrapper  # type: ignore[return-value]


T = TypeVar("T")
R = TypeVar("R")


def pmap(
    fn: Callable[[T], R], items: Sequence[T], cost: Callable[[T], float] | None = None
) -> list[R]:
    """``[fn(i) for i in items]``, on up to :func:`workers` threads; results in order.

    ``cost``: the expected work of a call; on threads the costliest start first (ties in
    ``items``' order), so that a long fit started last does not leave the other threads
    idle at the end (the candidates of a tangential step: ``normal_load``, the last of the
    library, took 2.0 of the 3.9 CPU seconds of a 1e6-sample step; on two threads the step
    takes 3.0 s in the library's order, 2.45 s with the costliest first). Each call's
    result is the same whatever the order.

    An exception in any call is raised here (the first in ``items``' order), as a serial
    loop would raise it; the calls not started yet are dropped (Ctrl-C does not wait for
    them).
    """
    n = min(workers(), len(items))
    if n <= 1:
        return [fn(i) for i in items]
    order = list(range(len(items)))
    if cost is not None:
        order.sort(key=lambda k: -cost(items[k]))  # (stable: ties keep their order)
    ex = ThreadPoolExecutor(n, thread_name_prefix="contactlab-diagnose")
    try:
        futures: list[Future[R] | None] = [None] * len(items)
        for k in order:
            futures[k] = ex.submit(fn, items[k])
        return [f.result() for f in futures if f is not None]
    finally:
        ex.shutdown(wait=True, cancel_futures=True)


#: threads that evaluate the finite-difference columns of a fit's Jacobian
#: (:func:`column_map`); one pool for the process, its tasks never wait on other tasks
_COLUMN_THREADS = 2
_column_pool: ThreadPoolExecutor | None = None
_column_lock = threading.Lock()
_in_column = threading.local()


def in_column() -> bool:
    """Whether this thread is evaluating a Jacobian column for :func:`column_map` (whose
    caller has counted the evaluation already)."""
    return bool(getattr(_in_column, "on", False))


def column_map(
    counter: EvaluationCounter | None,
) -> Callable[[Callable[[T], R], Sequence[T]], list[R]] | None:
    """A map-like callable for :func:`contactlab.fitting.least_squares_fit`'s ``workers``:
    a fit's finite-difference columns (independent model evaluations that release the GIL)
    on :data:`_COLUMN_THREADS` threads, counted in ``counter`` by the calling thread (so a
    fit's evaluations stay its thread's, :meth:`EvaluationCounter.mine`); the numbers are
    those of a serial loop. None when :func:`workers` says one thread (a busy machine)."""
    global _column_pool
    if workers() <= 1:
        return None
    with _column_lock:
        if _column_pool is None:
            _column_pool = ThreadPoolExecutor(_COLUMN_THREADS, thread_name_prefix="contactlab-jac")
        pool = _column_pool

    def one(fn: Callable[[T], R], x: T) -> R:
        _in_column.on = True
        try:
            return fn(x)
        finally:
            _in_column.on = False

    def run(fn: Callable[[T], R], items: Sequence[T]) -> list[R]:
        items = list(items)
        if counter is not None:
            counter.tick(len(items))
        return list(pool.map(functools.partial(one, fn), items))

    return run


class EvaluationCounter:
    """Model evaluations a diagnosis has spent (its budget), counted per thread so that fits
    on several threads neither lose counts nor mix them: :meth:`tick` from any thread,
    :meth:`mine` the calling thread's count so far, :attr:`total` everyone's."""

    def __init__(self) -> None:
        self._local = threading.local()
        self._counts: list[list[int]] = []
        self._lock = threading.Lock()

    def _slot(self) -> list[int]:
        c = getattr(self._local, "count", None)
        if c is None:
            c = self._local.count = [0]
            with self._lock:
                self._counts.append(c)
        return c

    def tick(self, n: int = 1) -> None:
        self._slot()[0] += n

    def mine(self) -> int:
        return self._slot()[0]

    @property
    def total(self) -> int:
        with self._lock:
            return sum(c[0] for c in self._counts)
