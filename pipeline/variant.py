"""Choosing the Mitsuba variant (:doc:`/design`, Proofing).

``cuda_ad_rgb`` where a GPU is present, else ``llvm_ad_rgb`` where a libLLVM that works
with Dr.Jit is found (libLLVM 14-16 crash in the JIT, so only 17 and newer are tried),
else ``scalar_rgb`` with one warning. Call :func:`use_mitsuba` before anything touches
Dr.Jit: the library path must be in the environment before the LLVM backend starts.
"""

from __future__ import annotations

import functools
import os
import re
import subprocess
import threading
import warnings
from pathlib import Path

__all__ = ["find_libllvm", "use_mitsuba"]

_MIN_LLVM = 17


def find_libllvm() -> str | None:
    """Path of the newest usable libLLVM (≥ 17), or None. Honours DRJIT_LIBLLVM_PATH."""
    given = os.environ.get("DRJIT_LIBLLVM_PATH")
    if given and Path(given).exists():
        return given
    try:
        out = subprocess.run(
            ["ldconfig", "-p"], capture_output=True, text=True, check=False, timeout=10
        ).stdout
    except (OSError, subprocess.SubprocessError):
        out = ""
    found = []
    for line in out.splitlines():
        m = re.search(r"libLLVM(?:-|\.so\.)(\d+)[^ ]* .*=> (\S+)", line)
        if m and int(m.group(1)) >= _MIN_LLVM:
            found.append((int(m.group(1)), m.group(2)))
    return max(found)[1] if found else None


def _has_cuda() -> bool:
    return any(Path(p).exists() for p in ("/dev/nvidia0", "/dev/nvidiactl"))


def use_mitsuba(preferred: str | None = None) -> str:
    """Set and return the Mitsuba variant: ``preferred`` or the fastest that works here."""
    # Threads asking at once (the designer's workers) must not race ``mi.set_variant``:
    # a variant that loses the race looks broken and the slow fallback wins.
    with _VARIANT_LOCK:
        return _choose_variant(preferred)


_VARIANT_LOCK = threading.Lock()


@functools.cache
def _choose_variant(preferred: str | None) -> str:
    libllvm = find_libllvm()
    if libllvm:
        os.environ.setdefault("DRJIT_LIBLLVM_PATH", libllvm)
    import mitsuba as mi

    candidates = [preferred] if preferred else []
    if _has_cuda():
        candidates.append("cuda_ad_rgb")
    if libllvm:
        candidates.append("llvm_ad_rgb")
    for variant in candidates:
        try:
            mi.set_variant(variant)
            return variant
        except Exception:  # noqa: BLE001 - a variant that fails to start is simply skipped
            continue
    warnings.warn(
        "no libLLVM >= 17 found (install Debian's libllvm19): rendering with the slow "
        "scalar_rgb variant",
        RuntimeWarning,
        stacklevel=2,
    )
    mi.set_variant("scalar_rgb")
    return "scalar_rgb"
