"""Write the seed corpora: small valid inputs of every target into fuzz/seeds/<target>/.

Run once (``fuzz/run.sh`` does it when a seed folder is missing). Seeds are made from the
package's own writers and synthetic recordings, so they follow the formats as written.
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent


def _recordings():
    from contactlab.io import Recording

    t = np.arange(64) / 1000.0
    x = 2e-5 * np.sin(2 * np.pi * 10 * t)
    tang = Recording(t, {"x": x, "F": 40 * np.tanh(x / 1e-5)}, {"x": "m", "F": "N"})
    p = 0.5e6 + 0.4e6 * np.sin(2 * np.pi * 10 * t)
    norm = Recording(t, {"p": p, "delta": p * 1e-11}, {"p": "Pa", "delta": "m"})
    return {"tangential": tang, "normal": norm}


def write_seeds(root: Path = HERE / "seeds") -> None:
    from contactlab.io import write_recording

    recs = _recordings()
    for target, ext, options in (
        ("read_csv", ".csv", [{}]),
        ("read_tdms", ".tdms", [{}]),
        ("read_hdf5", ".h5", [{}]),
        ("read_mat", ".mat", [{}, {"version": "7.3"}]),
    ):
        out = root / target
        out.mkdir(parents=True, exist_ok=True)
        with tempfile.TemporaryDirectory() as tmp:
            for kind, rec in recs.items():
                for i, opt in enumerate(options):
                    p = Path(tmp) / f"{kind}{i}{ext}"
                    write_recording(p, rec, **opt)
                    (out / f"{kind}{i}").write_bytes(p.read_bytes())
        if target == "read_csv":
            (out / "units").write_bytes(b"t [ms];x [um];F [kN]\n0;0,5;1\n1;1,5;2\n2;2,5;2.5\n")
            (out / "mapped").write_bytes(b"time,disp,force\n0,0,0\n0.001,1e-6,3\n0.002,2e-6,5\n")
    man = root / "manifest"
    man.mkdir(parents=True, exist_ok=True)
    (man / "full").write_bytes(
        b"file,kind,material,normal_load [N],amplitude [um],p0 [MPa],pa [MPa]\n"
        b"tangential.csv,tangential,Al/Al,50,10,,\n"
        b"normal.mat,normal,C45/C45,,,0.5,0.4\n"
    )
    (man / "semicolon").write_bytes(
        b"file;kind;material;normal_load [kN]\ntangential.csv;tangential;St;0,05\n"
    )
    # export: what analyze --json writes for bundled recordings, behind an option byte
    from contactlab.cli import main as cli
    from contactlab.data import data_dir

    out = root / "export"
    out.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory() as tmp:
        for i, (kind, pattern) in enumerate(
            (("tangential", "tangential/*.csv"), ("normal", "normal/*.csv"))
        ):
            js = Path(tmp) / f"{kind}.json"
            src = sorted(data_dir().glob(pattern))[0]
            cli(["analyze", str(src), "--model", kind, "--json", str(js), "--no-progress"])
            for sel in (0, 3, 8, 16, 25):
                (out / f"{kind}{i}-{sel}").write_bytes(bytes([sel]) + js.read_bytes())
    # the structured targets decode bytes themselves: a few random starts are enough
    rng = np.random.default_rng(0)
    for target in ("kernels", "analyze", "diagnose", "track", "identify", "simulate"):
        out = root / target
        out.mkdir(parents=True, exist_ok=True)
        for i in range(8):
            (out / f"r{i}").write_bytes(rng.integers(0, 256, 256, dtype=np.uint8).tobytes())


if __name__ == "__main__":
    write_seeds(Path(sys.argv[1]) if len(sys.argv) > 1 else HERE / "seeds")
