"""Issue 9 item 5: studies and tracking live in contactlab.studies; the old module paths
forward with a DeprecationWarning; the study module and the report builder no longer import
each other."""

from __future__ import annotations

import importlib
import subprocess
import sys

import pytest

OLD_NEW = [
    ("contactlab.study", "contactlab.studies.study", "run_study"),
    ("contactlab.manifest", "contactlab.studies.manifest", "read_manifest"),
    ("contactlab.study_plots", "contactlab.report.study_plots", "tangential_study_figures"),
    # issue 32: every plot and report writer lives in contactlab.report
    ("contactlab.studies.plots", "contactlab.report.study_plots", "tangential_study_figures"),
    ("contactlab.studies.track_plots", "contactlab.report.track_plots", "plot_quantity"),
    ("contactlab.tangential.plots", "contactlab.report.tangential", "plot_loop"),
    ("contactlab.tangential", "contactlab.report.tangential", "plot_residuals"),
    ("contactlab.normal", "contactlab.report.normal", "plot_comparison"),
    (
        "contactlab.structure",
        "contactlab.report.structure_plots",
        "plot_modal_amplitude_dependence",
    ),
    ("contactlab.structure.report", "contactlab.report.structure", "build_structure_report"),
    (
        "contactlab.structure.amplitude",
        "contactlab.report.structure_plots",
        "plot_amplitude_dependence",
    ),
    ("contactlab.normal.compare", "contactlab.report.normal", "plot_loops"),
    ("contactlab.diagnose.plots", "contactlab.report.diagnosis_plots", "plot_overlay"),
    # issue 32: synthetic data in contactlab.synthetic
    ("contactlab.tangential", "contactlab.synthetic.tangential", "synthetic_recording"),
    ("contactlab.tangential.synthetic", "contactlab.synthetic.tangential", "synthetic_recording"),
    ("contactlab.normal", "contactlab.synthetic.normal", "table2_model"),
    ("contactlab.normal.synthetic", "contactlab.synthetic.normal", "synthetic_recording"),
    ("contactlab.diagnose", "contactlab.synthetic.diagnosis", "hidden_effect_recording"),
    ("contactlab.diagnose.generator", "contactlab.synthetic.diagnosis", "HiddenEffectRecording"),
    ("contactlab.normal_study", "contactlab.studies.normal", "analyze_normal_recording"),
]


@pytest.mark.parametrize(("old", "new", "name"), OLD_NEW)
def test_old_paths_forward_with_a_deprecation_warning(old, new, name):
    mod = importlib.import_module(old)
    with pytest.warns(DeprecationWarning, match=new.replace(".", r"\.")):
        value = getattr(mod, name)
    assert value is getattr(importlib.import_module(new), name)


def test_no_import_cycle_between_study_and_report():
    code = (
        "import sys, contactlab.studies.study as s\n"
        "assert 'contactlab.report.study_report' not in sys.modules\n"
        "from contactlab.data import manifest_path\n"
        "r = s.run_study(sorted(manifest_path().parent.glob('tangential/*'))[:1], progress=False)\n"
        "assert '<table>' in r._repr_html_()\n"
        "assert 'contactlab.report.study_report' not in sys.modules\n"
    )
    subprocess.run([sys.executable, "-c", code], check=True, timeout=120)
