"""Sphinx configuration of the contactlab documentation (``make docs``).

Sphinx with numpydoc (the package's docstrings are numpydoc), MyST (the guides are Markdown,
so their ```python blocks are run by ``tests/package/test_readme.py`` like the README's) and
sphinx-gallery (``docs/examples/plot_*.py`` run at every build). Built with ``-W --keep-going
-n``: any warning, an unresolved cross-reference included, fails the build.
"""

from __future__ import annotations

import os
import re
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(HERE))  # docs/_ext

import contactlab  # noqa: E402  (after the backend is set)

project = "contactlab"
author = "the contactlab developers"
copyright = "the contactlab developers"
release = contactlab.__version__
version = release

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.mathjax",
    "sphinx.ext.viewcode",
    "numpydoc",
    "myst_parser",
    "sphinx_gallery.gen_gallery",
]

source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
root_doc = "index"
exclude_patterns = ["_build", "Thumbs.db", ".DS_Store", "examples/README.txt"]
templates_path = ["_templates"]
html_static_path = ["_static"]
html_theme = "alabaster"
html_theme_options = {"description": "Hysteresis of contact joints", "fixed_sidebar": True}
html_title = f"contactlab {release}"

myst_enable_extensions = ["dollarmath", "colon_fence", "deflist"]
myst_heading_anchors = 3

autosummary_generate = True
# each object documented once, in the module that defines it (a package's ``__all__``
# re-exports would describe it a second time)
autodoc_default_options = {
    "members": True,
    "undoc-members": False,
    "show-inheritance": False,
    "ignore-module-all": True,
}
autodoc_typehints = "none"  # the numpydoc sections say the types
autodoc_member_order = "bysource"
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
numpydoc_xref_param_type = False

# Nitpicky (-n): every cross-reference between the pages (documents, labels, headings) must
# resolve, and the build fails on one that does not. References to Python objects inside the
# docstrings are left out of that check: the docstrings name numpy's and the standard
# library's types (whose inventories cannot be fetched offline) and, by their short names,
# objects of their own module (``InputError``, ``steps.detrend``), which Sphinx cannot
# resolve from another module's page; they render as plain code. The API pages themselves
# are generated from the package, so they cannot point to a module that does not exist.
nitpicky = True
nitpick_ignore_regex = [(r"py:.*", r"(?s).*")]  # (?s): a target broken over two lines too


def public_modules() -> list[str]:
    """Every public module of the package, found by walking it (so a module that moves is
    listed where it now lives): no name part starting with an underscore (``__main__`` would
    run the command line), and no deprecated alias (a module whose import warns that it has
    moved: it is documented at its new home)."""
    import importlib
    import pkgutil
    import warnings

    out = ["contactlab"]
    for info in pkgutil.walk_packages(contactlab.__path__, "contactlab."):
        if any(part.startswith("_") for part in info.name.split(".")):
            continue
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            try:
                mod = importlib.import_module(info.name)
            except ImportError:  # an optional dependency absent: not documented here
                continue
        if any(issubclass(w.category, DeprecationWarning) and "contactlab" in str(w.message)
               for w in caught):  # fmt: skip
            continue
        if (mod.__doc__ or "").lstrip().lower().startswith("deprecated"):
            continue  # an alias left where a module was (its docstring says where it went)
        out.append(info.name)
    return sorted(out)


# The API page, written before the pages are read (autosummary's stub generation reads the
# source files as they are, so the module list must be in api.rst itself, not included).
(HERE / "api.rst").write_text(
    "API reference\n=============\n\n"
    "Generated from the docstrings (numpydoc) of every public module of the package, found "
    "by walking\nit at build time, so a module that moves is documented where it now lives. "
    "A module or name\nstarting with an underscore is private and not listed.\n\n"
    ".. autosummary::\n   :toctree: generated\n\n" + "".join(f"   {m}\n" for m in public_modules()),
    encoding="utf-8",
)

sphinx_gallery_conf = {
    "examples_dirs": "examples",
    "gallery_dirs": "auto_examples",
    "filename_pattern": r"/plot_",
    "download_all_examples": False,
    "remove_config_comments": True,
    "within_subsection_order": "FileNameSortKey",
    "abort_on_example_error": True,
    "min_reported_time": 1e9,  # no timing table (numbers that change per machine)
    "write_computation_times": False,
}

os.environ.setdefault("CONTACTLAB_DOCS", "1")

#: pages other changes add, put in the table of contents when they exist (docs/NAME.md), and
#: the repository's ARCHITECTURE.md (included from docs/architecture.md)
OPTIONAL_PAGES = {"effects": "User guides", "architecture": "Reference"}


# The repository's ARCHITECTURE.md (the layers and where code goes), shown as a page of its
# own: docs/architecture.md includes it, written here when it exists (and not committed).
if (ROOT / "ARCHITECTURE.md").exists():
    (HERE / "architecture.md").write_text(
        "```{include} ../ARCHITECTURE.md\n:relative-docs: docs/\n:relative-images:\n```\n",
        encoding="utf-8",
    )


def _optional_toc(app, docname, source):
    """Append the optional pages that exist to the index's table of contents."""
    if docname != "index":
        return
    present = [n for n in OPTIONAL_PAGES if (HERE / f"{n}.md").exists()]
    if present:
        source[0] += "\n```{toctree}\n:maxdepth: 2\n:caption: More\n\n" + "\n".join(present)
        source[0] += "\n```\n"


#: plain-text idioms of the docstrings that reStructuredText would read as markup: ``|F|``
#: (an absolute value, not a substitution) and ``*SPRING`` (a solver keyword, not emphasis)
_ABS = re.compile(r"(?<![\\|`\w])\|(?=[^\s|])([^|`\n]*?[^\s|])\|(?![|_\w])")
_KEYWORD = re.compile(r"(?<![\w*`\\])\*(?=[A-Z]{2})")


def _plain_text(app, what, name, obj, options, lines):
    """Escape ``|x|`` and ``*KEYWORD`` in docstrings, outside literals and tables."""
    for i, line in enumerate(lines):
        stripped = line.lstrip()
        if stripped.startswith(("|", "+-", "+=", ">>>", "...")) or "``" in line:
            continue
        lines[i] = _KEYWORD.sub(r"\\*", _ABS.sub(r"\\|\1\\|", line))


def setup(app):
    app.connect("source-read", _optional_toc)
    app.connect("autodoc-process-docstring", _plain_text)
