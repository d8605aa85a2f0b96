"""The self-contained HTML report and all-or-nothing output writing."""

from __future__ import annotations

import base64
import os
import re
from html.parser import HTMLParser

import matplotlib
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

matplotlib.use("Agg")
import matplotlib.pyplot as plt

from contactlab import InputError
from contactlab.report import Column, Report, commit_outputs, format_value, slugify


class _Refs(HTMLParser):
    def __init__(self):
        super().__init__()
        self.srcs, self.hrefs, self.tags = [], [], []

    def handle_starttag(self, tag, attrs):
        self.tags.append(tag)
        for k, v in attrs:
            if k == "src":
                self.srcs.append(v)
            if k == "href":
                self.hrefs.append(v)


def _fig(n=1):
    fig, ax = plt.subplots(figsize=(2, 1.5))
    ax.plot(range(n + 2))
    return fig


def test_report_is_self_contained_and_pngs_match(tmp_path):
    rep = Report("Test <report>", intro="intro & text")
    rep.text("before sections")
    rep.section("Results")
    rep.table(
        [{"f": "a.csv", "h0": 40.0, "h0_stderr": 0.25, "ac": float("nan")}],
        [Column("f"), Column("h0", "h0", "N", stderr="h0_stderr"), Column("ac", unit="1/mm")],
        caption="cap",
    )
    n1 = rep.figure(_fig(1), "Al/Al loop", "first")
    n2 = rep.figure(_fig(2), "Al/Al loop", "second")  # same name: made unique
    rep.section("Results")  # same title: unique anchor
    rep.preformatted("[[Fit]]\n  h0 = 40 <N>")
    rep.text("careful", note=True)
    paths = rep.write(tmp_path / "out", extra={"study.csv": b"a,b\n1,2\n"})
    assert {p.name for p in paths} == {"report.html", n1, n2, "study.csv"}
    assert (n1, n2) == ("al-al-loop.png", "al-al-loop-2.png")
    text = (tmp_path / "out" / "report.html").read_text(encoding="utf-8")
    p = _Refs()
    p.feed(text)
    assert len(p.srcs) == 2
    assert all(s.startswith("data:image/png;base64,") for s in p.srcs)
    for s, name in zip(p.srcs, (n1, n2), strict=True):
        png = base64.b64decode(s.split(",", 1)[1])
        assert png == (tmp_path / "out" / "figures" / name).read_bytes()
        assert png[:8] == b"\x89PNG\r\n\x1a\n"
    assert all(h.startswith("#") for h in p.hrefs)  # only internal anchors, nothing external
    assert "link" not in p.tags and "script" not in p.tags
    assert 'id="results"' in text and 'id="results-2"' in text
    assert "Test &lt;report&gt;" in text and "&lt;N&gt;" in text
    assert "40.00 ± 0.25" in text.replace("\u00a0", " ") and "h0 [N]" in text
    assert re.search(r"<td>—</td>", text)  # NaN shown as a dash, not 'nan'
    assert plt.get_fignums() == []  # figures closed after rendering


def test_format_value():
    assert format_value(float("nan")) == "—"
    assert format_value(None) == "—"
    assert format_value(True) == "yes"
    assert format_value(3) == "3"
    assert format_value(1234567.0) == "1.235e+06"
    assert slugify("Al/Al, W = 50 N") == "al-al-w-50-n"
    assert slugify("///") == "item"


def test_commit_outputs_writes_all(tmp_path):
    paths = commit_outputs(tmp_path / "new" / "dir", {"a.txt": b"1", "s/b.txt": b"2"})
    assert [p.read_bytes() for p in paths] == [b"1", b"2"]
    assert sorted(os.listdir(tmp_path / "new" / "dir")) == ["a.txt", "s"]
    mask = os.umask(0o022)
    os.umask(mask)
    assert paths[0].stat().st_mode & 0o777 == 0o666 & ~mask  # not mkstemp's 0600


def test_commit_outputs_all_or_nothing_on_interrupt(tmp_path, monkeypatch):
    out = tmp_path / "out"
    out.mkdir()
    (out / "a.txt").write_bytes(b"old")
    calls = {"n": 0}
    real = os.fdopen

    def flaky(fd, mode):
        calls["n"] += 1
        if calls["n"] == 3:
            os.close(fd)
            raise KeyboardInterrupt
        return real(fd, mode)

    monkeypatch.setattr(os, "fdopen", flaky)
    with pytest.raises(KeyboardInterrupt):
        commit_outputs(out, {"a.txt": b"new", "sub/b.txt": b"x", "c.txt": b"y"})
    # the folder is exactly as it was: old file untouched, no temporaries, no new sub-folder
    assert sorted(os.listdir(out)) == ["a.txt"]
    assert (out / "a.txt").read_bytes() == b"old"


@pytest.mark.parametrize("name", ["../escape.txt", "/abs.txt", ""])
def test_commit_outputs_rejects_escaping_names(tmp_path, name):
    with pytest.raises(InputError, match="relative path"):
        commit_outputs(tmp_path, {name: b"x"})


def test_report_file_name_must_be_html(tmp_path):
    with pytest.raises(InputError, match=r"\.html"):
        Report("x").write(tmp_path, html_name="report.txt")


@settings(max_examples=40, deadline=None)
@given(
    names=st.lists(
        st.sampled_from(["a.txt", "b.png", "s/c.csv", "s/t/d.bin", "e.html"]),
        min_size=1,
        max_size=5,
        unique=True,
    ),
    fail_at=st.integers(0, 6),
    data=st.binary(max_size=64),
)
def test_commit_outputs_is_all_or_nothing(tmp_path_factory, names, fail_at, data):
    """Whatever file fails, the folder is either fully updated or exactly as before."""
    out = tmp_path_factory.mktemp("o")
    (out / "a.txt").write_bytes(b"old")
    before = sorted((str(p.relative_to(out)), p.read_bytes() if p.is_file() else None)
                    for p in out.rglob("*"))  # fmt: skip
    real = os.fdopen
    calls = {"n": 0}

    def flaky(fd, mode):
        if calls["n"] == fail_at:
            os.close(fd)
            raise OSError("disk full")
        calls["n"] += 1
        return real(fd, mode)

    os.fdopen = flaky
    try:
        commit_outputs(out, dict.fromkeys(names, data))
        ok = True
    except OSError:
        ok = False
    finally:
        os.fdopen = real
    after = sorted((str(p.relative_to(out)), p.read_bytes() if p.is_file() else None)
                   for p in out.rglob("*"))  # fmt: skip
    if ok:
        assert fail_at >= len(names)
        for n in names:
            assert (out / n).read_bytes() == data
    else:
        assert after == before
