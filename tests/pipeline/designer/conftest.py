"""Fixtures of the designer's tests: a writable library in tmp, a designer, a client."""

from __future__ import annotations

from pathlib import Path

import pytest

from lookdev.library import Library


@pytest.fixture
def user_library(tmp_path: Path) -> Path:
    folder = tmp_path / "looks"
    folder.mkdir()
    return folder


@pytest.fixture
def designer(user_library: Path, tmp_path: Path):
    from lookdev.pipeline.designer.server import Designer

    d = Designer(
        ["gold"],
        library=Library([user_library], use_env=False),
        folder=tmp_path / "session",
        size=(32, 18),
    )
    yield d
    d.close()


@pytest.fixture
def client(designer):
    from starlette.testclient import TestClient

    with TestClient(designer.app, base_url=f"http://127.0.0.1:{designer.port}") as c:
        yield c
