"""A load fluctuation whose sideband ``f_n ± j f`` sits on a mains line the force still
carries is refused: the friction force times ``cos 2π f_n t`` puts a line there, and the
record cannot tell it from the hum (``normal_load.mains_line_sideband``, stop 48: a clean
record of the blind evaluation, 40.5 Hz drive, had a 0.6 % load named at 90.53 Hz = 50 Hz + f
where the force carried a 50 Hz line the mains remover had not confirmed in each third)."""

from __future__ import annotations

import numpy as np

from contactlab.diagnose._family import Prepared
from contactlab.diagnose.candidates_tangential import TangentialFamily
from contactlab.diagnose.effects.tangential.normal_load import (
    _force_mains_lines,
    hum_sideband,
    mains_line_sideband,
)
from contactlab.synthetic.rig import rig_recording

F, CYC, FS = 11.0, 20, 2000.0


def _prepared(hum: float) -> Prepared:
    rec = rig_recording(
        {}, "tangential", seed=4861, fs=FS, f=F, cycles=CYC, acA=1.5, x_noise=0.01, F_noise=0.01
    )
    t, x, y = rec.t, rec.x, np.array(rec.F, float)
    y = y + hum * float(np.ptp(y)) * np.sin(2 * np.pi * 50.0 * t + 0.3)
    d = Prepared.build(t, x, y)
    TangentialFamily().prepare(d)
    return d


def test_a_load_on_the_hum_sideband_is_refused_only_where_the_force_carries_the_line() -> None:
    hummed = _prepared(0.01)
    lines = _force_mains_lines(hummed)
    assert len(lines) == 1 and abs(lines[0][0] - 50.0) < 0.3
    # 50 Hz lies 5 Hz from the 5th harmonic: 9 bins on 1.8 s, clear of the remover's guard
    for f_n in (50.0 + F, 50.0 - F, 50.0 + 2 * F):
        why = mains_line_sideband(hummed, f_n)
        assert why is not None and "mains line" in why
        assert hum_sideband(hummed, f_n) == why
    assert mains_line_sideband(hummed, 1.37 * F) is None
    clean = _prepared(0.0)
    assert _force_mains_lines(clean) == []
    assert mains_line_sideband(clean, 50.0 + F) is None
