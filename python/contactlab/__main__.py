"""``python -m contactlab ...``: the same command line as the ``contactlab`` script (useful when
the venv's ``bin/`` is not on ``PATH``, e.g. on a shared test-rig PC or in a notebook)."""

import sys

try:
    from .cli import main
except KeyboardInterrupt:
    # a Ctrl-C while the command line itself is imported (a loaded machine can take most of
    # a second): nothing has started, nothing is written; say so with the interrupt's status
    # instead of a traceback out of the import machinery
    print("contactlab: interrupted; no partial outputs written", file=sys.stderr)
    sys.exit(130)

sys.exit(main())
