"""Every public module says what it offers: each module of the package whose dotted name has
no part starting with ``_`` declares ``__all__`` (read with ``ast``), and every name in it
exists once the module is imported (a lazy ``__getattr__`` counts)."""

from __future__ import annotations

import ast
import importlib
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
FOLDERS = ("materials", "library", "pipeline")  # installed as lookdev.<folder>


def public_modules() -> dict[str, Path]:
    """Dotted name → file of every module without an underscore part (``__init__`` aside)."""
    found = {}
    for folder in FOLDERS:
        for path in sorted((ROOT / folder).rglob("*.py")):
            parts = list(path.relative_to(ROOT).with_suffix("").parts)
            if parts[-1] == "__init__":
                parts.pop()
            if any(p.startswith("_") for p in parts) or "__pycache__" in path.parts:
                continue
            found[".".join(["lookdev", *parts])] = path
    return found


def declared_all(path: Path) -> list[str] | None:
    """The literal ``__all__`` at the top level of ``path``, or None when there is none."""
    for node in ast.parse(path.read_text(encoding="utf-8")).body:
        targets = (
            node.targets
            if isinstance(node, ast.Assign)
            else [node.target]
            if isinstance(node, ast.AnnAssign)
            else []
        )
        if any(isinstance(t, ast.Name) and t.id == "__all__" for t in targets):
            return list(ast.literal_eval(node.value))
    return None


MODULES = public_modules()


def test_the_tree_is_read():
    assert "lookdev.materials.disney" in MODULES and "lookdev.pipeline.cli" in MODULES
    assert not any(".__main__" in m or "._" in m for m in MODULES)


def test_every_public_module_declares_all():
    missing = [str(p.relative_to(ROOT)) for p in MODULES.values() if declared_all(p) is None]
    assert not missing, "modules without __all__:\n" + "\n".join(missing)


@pytest.mark.parametrize("module", sorted(MODULES))
def test_every_name_in_all_exists(module):
    names = declared_all(MODULES[module]) or []
    assert len(names) == len(set(names)), f"{module}.__all__ repeats a name"
    imported = importlib.import_module(module)
    absent = [n for n in names if not hasattr(imported, n)]
    assert not absent, f"{module}.__all__ names what it does not define: {absent}"
