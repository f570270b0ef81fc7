"""The one write path: every file lookdev writes goes through here (:doc:`/design`, Files on
shared storage).

The rules, written once:

- **Atomic.** Bytes go to a hidden temporary beside the destination
  (``.NAME.<host>-<pid>-<token>.tmp.SUFFIX``: same folder, so the rename never crosses a
  filesystem; same suffix, so OpenImageIO, USD and matplotlib pick the right format), are
  flushed with ``fsync``, and replace the destination in one ``os.replace``; the folder entry
  is flushed after. A reader sees the old file or the new one, never half.
- **Modes.** A new file gets the mode the umask gives (``0o666 & ~umask``: ``mkstemp``'s 0600
  would hide it from the group); a file that exists keeps its mode and its group, so a
  group-writable shared library stays group-writable.
- **Links.** A destination that is a symlink is written *through*: the temporary goes beside
  the link's target and replaces the target, so the link stays a link (what ``>`` does).
  Whether a link may be followed at all is the caller's policy (a library refuses links
  that lead out of its root, :mod:`lookdev.library.library`).
- **Nothing left behind.** The temporaries are removed on any failure (an ``ENOSPC`` mid-write
  included), on Ctrl-C (``KeyboardInterrupt`` unwinds through ``finally``) and on SIGTERM /
  SIGHUP: while a write is open, those signals raise :class:`Terminated` (a ``SystemExit``
  with code 128 + signal) so the same ``finally`` runs. Only SIGKILL cannot be caught: a
  later write of the same file removes the temporaries of dead processes of this host, and
  :func:`scratch_folder` sweeps scratch folders of dead or hour-old writers.
- **Folders.** Every command that writes a file creates the folder it goes into, and the
  missing parents (``mkdir -p``), through :func:`make_folder`; :func:`check_folder` says
  before any work whether that will succeed. A write that fails removes the folders it
  created (:meth:`Transaction.folder`).
- **One line.** An ``OSError`` becomes :class:`WriteError`: ``cannot write PATH: No space
  left on device``.

This module imports nothing else of lookdev but the error root, so exporters, proofs and
analysis may use it without touching presets (tests/test_architecture.py).
"""

from __future__ import annotations

import contextlib
import errno
import os
import platform
import re
import shutil
import signal
import stat
import threading
import time
from collections.abc import Callable, Iterator
from pathlib import Path

from lookdev.materials.errors import LookdevError

__all__ = [
    "READ_ONLY_ERRNOS",
    "SCRATCH_PREFIX",
    "STALE_SCRATCH_S",
    "Terminated",
    "Transaction",
    "WriteError",
    "atomic_path",
    "atomic_write",
    "failure_reason",
    "cache_root",
    "check_folder",
    "is_temporary",
    "make_folder",
    "new_file_mode",
    "remove_quietly",
    "scratch_folder",
    "signals_unwind",
    "write_error",
    "quiet_c_stderr",
]

TEMP_MARK = ".tmp"
SCRATCH_PREFIX = ".lookdev-bake-"
STALE_SCRATCH_S = 3600.0
"""A scratch folder of another host (whose processes we cannot see) is stale after this."""
READ_ONLY_ERRNOS = frozenset({errno.EROFS, errno.EACCES, errno.EPERM})
PAUSE_ENV = "LOOKDEV_TEST_WRITE_PAUSE"
"""Test hook: a write sleeps this many seconds with its temporary flushed, before the rename."""

# platform.node() is the host name Typer has already imported (socket would cost a command ≈ 2 ms)
_HOST = re.sub(r"[^A-Za-z0-9_]", "_", platform.node())[:32] or "host"
_TEMP_RE = re.compile(r"^\.(?P<name>.+)\.(?P<host>[A-Za-z0-9_]+)-(?P<pid>\d+)-[0-9a-f]+\.tmp")


class WriteError(LookdevError):
    """A file could not be written (a full disk, a read-only folder, a missing folder)."""


class Terminated(SystemExit):
    """SIGTERM/SIGHUP during a write: unwinds like Ctrl-C so temporaries are removed."""


def write_error(path: str | os.PathLike, exc: OSError) -> WriteError:
    """``cannot write PATH: <reason>``, one line."""
    reason = exc.strerror or str(exc) or type(exc).__name__
    return WriteError(f"cannot write {os.fspath(path)}: {reason}")


def failure_reason(path: str | os.PathLike, message: str) -> str:
    """The reason a writer that reports only its own words (OpenImageIO, USD) failed:
    ``No space left on device`` when the folder's filesystem is full, else its first line."""
    folder = os.path.dirname(os.path.abspath(path)) or "."
    with contextlib.suppress(OSError, AttributeError):
        if os.statvfs(folder).f_bavail == 0:
            return os.strerror(errno.ENOSPC)
    lines = [line.strip() for line in str(message).splitlines() if line.strip()]
    return lines[-1] if lines else "unknown error"


# -- folders ---------------------------------------------------------------------------


def check_folder(folder: str | os.PathLike) -> Path:
    """Raise :class:`WriteError` unless files can be written in ``folder``: it exists and is
    writable, or its nearest existing ancestor is a writable folder it can be made in."""
    folder = Path(folder)
    existing = next((p for p in (folder, *folder.parents) if p.exists()), Path("."))
    if not existing.is_dir():
        raise WriteError(f"cannot create folder {os.fspath(folder)}: {existing} is a file")
    if not os.access(existing, os.W_OK | os.X_OK):
        what = "is not writable" if existing == folder else f"cannot be made in {existing}"
        raise WriteError(f"folder {os.fspath(folder)} {what}: {os.strerror(errno.EACCES)}")
    return folder


def make_folder(folder: str | os.PathLike, created: list[Path] | None = None) -> Path:
    """Create ``folder`` and its missing parents: the one rule for the folder of every file
    a command writes. The folders it made are appended to ``created`` (outermost first),
    so a write that fails can remove them; a failure is one :class:`WriteError` line."""
    folder = check_folder(folder)
    missing = [p for p in (folder, *folder.parents) if not p.exists()]
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise WriteError(f"cannot create folder {os.fspath(folder)}: {exc.strerror}") from None
    if created is not None:
        created += reversed(missing)
    return folder


# -- modes -----------------------------------------------------------------------------

_umask_lock = threading.Lock()


def current_umask() -> int:
    """The process umask, read without changing it where Linux allows (``/proc``)."""
    try:
        with open("/proc/self/status", encoding="ascii") as f:
            for line in f:
                if line.startswith("Umask:"):
                    return int(line.split()[1], 8)
    except (OSError, ValueError):
        pass
    with _umask_lock:  # elsewhere: set and restore (the only portable way to read it)
        mask = os.umask(0o022)
        os.umask(mask)
    return mask


def new_file_mode() -> int:
    """The mode ``open(..., "w")`` would give a new file: ``0o666 & ~umask``."""
    return 0o666 & ~current_umask()


def _settle_mode(tmp: str, final: str) -> None:
    """Give ``tmp`` the mode (and group) ``final`` has, or a new file's mode."""
    try:
        st = os.stat(final)
    except FileNotFoundError:
        os.chmod(tmp, new_file_mode())
        return
    if os.stat(tmp).st_gid != st.st_gid:
        with contextlib.suppress(PermissionError):  # not a member of that group: keep ours
            os.chown(tmp, -1, st.st_gid)
    os.chmod(tmp, stat.S_IMODE(st.st_mode))  # after chown, which may clear set-id bits


# -- signals ---------------------------------------------------------------------------

_guard = threading.local()
_CAUGHT = tuple(s for s in (getattr(signal, "SIGTERM", None), getattr(signal, "SIGHUP", None)) if s)


def _raise_terminated(signum, frame) -> None:
    raise Terminated(128 + signum)


@contextlib.contextmanager
def signals_unwind() -> Iterator[None]:
    """While inside, SIGTERM and SIGHUP raise :class:`Terminated` instead of killing outright.

    Only handlers still at their default are replaced, only from the main thread, and they
    are restored on the way out (nesting is counted). Ctrl-C needs nothing: Python already
    raises ``KeyboardInterrupt``.
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    depth = getattr(_guard, "depth", 0)
    saved: dict[int, object] = {}
    if depth == 0:
        for sig in _CAUGHT:
            if signal.getsignal(sig) is signal.SIG_DFL:
                saved[sig] = signal.signal(sig, _raise_terminated)
    _guard.depth = depth + 1
    try:
        yield
    finally:
        _guard.depth = depth
        for sig, old in saved.items():
            signal.signal(sig, old)


# -- temporaries -----------------------------------------------------------------------


def is_temporary(name: str) -> bool:
    """Whether a file name is one of this module's temporaries."""
    return _TEMP_RE.match(name) is not None


def _temp_name(final: Path) -> Path:
    token = os.urandom(4).hex()  # what secrets.token_hex(4) returns, without importing it
    return final.with_name(f".{final.name}.{_HOST}-{os.getpid()}-{token}{TEMP_MARK}{final.suffix}")


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def _dead_writer(name: str) -> bool:
    m = _TEMP_RE.match(name)
    return bool(m) and m["host"] == _HOST and not _alive(int(m["pid"]))


def sweep_temporaries(folder: Path, name: str | None = None) -> None:
    """Remove temporaries left in ``folder`` by killed processes of this host.

    ``name`` limits the sweep to one destination's temporaries. A process of another host
    sharing the folder may still be writing, so its temporaries are left alone.
    """
    pattern = f".{glob_escape(name)}.*{TEMP_MARK}*" if name else f".*{TEMP_MARK}*"
    with contextlib.suppress(OSError):
        for tmp in folder.glob(pattern):
            if _dead_writer(tmp.name):
                remove_quietly(tmp)


def glob_escape(text: str) -> str:
    return re.sub(r"([*?[])", r"[\1]", text)


def remove_quietly(path: str | os.PathLike) -> None:
    """Remove a file if it is there; a read-only folder (EROFS even for a missing file) or
    any other refusal is ignored: this runs on the way out of a failure."""
    with contextlib.suppress(OSError):
        os.unlink(path)


def _fsync_file(path: str) -> None:
    fd = os.open(path, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


def fsync_folder(folder: str) -> None:
    # The rename is durable only once the directory entry is on disk (POSIX; no-op elsewhere).
    if os.name != "posix":
        return
    with contextlib.suppress(OSError):  # some filesystems refuse fsync on a folder
        _fsync_file(folder)


def _test_pause() -> None:
    seconds = os.environ.get(PAUSE_ENV)
    if seconds:
        time.sleep(float(seconds))


# -- the write path --------------------------------------------------------------------


class Transaction:
    """Several files written under temporary names and renamed into place together.

    ``temp_for(path)`` gives the temporary to write ``path``'s bytes to (any writer: OIIO,
    USD, a ``open(tmp, "wb")``); :meth:`commit` flushes, sets the modes and renames them in
    the order they were asked for (write an index or sidecar last); :meth:`abort` removes
    them and any folder :meth:`folder` created. As a context manager it commits on success,
    aborts on any exception or signal, and turns an ``OSError`` into :class:`WriteError`.
    """

    def __init__(self) -> None:
        self.moves: list[tuple[Path, Path, Path]] = []  # (temporary, final, as asked)
        self.created: list[Path] = []
        self._signals = contextlib.ExitStack()

    def __enter__(self) -> Transaction:
        self._signals.enter_context(signals_unwind())
        return self

    def __exit__(self, kind, exc, tb) -> bool:
        try:
            if kind is None:
                self.commit()
                return False
            asked = getattr(exc, "filename", None) or (self.moves and self.moves[-1][2]) or "file"
            asked = self._asked_for(asked)
            self.abort()
            if isinstance(exc, OSError) and not isinstance(exc, LookdevError):
                raise write_error(asked, exc) from None
            return False
        finally:
            self._signals.close()

    def _asked_for(self, name: str | os.PathLike) -> str | os.PathLike:
        for tmp, _, asked in self.moves:
            if os.fspath(tmp) == os.fspath(name):
                return asked
        return name

    def folder(self, path: str | os.PathLike) -> Path:
        """Create ``path`` (and parents) if missing (:func:`make_folder`); an abort removes
        what it created."""
        return make_folder(path, self.created)

    def temp_for(self, path: str | os.PathLike) -> Path:
        """A new, empty temporary for ``path`` (beside the file a link at ``path`` leads to)."""
        asked = Path(path)
        final = Path(os.path.realpath(asked)) if asked.is_symlink() else asked
        sweep_temporaries(final.parent, final.name)
        tmp = _temp_name(final)
        # Registered before it exists: a signal between the create and the registration
        # would otherwise leave a temporary that abort() does not know of.
        self.moves.append((tmp, final, asked))
        try:
            fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600)
            os.close(fd)
        except OSError as exc:
            self.moves.pop()
            raise write_error(asked, exc) from None
        return tmp

    def commit(self) -> None:
        try:
            for tmp, final, _ in self.moves:
                _fsync_file(os.fspath(tmp))
                _settle_mode(os.fspath(tmp), os.fspath(final))
            _test_pause()
            for i, (tmp, final, asked) in enumerate(self.moves):
                try:
                    os.replace(tmp, final)
                except OSError as exc:
                    del self.moves[:i]
                    raise write_error(asked, exc) from None
            for folder in dict.fromkeys(os.fspath(f.parent) for _, f, _ in self.moves):
                fsync_folder(folder)
        except OSError as exc:
            self.abort()
            raise write_error(self.moves[0][2] if self.moves else "file", exc) from None
        except BaseException:
            self.abort()
            raise
        self.moves.clear()
        self.created.clear()

    def abort(self) -> None:
        for tmp, _, _ in self.moves:
            remove_quietly(tmp)
        for folder in reversed(self.created):
            with contextlib.suppress(OSError):
                folder.rmdir()  # only if empty
        self.moves.clear()
        self.created.clear()


@contextlib.contextmanager
def atomic_path(path: str | os.PathLike) -> Iterator[Path]:
    """A temporary path to write ``path`` to; it replaces ``path`` when the block ends well.

    >>> with atomic_path(out) as tmp:          # doctest: +SKIP
    ...     image.write(str(tmp))
    """
    with Transaction() as t:
        yield t.temp_for(path)


def atomic_write(path: str | os.PathLike, data: bytes | str) -> Path:
    """Replace ``path`` with ``data`` (``str`` is written as UTF-8) atomically; returns it."""
    raw = data.encode("utf-8") if isinstance(data, str) else data
    with atomic_path(path) as tmp:
        with open(tmp, "wb") as f:
            f.write(raw)
    return Path(path)


def atomic_write_with(path: str | os.PathLike, write: Callable[[Path], None]) -> Path:
    """Call ``write(tmp)`` and move the result to ``path`` atomically; returns ``path``."""
    with atomic_path(path) as tmp:
        write(tmp)
    return Path(path)


# -- scratch folders -------------------------------------------------------------------


def _scratch_is_stale(entry: Path) -> bool:
    m = re.match(rf"^{re.escape(SCRATCH_PREFIX)}([A-Za-z0-9_]+)-(\d+)-", entry.name)
    if m and m[1] == _HOST:
        return not _alive(int(m[2]))
    try:
        return time.time() - entry.lstat().st_mtime > STALE_SCRATCH_S
    except OSError:
        return False


def sweep_scratch(folder: Path) -> None:
    """Remove scratch folders of killed writers: this host's dead PIDs at once, any other
    (another host's, or an old unnamed one) once it is an hour old."""
    with contextlib.suppress(OSError):
        for entry in folder.glob(f"{SCRATCH_PREFIX}*"):
            if entry.is_dir() and not entry.is_symlink() and _scratch_is_stale(entry):
                shutil.rmtree(entry, ignore_errors=True)


@contextlib.contextmanager
def scratch_folder(beside: str | os.PathLike | None) -> Iterator[Path]:
    """A hidden scratch folder in ``beside`` (or the system temp when ``None`` or not
    writable), removed when the block ends, on errors, Ctrl-C and SIGTERM/SIGHUP alike.

    Scratch space sits beside the output so baked files can be renamed into place on the
    same filesystem, and it is named ``.lookdev-bake-<host>-<pid>-…`` so that the next writer
    can tell a killed process's leftovers from a live one's and sweep them.
    """
    import tempfile

    where = None
    if beside is not None and os.path.isdir(beside) and os.access(beside, os.W_OK | os.X_OK):
        where = Path(beside)
        sweep_scratch(where)
    with signals_unwind():
        try:
            prefix = f"{SCRATCH_PREFIX}{_HOST}-{os.getpid()}-"
            path = Path(tempfile.mkdtemp(prefix=prefix, dir=where))
        except OSError as exc:
            raise write_error(where or tempfile.gettempdir(), exc) from None
        try:
            yield path
        finally:
            shutil.rmtree(path, ignore_errors=True)


# -- caches ----------------------------------------------------------------------------


def cache_root() -> Path:
    """``$LOOKDEV_CACHE``, default ``~/.cache/lookdev``: caches of read-only data live here."""
    return Path(os.environ.get("LOOKDEV_CACHE") or Path.home() / ".cache" / "lookdev")


@contextlib.contextmanager
def quiet_c_stderr() -> Iterator[None]:
    """File descriptor 2 goes to /dev/null for the block: libpng and OpenImageIO print
    some decode errors ("libpng error: …", "An ImageBuf was destroyed with a pending
    error …") straight to it, beside the one line lookdev reports for the same problem."""
    import sys

    try:
        sys.stderr.flush()
        saved = os.dup(2)
    except (OSError, ValueError, AttributeError):
        yield
        return
    try:
        with open(os.devnull, "wb") as null:
            os.dup2(null.fileno(), 2)
            yield
    finally:
        os.dup2(saved, 2)
        os.close(saved)
