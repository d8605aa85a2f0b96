"""Fuzz target: the CSV reader (`read_recording` on a `.csv` file).

Invariant: bytes → a Recording (t finite, strictly increasing; channels finite, with units)
or a `RecordingError`; nothing else (see _harness.py).
"""

from __future__ import annotations

from _harness import main
from _readers import reader_target

TARGET = "read_csv"
one_input = reader_target(".csv")

if __name__ == "__main__":
    main(one_input)
