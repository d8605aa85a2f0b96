"""The diagnosis's fitted model in its JSON (``final_model``), and for normal contact the
stiffness law's eq. 6 coefficients, which do not depend on the record's displacement scale.

``kappa`` is relative to ``δ_r``, the RMS of the displacement the fit saw; the stiffening
itself makes that RMS smaller than the generator's linear-record scale, so ``kappa`` reads
about 9 % low at a 5 % effect (the "κ −9 %" of the 1e6-sample evaluation). The coefficient
``a3 = k κ / δ_r²`` is the physical one: checked against the generator's own, on fresh seeds.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

import contactlab
from contactlab.synthetic.diagnosis import hidden_effect_recording


@pytest.mark.parametrize("seed", [82001, 82002])
def test_normal_stiffening_coefficient_matches_the_truth_where_kappa_cannot(seed):
    rec = hidden_effect_recording(
        ["stiffness_nonlinearity"], model="normal", magnitude=0.05, seed=seed
    )
    rep = contactlab.diagnose(rec, model="normal")
    assert rep.effect_names == ["stiffness_nonlinearity"]
    fm = json.loads(rep.to_json())["final_model"]
    truth = rec.truth
    k, dr = truth["base"]["k"], truth["base"]["delta_r"]
    kap = truth["effects"]["stiffness_nonlinearity"]["kappa"]
    a3_true = k * kap / dr**2
    assert fm["coefficients"]["a3"] == pytest.approx(a3_true, rel=0.03)
    assert fm["coefficients"]["a1"] == pytest.approx(k, rel=0.01)
    assert fm["coefficient_units"] == {"a1": "Pa/m", "a2": "Pa/m^2", "a3": "Pa/m^3"}
    # kappa alone is on the measured record's scale, which the effect shrinks
    ratio = fm["context"]["delta_r"] / dr
    assert ratio < 0.99
    assert fm["parameters"]["kappa"] == pytest.approx(kap * ratio**2, rel=0.03)
    assert "Stiffness law (eq. 6)" in rep.summary()


def test_tangential_final_model_in_the_json_without_coefficients():
    rec = hidden_effect_recording(["force_offset"], magnitude=0.05, seed=82003)
    rep = contactlab.diagnose(rec, model="tangential")
    fm = json.loads(rep.to_json())["final_model"]
    assert fm["model"] == "tangential" and fm["effects"] == rep.effect_names
    assert set(fm["parameters"]) >= {"h0", "ac"}
    assert all(v is None or np.isfinite(v) for v in fm["stderr"].values())
    assert "coefficients" not in fm
