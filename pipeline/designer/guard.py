"""What keeps the designer's server a private tool: token, Host/Origin, confined paths.

The server listens on loopback only, but any web page open in the same browser can
reach loopback, and a DNS name an attacker controls can be pointed at 127.0.0.1
("DNS rebinding"). So every request must carry the session's token (a 128-bit secret
printed with the URL, never stored in a cookie, which the browser would attach to other
pages' requests too), name the server's own host in ``Host``, and, when a browser sends
an ``Origin``, come from the server's own origin. Every file the page reads or writes
through the server is resolved by :class:`Roots`, which refuses anything outside the
library path and the session's own folders.

>>> g = Guard("t0ken", port=8765)
>>> g.host_ok("127.0.0.1:8765"), g.host_ok("evil.example:8765")
(True, False)
>>> g.origin_ok("http://localhost:8765"), g.origin_ok("http://evil.example")
(True, False)
"""

from __future__ import annotations

import os
import secrets
from collections.abc import Iterable
from pathlib import Path
from typing import Any

from lookdev.materials.errors import LookdevError

__all__ = ["Guard", "PathRefused", "Roots", "new_token"]

LOOPBACK_NAMES = ("127.0.0.1", "localhost")
TOKEN_HEADER = "x-lookdev-token"


def new_token() -> str:
    """A fresh per-session secret: 128 bits, URL-safe."""
    return secrets.token_urlsafe(16)


class PathRefused(LookdevError):
    """A path the page asked for lies outside what the session may read or write."""


class Guard:
    """The request checks of one server: its token and its own ``host:port``."""

    def __init__(self, token: str, *, port: int):
        self.token = token
        self.port = port

    def token_ok(self, given: str | None) -> bool:
        return given is not None and secrets.compare_digest(given.encode(), self.token.encode())

    def host_ok(self, host: str | None) -> bool:
        """``Host`` names this server as loopback (a rebound foreign name is refused)."""
        return host in {f"{name}:{self.port}" for name in LOOPBACK_NAMES}

    def origin_ok(self, origin: str | None) -> bool:
        """No ``Origin`` (not a browser's cross-origin request) or this server's own."""
        if origin is None:
            return True
        return origin in {f"http://{name}:{self.port}" for name in LOOPBACK_NAMES}

    def check(self, headers: dict[str, str], path_token: str | None) -> str | None:
        """None when the request may proceed, else the one-line reason it may not."""
        if not self.host_ok(headers.get("host")):
            return "foreign Host header"
        if not self.origin_ok(headers.get("origin")):
            return "foreign Origin"
        if not (self.token_ok(path_token) or self.token_ok(headers.get(TOKEN_HEADER))):
            return "missing or wrong session token"
        return None


class Roots:
    """The folders a session may read and write through the server, by name.

    A page names a file as ``(root, relative path)``; the relative path must be plain
    (no ``..``, not absolute, no backslash, no ``%``, no NUL: an encoded separator that a
    later layer decoded would be a second way in) and must resolve, links followed,
    inside its root.
    """

    def __init__(self, roots: dict[str, Path]):
        self.roots = {name: Path(os.path.realpath(p)) for name, p in roots.items()}

    def names(self) -> list[str]:
        return list(self.roots)

    def resolve(self, root: str, relative: str) -> Path:
        """The real path of ``relative`` under ``root``, or :class:`PathRefused`."""
        base = self.roots.get(root)
        if base is None:
            raise PathRefused(f"unknown folder {root!r}; allowed: {', '.join(self.roots)}")
        parts = _plain_parts(relative)
        real = Path(os.path.realpath(base.joinpath(*parts)))
        if real != base and not real.is_relative_to(base):
            raise PathRefused(f"{relative!r} leads out of the {root} folder")
        return real

    def locate(self, path: Path) -> tuple[str, str] | None:
        """``(root, relative)`` naming ``path`` if it lies under a root, else None."""
        real = Path(os.path.realpath(path))
        for name, base in self.roots.items():
            if real.is_relative_to(base):
                return name, real.relative_to(base).as_posix()
        return None

    def listing(self, root: str, relative: str, suffixes: Iterable[str]) -> dict[str, Any]:
        """One folder of the file picker: its sub-folders and files with ``suffixes``
        (``relative`` empty for the root itself). Entries whose links lead out of the
        root, and hidden ones, are left out: the picker never shows what it may not open."""
        base = self.roots.get(root)
        folder = self.resolve(root, relative) if relative else base
        if folder is None:
            raise PathRefused(f"unknown folder {root!r}; allowed: {', '.join(self.roots)}")
        if not folder.is_dir():
            raise PathRefused(f"{relative!r} is not a folder of {root}")
        wanted = tuple(s.lower() for s in suffixes)
        dirs, files = [], []
        for entry in sorted(folder.iterdir()):
            real = Path(os.path.realpath(entry))
            if entry.name.startswith(".") or not real.is_relative_to(base):
                continue
            name = entry.relative_to(base).as_posix()
            if real.is_dir():
                dirs.append(name)
            elif entry.name.lower().endswith(wanted):
                files.append(name)
        up = folder.relative_to(base).parent.as_posix() if folder != base else None
        return {
            "root": root,
            "path": relative,
            "up": "" if up == "." else up,
            "dirs": dirs,
            "files": files,
        }


def _plain_parts(relative: str) -> list[str]:
    bad = next((c for c in ("\\", "%", "\x00") if c in relative), None)
    if bad is not None:
        raise PathRefused(f"{relative!r}: {bad!r} is not allowed in a path")
    if relative.startswith("/") or (len(relative) > 1 and relative[1] == ":"):
        raise PathRefused(f"{relative!r}: absolute paths are not allowed")
    parts = [p for p in relative.split("/") if p not in ("", ".")]
    if ".." in parts:
        raise PathRefused(f"{relative!r}: '..' is not allowed")
    if not parts:
        raise PathRefused("empty path")
    return parts
