"""The measurements of the layering issue (32), re-runnable on any revision.

``python benches/layering_metrics.py`` measures the working tree;
``--rev REV`` measures a committed revision (read with ``git archive``, nothing checked out);
``--before REV [--before REV2 ...] --out FILE`` writes the table of those revisions next to
the working tree's. Measured:

- Python functions over 120 lines and files over 800 lines (``python/contactlab``);
  Rust functions over 150 lines and files over 800 lines (``rust/``);
- import cycles in ``python/contactlab``, every ``import`` statement counted, module level and
  inside functions (only ``if TYPE_CHECKING:`` blocks are left out: they run no import):
  strongly connected modules, and cycles between the children of each package (the packages
  and modules one level below it);
- private (``_name``) modules or names imported across a package inside the package, and test
  files that import a private name of contactlab;
- ``# fmt: skip`` comments in the package; ``allow(clippy::...)`` attributes in Rust.

A function's length runs from its ``def`` (or ``fn``) line to its last line, decorators left
out; nested functions count in their parent as well as on their own.
"""

from __future__ import annotations

import argparse
import ast
import io
import re
import subprocess
import sys
import tarfile
from collections import defaultdict
from dataclasses import dataclass, field
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PKG = "python/contactlab"
PY_FUNC_LIMIT = 120
RS_FUNC_LIMIT = 150
FILE_LIMIT = 800


@dataclass
class Metrics:
    """Every measurement of one revision."""

    py_long_functions: list[tuple[str, int]] = field(default_factory=list)
    py_long_files: list[tuple[str, int]] = field(default_factory=list)
    rs_long_functions: list[tuple[str, int]] = field(default_factory=list)
    rs_long_files: list[tuple[str, int]] = field(default_factory=list)
    module_cycles: list[list[str]] = field(default_factory=list)
    package_cycles: list[list[str]] = field(default_factory=list)
    private_crossings: list[str] = field(default_factory=list)
    test_files: int = 0
    test_files_private: list[str] = field(default_factory=list)
    fmt_skip: int = 0
    clippy_allows: list[str] = field(default_factory=list)


def _read_tree(rev: str | None) -> dict[str, str]:
    """The text of every .py and .rs file, by path, of a revision or of the working tree."""
    files: dict[str, str] = {}
    wanted = ("python/", "rust/", "tests/")
    if rev is None:
        for top in wanted:
            for path in sorted((ROOT / top).rglob("*")):
                rel = path.relative_to(ROOT).as_posix()
                if path.suffix in (".py", ".rs") and "/target/" not in rel:
                    files[rel] = path.read_text(encoding="utf-8")
        return files
    blob = subprocess.run(
        ["git", "archive", "--format=tar", rev, *wanted], cwd=ROOT, check=True, capture_output=True
    ).stdout
    with tarfile.open(fileobj=io.BytesIO(blob)) as tar:
        for member in tar.getmembers():
            if member.isfile() and member.name.endswith((".py", ".rs")):
                data = tar.extractfile(member)
                assert data is not None
                files[member.name] = data.read().decode("utf-8")
    return files


def module_name(path: str) -> str:
    """``python/contactlab/a/b.py`` -> ``contactlab.a.b`` (``__init__`` -> the package)."""
    parts = path[len("python/") : -len(".py")].split("/")
    if parts[-1] == "__init__":
        parts = parts[:-1]
    return ".".join(parts)


def _type_checking_nodes(tree: ast.AST) -> set[int]:
    """The ids of the import nodes inside ``if TYPE_CHECKING:`` blocks."""
    skip: set[int] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.If):
            test = node.test
            name = test.id if isinstance(test, ast.Name) else getattr(test, "attr", None)
            if name == "TYPE_CHECKING":
                for inner in node.body:
                    for sub in ast.walk(inner):
                        skip.add(id(sub))
    return skip


def imports_of(source: str, module: str, is_package: bool):
    """Every import of a module: yields ``(imported module, imported name or None, line)``.

    Relative imports are resolved against ``module``; ``from m import n`` yields ``(m, n)``.
    """
    tree = ast.parse(source)
    skip = _type_checking_nodes(tree)
    base = module.split(".") if is_package else module.split(".")[:-1]
    for node in ast.walk(tree):
        if id(node) in skip:
            continue
        if isinstance(node, ast.Import):
            for alias in node.names:
                yield alias.name, None, node.lineno
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                anchor = base[: len(base) - node.level + 1]
                target = ".".join(anchor + ([node.module] if node.module else []))
            else:
                target = node.module or ""
            for alias in node.names:
                yield target, alias.name, node.lineno


def import_graph(files: dict[str, str]) -> dict[str, set[str]]:
    """Module -> the contactlab modules it imports (a name that is a module counts as it)."""
    sources = {
        module_name(p): (text, p.endswith("__init__.py"))
        for p, text in files.items()
        if p.startswith(PKG + "/") and p.endswith(".py")
    }
    modules = set(sources)
    graph: dict[str, set[str]] = {m: set() for m in modules}
    for mod, (text, is_pkg) in sources.items():
        for target, name, _ in imports_of(text, mod, is_pkg):
            if not target.startswith("contactlab"):
                continue
            full = f"{target}.{name}" if name else None
            if full in modules:
                dest = full
            else:
                dest = target
                while dest not in modules and "." in dest:
                    dest = dest.rsplit(".", 1)[0]
            if dest in modules and dest != mod:
                graph[mod].add(dest)
    return graph


def strongly_connected(graph: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components with more than one node (Tarjan, iterative)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    on_stack: set[str] = set()
    stack: list[str] = []
    out: list[list[str]] = []
    counter = 0
    for root in sorted(graph):
        if root in index:
            continue
        work = [(root, iter(sorted(graph[root])))]
        index[root] = low[root] = counter
        counter += 1
        stack.append(root)
        on_stack.add(root)
        while work:
            node, children = work[-1]
            advanced = False
            for child in children:
                if child not in index:
                    index[child] = low[child] = counter
                    counter += 1
                    stack.append(child)
                    on_stack.add(child)
                    work.append((child, iter(sorted(graph.get(child, ())))))
                    advanced = True
                    break
                if child in on_stack:
                    low[node] = min(low[node], index[child])
            if advanced:
                continue
            work.pop()
            if work:
                parent = work[-1][0]
                low[parent] = min(low[parent], low[node])
            if low[node] == index[node]:
                component = []
                while True:
                    top = stack.pop()
                    on_stack.discard(top)
                    component.append(top)
                    if top == node:
                        break
                if len(component) > 1:
                    out.append(sorted(component))
    return sorted(out)


def sibling_cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """Cycles between the children of each package: every edge a.x... -> a.y... is an edge
    between the siblings a.x and a.y, at every depth."""
    packages = {m.rsplit(".", 1)[0] for m in graph if "." in m}
    out: list[list[str]] = []
    for pkg in sorted(packages):
        prefix = pkg + "."
        projected: dict[str, set[str]] = defaultdict(set)
        for src, dests in graph.items():
            if not src.startswith(prefix):
                continue
            a = prefix + src[len(prefix) :].split(".")[0]
            for dest in dests:
                if dest.startswith(prefix):
                    b = prefix + dest[len(prefix) :].split(".")[0]
                    if a != b:
                        projected[a].add(b)
                        projected.setdefault(b, set())
        out.extend(strongly_connected(dict(projected)))
    return out


def _private(part: str) -> bool:
    return part.startswith("_") and not part.startswith("__")


def private_crossings(files: dict[str, str]) -> list[str]:
    """Imports in the package of a private module or name from outside the package that owns it.

    A private module ``p._m`` and a private name ``_n`` of module ``p.m`` (or of package ``p``)
    belong to package ``p``; an import from outside ``p`` crosses it.
    """
    out = []
    for path, text in sorted(files.items()):
        if not (path.startswith(PKG + "/") and path.endswith(".py")):
            continue
        mod = module_name(path)
        is_pkg = path.endswith("__init__.py")
        own_pkg = mod if is_pkg else mod.rsplit(".", 1)[0]
        for target, name, line in imports_of(text, mod, is_pkg):
            if not target.startswith("contactlab"):
                continue
            parts = target.split(".") + ([name] if name else [])
            for i, part in enumerate(parts):
                if not _private(part) or i == 0:
                    continue
                dotted = ".".join(parts[:i])
                owner = dotted.rsplit(".", 1)[0] if _is_module_file(files, dotted) else dotted
                if not (own_pkg == owner or own_pkg.startswith(owner + ".")):
                    out.append(f"{path}:{line} {'.'.join(parts[: i + 1])}")
                break
    return out


def _is_module_file(files: dict[str, str], dotted: str) -> bool:
    """Whether a dotted name is a module file (not a package)."""
    return f"python/{dotted.replace('.', '/')}.py" in files


def test_private_imports(files: dict[str, str]) -> tuple[int, list[str]]:
    """The test files, and those importing a private (``_name``) module or name of contactlab."""
    tests = sorted(p for p in files if p.startswith("tests/") and Path(p).name.startswith("test_"))
    hits = []
    for path in tests:
        for node in ast.walk(ast.parse(files[path])):
            names: list[str] = []
            if isinstance(node, ast.Import):
                names = [a.name for a in node.names if a.name.startswith("contactlab")]
            elif isinstance(node, ast.ImportFrom) and (node.module or "").startswith("contactlab"):
                names = [f"{node.module}.{a.name}" for a in node.names]
            if any(_private(part) for n in names for part in n.split(".")):
                hits.append(path)
                break
    return len(tests), hits


RS_FN = re.compile(r"^\s*(?:pub(?:\([^)]*\))?\s+)?(?:const\s+)?(?:unsafe\s+)?fn\s+(\w+)")


def rust_functions(text: str) -> list[tuple[str, int, int]]:
    """``(name, first line, length)`` of each Rust ``fn`` with a body (braces counted, strings,
    chars and comments skipped)."""
    lines = text.split("\n")
    out = []
    for i, line in enumerate(lines):
        m = RS_FN.match(line)
        if not m:
            continue
        depth = 0
        opened = False
        for j in range(i, len(lines)):
            code = _strip_rust(lines[j])
            if not opened and ";" in code and "{" not in code:
                break  # a declaration without a body (trait method)
            for ch in code:
                if ch == "{":
                    depth += 1
                    opened = True
                elif ch == "}":
                    depth -= 1
            if opened and depth == 0:
                out.append((m.group(1), i + 1, j - i + 1))
                break
    return out


def _strip_rust(line: str) -> str:
    line = re.sub(r'"(?:\\.|[^"\\])*"', '""', line)
    line = re.sub(r"'(?:\\.|[^'\\])'", "''", line)
    return line.split("//", 1)[0]


def _reason(lines: list[str], at: int) -> str:
    """The ``//`` comment (not doc comment) just above line ``at`` (0-based), skipping the
    attributes and doc comments between: the justification an allowance carries."""
    said: list[str] = []
    k = at - 1
    while k >= 0:
        text = lines[k].strip()
        if text.startswith("//") and not text.startswith(("///", "//!")):
            said.insert(0, text.lstrip("/ "))
        elif said or not (text.startswith(("#[", "///")) or text == ""):
            break
        k -= 1
    return " ".join(said) or "(no comment)"


def measure(files: dict[str, str]) -> Metrics:
    """Every measurement of one tree."""
    m = Metrics()
    for path, text in sorted(files.items()):
        n_lines = text.count("\n") + (0 if text.endswith("\n") else 1)
        if path.startswith(PKG + "/") and path.endswith(".py"):
            if n_lines > FILE_LIMIT:
                m.py_long_files.append((path, n_lines))
            for node in ast.walk(ast.parse(text)):
                if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                    length = node.end_lineno - node.lineno + 1
                    if length > PY_FUNC_LIMIT:
                        m.py_long_functions.append((f"{path}:{node.name}", length))
            m.fmt_skip += len(re.findall(r"#\s*fmt:\s*skip", text))
        elif path.startswith("rust/") and path.endswith(".rs"):
            if n_lines > FILE_LIMIT:
                m.rs_long_files.append((path, n_lines))
            for name, _, length in rust_functions(text):
                if length > RS_FUNC_LIMIT:
                    m.rs_long_functions.append((f"{path}:{name}", length))
            rs_lines = text.split("\n")
            for k, line in enumerate(rs_lines, 1):
                if re.search(r"allow\(\s*clippy::", line) and not line.lstrip().startswith("//"):
                    lint = ", ".join(re.findall(r"clippy::(\w+)", line))
                    m.clippy_allows.append(f"{path}:{k} `{lint}`: {_reason(rs_lines, k - 1)}")
    graph = import_graph(files)
    m.module_cycles = strongly_connected(graph)
    m.package_cycles = sibling_cycles(graph)
    m.private_crossings = private_crossings(files)
    m.test_files, m.test_files_private = test_private_imports(files)
    return m


def _fmt_list(items: list[tuple[str, int]]) -> str:
    if not items:
        return "none"
    return "<br>".join(f"`{name}` {n}" for name, n in sorted(items, key=lambda t: -t[1]))


def _fmt_cycles(cycles: list[list[str]]) -> str:
    if not cycles:
        return "none"
    return "<br>".join(" ↔ ".join(f"`{c}`" for c in cyc) for cyc in cycles)


def _count(attr: str):
    return lambda m: str(len(getattr(m, attr)))


def _tests(m: Metrics) -> str:
    return f"{len(m.test_files_private)} of {m.test_files}"


def table(columns: list[tuple[str, Metrics]]) -> str:
    """The measurements of each revision side by side, in Markdown."""

    def row(label: str, cell) -> str:
        return f"| {label} | " + " | ".join(cell(m) for _, m in columns) + " |"

    def listed(attr: str):
        return lambda m: f"{len(getattr(m, attr))}: {_fmt_list(getattr(m, attr))}"

    def cycles(attr: str):
        return lambda m: f"{len(getattr(m, attr))}: {_fmt_cycles(getattr(m, attr))}"

    out = [
        "| measurement | " + " | ".join(label for label, _ in columns) + " |",
        "| --- |" + " --- |" * len(columns),
        row(f"Python functions > {PY_FUNC_LIMIT} lines", listed("py_long_functions")),
        row(f"Python files > {FILE_LIMIT} lines", listed("py_long_files")),
        row(f"Rust functions > {RS_FUNC_LIMIT} lines", listed("rs_long_functions")),
        row(f"Rust files > {FILE_LIMIT} lines", listed("rs_long_files")),
        row("import cycles between modules (strongly connected sets)", cycles("module_cycles")),
        row("import cycles between the children of a package", cycles("package_cycles")),
        row("private names crossing a package (in the package)", _count("private_crossings")),
        row("test files importing a private name of contactlab", _tests),
        row("`# fmt: skip` in python/contactlab", lambda m: str(m.fmt_skip)),
        row("`allow(clippy::…)` attributes in rust/", lambda m: str(len(m.clippy_allows))),
    ]
    return "\n".join(out)


def details(m: Metrics) -> str:
    """The lists behind the counts of one tree."""
    parts = ["### Test files importing private names", ""]
    parts += [f"- `{p}`" for p in m.test_files_private] or ["none"]
    parts += ["", "### Private names crossing a package", ""]
    parts += [f"- `{p}`" for p in m.private_crossings] or ["none"]
    parts += ["", "### `allow(clippy::…)` attributes and the comment that justifies each", ""]
    parts += [f"- {p}" for p in m.clippy_allows] or ["none"]
    return "\n".join(parts)


HEADER = """# Layering (issue 32): the measurements before and after

Written by `{argv}`; re-run it to refresh. Columns: {columns}. A function's length runs from
its `def`/`fn` line to its last line; imports are counted module level and inside functions
(only `if TYPE_CHECKING:` blocks left out), a name imported from a package that is a module of
it counting as that module.

"""

#: what the revisions this report is usually run with stand for
KNOWN = {
    "8660a71^": "the tree before the layering began (the issue's figures)",
    "6b32b6d": "the tree when the last round of the layering started (the big moves done)",
    "main": "the integration branch (other helpers' work, without this branch's)",
    "working tree": "this branch, main merged",
}


def fingerprints(before: Path) -> str:
    """The fingerprints of the working tree against those recorded in ``before``."""
    run = subprocess.run(
        [sys.executable, str(ROOT / "benches" / "layering_fingerprints.py")],
        cwd=ROOT,
        capture_output=True,
        text=True,
        check=True,
    )
    old = dict(_split(line) for line in before.read_text().splitlines() if line.strip())
    new = dict(_split(line) for line in run.stdout.splitlines() if line.strip())
    same = [k for k in new if old.get(k) == new[k]]
    changed = [k for k in new if k in old and old[k] != new[k]]
    out = [
        "## Results unchanged (benches/layering_fingerprints.py)",
        "",
        f"SHA-256 of `contactlab analyze --json` (and its printout) of the bundled data and of "
        f"fixed-seed outputs of every function the layering split, against "
        f"`{before.as_posix()}`: **{len(same)} of {len(new)} identical**"
        + (f", changed: {', '.join(changed)}" if changed else "")
        + (
            f", new: {len(new) - len(same) - len(changed)}"
            if len(new) > len(same) + len(changed)
            else ""
        )
        + ".",
    ]
    return "\n".join(out)


def _split(line: str) -> tuple[str, str]:
    digest, _, name = line.partition("  ")
    return name, digest


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--rev", help="measure this revision instead of the working tree")
    parser.add_argument(
        "--before", action="append", default=[], help="revision(s) to show before it"
    )
    parser.add_argument("--out", help="write the Markdown here")
    parser.add_argument(
        "--fingerprints",
        metavar="BEFORE",
        help="run benches/layering_fingerprints.py on the working tree and compare its lines "
        "with this file (recorded on the old tree)",
    )
    parser.add_argument("--notes", help="a Markdown file appended after the table")
    args = parser.parse_args(argv)
    after = measure(_read_tree(args.rev))
    after_label = args.rev or "working tree"
    columns = [(rev, measure(_read_tree(rev))) for rev in args.before]
    columns.append((after_label, after))
    text = HEADER.format(
        columns="; ".join(
            f"`{label}`" + (f" {KNOWN[label]}" if label in KNOWN else "") for label, _ in columns
        ),
        argv=" ".join(["python benches/layering_metrics.py", *(argv or sys.argv[1:])]),
    )
    text += table(columns) + "\n"
    if args.fingerprints:
        text += "\n" + fingerprints(Path(args.fingerprints)) + "\n"
    if args.notes:
        text += "\n" + Path(args.notes).read_text(encoding="utf-8").strip() + "\n"
    text += "\n## Details (" + after_label + ")\n\n" + details(after) + "\n"
    if args.out:
        Path(args.out).write_text(text, encoding="utf-8")
    else:
        sys.stdout.write(text)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
