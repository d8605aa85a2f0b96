"""A Ctrl-C that Python swallows where it lands (a finaliser, a fork hook: "Exception ignored
in: ...") still ends the run before it commits anything (CI of stop 39: a SIGINT landing in
``logging``'s fork hook while ``demo`` forked its pool's workers was lost, and the run went on
for more than 5 s)."""

from __future__ import annotations

import gc
import multiprocessing
import os
import signal
import sys

import pytest

from contactlab import _interrupt
from contactlab._io_atomic import write_text
from contactlab._outputs import commit_outputs
from contactlab.commands.common import process_pool


@pytest.fixture
def noted():
    """The command line's handler installed, as in a run; everything restored after."""
    before = signal.getsignal(signal.SIGINT)
    signal.signal(signal.SIGINT, signal.default_int_handler)
    _interrupt.install()
    yield
    _interrupt.reset()
    signal.signal(signal.SIGINT, before)


class _Finaliser:
    def __del__(self) -> None:
        os.kill(os.getpid(), signal.SIGINT)  # lands here: printed as "Exception ignored"
        for _ in range(1000):  # the handler runs between bytecodes
            pass


def _swallow_one() -> None:
    obj = _Finaliser()
    del obj
    gc.collect()


def test_swallowed_interrupt_is_not_lost(noted, tmp_path, monkeypatch) -> None:
    swallowed = []
    monkeypatch.setattr(sys, "unraisablehook", lambda u: swallowed.append(u.exc_type))
    _swallow_one()
    assert swallowed == [KeyboardInterrupt]  # Python went on as if nothing had happened
    with pytest.raises(KeyboardInterrupt):
        commit_outputs(tmp_path / "out", {"report.html": b"x", "sub/t.csv": b"1"})
    assert not (tmp_path / "out").exists()
    with pytest.raises(KeyboardInterrupt):
        write_text(tmp_path / "a.txt", "x")
    assert list(tmp_path.iterdir()) == []


def test_without_an_interrupt_outputs_are_written(noted, tmp_path) -> None:
    commit_outputs(tmp_path / "out", {"report.html": b"x"})
    write_text(tmp_path / "a.txt", "x")
    assert (tmp_path / "out" / "report.html").read_bytes() == b"x"
    assert (tmp_path / "a.txt").read_text() == "x"


def test_uninstall_gives_sigint_its_default_action(noted) -> None:
    _interrupt.uninstall()
    assert signal.getsignal(signal.SIGINT) is signal.SIG_DFL


def test_a_handler_not_ours_is_left_alone() -> None:
    before = signal.getsignal(signal.SIGINT)
    try:
        signal.signal(signal.SIGINT, signal.SIG_IGN)  # inherited ignored (a background job)
        _interrupt.install()
        assert signal.getsignal(signal.SIGINT) is signal.SIG_IGN
        _interrupt.uninstall()
        assert signal.getsignal(signal.SIGINT) is signal.SIG_IGN
    finally:
        signal.signal(signal.SIGINT, before)


def test_pool_workers_start_with_sigint_held_back(noted) -> None:
    with process_pool(2) as ex:
        # started before the pool is handed out, not at a first submit somewhere later
        assert len(multiprocessing.active_children()) == 2
        assert signal.getsignal(signal.SIGINT) is _interrupt._handler  # restored
        assert ex.submit(abs, -3).result() == 3


def test_sigint_during_the_launch_is_raised_after_it(noted) -> None:
    reached = False
    with pytest.raises(KeyboardInterrupt):
        with _interrupt.deferred():
            os.kill(os.getpid(), signal.SIGINT)  # held back: nothing raised in here
            for _ in range(10000):
                pass
            reached = True
    assert reached


def test_deferred_without_an_interrupt_raises_nothing(noted) -> None:
    with _interrupt.deferred():
        pass
    assert signal.getsignal(signal.SIGINT) is _interrupt._handler
