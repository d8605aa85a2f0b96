"""The README and the documentation's guides never lie: every ```python block in them runs as
written (in a temp folder) and does what its comments say; every ``contactlab ...`` command
line they show is accepted by the CLI; the two ``make`` targets the README starts with
exist. The guides are Markdown pages of ``docs/`` (MyST), so the blocks moved there from the
README are still run here."""

from __future__ import annotations

import re
import shlex
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
README = ROOT / "README.md"
TEXT = README.read_text(encoding="utf-8")
#: the README, then every Markdown page of the documentation (built pages excluded)
_BUILT = {"_build", "generated", "auto_examples"}
PAGES = [
    README,
    *sorted(
        p
        for p in (ROOT / "docs").rglob("*.md")
        if not _BUILT & set(p.relative_to(ROOT / "docs").parts)
    ),
]
ALL_TEXT = "\n".join(p.read_text(encoding="utf-8") for p in PAGES)
BLOCKS = re.findall(r"```python\n(.*?)```", ALL_TEXT, re.S)
COMMANDS = [
    line.split(" #")[0].strip()
    for block in re.findall(r"```bash\n(.*?)```", ALL_TEXT, re.S)
    # a line ending in a backslash continues on the next (comments stripped first)
    for line in re.sub(r"\\[ \t]*\n", " ", re.sub(r"[ \t]+#[^\n]*", "", block)).splitlines()
    if line.strip().startswith("contactlab ")
]


def _masing(ns):
    # the analytic loop energy and the area of the simulated steady loop agree
    e, area = (
        ns["m"].loop_energy(20e-6),
        ns["contactlab"].loop_area(ns["x"][-2001:], ns["F"][-2001:]),
    )
    assert area == pytest.approx(e, rel=1e-4)


def _tangential(ns):
    d = ns["res"].to_dict()
    assert d["energy_per_cycle_numeric"] == pytest.approx(d["energy_per_cycle"], rel=0.01)
    assert d["h0"] == pytest.approx(40.0, rel=0.05) and d["ac"] == pytest.approx(4e4, rel=0.05)


def _normal(ns):
    assert ns["run"].success and ns["run"].delta.size == ns["t"].size


def _diagnose(ns):
    assert ns["report"].effect_names == ["channel_delay"]  # as the block's comment says
    assert [e["name"] for e in ns["report"].to_dict()["effects"]] == ["channel_delay"]


def _study(ns):
    assert len(ns["files"]) == 3 and len(ns["rows"]) == 3  # W50N at three amplitudes
    assert (Path("study-out") / "report.html").is_file()


def _frame(ns):
    d = ns["d"]  # a Coulomb-like loop through the frame reconstruction: sign and plateau kept
    assert d["regime"] in ("gross sliding", "stick-slip") and d["force_sign"] == 1
    assert abs(d["h0"] - 0.8) < 0.03 * 0.8


def _structure_diagnosis(ns):
    rep = ns["rep"]  # the missing joint dashpot is named, with its size, nothing left over
    assert rep.effects == ["joint_damping"] and not rep.unexplained
    assert abs(rep.parameters["cj"] - 3.0) < 0.3


# What each block claims, keyed by a line that identifies the block.
CLAIMS = {
    "m = contactlab.Masing(h0=40.0, ac=4e4)": _masing,
    "res = analyze_tangential(rec)": _tangential,
    "run = nl.simulate(t, p - loop.p0)": _normal,
    'hidden_effect_recording(["channel_delay"]': _diagnose,
    "res = run_study(files)": _study,
    "fr = frame_friction_force(": _frame,
    "rep = contactlab.diagnose((t, yb, x), base=m": _structure_diagnosis,
}


def test_readme_has_examples():
    assert len(BLOCKS) >= 4 and len(COMMANDS) >= 6
    for key in CLAIMS:  # a claim whose block was edited away must be updated too
        assert sum(key in code for code in BLOCKS) == 1, key


@pytest.mark.parametrize("code", BLOCKS, ids=[f"block{i}" for i in range(len(BLOCKS))])
def test_readme_block_runs(code, tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    ns = {"__name__": "__readme__"}
    try:
        exec(compile(code, str(README), "exec"), ns)
        for key, check in CLAIMS.items():
            if key in code:
                check(ns)
    finally:  # a block that plots (as a user would) leaves its figure open: not for later tests
        if "matplotlib.pyplot" in sys.modules:
            sys.modules["matplotlib.pyplot"].close("all")


@pytest.mark.parametrize("line", COMMANDS)
def test_readme_command_lines_parse(line):
    from contactlab.cli import build_parser

    args = build_parser().parse_args(shlex.split(line)[1:])  # SystemExit(2) if not accepted
    assert callable(args.handler)


def test_readme_make_targets_exist():
    makefile = (ROOT / "Makefile").read_text(encoding="utf-8")
    first = re.search(r"```bash\n(.*?)```", TEXT, re.S)
    assert first is not None
    targets = [line.split()[1] for line in first.group(1).splitlines() if line.startswith("make ")]
    assert targets == ["demo", "test"]
    for t in targets:
        assert re.search(rf"^{t}:", makefile, re.M), t
