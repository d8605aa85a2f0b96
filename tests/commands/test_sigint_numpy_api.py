"""A Ctrl-C while numpy's C-API table loads, or while the command line is imported, is an
interrupt: never a panic, never a traceback.

The ``numpy`` crate loads that table on the first array the binding touches, and the load runs
Python code (``numpy.lib.NumpyVersion``). A ``KeyboardInterrupt`` raised there used to become a
Rust panic (``PanicException``, status 1: a ``demo`` run given SIGINT as it drew its first
Masing loop, CI of stop 46). The binding now loads the table at import under SIGINT deferral.
Here the interrupt is made to land exactly in that load.
"""

from __future__ import annotations

import subprocess
import sys
import textwrap

SCRIPT = textwrap.dedent(
    """
    import signal
    import numpy.lib

    # Python's own Ctrl-C handler, whatever this test run inherited (CI starts the suite with
    # SIGINT ignored: then no interrupt could land anywhere)
    signal.signal(signal.SIGINT, signal.default_int_handler)
    real = numpy.lib.NumpyVersion
    calls = []

    def interrupted(*args):
        # a SIGINT delivered while the table loads: its handler runs here
        calls.append(1)
        signal.raise_signal(signal.SIGINT)
        return real(*args)

    numpy.lib.NumpyVersion = interrupted
    try:
        import contactlab._core as core
    except KeyboardInterrupt:
        outcome = "KeyboardInterrupt"
    except BaseException as e:  # PanicException derives from BaseException
        outcome = type(e).__name__
    else:
        try:
            core.loop_area  # noqa: B018
            import numpy as np
            from contactlab import loop_area
            x = np.sin(np.linspace(0, 6.283, 101))
            loop_area(x, x)
            outcome = "no interrupt"
        except KeyboardInterrupt:
            outcome = "KeyboardInterrupt"
        except BaseException as e:
            outcome = type(e).__name__
    numpy.lib.NumpyVersion = real
    print(outcome, len(calls))
    # the load was not left half done: the binding works once the interrupt is handled
    import numpy as np
    import contactlab._core  # noqa: F401
    from contactlab import loop_area
    x = np.sin(np.linspace(0, 6.283, 101))
    print(round(loop_area(x, -np.cos(np.linspace(0, 6.283, 101))), 3))
    """
)


def test_interrupt_during_numpy_api_load_is_keyboard_interrupt() -> None:
    r = subprocess.run([sys.executable, "-c", SCRIPT], capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr[-2000:]
    lines = r.stdout.split()
    assert lines[:2] == ["KeyboardInterrupt", "1"], (r.stdout, r.stderr[-2000:])
    assert "panicked" not in r.stderr, r.stderr[-2000:]
    assert abs(abs(float(lines[2])) - 3.142) < 0.01, r.stdout


CLI_IMPORT = textwrap.dedent(
    """
    import runpy
    import sys

    class Interrupt:
        # a SIGINT landing while `python -m contactlab` imports its command line
        def find_spec(self, name, path=None, target=None):
            if name == "contactlab.cli":
                raise KeyboardInterrupt
            return None

    sys.meta_path.insert(0, Interrupt())
    runpy.run_module("contactlab", run_name="__main__")
    """
)


def test_interrupt_while_the_command_line_imports_exits_130_without_traceback() -> None:
    r = subprocess.run(
        [sys.executable, "-c", CLI_IMPORT], capture_output=True, text=True, timeout=120
    )
    assert r.returncode == 130, (r.returncode, r.stderr[-2000:])
    assert "Traceback" not in r.stderr, r.stderr[-2000:]
    assert "interrupted; no partial outputs written" in r.stderr


WRAPPED = textwrap.dedent(
    """
    import runpy
    import sys

    class Interrupt:
        # a SIGINT landing in a class body's __set_name__ while a verb's imports run:
        # Python hands it on wrapped in RuntimeError (CI: matplotlib's Axis, stop 47)
        def find_spec(self, name, path=None, target=None):
            if name == "contactlab.commands.demo":
                try:
                    raise KeyboardInterrupt
                except KeyboardInterrupt as exc:
                    raise RuntimeError("Error calling __set_name__") from exc
            return None

    sys.meta_path.insert(0, Interrupt())
    sys.argv = ["contactlab", "demo", "--quick", "--out", sys.argv[1]]
    runpy.run_module("contactlab", run_name="__main__")
    """
)


def test_an_interrupt_wrapped_in_another_exception_exits_130(tmp_path) -> None:
    out = tmp_path / "out"
    r = subprocess.run(
        [sys.executable, "-c", WRAPPED, str(out)], capture_output=True, text=True, timeout=120
    )
    assert r.returncode == 130, (r.returncode, r.stderr[-2000:])
    assert "Traceback" not in r.stderr, r.stderr[-2000:]
    assert "interrupted; no partial outputs written" in r.stderr
    assert not out.exists()
