"""Safe writes into a library folder: one lock per library, write → fsync → rename.

A reader never sees a half-written preset: the new bytes go to a hidden temporary file
beside the target, are flushed to disk, and replace the target in one ``os.replace``
(atomic on POSIX and Windows), after which the folder entry itself is flushed. A process
killed at any point leaves either the old file or the new one, plus at worst a stale
hidden ``.NAME.toml.HOST-PID-TOKEN.tmp.toml`` that listing ignores and the next locked
write removes. Modes, links and signals follow :mod:`lookdev.library.files`, the one write
path.

Two processes writing into one library serialise on ``.lookdev.lock`` (``filelock``),
so a read-modify-write (``presets set``) or a check-then-create (``presets new``) never
loses the other's change.

Test hook: with ``LOOKDEV_TEST_SAVE_PAUSE=SECONDS`` in the environment a save sleeps
between the flushed temporary file and the rename, so a test can kill it exactly there.
"""

from __future__ import annotations

import contextlib
import os
import time
from collections.abc import Iterator
from pathlib import Path

from . import files
from .errors import LibraryError

__all__ = [
    "LOCK_NAME",
    "LOCK_TIMEOUT_S",
    "PAUSE_ENV",
    "atomic_write",
    "locked",
    "make_folder",
    "read_only",
    "remove",
    "unwritable",
]

LOCK_NAME = ".lookdev.lock"
PAUSE_ENV = "LOOKDEV_TEST_SAVE_PAUSE"
LOCK_TIMEOUT_S = 60.0


@contextlib.contextmanager
def locked(folder: Path) -> Iterator[None]:
    """Hold the library's lock; an unwritable folder or a stuck lock is a LibraryError."""
    from filelock import FileLock, Timeout  # only writes lock: reading pays nothing for it

    lock = FileLock(str(folder / LOCK_NAME), timeout=LOCK_TIMEOUT_S)
    try:
        lock.acquire()
    except Timeout:
        raise LibraryError(
            f"library is locked by another lookdev process for over {LOCK_TIMEOUT_S:g} s; "
            f"retry, or remove {LOCK_NAME} if no lookdev is running",
            where=str(folder),
        ) from None
    except OSError as exc:
        raise unwritable(folder, exc) from None
    try:
        _remove_stale_temporaries(folder)
        yield
    finally:
        lock.release()


def _remove_stale_temporaries(folder: Path) -> None:
    """Temporaries of killed saves: every writer holds the lock, so none is in use now."""
    with contextlib.suppress(OSError):
        for tmp in folder.glob(".*.toml.*.tmp.toml"):
            if files.is_temporary(tmp.name):
                files.remove_quietly(tmp)


def atomic_write(path: Path, data: bytes) -> None:
    """Replace ``path`` with ``data`` so that readers see the old or the new file, never half.

    The write path is :mod:`lookdev.library.files` (modes, links, signals); here a refusal
    becomes the library's one-line error.
    """
    try:
        with files.Transaction() as t:
            tmp = t.temp_for(path)
            with open(tmp, "wb") as f:
                f.write(data)
            _test_pause()
    except files.WriteError as exc:
        raise LibraryError(exc.message) from None


def remove(path: Path) -> None:
    """Delete one preset file, durably."""
    try:
        path.unlink()
        files.fsync_folder(str(path.parent))
    except OSError as exc:
        raise unwritable(path.parent, exc) from None


def make_folder(folder: Path) -> None:
    """Create a library folder (and parents) for a first save."""
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise unwritable(folder, exc) from None


def unwritable(folder: Path, exc: OSError) -> LibraryError:
    """The one-line error for a library folder that refuses a write."""
    reason = exc.strerror or type(exc).__name__
    if exc.errno in files.READ_ONLY_ERRNOS:
        return read_only(folder, reason)
    return LibraryError(
        f"cannot write to this library ({reason}); choose a writable folder with --library",
        where=str(folder),
    )


def read_only(folder: Path, reason: str = "not writable") -> LibraryError:
    """The one-line error for a write to a library that can only be read."""
    return LibraryError(
        f"cannot write to this library: it is read-only ({reason}); "
        "choose a writable folder with --library",
        where=str(folder),
    )


def _test_pause() -> None:
    seconds = os.environ.get(PAUSE_ENV)
    if seconds:
        time.sleep(float(seconds))
