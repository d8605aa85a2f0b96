"""diagnose._parallel.pmap with a cost: the costliest calls start first on threads, the
results come back in the items' order and the first error in that order is raised."""

from __future__ import annotations

import pytest

from contactlab.diagnose._parallel import pmap


def test_costliest_start_first_results_in_order(monkeypatch):
    import contactlab.diagnose._parallel as par

    submitted: list[int] = []

    class Recording(par.ThreadPoolExecutor):
        def submit(self, fn, /, *args, **kwargs):  # type: ignore[no-untyped-def]
            submitted.append(args[0])
            return super().submit(fn, *args, **kwargs)

    monkeypatch.setattr(par, "ThreadPoolExecutor", Recording)
    monkeypatch.setenv("CONTACTLAB_DIAGNOSE_THREADS", "2")
    items = list(range(8))
    out = pmap(lambda i: i * i, items, cost=lambda i: 1.0 if i in (5, 7) else 0.0)
    assert out == [i * i for i in items]
    assert submitted == [5, 7, 0, 1, 2, 3, 4, 6]  # the costly first, ties in the items' order
    submitted.clear()
    assert pmap(lambda i: i * i, items) == out  # no cost: the items' order
    assert submitted == items
    monkeypatch.setenv("CONTACTLAB_DIAGNOSE_THREADS", "1")  # serially: the items' order
    ran: list[int] = []
    assert pmap(lambda i: ran.append(i) or i * i, items, cost=float) == out
    assert ran == items


def test_first_error_in_item_order_whatever_started_first(monkeypatch):
    monkeypatch.setenv("CONTACTLAB_DIAGNOSE_THREADS", "2")

    def f(i: int) -> int:
        if i in (2, 6):
            raise ValueError(f"bad {i}")
        return i

    with pytest.raises(ValueError, match="bad 2"):
        pmap(f, list(range(8)), cost=lambda i: float(i))  # 6 starts before 2
