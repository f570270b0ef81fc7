"""The documentation holds together: nothing points outside the repository, every citation
resolves in ``docs/references.bib``, the README's links and commands exist, and code
docstrings cite papers, not tracker numbers. (The site itself is built, warnings as errors,
by ``scripts/test.sh``.)"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
SKIP_DIRS = {".git", ".venv", "docs/_build", "docs/api/generated", "build", "dist"}
TEXT_SUFFIXES = {".py", ".md", ".toml", ".sh", ".txt", ".json", ".js", ".css", ".bib", ".cfg"}

# Spelled in two halves so this file does not match itself.
OUTSIDE = ["DESIGN" + ".md", "../" + "shared", "/work/" + "shared"]


def _files(suffixes: set[str] = TEXT_SUFFIXES, under: tuple[str, ...] = ("",)) -> list[Path]:
    found = []
    for top in under:
        for path in (ROOT / top).rglob("*"):
            rel = path.relative_to(ROOT).as_posix()
            if any(rel == d or rel.startswith(d + "/") for d in SKIP_DIRS):
                continue
            if ".egg-info" in rel or "__pycache__" in rel or "/." in "/" + rel:
                continue
            if path.is_file() and path.suffix in suffixes:
                found.append(path)
    return found


def test_nothing_points_outside_the_repository():
    hits = [
        f"{p.relative_to(ROOT)}:{n}: {line.strip()}"
        for p in _files()
        for n, line in enumerate(p.read_text(errors="replace").splitlines(), 1)
        if any(o in line for o in OUTSIDE)
    ]
    assert not hits, "\n".join(hits)


def _bib_keys() -> list[str]:
    return re.findall(r"^@\w+\{([^,\s]+),", (ROOT / "docs/references.bib").read_text(), re.M)


def test_bibliography_keys_are_unique_and_entries_complete():
    keys = _bib_keys()
    assert len(keys) >= 20
    assert len(keys) == len(set(keys))
    entries = re.split(r"^@", (ROOT / "docs/references.bib").read_text(), flags=re.M)[1:]
    for entry in entries:
        for field in ("author", "title", "year"):
            assert re.search(rf"^\s*{field}\s*=", entry, re.M), (entry.split(",")[0], field)


CITE_PY = re.compile(r":cite(?::\w+)?:`([^`]+)`")
CITE_MD = re.compile(r"\{cite(?::\w+)?\}`([^`]+)`")


def _cited() -> dict[str, str]:
    cited = {}
    for p in _files({".py"}, ("materials", "library", "pipeline")):
        for m in CITE_PY.finditer(p.read_text()):
            for key in m.group(1).split(","):
                cited.setdefault(key.strip(), str(p.relative_to(ROOT)))
    for p in _files({".md"}, ("docs",)):
        for m in CITE_MD.finditer(p.read_text()):
            for key in m.group(1).split(","):
                cited.setdefault(key.strip(), str(p.relative_to(ROOT)))
    return cited


def test_every_cited_key_is_in_the_bibliography():
    cited = _cited()
    assert cited, "the pages cite the papers they build on"
    missing = {k: where for k, where in cited.items() if k not in set(_bib_keys())}
    assert not missing, missing


def test_code_docstrings_cite_no_tracker_numbers():
    pattern = re.compile(r"\b[Ii]ssues? #?\d+|(?<![\w&])#\d{1,3}\b(?![0-9a-fA-F])")
    hits = [
        f"{p.relative_to(ROOT)}:{n}: {line.strip()}"
        for p in _files({".py"}, ("materials", "library", "pipeline"))
        for n, line in enumerate(p.read_text().splitlines(), 1)
        if pattern.search(line) and "noqa" not in line
    ]
    assert not hits, "\n".join(hits)


def test_test_paths_named_in_code_exist():
    pattern = re.compile(r"\btests/[\w/]+\.py")
    stale = [
        f"{p.relative_to(ROOT)}: {m.group(0)}"
        for p in _files({".py", ".sh"}, ("materials", "library", "pipeline", "scripts", "tests"))
        for m in pattern.finditer(p.read_text())
        if not (ROOT / m.group(0)).is_file()
    ]
    assert not stale, stale


README = (ROOT / "README.md").read_text()


def test_readme_links_resolve():
    links = re.findall(r"\]\(([^)#\s]+)\)", README) + re.findall(r'src="([^"]+)"', README)
    assert links
    missing = [link for link in links if "://" not in link and not (ROOT / link).exists()]
    assert not missing, missing


def _table_commands() -> list[list[str]]:
    """``lookdev a b|c`` in the README's command table → [["a", "b"], ["a", "c"]]."""
    commands = []
    for cell in re.findall(r"^\| `lookdev ([^`]+)` \|", README, re.M):
        words = cell.replace("\\|", "|").split()
        words = [w for w in words if w.isupper() is False]  # NAME placeholders
        head, *tail = words
        for alternative in tail[0].split("|") if tail else [None]:
            commands.append([head] + ([alternative] if alternative else []))
    return commands


def test_readme_table_names_real_commands(cli):
    commands = _table_commands()
    assert len(commands) >= 15
    for words in commands:
        result = cli(*words, "--help")
        assert result.code == 0, (words, result.err)
        assert "Usage" in result.out


def test_readme_fits_a_newcomer():
    lines = README.splitlines()
    assert len(lines) <= 120
    quick = README.index("## Quick start")
    assert README.index("bash scripts/run.sh") < quick
    assert README.index("bash scripts/test.sh") < quick
    assert "docs/gallery/" in README[:quick]


@pytest.mark.parametrize("page", ["guide/index.md", "measurements/index.md"])
def test_guide_and_measurements_toctrees_glob_their_folders(page):
    text = (ROOT / "docs" / page).read_text()
    assert ":glob:" in text and re.search(r"^\*$", text, re.M)
