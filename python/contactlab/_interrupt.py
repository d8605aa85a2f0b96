"""Ctrl-C that is never lost.

Python turns SIGINT into ``KeyboardInterrupt`` wherever the main thread happens to be. Where
that is a finaliser, a weak-reference callback or a fork hook (``os.fork`` runs
``logging``'s lock hooks in the parent), the interpreter prints "Exception ignored in: ..."
and goes on: the interrupt is lost and the run writes its outputs as if nothing had
happened (a ``demo`` run given SIGINT while its pool forked its workers went on for seconds).

The command line's handler therefore also notes the interrupt; :func:`check`, called just
before outputs are committed and before a pool waits for its tasks, raises it again if it
was swallowed. :func:`deferred` holds SIGINT back over a short stretch where it would be
swallowed (launching a pool's workers) and raises it right after.
"""

from __future__ import annotations

import contextlib
import signal
from collections.abc import Iterator
from typing import Any

_pending = False


def _handler(signum: int, frame: Any) -> None:
    global _pending
    _pending = True
    raise KeyboardInterrupt


def install() -> None:
    """Note every SIGINT of this process (the command line's own run). A process that
    inherited SIGINT ignored (started in the background by a non-interactive shell), or whose
    handler is someone else's, keeps it."""
    global _pending
    _pending = False
    if signal.getsignal(signal.SIGINT) is signal.default_int_handler:
        signal.signal(signal.SIGINT, _handler)


def uninstall() -> None:
    """Once the run has ended (its outputs committed or none written), SIGINT takes its
    default action again: a Ctrl-C while the interpreter shuts down ends the process at once,
    instead of landing in an exit handler as "Exception ignored" and being lost."""
    if signal.getsignal(signal.SIGINT) is _handler:
        signal.signal(signal.SIGINT, signal.SIG_DFL)


def check() -> None:
    """Raise ``KeyboardInterrupt`` if a SIGINT arrived and was swallowed where it landed."""
    if _pending:
        raise KeyboardInterrupt


def pending() -> bool:
    """Whether a SIGINT arrived (raised or swallowed) since :func:`install` or :func:`reset`."""
    return _pending


def reset() -> None:
    """Forget a noted interrupt (after it was handled, and in tests)."""
    global _pending
    _pending = False


@contextlib.contextmanager
def deferred() -> Iterator[None]:
    """Hold a Ctrl-C back over the block and raise it when the block ends, in ordinary code.

    Over the block SIGINT's handler only notes the interrupt. (Blocking the signal with
    ``pthread_sigmask`` would not do: the kernel hands a process's signal to any thread that
    does not block it, a BLAS thread say, and the main thread would still run the handler
    inside the block.) Outside the main thread, or where SIGINT is ignored or takes its
    default action, the block runs as it is."""
    import threading

    before = signal.getsignal(signal.SIGINT)
    if threading.current_thread() is not threading.main_thread() or not callable(before):
        yield
        return
    got: list[int] = []

    def note(signum: int, frame: Any) -> None:
        global _pending
        _pending = True
        got.append(signum)

    signal.signal(signal.SIGINT, note)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, before)
    if got:
        raise KeyboardInterrupt
