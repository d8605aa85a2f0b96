"""The stated bound of ``normal_load`` beside its rivals (issue 29, stop 53): the size at which
the load's own direction passes the gain rules *and* out-gains a dashpot and a parallel
spring (the search compares them by held-out gain at the same step), not the size at which
its direction beyond both rivals at once would pass the rules alone. On a short record near
gross sliding the two rivals together take nearly all of the load's in-phase part, and the
bound was none (or 11 times the ideal test's size) where such loads were named at 1-2 times
it (rig, ``benches/eval_ideal_bound.py --conds load_f``)."""

from __future__ import annotations

import warnings

import numpy as np
import pytest


def test_load_compares_with_its_rivals_on_the_heldout_units() -> None:
    """The load states its bound by the comparison with its rivals (``rival_rows``) over
    the held-out units (the cycles and the start-up), as the search compares them."""
    from contactlab.diagnose.effects import registry
    from contactlab.diagnose.select import heldout_unit

    eff = registry("tangential")["normal_load"]
    assert set(eff.rivals) == {"viscous_damping", "parallel_stiffness"}
    assert callable(getattr(eff, "rival_rows", None))
    # no margin beyond the comparison's own noise (the search names the larger gain)
    assert float(getattr(eff, "rival_z", 0.0)) == 0.0
    # the bound is widened beyond the linearised comparison (in phase with the stroke a
    # load was missed at it 4 times in 20 on the rig)
    from contactlab.diagnose.effects.tangential.normal_load import POWER_MARGIN
    from contactlab.diagnose.power import power_margin

    class _F:
        kind = "tangential"

    assert power_margin(_F(), "normal_load") == POWER_MARGIN >= 1.5

    class _D:
        pass

    cyc = np.array([-1, -1, 0, 0, 1, 1, 2, -1])

    class _C:
        cycle = cyc

    d = _D()
    d.cycles = _C()
    d.extra = {}
    assert np.array_equal(eff.rival_rows(d), heldout_unit(d) >= 0)


@pytest.mark.slow
def test_short_record_near_gross_sliding_states_a_load_bound() -> None:
    """Rig at the blind evaluation's missed load (fs 10 kHz, 17.5 Hz, 5 cycles, ac·A 1.75, x
    noise 0.9 % and F noise 1.8 % of the range), clean, tuning seed 53100000: a dashpot and
    a spring together took 89 % of the in-phase part's direction, its bound beyond the
    range (0.59 > 0.5): no bound. Compared as the search compares them, the bound is a few
    per cent (the ideal test's size 0.022; loads of 0.04 at phases 0, π/2, π, 3π/2 were
    named on tuning seeds 53100030-53100033)."""
    import contactlab
    from contactlab.synthetic.rig import rig_recording

    rec = rig_recording(
        {}, "tangential", seed=53100000, fs=10000.0, f=17.5, cycles=5, acA=1.75, h0=40.0,
        ac=4.0e4, x_noise=0.018, F_noise=0.036, x_drift=0.0, bits=16,
    )  # fmt: skip
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        rep = contactlab.diagnose((rec.t, rec.channels["x"], rec.channels["F"]), "tangential")
    assert rep.effect_names == []
    b = {x.effect: x for x in rep.not_detected}["normal_load"]
    assert b.detectable_above is not None, b.reason
    assert 0.01 < b.detectable_above < 0.1
    # the widened bound is 1.5 times the linearised one (at 1x it named 36 of 40)
    assert b.detectable_above > 0.045
    assert all(v is not None and v < 0.1 for v in b.per_parameter.values())
