"""Run a bench script with the misfit null's decision computed both without and with the
hum's directions (``misfit_null.HUM``, stop 48): the script sees the decision with them
(this tree); each diagnosed record adds a line ``humcmp <n> harmonics [...] before <flag>
after <flag>`` to stderr, the same final model and null draws in both. Where a record has no
drive harmonic near the mains (:func:`contactlab.diagnose.misfit_null.hum_harmonics` empty)
both decisions are the same computation.

    nice .venv/bin/python benches/hum_compare.py benches/eval_clean_quiet.py 482000 0.5
"""

from __future__ import annotations

import runpy
import sys
from typing import Any

import contactlab.diagnose.misfit_null as mn

_original = mn.simulated_null
_original_flag = mn.calibrated_flag
_count = [0]
_before: list[Any] = [None, []]


def _both(*a: Any, **k: Any) -> Any:
    _count[0] += 1
    mn.HUM = False
    _before[0] = _original(*a, **k)
    mn.HUM = True
    _before[1] = [round(f, 2) for f in mn.hum_harmonics(a[3])]
    return _original(*a, **k)


def _flag(nd: Any, *a: Any, **k: Any) -> dict[str, Any]:
    after = _original_flag(nd, *a, **k)
    before = None if _before[0] is None else _original_flag(_before[0], *a, **k)
    print(
        f"humcmp {_count[0]} harmonics {_before[1]} "
        f"before {None if before is None else before['by']} "
        f"T {None if before is None else before['T']} / "
        f"{None if before is None else before['T_threshold']} "
        f"after {after['by']} T {after['T']} / {after['T_threshold']}",
        file=sys.stderr,
        flush=True,
    )
    return after


mn.simulated_null = _both
mn.calibrated_flag = _flag
script = sys.argv[1]
sys.argv = sys.argv[1:]
runpy.run_path(script, run_name="__main__")
