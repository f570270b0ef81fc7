"""Fixtures of the USD export tests."""

from __future__ import annotations

import pytest


@pytest.fixture(scope="session")
def exported(tmp_path_factory):
    """Every built-in preset exported once as USD and ``.mtlx`` (maps at 16 texels): the
    export's result, and the MaterialX document with MaterialX's own libraries imported."""
    mx = pytest.importorskip("MaterialX")
    from lookdev.pipeline import api

    folder = tmp_path_factory.mktemp("mtlx")
    result = api.export_usd(
        None, folder / "all.usda", mtlx=folder / "all.mtlx", all_presets=True, map_resolution=16
    )
    doc = mx.createDocument()
    mx.readFromXmlFile(doc, str(folder / "all.mtlx"))
    libraries = mx.createDocument()
    mx.loadLibraries(mx.getDefaultDataLibraryFolders(), mx.getDefaultDataSearchPath(), libraries)
    doc.importLibrary(libraries)
    return result, doc
