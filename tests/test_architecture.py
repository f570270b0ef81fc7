"""Import directions of the source tree (docs/design.md, Layout and Data flow), read from the
source with ``ast``, nothing imported: ``pipeline → library → materials``; nothing outside
``pipeline/cli`` imports the CLI; benchmarks are imported only by the CLI and by each
other; and no two modules import each other, directly or round a longer loop.

Every ``import`` counts, at the top of a module or inside a function (an import deferred
into a function still ties the two modules together); relative imports are resolved, and
``from package import name`` counts as importing the submodule ``package.name`` where
there is one, else the package's ``__init__``. The parent packages Python initialises on
the way to a module are not counted as imports of it.
"""

from __future__ import annotations

import ast
from dataclasses import dataclass
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
FOLDERS = ("materials", "library", "pipeline")  # installed as lookdev.<folder>


@dataclass(frozen=True)
class Import:
    source: str  # importing module, dotted
    file: str  # its path relative to the repository
    line: int
    target: str  # imported module, dotted (a module of the tree where it names one)

    def __str__(self) -> str:
        return f"{self.file}:{self.line} imports {self.target}"


def module_name(path: Path) -> str:
    parts = list(path.relative_to(ROOT).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(["lookdev", *parts])


def source_files() -> dict[str, Path]:
    files = {}
    for folder in FOLDERS:
        for path in sorted((ROOT / folder).rglob("*.py")):
            if not any(p.startswith(".") or p == "__pycache__" for p in path.parts):
                files[module_name(path)] = path
    return files


def _resolve(module: str, is_package: bool, level: int, name: str | None) -> str:
    """The absolute name of ``from <level dots><name> import …`` in ``module``."""
    if level == 0:
        return name or ""
    package = module.split(".") if is_package else module.split(".")[:-1]
    base = package[: len(package) - (level - 1)]
    return ".".join([*base, name] if name else base)


def imports_of(module: str, path: Path, modules: set[str]) -> list[Import]:
    """Every import in ``path``, each resolved to the most specific module it names."""
    rel = path.relative_to(ROOT).as_posix()
    tree = ast.parse(path.read_text(encoding="utf-8"), filename=rel)
    is_package = path.name == "__init__.py"
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            found += [Import(module, rel, node.lineno, a.name) for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = _resolve(module, is_package, node.level, node.module)
            for alias in node.names:
                sub = f"{base}.{alias.name}"
                # ``from package import submodule`` imports the submodule itself
                target = sub if sub in modules else base
                found.append(Import(module, rel, node.lineno, target))
    return found


@pytest.fixture(scope="module")
def graph() -> list[Import]:
    files = source_files()
    modules = set(files)
    edges = []
    for module, path in files.items():
        edges += imports_of(module, path, modules)
    return edges


def _inside(module: str, package: str) -> bool:
    return module == package or module.startswith(package + ".")


def _offending(graph: list[Import], sources: tuple[str, ...], targets: tuple[str, ...]):
    return _lines(
        e
        for e in graph
        if any(_inside(e.source, s) for s in sources) and any(_inside(e.target, t) for t in targets)
    )


def _lines(edges) -> list[str]:
    """One line per import statement and target (``from x import a, b`` is one)."""
    return list(dict.fromkeys(str(e) for e in edges))


def test_the_tree_is_read():
    files = source_files()
    assert "lookdev.materials.microfacet" in files and "lookdev.pipeline.cli" in files
    assert _resolve("lookdev.pipeline.blend.engine", False, 1, "result") == (
        "lookdev.pipeline.blend.result"
    )
    assert _resolve("lookdev.pipeline.blend", True, 2, "export") == "lookdev.pipeline.export"
    assert _resolve("lookdev.pipeline.cli.bench", False, 2, None) == "lookdev.pipeline"


def test_materials_import_neither_library_nor_pipeline(graph):
    bad = _offending(graph, ("lookdev.materials",), ("lookdev.library", "lookdev.pipeline"))
    assert not bad, "materials/ must not depend on library/ or pipeline/:\n" + "\n".join(bad)


def test_library_does_not_import_pipeline(graph):
    bad = _offending(graph, ("lookdev.library",), ("lookdev.pipeline",))
    assert not bad, "library/ must not depend on pipeline/:\n" + "\n".join(bad)


def test_only_the_cli_imports_the_cli(graph):
    bad = _lines(
        e
        for e in graph
        if _inside(e.target, "lookdev.pipeline.cli")
        and not _inside(e.source, "lookdev.pipeline.cli")
    )
    assert not bad, "only pipeline/cli may import pipeline/cli:\n" + "\n".join(bad)


def test_only_the_cli_and_the_benchmarks_import_the_benchmarks(graph):
    allowed = ("lookdev.pipeline.bench", "lookdev.pipeline.cli")
    bad = _lines(
        e
        for e in graph
        if _inside(e.target, "lookdev.pipeline.bench")
        and not any(_inside(e.source, a) for a in allowed)
    )
    assert not bad, "only pipeline/cli and pipeline/bench may import pipeline/bench:\n" + (
        "\n".join(bad)
    )


CONSUMERS = ("lookdev.pipeline.export", "lookdev.pipeline.proof", "lookdev.pipeline.analysis")
"""Modules that take the blended material (docs/design.md: one hub): exporters, proofs, plots,
the report and the stability sweep."""
PRESET_WRITERS = ("lookdev.pipeline.export.usd.presets",)
"""`lookdev import usd` writes what it read as preset files: the one consumer that needs
the library, and only to write presets, never to look materials up."""
WRITE_PATH = "lookdev.library.files"
"""The one write path (atomic, modes, links, signals): every consumer writes through it.
It lives in ``library`` (which ``materials``, doing no I/O, cannot hold) and imports nothing
of the library but the error root, so using it looks no preset up."""


def test_consumers_never_look_presets_up(graph):
    bad = [
        line
        for line in _offending(graph, CONSUMERS, ("lookdev.library",))
        if not any(
            line.startswith(str(source_files()[m].relative_to(ROOT))) for m in PRESET_WRITERS
        )
        and not line.endswith(f"imports {WRITE_PATH}")
    ]
    assert not bad, "exporters, proofs and analysis take the blend, not presets:\n" + "\n".join(bad)


def test_the_write_path_imports_nothing_of_the_library(graph):
    bad = [
        str(e)
        for e in graph
        if e.source == WRITE_PATH and e.target.startswith("lookdev.") and e.target != WRITE_PATH
        if e.target != "lookdev.materials.errors"
    ]
    assert not bad, "library/files.py must stay generic:\n" + "\n".join(bad)


def test_consumers_never_blend():
    """Nothing that takes the hub imports the blending engine or its ``blend`` function."""
    bad = []
    for module, path in source_files().items():
        if not any(_inside(module, c) for c in CONSUMERS):
            continue
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.ImportFrom) and (node.module or "").endswith("blend"):
                if any(alias.name == "blend" for alias in node.names):
                    bad.append(f"{path.relative_to(ROOT)}:{node.lineno} imports blend()")
            if isinstance(node, ast.ImportFrom) and (node.module or "").endswith("blend.engine"):
                bad.append(f"{path.relative_to(ROOT)}:{node.lineno} imports the engine")
    assert not bad, "consumers take the blended material; blend runs once, upstream:\n" + (
        "\n".join(bad)
    )


def cycles(graph: list[Import]) -> list[list[Import]]:
    """One loop of imports through each strongly connected group of modules (Tarjan)."""
    modules = {e.source for e in graph}
    out: dict[str, list[Import]] = {m: [] for m in modules}
    for e in graph:
        if e.target in modules and e.target != e.source:
            out[e.source].append(e)
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    groups: list[set[str]] = []

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for e in out[v]:
            w = e.target
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            group = set()
            while True:
                w = stack.pop()
                on_stack.discard(w)
                group.add(w)
                if w == v:
                    break
            if len(group) > 1:
                groups.append(group)

    for m in sorted(modules):
        if m not in index:
            visit(m)
    return [_loop(sorted(g)[0], g, out) for g in groups]


def _loop(start: str, group: set[str], out: dict[str, list[Import]]) -> list[Import]:
    """The shortest import path from ``start`` back to itself within ``group``."""
    paths: dict[str, list[Import]] = {start: []}
    frontier = [start]
    while frontier:
        nxt = []
        for v in frontier:
            for e in out[v]:
                if e.target not in group:
                    continue
                if e.target == start:
                    return [*paths[v], e]
                if e.target not in paths:
                    paths[e.target] = [*paths[v], e]
                    nxt.append(e.target)
        frontier = nxt
    raise AssertionError(f"no loop through {start}")


def test_cycle_finder_names_each_edge():
    a = Import("a", "a.py", 3, "b")
    b = Import("b", "b.py", 7, "a")
    (loop,) = cycles([a, b, Import("b", "b.py", 9, "c")])
    assert [str(e) for e in loop] == ["a.py:3 imports b", "b.py:7 imports a"]


def test_no_import_cycles(graph):
    found = cycles(graph)
    text = "\n\n".join("\n".join(f"  {e}" for e in loop) for loop in found)
    assert not found, f"{len(found)} import cycle(s) in the source tree:\n{text}"
