"""``Structure.simulate(..., outputs=...)``: the outputs asked for equal a full run's, the
others come back empty; unknown names are an InputError."""

from __future__ import annotations

import numpy as np
import pytest

import contactlab
from contactlab.structure import Structure

ALL = ("x", "v", "a", "joint_force", "joint_energy", "joint_work", "input_work", "damping_work")


def _structure(n: int) -> Structure:
    if n == 1:
        s = Structure(0.8, 1.5, 900.0)
    else:
        s = Structure(np.diag([0.8, 0.5]), [[1.5, -0.5], [-0.5, 0.5]], [[900, -400], [-400, 400]])
    s.add_joint("masing", 0, h0=3.0, ac=2e3, scale=2.0)
    if n == 2:
        s.add_joint("jenkins", 1, k=300.0, fs=0.6)
    return s


@pytest.mark.parametrize("n", [1, 2])
@pytest.mark.parametrize(
    "wanted", [("x",), ("joint_energy", "v"), ("input_work", "damping_work", "a")]
)
def test_selected_outputs_equal_the_full_run(n: int, wanted: tuple[str, ...]) -> None:
    s = _structure(n)
    t = np.arange(1500) * 1e-3
    f = 2.0 * np.sin(2 * np.pi * 4.0 * t) + 0.8 * np.cos(47.0 * t)
    f = f if n == 1 else np.column_stack([f, 0.5 * f])
    full = s.simulate(t, force=f)
    part = s.simulate(t, force=f, outputs=wanted)
    assert part.success and (part.n_steps, part.n_iter) == (full.n_steps, full.n_iter)
    for name in ALL:
        got, want = getattr(part, name), getattr(full, name)
        if name in wanted:
            np.testing.assert_array_equal(got, want)
        else:
            assert got.size == 0 and got.shape[1:] == want.shape[1:], name


def test_selected_outputs_with_substeps_and_periodic() -> None:
    s = _structure(1)
    t = np.arange(400) * 2.5e-3
    f = 2.0 * np.sin(2 * np.pi * t / (t[-1] + t[1]))
    for kw in ({"substeps": 3}, {"periodic": True}):
        full = s.simulate(t, force=f, **kw)
        part = s.simulate(t, force=f, outputs=["x"], **kw)
        np.testing.assert_array_equal(part.x, full.x)
        assert part.a.size == 0 and part.t.size == full.t.size


def test_no_joints_keeps_its_zero_width_joint_arrays() -> None:
    s = Structure(1.0, 0.5, 100.0)
    t = np.arange(50) * 1e-2
    full = s.simulate(t, force=np.sin(t))
    part = s.simulate(t, force=np.sin(t), outputs=["x"])
    assert full.joint_force.shape == (50, 0) and part.joint_force.shape == (0, 0)
    np.testing.assert_array_equal(part.x, full.x)


def test_unknown_output_is_an_input_error() -> None:
    s = _structure(1)
    t = np.arange(10) * 1e-3
    with pytest.raises(contactlab.InputError, match="unknown output 'y'"):
        s.simulate(t, force=np.zeros(10), outputs=("x", "y"))
