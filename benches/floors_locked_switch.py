"""Run a bench with contactlab.diagnose.search.NOISE_LOCKED_RULE from $LOCKED (0: off, the
floors before stop 51; 1: on), for a before/after on one tree ($ANCHOR: its
LOCKED_ANCHOR_SHARE, 0 for stop 51's floor; $SIGZ: workflow.SIGNATURE_Z, inf for stop 51):

    LOCKED=0 nice .venv/bin/python benches/floors_locked_switch.py benches/eval_ideal_bound.py ...
"""

import os
import runpy
import sys

from contactlab.diagnose import search

search.NOISE_LOCKED_RULE = os.environ.get("LOCKED", "1") == "1"
# $ANCHOR: search.LOCKED_ANCHOR_SHARE (0: the locked floor of stop 51, no margin)
if "ANCHOR" in os.environ:
    search.LOCKED_ANCHOR_SHARE = float(os.environ["ANCHOR"])
print("LOCKED_ANCHOR_SHARE", search.LOCKED_ANCHOR_SHARE, file=sys.stderr)
# $SIGZ: workflow.SIGNATURE_Z (inf: no wave kept by its own signature, as at stop 51)
if "SIGZ" in os.environ:
    from contactlab.diagnose import workflow

    workflow.SIGNATURE_Z = float(os.environ["SIGZ"])
    print("SIGNATURE_Z", workflow.SIGNATURE_Z, file=sys.stderr)
print("NOISE_LOCKED_RULE", search.NOISE_LOCKED_RULE, file=sys.stderr)
script = sys.argv[1]
sys.argv = sys.argv[1:]
sys.path.insert(0, os.path.dirname(os.path.abspath(script)))
runpy.run_path(script, run_name="__main__")
