"""``contactlab._json``: numpy arrays converted at numpy's speed give exactly what the
element-by-element conversion gave, and the writer that puts lists of numbers on one line
gives the same JSON values as ``json.dumps(indent=...)``."""

from __future__ import annotations

import json
import math
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np
from hypothesis import given
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

from contactlab._json import dumps, jsonable


def _reference(value: Any) -> Any:
    """The element-by-element conversion (the writer before the numpy fast path)."""
    if isinstance(value, Mapping):
        return {str(k): _reference(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_reference(v) for v in value]
    if isinstance(value, np.ndarray):
        return _reference(value.tolist())
    if isinstance(value, (np.floating, np.integer, np.bool_)):
        value = value.item()
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if isinstance(value, Path):
        return str(value)
    return value


def _same(a: Any, b: Any) -> bool:
    """Equal values of equal types (1 and 1.0 and True differ in JSON text)."""
    return json.dumps(a, allow_nan=False) == json.dumps(b, allow_nan=False)


_dtypes = st.sampled_from([np.float64, np.float32, np.int64, np.int32, np.uint8, np.bool_])


@given(hnp.arrays(_dtypes, hnp.array_shapes(min_dims=0, max_dims=3, min_side=0, max_side=5)))
def test_arrays_as_before(a):
    assert _same(jsonable(a), _reference(a))
    assert _same(jsonable({"k": [a, a]}), _reference({"k": [a, a]}))


def test_special_values():
    cases = [
        np.array([1.0, np.nan, -np.inf, np.inf, -0.0, 1e308, 5e-324]),
        np.array([[1.0, np.nan], [3.0, 4.0]]),
        np.array(np.nan),
        np.array(2.5),
        np.array(["a", "b"]),
        np.array([1, None, 2.5], dtype=object),
        np.zeros((0, 3)),
        {"p": Path("/x"), "f": np.float32(1.5), "i": np.int64(3), "b": np.bool_(True)},
    ]
    for c in cases:
        assert _same(jsonable(c), _reference(c)), c


_scalars = st.none() | st.booleans() | st.integers(-(10**6), 10**6) | st.text(max_size=5)
_scalars = _scalars | st.floats(allow_nan=False, allow_infinity=False)
_json = st.recursive(
    _scalars,
    lambda inner: (
        st.lists(inner, max_size=4) | st.dictionaries(st.text(max_size=4), inner, max_size=4)
    ),
    max_leaves=20,
)


@given(_json, st.integers(0, 3))
def test_dumps_same_values(doc, indent):
    text = dumps(doc, indent)
    assert json.loads(text) == json.loads(json.dumps(doc, indent=indent))
    assert text.count("\n") <= json.dumps(doc, indent=indent).count("\n")


def test_dumps_refuses_nan():
    import pytest

    with pytest.raises(ValueError):
        dumps({"a": [float("nan")]})
