"""Bundled example recordings for ``contactlab demo`` and the tutorials.

Synthetic but realistic (sensor noise, offsets, ADC quantisation, slow drift), made by the
seeded script :mod:`contactlab.synthetic.bundled` (``python -m contactlab.data.generate``):

- tangential: three material pairs (Al/Al, PVC/steel, steel/steel) at three normal loads and
  three amplitudes each, Masing hysteresis with an exponential virgin curve (the tangential
  paper); steel/steel with a tiny loop where only h0·ac is identifiable;
- normal: ground C45 steel rings at p0 = 0.5-2.5 MPa, pa = 0.4 MPa, ω = 1 1/s (Konowalski 2009);

in CSV (units in the headers), NI TDMS, HDF5 and MATLAB .mat, listed in ``manifest.csv`` with
their tags and the true parameters used to make them (``true_*`` columns).
"""

from __future__ import annotations

from pathlib import Path

DATA_DIR = Path(__file__).resolve().parent


def data_dir() -> Path:
    """Folder of the bundled example recordings."""
    return DATA_DIR


def manifest_path() -> Path:
    """Manifest of the bundled example study (tags and true parameters per recording)."""
    return DATA_DIR / "manifest.csv"
