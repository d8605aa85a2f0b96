"""``benches/bench_analyze.py --baseline``: the baseline tree's modules are compiled before it
is timed (uncompiled, with ``PYTHONDONTWRITEBYTECODE=1`` every run compiled them: 0.13 s of
CPU counted as the baseline's)."""

import importlib.util
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def _bench():
    sys.path.insert(0, str(ROOT / "benches"))
    try:
        spec = importlib.util.spec_from_file_location(
            "bench_analyze_under_test", ROOT / "benches" / "bench_analyze.py"
        )
        mod = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(mod)
        return mod
    finally:
        sys.path.remove(str(ROOT / "benches"))


def test_compile_tree_compiles_every_module(tmp_path):
    pkg = tmp_path / "pkg"
    (pkg / "sub").mkdir(parents=True)
    (pkg / "__init__.py").write_text("")
    (pkg / "mod.py").write_text("X = 1\n")
    (pkg / "sub" / "__init__.py").write_text("")
    (pkg / "sub" / "deep.py").write_text("Y = 2\n")
    (tmp_path / "notes").mkdir()  # not a package: left alone
    (tmp_path / "notes" / "scratch.py").write_text("Z = 3\n")
    assert not list(tmp_path.rglob("*.pyc"))
    assert _bench().compile_tree(tmp_path) == 0
    compiled = {p.name.split(".")[0] for p in tmp_path.rglob("*.pyc")}
    assert compiled == {"__init__", "mod", "deep"}
    (pkg / "broken.py").write_text("def (:\n")
    assert _bench().compile_tree(tmp_path) == 1
