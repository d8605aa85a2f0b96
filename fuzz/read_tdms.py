"""Fuzz target: the TDMS reader (`read_recording` on a `.tdms` file).

Invariant: bytes → a Recording (t finite, strictly increasing; channels finite, with units)
or a `RecordingError`; nothing else (see _harness.py).
"""

from __future__ import annotations

from _harness import main
from _readers import reader_target

TARGET = "read_tdms"
one_input = reader_target(".tdms")

if __name__ == "__main__":
    main(one_input)
