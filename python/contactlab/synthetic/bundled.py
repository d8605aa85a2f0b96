"""Make the bundled example recordings (run: ``python -m contactlab.data.generate [--out DIR]``).

The generator lives outside :mod:`contactlab.data`, which holds only the files, because it
simulates with the models: the data package stays at the bottom of the import graph.

Everything is seeded, so the files are reproducible bit for bit from this script. What is
simulated, and why:

Tangential (the Masing paper; PHYSICS.md §1). A reciprocating tribometer at f = 1 Hz drives
the relative displacement ``x = A sin(2π f t)`` (starting from rest at the origin, so the first
quarter cycle is the virgin curve); the friction force is the Masing response with the virgin
curve ``f(u) = h0 (1 - exp(-ac u))``. Per material pair, ``h0 = μ W`` (saturation at the static
friction limit) and ``ac = ac_ref (W / W_ref)^(-1/3)``, so the initial stiffness
``k0 = h0 ac ∝ W^(2/3)`` grows with load as Mindlin's contact law has it and the paper measured.
Material pairs: Al/Al (μ = 0.42, stiff, loops of a few to 20 µm), PVC/steel (μ = 0.30, soft,
longer pre-sliding), steel/steel (μ = 0.18, amplitudes below 1 µm: the actuator reaches only a
small part of the loop, ``ac A < 0.1``, nearly pure stiffness — the paper's steel case where only
h0·ac is identifiable).

Sensor imperfections: displacement sensor with white noise (10 nm; 2 nm for the steel set's
capacitive probe), a zero offset and a slow thermal drift; load cell with white noise, an
offset, drift and 16-bit ADC quantisation over its range; the displacement is stored at 1 nm
resolution. Formats as rigs write them: CSV with units in the headers (``time [ms]``,
``disp [um]``, ``force [N]``), NI TDMS (channel ``unit_string``), HDF5 (``unit`` attributes)
and MATLAB .mat.

Normal (Konowalski 2009; PHYSICS.md §2). Dynamic pressure ``p = pa sin(ω t)`` about the static
pressure p0 = 0.5 ... 2.5 MPa, pa = 0.4 MPa, ω = 1 1/s, 256 samples per cycle as the paper's
rig; the displacement comes from :func:`contactlab.synthetic.normal.synthetic_recording` (the
nonlinear model, eq. 17, with a stiffness that grows with p0) with its sensor noise and
quantisation, plus an imperfect zeroing of the displacement probe.

The manifest lists each file with its tags and the true parameters (``true_h0``, ``true_ac``),
so a study can be checked against the truth.
"""

from __future__ import annotations

import argparse
import csv
import io
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .._io_atomic import write_text
from ..data import DATA_DIR
from ..masing import Masing

SEED = 20091  # one seed for the whole set; each file derives its own stream from it
FREQUENCY = 1.0  # Hz, as in the paper
FS = 200.0  # Hz: 200 samples per cycle
N_CYCLES = 6


@dataclass(frozen=True)
class MaterialPair:
    key: str  # file-name token (no "/" or "_")
    material: str
    mu: float  # h0 = mu * W
    ac_ref: float  # 1/m at W_ref
    w_ref: float  # N
    loads: tuple[float, ...]  # N
    amplitudes: tuple[float, ...]  # m
    formats: tuple[str, ...]  # file extensions, cycled over the recordings
    x_noise: float  # m, displacement sensor noise (1 sigma)
    f_noise: float  # N, load-cell noise (1 sigma)
    f_range: float  # N, load-cell range (ADC full scale is ± f_range)


MATERIALS = (
    MaterialPair(
        "Al-Al",
        "Al/Al",
        0.42,
        6.0e4,
        100.0,
        (50.0, 109.0, 150.0),
        (5e-6, 10e-6, 20e-6),
        ("csv",),
        10e-9,
        0.05,
        200.0,
    ),
    MaterialPair(
        "PVC-steel",
        "PVC/steel",
        0.30,
        2.5e4,
        60.0,
        (30.0, 60.0, 90.0),
        (10e-6, 20e-6, 40e-6),
        ("tdms",),
        10e-9,
        0.03,
        100.0,
    ),
    MaterialPair(
        "steel-steel",
        "steel/steel",
        0.18,
        5.0e4,
        75.0,
        (75.0, 150.0, 225.0),
        (0.25e-6, 0.5e-6, 1.0e-6),
        ("h5", "mat"),
        5e-9,
        0.02,
        50.0,
    ),
)

NORMAL_P0 = (0.5e6, 1.0e6, 1.5e6, 2.0e6, 2.5e6)  # Pa
NORMAL_PA = 0.4e6  # Pa
NORMAL_OMEGA = 1.0  # 1/s (Konowalski's ω)
NORMAL_FORMATS = ("csv", "mat")
NORMAL_CYCLES = 6  # the paper recorded 128 cycles of 256 samples; 6 keep the files small


def truth(pair: MaterialPair, load: float) -> tuple[float, float]:
    """True (h0, ac) of a material pair at normal load ``load``."""
    return pair.mu * load, pair.ac_ref * (load / pair.w_ref) ** (-1.0 / 3.0)


def tangential_signal(
    h0: float, ac: float, amplitude: float, rng: np.random.Generator, pair: MaterialPair
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Time (s), measured displacement (m) and force (N) with sensor imperfections."""
    n = round(N_CYCLES * FS / FREQUENCY) + 1
    t = np.arange(n) / FS
    x_true = amplitude * np.sin(2.0 * np.pi * FREQUENCY * t)
    f_true = Masing(h0, ac).force(x_true)
    duration = t[-1]
    # displacement sensor: zero offset, thermal drift (a few % of A over the record), noise
    x_off = rng.uniform(-0.3, 0.3) * amplitude
    x_drift = rng.uniform(-0.02, 0.02) * amplitude / duration
    x = x_true + x_off + x_drift * t + rng.normal(0.0, pair.x_noise, n)
    x = np.round(x / 1e-9) * 1e-9  # stored at 1 nm resolution
    # load cell: offset, drift, noise, 16-bit ADC over ± range
    f_off = rng.uniform(-0.02, 0.02) * pair.f_range
    f_drift = rng.uniform(-1e-4, 1e-4) * pair.f_range / duration
    f = f_true + f_off + f_drift * t + rng.normal(0.0, pair.f_noise, n)
    lsb = 2.0 * pair.f_range / 2**16
    f = np.round(f / lsb) * lsb
    return t, x, f


def _csv_text(header: Sequence[str], columns: Sequence[np.ndarray], fmts: Sequence[str]) -> str:
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(header)
    for row in zip(*columns, strict=True):
        w.writerow([fmt % v for fmt, v in zip(fmts, row, strict=True)])
    return buf.getvalue()


def write_tangential(path: Path, t: np.ndarray, x: np.ndarray, f: np.ndarray) -> Path:
    """Write in instrument units: time ms, displacement µm, force N."""
    ext = path.suffix.lower()
    if ext == ".csv":
        text = _csv_text(
            ["time [ms]", "disp [um]", "force [N]"],
            [t * 1e3, x * 1e6, f],
            ["%.3f", "%.4f", "%.6f"],
        )
        return write_text(path, text)
    from ..io import Recording, write_recording

    rec = Recording(
        t,
        {"x": x * 1e6, "F": f},
        {"x": "um", "F": "N"},
        source="contactlab.data.generate",
        meta={"units_of_t": "s"},
    )
    return write_recording(path, rec)


def write_normal(path: Path, t: np.ndarray, p: np.ndarray, delta: np.ndarray) -> Path:
    """Write in the paper's units: time s, pressure MPa, displacement µm."""
    ext = path.suffix.lower()
    if ext == ".csv":
        text = _csv_text(
            ["t [s]", "p [MPa]", "delta [um]"],
            [t, p * 1e-6, delta * 1e6],
            ["%.5f", "%.6f", "%.5f"],
        )
        return write_text(path, text)
    from ..io import Recording, write_recording

    rec = Recording(
        t,
        {"p": p * 1e-6, "delta": delta * 1e6},
        {"p": "MPa", "delta": "um"},
        source="contactlab.data.generate",
    )
    return write_recording(path, rec)


def normal_signal(p0: float, rng: np.random.Generator) -> tuple[np.ndarray, ...]:
    """Time (s), total pressure p0 + pa sin ωt (Pa) and displacement δ (m) of one test.

    :func:`contactlab.synthetic.normal.synthetic_recording` gives the steady-state response of the
    nonlinear model (eq. 17) with its "realistic" sensor noise (0.2 % of pa on p, 2 nm on δ,
    16-bit quantisation); the displacement probe's zeroing under p0 is left imperfect here
    (a residual offset of up to ±20 nm).
    """
    from .normal import synthetic_recording

    seed = int(rng.integers(2**31))
    t, p, delta = synthetic_recording(
        p0, NORMAL_PA, NORMAL_OMEGA, n_cycles=NORMAL_CYCLES, samples_per_cycle=256, seed=seed
    )
    t, p, delta = (np.asarray(a, dtype=float) for a in (t, p, delta))
    delta = delta + rng.uniform(-20e-9, 20e-9)
    return t, p, delta


MANIFEST_HEADER = [
    "file",
    "kind",
    "material",
    "normal_load [N]",
    "amplitude [um]",
    "frequency [Hz]",
    "p0 [MPa]",
    "pa [MPa]",
    "true_h0 [N]",
    "true_ac [1/m]",
]


def generate(out: Path, *, normal: bool = True) -> list[Path]:
    """Write every example recording and ``manifest.csv`` under ``out``; returns the paths."""
    root = np.random.SeedSequence(SEED)
    rows: list[list[str]] = []
    written: list[Path] = []
    for pair in MATERIALS:
        for i_w, load in enumerate(pair.loads):
            for i_a, amp in enumerate(pair.amplitudes):
                rng = np.random.default_rng(root.spawn(1)[0])
                h0, ac = truth(pair, load)
                ext = pair.formats[(i_w * len(pair.amplitudes) + i_a) % len(pair.formats)]
                name = f"tangential/{pair.key}_W{load:g}N_A{amp * 1e6:g}um.{ext}"
                t, x, f = tangential_signal(h0, ac, amp, rng, pair)
                written.append(write_tangential(out / name, t, x, f))
                rows.append(
                    [
                        name,
                        "tangential",
                        pair.material,
                        f"{load:g}",
                        f"{amp * 1e6:g}",
                        f"{FREQUENCY:g}",
                        "",
                        "",
                        f"{h0:.6g}",
                        f"{ac:.6g}",
                    ]
                )
    if normal:
        for i, p0 in enumerate(NORMAL_P0):
            rng = np.random.default_rng(root.spawn(1)[0])
            ext = NORMAL_FORMATS[i % len(NORMAL_FORMATS)]
            name = f"normal/C45-C45_p0-{p0 * 1e-6:g}MPa_pa-{NORMAL_PA * 1e-6:g}MPa.{ext}"
            t, p, delta = normal_signal(p0, rng)
            written.append(write_normal(out / name, t, p, delta))
            freq = NORMAL_OMEGA / (2.0 * np.pi)
            rows.append(
                [
                    name,
                    "normal",
                    "C45/C45",
                    "",
                    "",
                    f"{freq:.12g}",
                    f"{p0 * 1e-6:g}",
                    f"{NORMAL_PA * 1e-6:g}",
                    "",
                    "",
                ]
            )
    buf = io.StringIO()
    buf.write("# Example study made by contactlab.data.generate (seeded; see its docstring).\n")
    buf.write("# true_h0, true_ac: the parameters the tangential recordings were made with.\n")
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(MANIFEST_HEADER)
    w.writerows(rows)
    written.append(write_text(out / "manifest.csv", buf.getvalue()))
    for path in written:  # atomic writers create 0600 files; data files are for everyone
        path.chmod(0o644)
    return written


def main(argv: Sequence[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m contactlab.data.generate", description=__doc__)
    ap.add_argument(
        "--out", default=str(DATA_DIR), help="output folder (default: the package's data folder)"
    )
    ap.add_argument("--no-normal", action="store_true", help="tangential recordings only")
    args = ap.parse_args(argv)
    paths = generate(Path(args.out), normal=not args.no_normal)
    total = sum(p.stat().st_size for p in paths)
    print(f"wrote {len(paths)} files, {total / 1e6:.2f} MB, under {args.out}")
    return 0


if __name__ == "__main__":  # pragma: no cover
    raise SystemExit(main())
