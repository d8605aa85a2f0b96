"""Imports run one way (issue 13): commands → studies/diagnosis → models → masing/fitting/io →
``_core``, with no cycles and no private names taken from another module.

The graph is read from the source (every ``import``/``from ... import`` of a contactlab module,
at module level or inside a function; only ``if TYPE_CHECKING:`` blocks are left out, since
they never run). ``python tests/test_import_graph.py`` prints it.
"""

from __future__ import annotations

import ast
import sys
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[1] / "python" / "contactlab"

# Layer of each module, by longest matching prefix; a module may import its own layer or lower.
LAYERS = {
    "base": 0,
    "masing/fitting/io": 1,
    "models": 2,
    "studies/diagnosis": 3,
    "commands": 4,
}
PREFIXES = {
    "contactlab._core": "base",
    "contactlab.errors": "base",
    "contactlab._version": "base",
    "contactlab._arrays": "base",
    "contactlab._physical": "base",
    "contactlab._io_atomic": "base",
    "contactlab._json": "base",
    "contactlab._range": "base",
    "contactlab._malloc": "base",  # the CLI's allocator thresholds (glibc mallopt)
    "contactlab._filters": "base",  # numpy Savitzky-Golay and friends (no scipy.signal import)
    "contactlab._trf": "base",  # scipy's bounded least-squares solver (for contactlab.fitting)
    "contactlab.data": "base",  # bundled files only (the generator is contactlab._datagen)
    "contactlab.masing": "masing/fitting/io",
    "contactlab.reversals": "masing/fitting/io",
    "contactlab.fitting": "masing/fitting/io",
    "contactlab.io": "masing/fitting/io",
    "contactlab.report": "masing/fitting/io",  # the generic HTML report writer
    "contactlab.tangential": "models",
    "contactlab.normal": "models",
    "contactlab.structure": "models",
    "contactlab.joints": "models",
    "contactlab.diagnose": "studies/diagnosis",
    "contactlab.diagnose.structure": "studies/diagnosis",  # diagnosis on identified structures
    "contactlab.studies": "studies/diagnosis",
    "contactlab.study": "studies/diagnosis",
    "contactlab.normal_study": "studies/diagnosis",
    "contactlab.study_plots": "studies/diagnosis",
    "contactlab.manifest": "studies/diagnosis",
    "contactlab.report.study_report": "studies/diagnosis",
    "contactlab.report.track_report": "studies/diagnosis",
    "contactlab._datagen": "studies/diagnosis",
    "contactlab.fem": "studies/diagnosis",  # FE export of identified joints and structures
    "contactlab.commands": "commands",
    "contactlab.cli": "commands",
    "contactlab.__main__": "commands",
}
ROOT_LAYER = "commands"  # the package root itself re-exports everything (lazily)


def module_name(path: Path) -> str:
    parts = list(path.relative_to(PACKAGE.parent).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def modules() -> dict[str, Path | None]:
    found: dict[str, Path | None] = {module_name(p): p for p in PACKAGE.rglob("*.py")}
    found["contactlab._core"] = None  # the compiled extension
    return found


def _is_type_checking(node: ast.If) -> bool:
    t = node.test
    return (isinstance(t, ast.Name) and t.id == "TYPE_CHECKING") or (
        isinstance(t, ast.Attribute) and t.attr == "TYPE_CHECKING"
    )


def _imports(tree: ast.AST):
    """Every import node, skipping ``if TYPE_CHECKING:`` bodies."""
    for node in ast.iter_child_nodes(tree):
        if isinstance(node, ast.If) and _is_type_checking(node):
            yield from (n for child in node.orelse for n in _imports_in(child))
            continue
        yield from _imports_in(node)


def _imports_in(node: ast.AST):
    if isinstance(node, (ast.Import, ast.ImportFrom)):
        yield node
    else:
        yield from _imports(node)


def import_graph() -> tuple[dict[str, set[str]], list[str]]:
    """``module -> imported contactlab modules`` and the private names imported across modules."""
    mods = modules()
    graph: dict[str, set[str]] = {}
    private: list[str] = []
    for name, path in mods.items():
        if path is None:
            graph[name] = set()
            continue
        package = name if path.name == "__init__.py" else name.rpartition(".")[0]
        targets: set[str] = set()
        for node in _imports(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Import):
                targets |= {a.name for a in node.names if a.name.split(".")[0] == "contactlab"}
                continue
            if node.level:
                base = package.split(".")[: len(package.split(".")) - node.level + 1]
                source = ".".join(base + ([node.module] if node.module else []))
            else:
                source = node.module or ""
            if source.split(".")[0] != "contactlab":
                continue
            for alias in node.names:
                sub = f"{source}.{alias.name}"
                if sub in mods:  # `from . import normal`: the submodule itself
                    targets.add(sub)
                    continue
                targets.add(source)
                if alias.name.startswith("_") and not alias.name.startswith("__"):
                    private.append(f"{name} imports {alias.name} from {source}")
        targets.discard(name)
        graph[name] = targets
    return graph, private


def _home(module: str) -> str | None:
    hits = [p for p in PREFIXES if module == p or module.startswith(p + ".")]
    if hits:
        return PREFIXES[max(hits, key=len)]
    return ROOT_LAYER if module == "contactlab" else None


def layer(module: str) -> int:
    home = _home(module)
    if home is None:
        raise KeyError(f"{module} has no layer: add it to PREFIXES")
    return LAYERS[home]


def cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """Strongly connected components with more than one module (Tarjan)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    found: list[list[str]] = []

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in sorted(graph.get(v, ())):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                found.append(sorted(comp))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return found


def format_graph(graph: dict[str, set[str]]) -> str:
    names = {v: k for k, v in LAYERS.items()}
    lines = []
    for level in sorted(LAYERS.values(), reverse=True):
        lines.append(f"[{names[level]}]")
        for m in sorted(m for m in graph if layer(m) == level):
            deps = ", ".join(d.removeprefix("contactlab.") for d in sorted(graph[m])) or "-"
            lines.append(f"  {m.removeprefix('contactlab.') or 'contactlab'} -> {deps}")
    return "\n".join(lines)


def test_every_module_has_a_layer():
    unplaced = [m for m in modules() if _home(m) is None]
    assert not unplaced, f"give these modules a layer in PREFIXES: {unplaced}"


def test_import_graph_has_no_cycles():
    graph, _ = import_graph()
    assert cycles(graph) == [], format_graph(graph)


def test_imports_run_one_way():
    graph, _ = import_graph()
    upward = [
        f"{a} ({layer(a)}) imports {b} ({layer(b)})"
        for a, deps in graph.items()
        for b in deps
        if layer(b) > layer(a)
    ]
    assert not upward, "\n".join(upward)


def test_no_private_names_imported_across_modules():
    _, private = import_graph()
    assert not private, "\n".join(private)


def test_the_checker_sees_cycles_and_upward_imports():
    assert cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]
    assert cycles({"a": {"b"}, "b": set()}) == []
    assert layer("contactlab.report.study_report") > layer("contactlab.report.html")
    assert layer("contactlab.commands.demo") > layer("contactlab.diagnose.workflow")
    assert layer("contactlab.masing") > layer("contactlab._core")
    assert _home("contactlab.no_such_module") is None  # new modules must be placed
    graph, _ = import_graph()
    assert "contactlab.masing" in graph["contactlab.tangential.model"]
    assert "contactlab._core" in graph["contactlab.masing"]
    # a function-level import counts; a TYPE_CHECKING one does not
    assert "contactlab.diagnose" in graph["contactlab.commands.diagnose"]
    assert "contactlab.diagnose.plots" in graph["contactlab.diagnose.workflow"]
    assert "contactlab.normal.loop" not in graph["contactlab.normal.models"]


if __name__ == "__main__":
    g, p = import_graph()
    print(format_graph(g))
    print("cycles:", cycles(g) or "none")
    print("private names across modules:", p or "none")
    sys.exit(0)
