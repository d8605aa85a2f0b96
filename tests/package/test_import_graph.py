"""No import cycle in contactlab, imports inside functions counted (issue 32).

Every ``import`` and ``from ... import`` of every module of ``python/contactlab`` is read from
its source (module level, inside functions and methods, in ``try`` blocks; only ``if
TYPE_CHECKING:`` blocks are left out, as they import nothing at run time). A name imported
from a package that is a module of it counts as that module. Two checks:

- between modules: no set of modules imports itself round (strongly connected components);
- between packages: for every package, its children (sub-packages and modules, with all they
  hold) import each other without a round, at every depth.

A lazy import inside a function does not excuse a cycle: it only moves the failure from
import time to the first call. The same reading checks that no private (``_name``) module
or name crosses the package that owns it.
"""

from __future__ import annotations

import ast
import functools
from collections import defaultdict
from pathlib import Path

PKG = Path(__file__).resolve().parents[2] / "python" / "contactlab"


def _module_name(rel: Path) -> str:
    parts = list(rel.with_suffix("").parts)
    if parts[-1] == "__init__":
        parts = parts[:-1]
    return ".".join(["contactlab", *parts])


def read_package(root: Path = PKG) -> dict[str, tuple[str, bool]]:
    """Module name -> (source, is a package) of every module under ``root``."""
    return {
        _module_name(p.relative_to(root)): (p.read_text(encoding="utf-8"), p.name == "__init__.py")
        for p in sorted(root.rglob("*.py"))
    }


def _type_checking_only(tree: ast.AST) -> set[int]:
    skip: set[int] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.If):
            test = node.test
            name = test.id if isinstance(test, ast.Name) else getattr(test, "attr", None)
            if name == "TYPE_CHECKING":
                for inner in node.body:
                    skip.update(id(sub) for sub in ast.walk(inner))
    return skip


@functools.cache
def imports(source: str, module: str, is_package: bool) -> tuple[tuple[str, str | None, int], ...]:
    """``(module, name or None, line)`` of every import of a module, relative ones resolved."""
    tree = ast.parse(source)
    skip = _type_checking_only(tree)
    base = module.split(".") if is_package else module.split(".")[:-1]
    out: list[tuple[str, str | None, int]] = []
    for node in ast.walk(tree):
        if id(node) in skip:
            continue
        if isinstance(node, ast.Import):
            out += [(alias.name, None, node.lineno) for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                anchor = base[: len(base) - node.level + 1]
                target = ".".join(anchor + ([node.module] if node.module else []))
            else:
                target = node.module or ""
            out += [(target, alias.name, node.lineno) for alias in node.names]
    return tuple(out)


def import_graph(modules: dict[str, tuple[str, bool]]) -> dict[str, dict[str, int]]:
    """Module -> {imported contactlab module: line of the first such import}."""
    graph: dict[str, dict[str, int]] = {m: {} for m in modules}
    for mod, (source, is_pkg) in modules.items():
        for target, name, line in imports(source, mod, is_pkg):
            if not target.startswith("contactlab"):
                continue
            dest = f"{target}.{name}" if name and f"{target}.{name}" in modules else target
            while dest not in modules and "." in dest:
                dest = dest.rsplit(".", 1)[0]
            if dest in modules and dest != mod:
                graph[mod].setdefault(dest, line)
    return graph


def cycles(graph: dict[str, dict[str, int]] | dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components of more than one node (Tarjan, iterative)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    found: list[list[str]] = []
    for root in sorted(graph):
        if root in index:
            continue
        index[root] = low[root] = len(index)
        stack.append(root)
        on_stack.add(root)
        work = [(root, iter(sorted(graph[root])))]
        while work:
            node, children = work[-1]
            child = next(children, None)
            if child is not None:
                if child not in index:
                    index[child] = low[child] = len(index)
                    stack.append(child)
                    on_stack.add(child)
                    work.append((child, iter(sorted(graph.get(child, ())))))
                elif child in on_stack:
                    low[node] = min(low[node], index[child])
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[node])
            if low[node] == index[node]:
                component = []
                while True:
                    top = stack.pop()
                    on_stack.discard(top)
                    component.append(top)
                    if top == node:
                        break
                if len(component) > 1:
                    found.append(sorted(component))
    return sorted(found)


def sibling_graphs(graph: dict[str, dict[str, int]]) -> dict[str, dict[str, set[str]]]:
    """For each package, the imports between its children (a child stands for everything in
    it): ``{package: {child: {children it imports}}}``."""
    packages = {m.rsplit(".", 1)[0] for m in graph if "." in m}
    out: dict[str, dict[str, set[str]]] = {}
    for pkg in sorted(packages):
        prefix = pkg + "."
        edges: dict[str, set[str]] = defaultdict(set)
        for src, dests in graph.items():
            if not src.startswith(prefix):
                continue
            a = prefix + src[len(prefix) :].split(".")[0]
            for dest in dests:
                if dest.startswith(prefix):
                    b = prefix + dest[len(prefix) :].split(".")[0]
                    if a != b:
                        edges[a].add(b)
                        edges.setdefault(b, set())
        out[pkg] = dict(edges)
    return out


def _explain(cycle: list[str], graph: dict[str, dict[str, int]]) -> str:
    members = set(cycle)
    links = [
        f"{src} -> {dest} (line {line})"
        for src in cycle
        for dest, line in sorted(graph[src].items())
        if dest in members
    ]
    return "; ".join(links)


def private_crossings(modules: dict[str, tuple[str, bool]]) -> list[str]:
    """Imports of a private module or name from outside the package that owns it."""
    out = []
    for mod, (source, is_pkg) in modules.items():
        own = mod if is_pkg else mod.rsplit(".", 1)[0]
        for target, name, line in imports(source, mod, is_pkg):
            if not target.startswith("contactlab"):
                continue
            parts = [*target.split("."), *([name] if name else [])]
            for i, part in enumerate(parts[1:], start=1):
                if part.startswith("_") and not part.startswith("__"):
                    holder = ".".join(parts[:i])
                    is_module = holder in modules and not modules[holder][1]
                    owner = holder.rsplit(".", 1)[0] if is_module else holder
                    if own != owner and not own.startswith(owner + "."):
                        out.append(f"{mod}:{line} imports {'.'.join(parts[: i + 1])}")
                    break
    return out


# -- the package ---------------------------------------------------------------------------


@functools.cache
def _package() -> tuple[dict[str, tuple[str, bool]], dict[str, dict[str, int]]]:
    modules = read_package()
    return modules, import_graph(modules)


def test_no_import_cycle_between_modules():
    modules, graph = _package()
    assert len(modules) > 100, "the package was not found"
    found = cycles(graph)
    assert not found, "\n".join(_explain(c, graph) for c in found)


def test_no_import_cycle_between_packages_at_any_depth():
    graph = _package()[1]
    bad = []
    for pkg, edges in sibling_graphs(graph).items():
        bad += [f"in {pkg}: {' <-> '.join(c)}" for c in cycles(edges)]
    assert not bad, "\n".join(bad)


def test_no_private_name_crosses_its_package():
    assert private_crossings(_package()[0]) == []


# -- the checks themselves find what they look for -------------------------------------------


def _fake(tmp_path: Path, files: dict[str, str]) -> dict[str, tuple[str, bool]]:
    for rel, text in files.items():
        path = tmp_path / rel
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text)
    return read_package(tmp_path)


def test_a_cycle_through_an_import_inside_a_function_is_found(tmp_path):
    modules = _fake(
        tmp_path,
        {
            "__init__.py": "",
            "a/__init__.py": "",
            "a/x.py": "from ..b.y import f\n",
            "b/__init__.py": "",
            "b/y.py": "def f():\n    from contactlab.a import x\n    return x\n",
            "b/z.py": "import typing\nif typing.TYPE_CHECKING:\n    from ..a import x\n",
        },
    )
    graph = import_graph(modules)
    assert graph["contactlab.a.x"] == {"contactlab.b.y": 1}
    assert graph["contactlab.b.y"] == {"contactlab.a.x": 2}
    assert graph["contactlab.b.z"] == {}  # a type-checking import runs nothing
    assert cycles(graph) == [["contactlab.a.x", "contactlab.b.y"]]
    assert "contactlab.b.y -> contactlab.a.x (line 2)" in _explain(cycles(graph)[0], graph)


def test_a_cycle_between_packages_without_one_between_modules_is_found(tmp_path):
    modules = _fake(
        tmp_path,
        {
            "__init__.py": "",
            "a/__init__.py": "",
            "a/x.py": "import contactlab.b.y\n",
            "a/w.py": "",
            "b/__init__.py": "",
            "b/y.py": "",
            "b/z.py": "from contactlab.a import w\n",
        },
    )
    graph = import_graph(modules)
    assert cycles(graph) == []
    edges = sibling_graphs(graph)["contactlab"]
    assert cycles(edges) == [["contactlab.a", "contactlab.b"]]


def test_a_private_name_crossing_its_package_is_found(tmp_path):
    modules = _fake(
        tmp_path,
        {
            "__init__.py": "",
            "_base.py": "",
            "a/__init__.py": "",
            "a/_x.py": "",
            "a/y.py": "from ._x import f\nfrom .._base import g\ndef _h(): pass\n",
            "b/__init__.py": "",
            "b/z.py": "from contactlab.a.y import _h\nfrom contactlab.a import _x\n",
        },
    )
    assert private_crossings(modules) == [
        "contactlab.b.z:1 imports contactlab.a.y._h",
        "contactlab.b.z:2 imports contactlab.a._x",
    ]
