"""The 'not separately identifiable' warning gives relative errors a reader can use: a
parameter whose standard error is beyond 1000 % of its value is called undetermined, not
printed as '1175301844650%' (the bundled steel-steel A = 0.25 µm loop, ac·A = 1e-12)."""

from __future__ import annotations

import math
import re

import pytest

from contactlab.data import data_dir
from contactlab.studies import run_study
from contactlab.tangential.quantities import _percent


@pytest.mark.parametrize(
    ("rel", "text"),
    [
        (0.0, "0%"),
        (0.283, "28%"),
        (9.99, "999%"),
        (10.0, "over 1000% (undetermined)"),
        (1.17e10, "over 1000% (undetermined)"),
        (math.inf, "over 1000% (undetermined)"),
        (math.nan, "over 1000% (undetermined)"),
    ],
)
def test_percent(rel, text):
    assert _percent(rel) == text


def test_bundled_linear_loop_is_called_undetermined():
    f = data_dir() / "tangential" / "steel-steel_W225N_A0.25um.h5"
    r = run_study([f], progress=False).results[0]
    w = str(r.row.get("warnings"))
    assert "NOT separately identifiable" in w
    assert "relative errors h0 over 1000% (undetermined)" in w
    assert not re.search(r"\d{5,}%", w)  # no ten-digit percentages
