"""No internal message reaches a user on the analyze path (issue 8 item 7): a constant force,
values near the float64 limits, a channel of zeros, pure noise — each gets a sentence about
the data (typed error, exit code 1, no traceback, no numpy warning) or an honest result."""

from __future__ import annotations

import numpy as np
import pytest

from contactlab.cli import main

T = np.arange(3000) / 1000.0
X = 20e-6 * np.sin(2 * np.pi * T)
F = 10 * np.tanh(X / 5e-6) + 0.01 * np.random.default_rng(0).normal(size=T.size)
P = 0.5e6 + 0.4e6 * np.sin(2 * np.pi * T)
D = 1e-6 * np.sin(2 * np.pi * T - 0.1)


def _write(path, header, a, b):
    rows = "\n".join(f"{t:.6f},{u:.10e},{v:.10e}" for t, u, v in zip(T, a, b, strict=True))
    path.write_text(header + "\n" + rows + "\n")
    return path


TANGENTIAL = {
    "constant_force": (X, np.full(T.size, 3.0), "F is constant (3 N"),
    "zero_force": (X, np.zeros(T.size), "F is zero in all"),
    "zero_displacement": (np.zeros(T.size), F, "x is zero in all"),
    "huge_force": (X, F * 1e299, "beyond any physical force"),
    "huge_displacement": (X * 1e300, F, "beyond any physical displacement"),
    "tiny_force": (X, F * 1e-300, "far below any physical force"),
    "tiny_displacement": (X * 1e-157, F, "far below any physical displacement"),
}
NORMAL = {
    "constant_pressure": (np.full(T.size, 0.5e6), D, "p is constant"),
    "zero_pressure": (np.zeros(T.size), D, "p is zero in all"),
    "zero_displacement": (P, np.zeros(T.size), "delta is"),
    "huge_pressure": (P * 1e299, D, "beyond any physical pressure"),
    "huge_displacement": (P, D * 1e300, "beyond any physical displacement"),
}
INTERNAL = ("Traceback", "outside [nan", "must be finite and > 0", "RuntimeWarning", "singular")


@pytest.mark.parametrize("case", sorted(TANGENTIAL))
def test_tangential_bad_data_gets_a_sentence(case, tmp_path, capsys):
    x, f, expected = TANGENTIAL[case]
    path = _write(tmp_path / f"{case}.csv", "t [s],x [m],F [N]", x, f)
    out = tmp_path / "o.json"
    assert main(["analyze", str(path), "--model", "tangential", "--json", str(out)]) == 1
    err = capsys.readouterr().err
    assert expected in err and path.name in err
    assert not any(s in err for s in INTERNAL)
    assert not out.exists()


@pytest.mark.parametrize("case", sorted(NORMAL))
def test_normal_bad_data_gets_a_sentence(case, tmp_path, capsys):
    p, d, expected = NORMAL[case]
    path = _write(tmp_path / f"{case}.csv", "t [s],p [Pa],delta [m]", p, d)
    assert main(["analyze", str(path), "--model", "normal", "--json", "-"]) == 1
    err = capsys.readouterr().err
    assert expected in err and not any(s in err for s in INTERNAL)


def test_noise_only_force_is_refused_with_a_sentence(tmp_path, capsys):
    """Pure noise on the force (issue 31: it gave "± nan N/m (inf%)" and "ac < inf")."""
    f = np.random.default_rng(3).normal(size=T.size)
    path = _write(tmp_path / "noise.csv", "t [s],x [m],F [N]", X, f)
    out = tmp_path / "o.json"
    assert main(["analyze", str(path), "--model", "tangential", "--json", str(out)]) == 1
    assert not out.exists()
    err = capsys.readouterr().err
    assert "no friction loop in this recording" in err and "not distinguishable from zero" in err
    assert not any(s in err for s in (*INTERNAL, "nan", "inf"))
