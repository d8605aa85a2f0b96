"""`_arrays.scan` (finiteness and extremes of a channel) against plain reductions, and the
checks built on it still name the bad sample."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from contactlab._arrays import as_1d, scan
from contactlab._physical import check_channel
from contactlab.errors import InputError
from contactlab.io.recording import RecordingError, check_finite


def _numpy(a):
    ok = [bool(np.isfinite(v)) for v in a]
    good = [float(v) for v, k in zip(a, ok, strict=True) if k]
    return all(ok), min(good, default=float("inf")), max(good, default=float("-inf"))


@settings(max_examples=60, deadline=None)
@given(
    n=st.integers(0, 3 * 4096),
    seed=st.integers(0, 2**32 - 1),
    bad=st.sampled_from([None, np.nan, np.inf, -np.inf]),
    scale=st.sampled_from([1.0, 1e-300, 1e300]),
)
def test_scan_equals_plain_reductions(n, seed, bad, scale):
    rng = np.random.default_rng(seed)
    a = rng.standard_normal(n) * scale
    if bad is not None and n:
        a[rng.integers(n)] = bad
    got = scan(a)
    want = _numpy(a)
    assert got == want
    assert scan(a, extremes=False)[0] == want[0]
    # a strided view takes numpy's reductions, the contiguous array the core's one pass
    assert scan(np.repeat(a, 2)[::2]) == want


def test_long_channel_checks_name_the_sample():
    a = np.linspace(-1.0, 1.0, 5 * 4096)
    a[12345] = np.nan
    with pytest.raises(InputError, match=r"x\[12345\] is not finite"):
        as_1d(a, "x")
    with pytest.raises(RecordingError, match="sample 12345: "):
        check_finite(a, file="f.csv", column="x")
    b = np.full(5 * 4096, 2.5)
    with pytest.raises(InputError, match="constant"):
        check_channel("F", b, "N", "force")
    b[777] = -3e120
    with pytest.raises(InputError, match="at sample 777"):
        check_channel("F", b, "N", "force")
    with pytest.raises(InputError, match="zero in all"):
        check_channel("F", np.zeros(5 * 4096), "N", "force")


@settings(max_examples=300, deadline=None)
@given(
    v=st.lists(
        st.one_of(
            st.floats(allow_nan=True, allow_infinity=True, width=64),
            st.sampled_from([0.0, -0.0, 1.0, -1.0]),  # ties and signed zeros
        ),
        min_size=1,
        max_size=40,
    ),
    kind=st.sampled_from(["f8", "f4", "i8"]),
)
def test_median_is_numpys_bit_for_bit(v, kind):
    """``_arrays.median`` (no ``numpy.ma`` import) gives ``np.median``'s number and type:
    the same order statistics, their ``np.mean``, NaN where one is present."""
    from contactlab._arrays import median

    a = np.array(v, dtype=float)
    if kind == "i8":
        a = np.nan_to_num(a, nan=0.0, posinf=5.0, neginf=-5.0).clip(-1e9, 1e9).astype(np.int64)
    else:
        with np.errstate(over="ignore"):
            a = a.astype(kind)
    with np.errstate(all="ignore"):  # inf - inf in the mean of the middle two
        ref, got = np.median(a), median(a)
    assert type(got) is type(ref)
    assert (np.isnan(ref) and np.isnan(got)) or (ref == got and np.signbit(ref) == np.signbit(got))
