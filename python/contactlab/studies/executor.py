"""Running the analysis of many recordings on any executor, in order, with bounded memory.

``executor=`` accepts anything with ``submit(fn, *args)`` returning a future with
``result()``: a :class:`concurrent.futures.ThreadPoolExecutor` or ``ProcessPoolExecutor``, or
a Dask ``distributed.Client`` (a cluster; ``pip install 'contactlab[scale]'``). Results come
back in the order of the inputs, identical to a serial run (the same function on the same
data), and only a bounded number of tasks is in flight, so a study of thousands of files
never holds more than a few recordings at a time.
"""

from __future__ import annotations

import os
from collections import deque
from collections.abc import Callable, Iterable, Iterator
from typing import Any, TypeVar

from ..errors import InputError

T = TypeVar("T")
R = TypeVar("R")


def _is_dask(executor: Any) -> bool:
    return type(executor).__module__.split(".")[0] == "distributed"


def n_workers(executor: Any) -> int:
    """Parallel slots of ``executor`` (1 for None): pool size, or the Dask cluster's threads."""
    if executor is None:
        return 1
    if _is_dask(executor):
        try:
            info = executor.scheduler_info()
            return max(1, sum(int(w.get("nthreads", 1)) for w in info["workers"].values()))
        except Exception:  # a client that cannot tell: assume the machine's cores
            return os.cpu_count() or 1
    return int(getattr(executor, "_max_workers", 0) or os.cpu_count() or 1)


def ordered_map(
    fn: Callable[[T], R],
    items: Iterable[T],
    executor: Any = None,
    *,
    in_flight: int | None = None,
) -> Iterator[R]:
    """``fn(item)`` for each item, in order: serially (``executor=None``) or on ``executor``
    with at most ``in_flight`` tasks submitted and not yet collected (default 2 per worker).

    ``fn`` and the items must pickle for process pools and Dask (module-level functions,
    ``functools.partial``). An exception of a task is raised when its turn comes; the tasks
    not yet started are cancelled then, and on Ctrl-C.
    """
    if executor is None:
        for item in items:
            yield fn(item)
        return
    if not callable(getattr(executor, "submit", None)):
        raise InputError(
            f"executor must have a submit() method (concurrent.futures executor or "
            f"distributed.Client), got {type(executor).__name__}"
        )
    limit = in_flight if in_flight is not None else 2 * n_workers(executor)
    if limit < 1:
        raise InputError(f"in_flight must be >= 1, got {limit}")
    dask = _is_dask(executor)
    pending: deque[Any] = deque()

    def submit(item: T) -> Any:
        if dask:  # pure=False: the same input twice is two tasks, not one cached result
            return executor.submit(fn, item, pure=False)
        return executor.submit(fn, item)

    try:
        for item in items:
            pending.append(submit(item))
            if len(pending) >= limit:
                yield pending.popleft().result()
        while pending:
            yield pending.popleft().result()
    finally:
        for fut in pending:
            fut.cancel()


__all__ = ["n_workers", "ordered_map"]
