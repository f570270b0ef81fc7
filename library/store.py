"""Safe writes into a library folder: one lock per library, write → fsync → rename.

A reader never sees a half-written preset: the new bytes go to a hidden temporary file
beside the target, are flushed to disk, and replace the target in one ``os.replace``
(atomic on POSIX and Windows), after which the folder entry itself is flushed. A process
killed at any point leaves either the old file or the new one, plus at worst a stale
hidden ``.NAME.toml.PID.tmp`` that listing ignores and the next locked write removes.

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

from filelock import FileLock, Timeout

from .errors import LibraryError

LOCK_NAME = ".lookdev.lock"
PAUSE_ENV = "LOOKDEV_TEST_SAVE_PAUSE"
LOCK_TIMEOUT_S = 60.0


@contextlib.contextmanager
def locked(folder: Path) -> Iterator[None]:
    """Hold the library's lock; an unwritable folder or a stuck lock is a LibraryError."""
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
    for tmp in folder.glob(".*.toml.*.tmp"):
        tmp.unlink(missing_ok=True)


def atomic_write(path: Path, data: bytes) -> None:
    """Replace ``path`` with ``data`` so that readers see the old or the new file, never half."""
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    try:
        with open(tmp, "wb") as f:
            f.write(data)
            f.flush()
            os.fsync(f.fileno())
        _test_pause()
        os.replace(tmp, path)
        _fsync_folder(path.parent)
    except OSError as exc:
        tmp.unlink(missing_ok=True)
        raise unwritable(path.parent, exc) from None
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise


def remove(path: Path) -> None:
    """Delete one preset file, durably."""
    try:
        path.unlink()
        _fsync_folder(path.parent)
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
    return LibraryError(
        f"cannot write to this library ({reason}); choose a writable folder with --library",
        where=str(folder),
    )


def _fsync_folder(folder: Path) -> None:
    # The rename is durable only once the directory entry is on disk (POSIX; no-op elsewhere).
    if os.name != "posix":
        return
    fd = os.open(folder, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


def _test_pause() -> None:
    seconds = os.environ.get(PAUSE_ENV)
    if seconds:
        time.sleep(float(seconds))
