"""Sphinx glue for lookdev's docstrings and measurement pages.

* The docstrings write maths as text: ``|cos θi|`` is an absolute value, not a reST
  substitution, and ``sheen_`` in a table is a word, not a link. :func:`escape_bars`
  escapes such bars and underscores before the docstring is parsed (not in literals,
  doctests, literal blocks or table rows).
* Docstrings cross-reference sibling modules relatively (``:mod:`.sheen``` in
  ``lookdev.materials.disney``). Sphinx looks such a name up by suffix, which is ambiguous
  when two packages have a ``sheen`` module; :func:`nearest` keeps the candidate nearest the
  referring module, as Python's own relative import would.
* Re-exported numpy functions (``NumpyOps.sqrt = np.sqrt``) and type aliases are not
  lookdev's API: :func:`skip_foreign` leaves them out.
* ``{json-table}`` renders a table from a benchmark's JSON file (``docs/measurements/data``),
  so a measurement page shows what the benchmark wrote, not a copy.
"""

from __future__ import annotations

import json
import re
import types
from pathlib import Path
from typing import Any

from docutils import nodes
from docutils.parsers.rst import directives
from sphinx.domains.python import PythonDomain
from sphinx.util.docutils import SphinxDirective

__all__ = ["JsonTable", "escape_bars", "nearest", "setup", "skip_foreign"]

_LITERAL = re.compile(r"(``.+?``|`[^`]*`)")


_BARE_REFERENCE = re.compile(r"(?<=[A-Za-z0-9])_(?=\s|$|[.,;:)])")


def _escape_line(line: str) -> str:
    parts = _LITERAL.split(line)
    return "".join(
        p if i % 2 else _BARE_REFERENCE.sub(r"\\_", p.replace("|", r"\|"))
        for i, p in enumerate(parts)
    )


def escape_bars(app: Any, what: str, name: str, obj: Any, options: Any, lines: list[str]) -> None:
    """Escape ``|`` written as maths in a docstring's prose lines, in place."""
    literal_indent: int | None = None
    for i, line in enumerate(lines):
        stripped = line.lstrip()
        indent = len(line) - len(stripped)
        if literal_indent is not None:
            if stripped and indent <= literal_indent:
                literal_indent = None
            else:
                continue
        if stripped.startswith((">>>", "...", "|", "+-", "+=")):
            pass
        else:
            lines[i] = _escape_line(line)
        if stripped.endswith("::"):
            literal_indent = indent


def skip_foreign(app: Any, what: str, name: str, obj: Any, skip: bool, options: Any) -> bool | None:
    """Skip members that are numpy's functions or bare type aliases, not lookdev's own."""
    if isinstance(obj, (types.GenericAlias, types.UnionType)):
        return True
    module = getattr(obj, "__module__", None) or ""
    if callable(obj) and not isinstance(obj, type) and module.split(".")[0] == "numpy":
        return True
    if type(obj).__name__ == "ufunc":
        return True
    return None


def nearest(matches: list[tuple[str, Any]], modname: str | None) -> list[tuple[str, Any]]:
    """Of several suffix matches, those in the package nearest ``modname``."""
    if len(matches) < 2 or not modname:
        return matches
    here = modname.split(".")

    def shared(target: str) -> int:
        n = 0
        for a, b in zip(here, target.split("."), strict=False):
            if a != b:
                break
            n += 1
        return n

    best = max(shared(t) for t, _ in matches)
    closest = [m for m in matches if shared(m[0]) == best]
    return closest if len(closest) == 1 else matches


_find_obj = PythonDomain.find_obj


def _find_obj_nearest(self, env, modname, classname, name, type, searchmode=0):  # noqa: A002
    matches = _find_obj(self, env, modname, classname, name, type, searchmode)
    if searchmode == 1 and len(matches) > 1:
        matches = nearest(matches, modname)
    return matches


class JsonTable(SphinxDirective):
    """``{json-table} data/file.json`` with ``:rows: key.path`` and ``:columns:``.

    ``:columns:`` is ``key = Heading`` pairs separated by ``;``; a key may be a dotted path
    into the row.
    ``:format:`` gives a Python format per key (``key = {:.3g}``); ``:sort: key`` (``-key``
    descending) and ``:limit: N`` pick the rows shown. The file is a dependency of the
    page, so a regenerated file rebuilds it.
    """

    required_arguments = 1
    has_content = False
    option_spec = {
        "rows": directives.unchanged_required,
        "columns": directives.unchanged_required,
        "format": directives.unchanged,
        "caption": directives.unchanged,
        "sort": directives.unchanged,
        "limit": directives.nonnegative_int,
    }

    def run(self) -> list[nodes.Node]:
        rel, path = self.env.relfn2path(self.arguments[0])
        self.env.note_dependency(rel)
        data = json.loads(Path(path).read_text())
        rows = _dig(data, self.options["rows"])
        if isinstance(rows, dict):
            rows = [
                {"key": k, **v} if isinstance(v, dict) else {"key": k, "value": v}
                for k, v in rows.items()
            ]
        columns = [
            tuple(s.strip() for s in c.split("=", 1))
            for c in re.split(r"[;\n]", self.options["columns"])
            if c.strip()
        ]
        formats = dict(
            tuple(s.strip() for s in f.split("=", 1))
            for f in re.split(r"[;\n]", self.options.get("format", ""))
            if f.strip()
        )
        if "sort" in self.options:
            key = self.options["sort"].strip()
            descending = key.startswith("-")
            key = key.lstrip("-")
            rows = sorted(rows, key=lambda r: _dig(r, key), reverse=descending)
        if "limit" in self.options:
            rows = rows[: self.options["limit"]]
        table = nodes.table()
        group = nodes.tgroup(cols=len(columns))
        table += group
        for _ in columns:
            group += nodes.colspec(colwidth=1)
        head = nodes.thead()
        group += head
        head += _row([h for _, h in columns])
        body = nodes.tbody()
        group += body
        for r in rows:
            cells = []
            for key, _ in columns:
                value = _dig(r, key)
                fmt = formats.get(key)
                cells.append("–" if value is None else fmt.format(value) if fmt else str(value))
            body += _row(cells)
        if "caption" in self.options:
            table.insert(0, nodes.title(text=self.options["caption"]))
        return [table]


def _dig(data: Any, path: str) -> Any:
    for part in path.split("."):
        if isinstance(data, dict):
            data = data.get(part)
        elif isinstance(data, list) and part.isdigit():
            data = data[int(part)]
        else:
            return None
    return data


def _row(cells: list[str]) -> nodes.row:
    row = nodes.row()
    for text in cells:
        entry = nodes.entry()
        entry += nodes.paragraph(text=text)
        row += entry
    return row


def setup(app: Any) -> dict[str, Any]:
    PythonDomain.find_obj = _find_obj_nearest
    app.connect("autodoc-process-docstring", escape_bars, priority=400)
    app.connect("autodoc-skip-member", skip_foreign)
    app.add_directive("json-table", JsonTable)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
