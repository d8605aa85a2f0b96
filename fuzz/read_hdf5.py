"""Fuzz target: the HDF5 reader (`read_recording` on a `.h5` file).

Invariant: bytes → a Recording (t finite, strictly increasing; channels finite, with units)
or a `RecordingError`; nothing else (see _harness.py).
"""

from __future__ import annotations

from _harness import main
from _readers import reader_target

TARGET = "read_hdf5"
one_input = reader_target(".h5")

if __name__ == "__main__":
    main(one_input)
