"""What a preset file is before it is a preset: bytes, TOML, a name.

Kept apart from :mod:`.preset` (the schemas) so that reading headers
(:mod:`.index`, ``lookdev presets list``) needs neither pydantic nor the models.
"""

from __future__ import annotations

import re
import tomllib
from typing import Any

from lookdev.materials.errors import short_repr

from .errors import PresetError

__all__ = ["MAX_BYTES", "NAME_RE", "check_name", "parse_toml"]

MAX_BYTES = 1 << 20  # presets are hand-written text; anything larger is not one
NAME_RE = re.compile(r"[A-Za-z0-9][A-Za-z0-9_-]{0,99}")  # whole names: fullmatch


def check_name(name: str, *, field: str | None = "name") -> str:
    """``name`` if it is a safe preset name: a file name in its library and nothing more.

    Letters, digits, ``_`` and ``-``; no path separators, no ``..``, not absolute.

    >>> check_name("gold_leaf")
    'gold_leaf'
    """
    if not isinstance(name, str) or not NAME_RE.fullmatch(name):
        raise PresetError(
            f"preset name {short_repr(name)} is not allowed; use 1-100 letters, digits, '_' or '-' "
            "(no path separators, no '..')",
            field=field,
        )
    return name


def parse_toml(data: bytes, *, where: str) -> dict[str, Any]:
    """The TOML document in ``data``, or a :class:`PresetError` naming the line."""
    if len(data) > MAX_BYTES:
        raise PresetError(
            f"file is {len(data)} bytes; a preset is a small text file (at most {MAX_BYTES})",
            where=where,
        )
    try:
        # A byte-order mark (some Windows editors write one) is accepted and ignored.
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise PresetError(f"not UTF-8 text (bad byte at offset {exc.start})", where=where) from None
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        # tomllib says "at end of document" without a line; editors want one.
        at_end = f"at end of document, line {text.count(chr(10)) + 1}"
        msg = str(exc).replace("at end of document", at_end)
        raise PresetError(f"malformed TOML: {msg}", where=where) from None
    except RecursionError:
        raise PresetError("malformed TOML: values nested too deeply", where=where) from None
