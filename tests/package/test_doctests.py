"""Every docstring example in the package runs and prints what it says (``doctest``).

The examples are the first thing a user copies; this keeps them right. Modules without
examples are skipped by doctest itself (0 attempted).
"""

from __future__ import annotations

import doctest
import importlib
import pkgutil

import matplotlib
import pytest

import contactlab

matplotlib.use("Agg")

MODULES = sorted(
    m.name
    for m in pkgutil.walk_packages(contactlab.__path__, prefix="contactlab.")
    if not m.name.endswith("__main__")
    # deprecated forwarding modules (their names live on in contactlab.studies)
    and m.name
    not in {
        "contactlab.manifest",
        "contactlab.normal_study",
        "contactlab.study",
        "contactlab.study_plots",
        # issue 32: plots and reports moved to contactlab.report
        "contactlab.diagnose.plots",
        "contactlab.structure.report",
        "contactlab.studies.plots",
        "contactlab.studies.track_plots",
        "contactlab.tangential.plots",
        "contactlab.diagnose.generator",
        "contactlab.diagnose.generator_normal",
        "contactlab.normal.synthetic",
        "contactlab.tangential.synthetic",
    }
)


def test_the_package_has_examples():
    attempted = 0
    for name in MODULES:
        finder = doctest.DocTestFinder()
        mod = importlib.import_module(name)
        attempted += sum(len(t.examples) for t in finder.find(mod))
    assert attempted >= 100  # 103 when this test was written


@pytest.mark.parametrize("name", MODULES)
def test_docstring_examples(name, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # examples that write files write them here
    module = importlib.import_module(name)
    failed, _ = doctest.testmod(module, optionflags=doctest.ELLIPSIS, report=False)
    assert failed == 0, f"{failed} docstring example(s) of {name} failed; run doctest on it"
