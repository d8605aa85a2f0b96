"""``python -m contactlab.data.generate [--out DIR]``: remake the bundled example recordings.

The generator is :mod:`contactlab.synthetic.bundled` (it simulates with the models, which the data
package must not import); this module forwards the command and its names there.
"""

from __future__ import annotations

import importlib
from typing import Any

_HOME = "contactlab.synthetic.bundled"


def __getattr__(name: str) -> Any:
    return getattr(importlib.import_module(_HOME), name)


if __name__ == "__main__":  # pragma: no cover - exercised through a subprocess in the tests
    raise SystemExit(importlib.import_module(_HOME).main())
