"""One BLAS thread for the structure fits.

The least-squares solver factors a tall, skinny Jacobian (samples × a few parameters) at
every iteration. Threaded BLAS gains nothing on such a matrix and, on a machine whose cores
are busy, its threads wait for each other: a 1500 × 9 SVD took 0.28 s with the default
threads against 3 ms with one on the 2-core test machine under load, which made the SVDs
half of an identification. :func:`single_blas_thread` limits the BLAS and OpenMP pools to one
thread for the duration of a block (``threadpoolctl``; a no-op when it is not installed).
"""

from __future__ import annotations

import contextlib
import functools
from collections.abc import Callable, Iterator
from typing import Any, TypeVar

F = TypeVar("F", bound=Callable[..., Any])


@contextlib.contextmanager
def single_blas_thread() -> Iterator[None]:
    """Run the block with one BLAS thread (restored afterwards)."""
    try:
        from threadpoolctl import threadpool_limits
    except ImportError:  # optional at run time: only slower without it
        yield
        return
    with threadpool_limits(limits=1, user_api="blas"):
        yield


def with_single_blas_thread(fn: F) -> F:
    """Decorator: call ``fn`` inside :func:`single_blas_thread`."""

    @functools.wraps(fn)
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        with single_blas_thread():
            return fn(*args, **kwargs)

    return wrapper  # type: ignore[return-value]
