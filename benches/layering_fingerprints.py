"""Fingerprints that show a refactoring left the numbers alone (issue 32).

Prints one SHA-256 (first 16 hex digits) per line for: the ``contactlab analyze --json``
output of the bundled example data (tangential and normal, each run as the CLI runs it), and
fixed-seed outputs of the functions the layering split — the rig simulator
(``rig_recording``, ``masing_force``), ``hidden_effect_recording``, ``analyze_tangential``
(the steps of ``tangential/steps.py``), ``normal.analyze_loop``, ``io.resolve_columns`` and
``structure.identify``. Arrays are hashed by their bytes, dicts as sorted JSON with floats by
``repr``: any change of a bit shows.

    python benches/layering_fingerprints.py > before.txt   # on the old tree
    python benches/layering_fingerprints.py > after.txt    # on the new one
    diff before.txt after.txt
"""

from __future__ import annotations

import hashlib
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import Any

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT / "python" / "contactlab" / "data"


def _feed(h: Any, obj: Any) -> None:
    if isinstance(obj, np.ndarray):
        h.update(f"{obj.dtype}{obj.shape}".encode())
        h.update(np.ascontiguousarray(obj).tobytes())
    elif isinstance(obj, dict):
        for k in sorted(obj, key=str):
            h.update(repr(k).encode())
            _feed(h, obj[k])
    elif isinstance(obj, (list, tuple)):
        h.update(b"[")
        for v in obj:
            _feed(h, v)
        h.update(b"]")
    elif isinstance(obj, (float, np.floating)):
        h.update(repr(float(obj)).encode())
    else:
        h.update(repr(obj).encode())


def digest(obj: Any) -> str:
    """The first 16 hex digits of the SHA-256 of an object's arrays, numbers and keys."""
    h = hashlib.sha256()
    _feed(h, obj)
    return h.hexdigest()[:16]


def analyze_json() -> dict[str, str]:
    """``contactlab analyze --json`` of the bundled data, per kind (paths relative)."""
    out = {}
    exe = Path(sys.executable).parent / "contactlab"
    for kind in ("tangential", "normal"):
        files = sorted(p.name for p in (DATA / kind).glob("*.csv"))
        with tempfile.TemporaryDirectory() as tmp:
            js = Path(tmp) / "out.json"
            run = subprocess.run(
                [exe, "analyze", *files, "--json", str(js), "--workers", "0"],
                cwd=DATA / kind,
                capture_output=True,
                text=True,
                env={**os.environ, "PYTHONHASHSEED": "0"},
            )
            if run.returncode != 0:
                raise SystemExit(run.stdout + run.stderr)
            out[f"analyze --json {kind}"] = hashlib.sha256(js.read_bytes()).hexdigest()[:16]
            said = run.stdout.replace(str(js), "OUT.json")  # the temporary path varies
            out[f"analyze stdout {kind}"] = hashlib.sha256(said.encode()).hexdigest()[:16]
    return out


def rig() -> dict[str, str]:
    """The rig simulator: every effect alone, a few together, both kinds, and the operator."""
    from contactlab.synthetic import rig as r

    out = {}
    cases: list[tuple[str, Any]] = [("tangential", ())]
    for name in r.TANGENTIAL_EFFECTS + r.NEW_EFFECTS:
        cases.append(("tangential", [name]))
    cases += [
        ("tangential", {"channel_delay": {"tau": 2e-4}, "viscous_damping": {"c": 30.0}}),
        ("tangential", {"series_compliance": {"k_s": 3e6}, "non_masing_scaling": {"lam": 2.4}}),
        ("tangential", {"stick_slip": {"b": 0.1}, "stribeck": {"s": 0.2}}),
        ("tangential", {"power_law_microslip": {"chi": -0.4, "beta": 0.1}}),
        ("tangential", {"rate_dependent_presliding": {"sigma1": 0.5}}),
        ("tangential", {"backlash": {"b": 1e-6}, "force_drift": {"rate": 0.3}}),
        ("normal", ()),
        ("normal", {"stiffness_nonlinearity": {"a2": 1e17}, "channel_delay": {"tau": 1e-3}}),
        ("normal", {"hysteretic_damping": {"eta": 0.05}, "creep_drift": {"D": 1e-8}}),
        ("normal", {"asymmetric_branches": {"a": 0.1}}),
    ]
    for i, (kind, eff) in enumerate(cases):
        kw: dict[str, Any] = {"seed": 100 + i, "cycles": 3}
        if kind == "normal":
            kw.update(frequencies=(1.0, 2.0), cycles=2)
        rec = r.rig_recording(eff, kind, **kw)
        out[f"rig_recording {kind} {json.dumps(eff, sort_keys=True)}"] = digest(
            [rec.t, rec.channels, rec.truth]
        )
    rec = r.rig_recording(["channel_delay"], seed=7, cycles=2, bits=None, ramp_cycles=0.0)
    out["rig_recording no ADC, abrupt"] = digest([rec.t, rec.channels, rec.truth])
    rng = np.random.default_rng(5)
    x = np.cumsum(rng.standard_normal(3000)) * 1e-6
    v = r.Virgin.exponential(40.0, 4e4)
    for lam in (2.0, 1.7, 2.6):
        for k_s in (np.inf, 2e6):
            force = r.masing_force(x, v, lam=lam, k_s=k_s)
            out[f"masing_force lam={lam} k_s={k_s}"] = digest(force)
    seg = r.Virgin.segalman(40.0, 1.6e6, -0.5, 0.2)
    out["masing_force segalman"] = digest(r.masing_force(x, seg))
    out["play_operator"] = digest(r.play_operator(x, 2e-6))
    return out


def hidden() -> dict[str, str]:
    """``hidden_effect_recording`` for each tangential effect, a pair, and the normal kind."""
    from contactlab.synthetic.diagnosis import TANGENTIAL_EFFECTS, hidden_effect_recording

    out = {}
    for i, name in enumerate(TANGENTIAL_EFFECTS):
        rec = hidden_effect_recording([name], seed=200 + i, samples_per_cycle=60)
        out[f"hidden {name}"] = digest([rec.t, rec.data, rec.truth])
    for kw in (
        {"effects": [], "seed": 1},
        {"effects": {"force_offset": 0.03, "channel_delay": 0.05}, "seed": 2, "start": "steady"},
        {"effects": ["viscous_damping"], "seed": 3, "anti_alias": (0.5, 0.4), "bits": 12},
        {"effects": ["channel_delay"], "seed": 4, "model": "normal"},
        {"effects": [], "seed": 5, "model": "normal", "frequencies": [1.0]},
    ):
        rec = hidden_effect_recording(**kw)
        out[f"hidden {json.dumps(kw, sort_keys=True)}"] = digest([rec.t, rec.data, rec.truth])
    return out


def analyses() -> dict[str, str]:
    """``analyze_tangential``, ``analyze_loop``, ``resolve_columns`` and ``identify``."""
    from contactlab.errors import ContactLabError
    from contactlab.io.recording import resolve_columns
    from contactlab.normal import analyze_loop
    from contactlab.structure import Structure, identify
    from contactlab.synthetic.normal import synthetic_recording as normal_recording
    from contactlab.synthetic.tangential import synthetic_recording
    from contactlab.tangential import analyze_tangential

    out = {}
    for seed, acA in ((11, 0.8), (12, 3.0), (13, 8.0)):
        rec = synthetic_recording(
            h0=40.0, ac=4e4, amplitude=acA / 4e4, n_cycles=6, fs=2000.0, noise=0.01, seed=seed
        )
        res = analyze_tangential(rec, warn=False)
        out[f"analyze_tangential seed={seed}"] = digest(res.to_dict())
    for seed, kw in ((21, {}), (22, {"pa": 0.4e6}), (23, {"zero_delta": False, "degree": 3})):
        t, p, d = normal_recording(model="table2", n_cycles=5, noise=0.01, seed=seed)
        res = analyze_loop(t, p, d, **kw)
        out[f"analyze_loop seed={seed} {kw}"] = digest(res.to_dict(arrays=True))
    t, p, d = normal_recording(model="table2", n_cycles=5, noise=0.01, seed=24)
    res = analyze_loop(t, p, d, options={"degree": 3, "pa": 0.4e6})
    out["analyze_loop seed=24 options={degree: 3, pa: 4e5}"] = digest(res.to_dict(arrays=True))
    layouts = [
        (["t [ms]", "x [um]", "F [N]"], {}, None, {}),
        (["time", "disp", "force", "other"], {}, None, {}),
        (["p / MPa", "delta [um]", "t"], {}, None, {}),
        (["a", "b", "c"], {"x": "a", "F": "b"}, "tangential", {}),
        (["t", "x_top", "x_base", "F"], {}, "frame", {}),
        (["a", "b"], {}, None, {"F": "complex", "data": "a MATLAB struct"}),
        (["t", "x"], {}, "tangential", {"F": "text"}),
        (["t", "x", "F"], {"F": "nothing"}, None, {}),
    ]
    for avail, cols, kind, unusable in layouts:
        try:
            got: Any = resolve_columns(
                avail, columns=cols, kind=kind, file="f.csv", unusable=unusable
            )
        except ContactLabError as exc:
            got = f"{type(exc).__name__}: {exc}"
        out[f"resolve_columns {avail} {cols} {kind} {unusable}"] = digest(got)
    rng = np.random.default_rng(90213)
    n, fs = 600, 500.0
    t = np.arange(n) / fs
    u = sum(np.sin(2 * np.pi * f * t + rng.uniform(0, 2 * np.pi)) for f in np.arange(3, 60, 0.5))
    u *= 6.0 / np.std(u)
    s = Structure(1.0, 2.0, 4e3)
    s.add_joint("jenkins", 0, k=3e3, fs=2.0)
    y = s.simulate(t, force=u, substeps=4).x
    um = u + 0.01 * np.std(u) * rng.standard_normal(n)
    ym = y + 0.01 * np.std(y) * rng.standard_normal(n)
    m = identify(t, um, ym, joint="jenkins", substeps=1, multistart=False)
    d = m.to_dict()
    d.pop("elapsed", None)
    out["identify jenkins sdof"] = digest(d)
    m = identify(t[:300], um[:300], ym[:300], joint="jenkins", substeps=1, start_samples=200)
    d = m.to_dict()
    d.pop("elapsed", None)
    out["identify jenkins multistart"] = digest(d)
    # a short base-excited frame on which the equation error fails: the grid starts
    from contactlab.structure.identify import equation_error

    for seed in range(91000, 91100):
        frame = _short_frame(seed)
        if equation_error(*frame, "base", 3.08)["k"] <= 0:
            break
    m = identify(*frame, joint="jenkins", excitation="base", mass=3.08, substeps=2)
    d = m.to_dict()
    d.pop("elapsed", None)
    out[f"identify short frame seed={seed} (grid starts)"] = digest(d)
    # two DOFs, a Jenkins joint between them, force on the second (identify_mdof)
    rng = np.random.default_rng(40417)
    n = 600
    t = np.arange(n) / 500.0
    u = sum(np.sin(2 * np.pi * f * t + rng.uniform(0, 2 * np.pi)) for f in np.arange(3, 60, 0.5))
    u = u * 6.0 / np.std(u)
    K = np.array([[6e3, -2e3], [-2e3, 2e3]])
    C = np.array([[3.0, -1.0], [-1.0, 1.0]])
    s2 = Structure(np.diag([1.0, 0.5]), C, K)
    s2.add_joint("jenkins", 0, 1, k=1.5e3, fs=1.5)
    f2 = np.zeros((n, 2))
    f2[:, 1] = u
    y2 = s2.simulate(t, force=f2, substeps=4).x
    um = u + 0.01 * np.std(u) * rng.standard_normal(n)
    ym = y2 + 0.01 * np.std(y2, axis=0) * rng.standard_normal(y2.shape)
    m = identify(t, um, ym, joint="jenkins", joint_dofs=(0, 1), input_dof=1, substeps=1)
    d = m.to_dict()
    d.pop("elapsed", None)
    out["identify_mdof jenkins between DOFs"] = digest(d)
    return out


def _short_frame(seed: int, n: int = 400) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A base-excited frame with a Jenkins joint to the wall, 400 samples (as
    tests/structure/test_identify.py)."""
    from contactlab.structure import Structure

    rng = np.random.default_rng(seed)
    t = np.arange(n) * 1e-3
    freqs = np.array([1.0, 2.7, 4.3]) * rng.uniform(0.9, 1.1)
    arg = 2 * np.pi * freqs[None, :] * t[:, None] + rng.uniform(0, 2 * np.pi, 3)
    ub = np.sin(arg) @ (np.array([1.0, 0.3, 0.16]) * 1e-3)
    s = Structure(3.08, 0.67, 1200.0)
    s.add_joint("jenkins", 0, k=6000.0, fs=0.9)
    x = s.simulate(t, base=ub, substeps=4).x
    u = ub + 0.03 * np.std(ub) * rng.standard_normal(n)
    return t, u, x + 0.03 * np.std(x) * rng.standard_normal(n)


def main() -> int:
    out: dict[str, str] = {}
    for part in (analyze_json, rig, hidden, analyses):
        out.update(part())
    for k, v in out.items():
        print(f"{v}  {k}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
