"""WindowCuts.cuts (a block's crossings counted at once) against WindowCuts.crossing one by
one: the same cuts, counts and state, whatever the mode and the blocks."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from contactlab.studies.track_cuts import WindowCuts


def _state(c: WindowCuts) -> tuple:
    return (
        c.mode,
        c.size,
        c.n_cross,
        c.next_cross_target,
        c.window_t0,
        c.crossings_in_window,
    )


@given(
    mode=st.sampled_from(["cycles", "time", "auto"]),
    size=st.integers(1, 9),
    auto=st.integers(20, 400),
    blocks=st.lists(st.lists(st.integers(1, 60), max_size=40), min_size=1, max_size=12),
)
@settings(max_examples=300, deadline=None)
def test_cuts_equal_one_by_one(mode: str, size: int, auto: int, blocks: list) -> None:
    a, b = WindowCuts(mode, float(size), auto), WindowCuts(mode, float(size), auto)
    pos = 0
    for gaps in blocks:
        gs = []
        for d in gaps:
            pos += d
            gs.append(pos)
        t0 = 0.01 * (gs[0] if gs else pos)
        for c in (a, b):
            c.block(t0, np.asarray(gs, dtype=int))
        one = [(g, a.n_cross - 1) for g in gs if a.crossing(0.01 * g)]
        many = b.cuts(gs, lambda g: 0.01 * g)
        assert many == one
        assert _state(a) == _state(b)
