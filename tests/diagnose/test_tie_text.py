"""The stated bound's reason for a rival noted beside a named effect is true for each sign and
size of the paired t (issue 29, stop 47): a rival that fitted the held-out cycles
significantly better and was refused for another reason is not "not told apart"."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from contactlab.diagnose.power import _not_told_apart, tie_text
from contactlab.diagnose.search import NOT_TOLD_APART, _mark_not_told_apart
from contactlab.diagnose.select import Verdict

TIE = {"named": "inertia", "gain_named": 0.0003, "gain": 0.0555, "refused": ""}


@pytest.mark.parametrize("t", [-7.62, -4.07, -3.0])
def test_a_significantly_better_rival_refused_is_told_apart(t):
    why = tie_text("channel_delay", {**TIE, "t": t, "refused": "held-out gain below 0.062 σ²"})
    assert why.startswith("told apart from inertia")
    assert "significantly better" in why and "refused (held-out gain below 0.062" in why
    assert "do not say which" not in why and f"{t:.2f}" in why


def test_a_significantly_better_rival_accepted_but_ranked_below_says_so():
    why = tie_text("channel_delay", {**TIE, "t": -5.0})
    assert "significantly better" in why and "added inertia first" in why
    assert "do not say which" not in why


@pytest.mark.parametrize(
    ("t", "how"),
    [(-2.9, "as well or better"), (0.0, "about as well"), (2.5, "about as well"), (3.0, "about")],
)
def test_a_tie_says_the_data_do_not_choose(t, how):
    why = tie_text("channel_delay", {**TIE, "t": t, "refused": "look-alike: x"})
    assert why.startswith("not told apart from inertia") and how in why
    assert "do not say which" in why and "not named (look-alike: x)" in why
    assert "significantly better" not in why


def test_the_search_notes_z_and_the_bound_reads_it():
    d = SimpleNamespace(extra={NOT_TOLD_APART: {"channel_delay": {**TIE, "t": -2.5, "z": 2.0}}})
    assert _not_told_apart("channel_delay", d, ("inertia",)).startswith("told apart")
    d.extra[NOT_TOLD_APART]["channel_delay"]["z"] = 3.0
    assert _not_told_apart("channel_delay", d, ("inertia",)).startswith("not told apart")


def _trial(shares, per=20):
    pred = np.repeat(np.asarray(shares, float), per)
    return SimpleNamespace(prediction=pred, heldout=np.ones(pred.size, bool))


def test_the_search_says_which_rivals_fitted_significantly_better():
    n_c, per = 10, 20
    d = SimpleNamespace(
        y=np.ones(n_c * per),
        cycles=SimpleNamespace(cycle=np.repeat(np.arange(n_c), per)),
        extra={},
    )
    current = _trial([0.0] * n_c)
    named = (Verdict("inertia", 1.0, 0.1, 5.0, -5.0, True, "accepted"), _trial([0.1] * n_c))
    noisy = [0.1, 0.12, 0.08, 0.11, 0.09, 0.1, 0.12, 0.08, 0.1, 0.1]
    tried = {
        "inertia": named,
        "channel_delay": (
            Verdict("channel_delay", 1.0, 0.5, 5.0, -9.0, False, "held-out gain below 0.6 σ²"),
            _trial([0.5 + 0.5 * (s - 0.1) for s in noisy]),
        ),
        "viscous_damping": (
            Verdict("viscous_damping", 1.0, 0.1, 5.0, -5.0, False, "held-out gain below"),
            _trial(noisy),
        ),
    }
    st = SimpleNamespace(effects=(), current=current, where=[])
    _mark_not_told_apart(named, tried, st, d, 3.0)
    assert set(d.extra[NOT_TOLD_APART]) == {"channel_delay", "viscous_damping"}
    assert d.extra[NOT_TOLD_APART]["channel_delay"]["t"] <= -3.0
    assert len(st.where) == 2
    tie = next(w for w in st.where if "not told apart" in w)
    assert "viscous_damping" in tie and "channel_delay" not in tie
    told = next(w for w in st.where if "significantly better" in w)
    assert "channel_delay" in told and "held-out gain below 0.6" in told
