"""Running the analysis of many recordings on any executor, in order, with bounded memory.

``executor=`` accepts anything with ``submit(fn, *args)`` returning a future with
``result()``: a :class:`concurrent.futures.ThreadPoolExecutor` or ``ProcessPoolExecutor``, or
a Dask ``distributed.Client`` (a cluster; ``pip install 'contactlab[scale]'``). Results come
back in the order of the inputs, identical to a serial run (the same function on the same
data), and only a bounded number of tasks is in flight (2 per worker) or finished ahead of
its turn (8 per worker, at least 16), so a study of thousands of files never holds more
than that many recordings at a time. A free worker gets the next task as soon as any task
finishes, so one long recording does not stall the others.
"""

from __future__ import annotations

import contextlib
import os
import queue
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
    max_held: int | None = None,
) -> Iterator[R]:
    """``fn(item)`` for each item, in order: serially (``executor=None``) or on ``executor``.

    At most ``in_flight`` tasks are submitted and not yet finished (default 2 per worker), so
    that every worker always has its next task queued; a new task is submitted as soon as any
    task finishes, not only when the oldest one is collected, so one slow recording does not
    leave the other workers idle. Results that finished before an earlier one are held until
    their turn, at most ``max_held`` of them (default 8 per worker, at least 16); when that many
    are waiting, nothing more is submitted until the oldest task finishes. So at most
    ``in_flight + max_held`` results or inputs exist at a time, however many items there are.

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
    workers = n_workers(executor)
    limit = in_flight if in_flight is not None else 2 * workers
    if limit < 1:
        raise InputError(f"in_flight must be >= 1, got {limit}")
    held_limit = max_held if max_held is not None else max(16, 8 * workers)
    if held_limit < 0:
        raise InputError(f"max_held must be >= 0, got {held_limit}")
    dask = _is_dask(executor)
    futures: dict[int, Any] = {}  # submitted and not yet yielded, by position
    finished: queue.SimpleQueue[int] = queue.SimpleQueue()  # positions, from done callbacks
    done: set[int] = set()  # finished and not yet yielded
    callbacks = True  # False: futures without add_done_callback; wait for the oldest instead

    def submit(pos: int, item: T) -> None:
        nonlocal callbacks
        fut = executor.submit(fn, item, pure=False) if dask else executor.submit(fn, item)
        # pure=False: for Dask, the same input twice is two tasks, not one cached result
        futures[pos] = fut
        add = getattr(fut, "add_done_callback", None) if callbacks else None
        if callable(add):
            add(lambda _f, pos=pos: finished.put(pos))
        else:
            callbacks = False

    source = iter(items)
    submitted = yielded = 0
    exhausted = False
    try:
        while True:
            running = submitted - yielded - len(done)
            while not exhausted and running < limit and submitted - yielded < limit + held_limit:
                try:
                    item = next(source)
                except StopIteration:
                    exhausted = True
                    break
                submit(submitted, item)
                submitted += 1
                running += 1
            if not callbacks:  # the oldest one's turn: wait for it
                if yielded == submitted:
                    return
                fut = futures.pop(yielded)
                yielded += 1
                yield fut.result()
                continue
            if yielded in done:  # the oldest has finished: its turn (then refill first)
                done.discard(yielded)
                fut = futures.pop(yielded)
                yielded += 1
                yield fut.result()  # a task's exception is raised here, in its turn
                continue
            if exhausted and yielded == submitted:
                return
            while True:  # wait for any task to finish; interruptible by Ctrl-C
                try:
                    done.add(finished.get(timeout=0.25))
                    break
                except queue.Empty:
                    continue
            while True:  # and collect whatever else has finished meanwhile
                try:
                    done.add(finished.get_nowait())
                except queue.Empty:
                    break
    finally:
        for fut in futures.values():
            fut.cancel()


def kill_worker_processes() -> None:
    """Kill every child process this process started through multiprocessing (the pools'
    workers); they hold no outputs (every output is written by the parent, all or nothing).

    For a process that is ending (an interrupted or failed command-line run): the pools'
    own threads, finding their workers gone, would print a traceback ("Exception in thread
    ..."); from here on such an error in a thread (a closed pipe, a cancelled future) is not
    printed (any other thread exception still goes to the hook that was there)."""
    import multiprocessing
    import threading
    from concurrent.futures import InvalidStateError

    previous = threading.excepthook
    # what a pool's manager thread raises when its workers vanish: a closed pipe, and (Python
    # 3.11's terminate_broken) setting an exception on a future already cancelled
    expected = (OSError, EOFError, InvalidStateError)

    def quiet(args: Any) -> None:
        if args.exc_type is not None and issubclass(args.exc_type, expected):
            return
        previous(args)

    if getattr(previous, "__name__", "") != "quiet":
        threading.excepthook = quiet
    for child in multiprocessing.active_children():
        with contextlib.suppress(Exception):
            child.kill()
    for child in multiprocessing.active_children():
        with contextlib.suppress(Exception):
            child.join(timeout=1.0)


__all__ = ["kill_worker_processes", "n_workers", "ordered_map"]
