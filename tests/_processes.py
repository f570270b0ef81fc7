"""Child processes for tests that kill, pause or race lookdev: start one, wait on it."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time


def spawn(code: str, *args: str, env_extra: dict[str, str] | None = None) -> subprocess.Popen:
    """``python -c code args…`` with pipes, outside any ``LOOKDEV_LIBRARY_PATH``."""
    env = dict(os.environ)
    env.pop("LOOKDEV_LIBRARY_PATH", None)
    env.update(env_extra or {})
    return subprocess.Popen(
        [sys.executable, "-c", code, *args],
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        preexec_fn=_default_sigint,
    )


def _default_sigint() -> None:
    # A test run started in the background (`cmd &`, nohup) ignores SIGINT, and a child
    # inherits that: Python then installs no KeyboardInterrupt, and a Ctrl-C test is void.
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def wait_for(predicate, proc: subprocess.Popen, timeout: float) -> None:
    """Poll ``predicate`` until true; fail if ``proc`` ends first or ``timeout`` passes."""
    deadline = time.monotonic() + timeout
    while not predicate():
        if proc.poll() is not None:
            raise AssertionError(f"process ended early: {proc.communicate()}")
        if time.monotonic() > deadline:
            proc.kill()
            raise AssertionError("timed out")
        time.sleep(0.01)
