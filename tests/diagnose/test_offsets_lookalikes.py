"""A displacement offset whose evidence lies in the first loading, and a look-alike that
yields only to a rival named at the same step (issue 29, helper offsets).

- a steady Masing loop is the same loop shifted along x: an offset of the displacement
  sensor shows in the first loading from rest, so its held-out gain sits in the first
  cycles and rule 2 passes by the proportional t across cycles (as a drift's does);
- a 2f load in phase with the stroke yields to a Stribeck term only when that term is the
  one named: a third candidate that outgains the Stribeck term but not the load leaves the
  load standing.
"""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np

import contactlab
from contactlab.diagnose._family import Prepared
from contactlab.diagnose.search import _proportional, _yield_to_lookalikes
from contactlab.diagnose.select import Verdict
from contactlab.masing import Masing

H0, AC = 10.0, 1e4


def test_a_displacement_offset_passes_rule_2_by_the_proportional_t():
    fam = SimpleNamespace(kind="tangential")
    assert _proportional(fam, ("displacement_offset",))
    # a candidate set with an effect whose gain is even across cycles does not
    assert not _proportional(fam, ("displacement_offset", "parallel_stiffness"))


def _offset_record(x0_share: float, seed: int = 3, acA: float = 4.0, cycles: int = 8):
    """A sine from rest at the sensor's reading ``x0`` (the contact's rest point), ramped
    over one cycle, in gross sliding; the force of Masing's rules on ``x - x0``; 1.5 % noise
    on x and 1 % on F (independent streams)."""
    A = acA / AC
    x0 = x0_share * A
    n_c = 250
    n = (cycles + 1) * n_c
    t = np.arange(n) / 2500.0
    ramp = np.clip(np.arange(n) / n_c, 0.0, 1.0)
    u = A * ramp * np.sin(2 * np.pi * np.arange(n) / n_c)
    F = Masing(H0, AC).force(u)
    rx, rf = np.random.default_rng([seed, 1]), np.random.default_rng([seed, 2])
    x = u + x0 + 0.015 * 2 * A * rx.standard_normal(n)
    F = F + 0.01 * float(np.ptp(F)) * rf.standard_normal(n)
    return t, x, F


def test_an_offset_seen_in_the_first_loading_is_named():
    t, x, F = _offset_record(0.2)
    rep = contactlab.diagnose((t, x, F), model="tangential")
    named = [e.name for e in rep.effects]
    assert "displacement_offset" in named, [str(v) for v in rep.steps[0].candidates]
    (x0,) = [e.parameters["x0"] for e in rep.effects if e.name == "displacement_offset"]
    A = 4.0 / AC
    assert abs(x0 - 0.2 * A) < 0.05 * A


def _in_phase_load(d, eps=0.1):
    f2 = 2.0 / (400 * d.dt)
    return {"h0": H0, "ac": AC, "eps_c": eps, "eps_s": 0.0, "f_n": f2}


def _record():
    n = 8 * 400
    t = np.arange(n) / 2000.0
    x = 3.0 / AC * np.sin(2 * np.pi * np.arange(n) / 400.0)
    return Prepared.build(t, x, Masing(H0, AC).force(x))


def _accepted(name, gain, p):
    v = Verdict(name, 1.0, gain, 10.0, -50.0, True, "accepted")
    return v, SimpleNamespace(full=SimpleNamespace(params=p))


def test_a_load_yields_to_a_stribeck_term_only_when_that_term_is_named():
    d = _record()
    fam = SimpleNamespace(kind="tangential")
    load = _accepted("normal_load", 1.0, _in_phase_load(d))
    strib = _accepted("stribeck", 0.8, {"h0": H0, "ac": AC, "s": 0.2, "v_s": 1e-3})
    # the Stribeck term is the best of the rest: the load yields to it
    spring = _accepted("parallel_stiffness", 0.7, {"h0": H0, "ac": AC, "k_p": 1e3})
    keep, verdicts = _yield_to_lookalikes(fam, [load, strib, spring], [load[0], strib[0],
                                                                       spring[0]], d)  # fmt: skip
    assert sorted(v.name for v, _ in keep) == ["parallel_stiffness", "stribeck"]
    assert not verdicts[0].accepted and "look-alike" in verdicts[0].reason
    # a spring outgains the Stribeck term, not the load: the load's reading fails, it stands
    spring = _accepted("parallel_stiffness", 0.98, {"h0": H0, "ac": AC, "k_p": 1e3})
    keep, verdicts = _yield_to_lookalikes(fam, [load, strib, spring], [load[0], strib[0],
                                                                       spring[0]], d)  # fmt: skip
    assert max(keep, key=lambda vc: vc[0].gain)[0].name == "normal_load"
    assert all(v.accepted for v in verdicts)
    # ... and a spring that outgains the load itself is named whatever the load does
    spring = _accepted("parallel_stiffness", 1.1, {"h0": H0, "ac": AC, "k_p": 1e3})
    keep, _ = _yield_to_lookalikes(fam, [load, strib, spring], [load[0], strib[0], spring[0]], d)
    assert max(keep, key=lambda vc: vc[0].gain)[0].name == "parallel_stiffness"
    assert "normal_load" not in [v.name for v, _ in keep]


def _fitted_offset(t, x, F):
    """The sensor zero ``F0`` a force offset fits on the steady loop (the second half of the
    record) of a Masing element of the record's own ``(H0, AC)`` on the measured ``x``."""
    half = t.size // 2
    return float(np.mean(F[half:] - Masing(H0, AC).force(x)[half:]))


def test_a_force_offset_must_explain_the_first_loading_from_rest():
    """No still stretch at the start (the ramp moves x from the first sample), but a first
    loading from rest: a sensor's zero is there before the motion, the shift a displacement
    offset draws is not."""
    eff = __import__("contactlab.diagnose.effects", fromlist=["registry"]).registry("tangential")[
        "force_offset"
    ]
    for acA in (1.0, 2.5):
        t, x, F = _offset_record(0.25, acA=acA)
        d = Prepared.build(t, x, F)
        p = {"h0": H0, "ac": AC, "F0": _fitted_offset(t, x, F)}
        ok, why = eff.plausible(d, p)
        assert not ok and "first loading from rest" in why, (acA, p, why)
        # a true sensor zero off by the same amount stands
        t, u, _ = _offset_record(0.0, acA=acA)
        F0 = p["F0"]
        G = Masing(H0, AC).force(u - float(u[0])) + F0
        G = G + 0.01 * float(np.ptp(G)) * np.random.default_rng(5).standard_normal(u.size)
        d = Prepared.build(t, u, G)
        ok, why = eff.plausible(d, {"h0": H0, "ac": AC, "F0": F0})
        assert ok, (acA, why)


def test_only_a_record_from_rest_is_checked_at_its_first_loading():
    """A record cut from a running test (full speed at its first sample) has no first
    loading from rest: a sensor's zero is not checked there."""
    from contactlab.diagnose.effects.tangential.force_offset import starts_slowly

    t, x, F = _offset_record(0.0)
    assert starts_slowly(Prepared.build(t, x, F))
    n = 8 * 250
    tc = np.arange(n) / 2500.0
    xc = 4.0 / AC * np.sin(2 * np.pi * np.arange(n) / 250.0)  # mid-stroke at full speed
    assert not starts_slowly(Prepared.build(tc, xc, Masing(H0, AC).force(xc)))
