"""Helpers of the designer's tests."""

from __future__ import annotations

import os
from pathlib import Path


def snapshot(*folders: Path) -> dict[str, bytes]:
    """Every file under ``folders`` with its bytes: what "nothing written" compares."""
    out = {}
    for folder in folders:
        for root, _, names in os.walk(folder):
            for n in names:
                p = Path(root, n)
                if not p.is_symlink():
                    out[str(p)] = p.read_bytes()
    return out
