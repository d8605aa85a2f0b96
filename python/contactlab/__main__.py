"""``python -m contactlab ...``: the same command line as the ``contactlab`` script (useful when
the venv's ``bin/`` is not on ``PATH``, e.g. on a shared test-rig PC or in a notebook)."""

import sys

from .cli import main

sys.exit(main())
