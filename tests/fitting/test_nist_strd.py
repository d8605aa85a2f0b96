"""contactlab.fitting on the NIST StRD nonlinear regression problems (lower and average
difficulty), from both certified start points: at least 6 significant digits on every
parameter and standard error, or ``success=False`` with a reason — never a wrong answer
reported as a success. Data and certified values: tests/data/nist/ (see its README).

``python tests/fitting/test_nist_strd.py`` prints the table (problem, start, digits on parameters,
digits on standard errors).
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
import nist_strd
from contactlab.fitting import least_squares_fit

PROBLEMS = nist_strd.LOWER + nist_strd.AVERAGE


def fit(name: str, start: int, **kw):
    p = nist_strd.load(name)
    b0 = p.start1 if start == 1 else p.start2
    names = [f"b{i + 1}" for i in range(b0.size)]

    def residual(v):
        return p.y - p.model(np.array([v[k] for k in names]))

    return p, names, least_squares_fit(residual, dict(zip(names, b0, strict=True)), **kw)


def digits(name: str, start: int, **kw) -> tuple[bool, float, float | None, str]:
    """(success, min digits on parameters, min digits on stderr or None if not given, msg)."""
    p, names, res = fit(name, start, **kw)
    dp = min(nist_strd.lre(res.params[k].value, c) for k, c in zip(names, p.certified, strict=True))
    errs = [res.params[k].stderr for k in names]
    ds = None
    if all(e is not None for e in errs):
        ds = min(nist_strd.lre(e, c) for e, c in zip(errs, p.certified_stderr, strict=True))
    return res.success, dp, ds, res.message + " " + " ".join(res.notes)


def test_certified_values_reproduce_the_certified_rss():
    """The data files and the models written out here agree (independent of the fitter)."""
    for name in PROBLEMS:
        p = nist_strd.load(name)
        r = p.y - p.model(p.certified)
        rss = float(r @ r)
        if name == "Lanczos1":  # RSS 1.4e-25: the certified values' own 11-digit rounding
            assert rss < 1e-20
        else:
            assert rss == pytest.approx(p.rss, rel=1e-8), name


@pytest.mark.parametrize("start", [1, 2])
@pytest.mark.parametrize("name", PROBLEMS)
def test_six_digits_or_an_honest_failure(name, start):
    ok, dp, ds, msg = digits(name, start)
    if not ok:
        assert "not converged" in msg or msg.strip(), "a failure must say why"
        return
    assert dp >= 6.0, f"{name} start {start}: {dp:.1f} digits on parameters ({msg})"
    if ds is None:
        # only an exact fit (residuals at rounding level) may withhold its standard errors
        assert "rounding level" in msg, msg
        assert name == "Lanczos1"
    else:
        assert ds >= 6.0, f"{name} start {start}: {ds:.1f} digits on standard errors"


@pytest.mark.parametrize("name", ["ENSO", "MGH17", "Lanczos3", "Hahn1"])
@pytest.mark.parametrize("max_nfev", [5, 15, 40])
def test_a_stopped_fit_never_claims_a_wrong_answer(name, max_nfev):
    """Cut short by max_nfev, the fit reports success=False with a reason, unless its answer
    is right to 6 digits anyway."""
    ok, dp, _ds, msg = digits(name, 1, max_nfev=max_nfev)
    if ok:
        assert dp >= 6.0, f"{name}, max_nfev={max_nfev}: success with {dp:.1f} digits"
    else:
        assert msg.strip()


def table() -> list[tuple[str, int, bool, float, float | None]]:
    return [(n, s, *digits(n, s)[:3]) for n in PROBLEMS for s in (1, 2)]


if __name__ == "__main__":
    print(f"{'problem':10s} {'start':>5s} {'success':>7s} {'params':>7s} {'stderr':>7s}")
    for n, s, ok, dp, ds in table():
        sd = "n/a" if ds is None else f"{ds:.1f}"
        print(f"{n:10s} {s:5d} {ok!s:>7s} {dp:7.1f} {sd:>7s}")
