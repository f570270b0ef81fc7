"""The writer's Sdf authoring makes the layer the ``UsdShade`` API makes, byte for byte.

The reference is the benchmark's naive path (:func:`lookdev.pipeline.bench.usd.author_naive`:
``UsdShade.Material.Define``, ``CreateInput(...).Set``, ``ConnectToSource`` …), which
shares no authoring code with :mod:`lookdev.pipeline.export.usd.writer`: whatever call
patterns the writer uses for speed, its ``.usda`` text must stay the one the high-level
API writes for the same networks.
"""

from __future__ import annotations

import pytest

pytest.importorskip("pxr")


@pytest.mark.parametrize("surface", ["openpbr", "disney"])
def test_the_writer_authors_what_usdshade_authors_for_every_shipped_preset(
    tmp_path, monkeypatch, surface
):
    from lookdev.pipeline import api
    from lookdev.pipeline.bench.usd import author_naive
    from lookdev.pipeline.export.usd import writer

    calls = []
    real = writer.author

    def spy(layer, specs, base):
        calls.append((list(specs), base))
        return real(layer, specs, base)

    monkeypatch.setattr(writer, "author", spy)
    api.export_usd(
        None, tmp_path / "all.usda", all_presets=True, map_resolution=8, mtlx_surface=surface
    )
    ((specs, base),) = calls
    assert len(specs) == len(api.library_for(None).names())
    kinds = {
        k for s in specs for net in s.networks for n in net.nodes for k, _ in n.inputs.values()
    }
    assert {"asset", "color3f", "float", "float2", "int", "token"} <= kinds  # textures too
    layer = writer.new_layer()
    real(layer, specs, base)
    stage = author_naive(specs, base)  # the stage keeps its root layer alive
    assert layer.ExportToString() == stage.GetRootLayer().ExportToString()
