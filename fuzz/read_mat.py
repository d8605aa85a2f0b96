"""Fuzz target: the MAT reader (`read_recording` on a `.mat` file).

Invariant: bytes → a Recording (t finite, strictly increasing; channels finite, with units)
or a `RecordingError`; nothing else (see _harness.py).
"""

from __future__ import annotations

from _harness import main
from _readers import reader_target

TARGET = "read_mat"
one_input = reader_target(".mat")

if __name__ == "__main__":
    main(one_input)
