"""The writer's Sdf authoring makes the layer the ``UsdShade`` API makes, byte for byte.

The reference is the benchmark's naive path (:func:`lookdev.pipeline.bench.usd.author_naive`:
``UsdShade.Material.Define``, ``CreateInput(...).Set``, ``ConnectToSource`` …), which
shares no authoring code with :mod:`lookdev.pipeline.export.usd.writer`: whatever call
patterns the writer uses for speed, its ``.usda`` text must stay the one the high-level
API writes for the same networks.
"""

from __future__ import annotations

from copy import deepcopy

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


def _naive_text(specs, base) -> str:
    from lookdev.pipeline.bench.usd import author_naive

    stage = author_naive(specs, base)  # the stage keeps its root layer alive
    return stage.GetRootLayer().ExportToString()


def _written(specs, base):
    from lookdev.pipeline.export.usd import authoring

    layer = authoring.new_layer()
    authoring.author(layer, specs, base)
    return layer


def test_materials_copied_from_a_template_of_their_shape_carry_their_own_values(tmp_path):
    """Random materials of few shapes (the benchmark's): every one after the first of its
    shape is a copy with its values set, and the layer is still the UsdShade one."""
    from lookdev.pipeline.bench.usd import bench_specs, shapes_of

    specs = bench_specs(80)
    assert len(shapes_of(specs)) < len(specs) / 2  # most of them are copies
    layer = _written(specs, tmp_path)
    assert layer.ExportToString() == _naive_text(specs, tmp_path)
    values = {
        tuple(layer.GetAttributeAtPath(f"/Materials/{s.name}.inputs:base_color").default)
        for s in specs
        if layer.GetAttributeAtPath(f"/Materials/{s.name}.inputs:base_color")
    }
    assert len(values) > 40  # each copy holds its own colour, not its template's


def test_a_copy_of_every_shipped_preset_keeps_its_maps_colour_spaces_and_metadata(
    tmp_path, monkeypatch
):
    """Each preset twice, the second under another name with other metadata: copies of
    textured, layered and Pixar networks are the UsdShade layer too."""
    import dataclasses

    from lookdev.pipeline import api
    from lookdev.pipeline.export.usd import writer

    calls, real = [], writer.author

    def spy(layer, specs, base):
        calls.append((list(specs), base))
        return real(layer, specs, base)

    monkeypatch.setattr(writer, "author", spy)
    api.export_usd(None, tmp_path / "all.usda", all_presets=True, map_resolution=8)
    ((specs, base),) = calls
    again = [
        dataclasses.replace(s, name=f"{s.name}_again", custom={**s.custom, "preset": "again"})
        for s in specs
    ]
    both = [x for pair in zip(specs, again, strict=True) for x in pair]
    assert _written(both, base).ExportToString() == _naive_text(both, base)


def test_a_copy_writes_a_zero_of_its_own_sign():
    """0.0 equals −0.0 but USD writes them apart: a copy never keeps a zero from its
    template."""
    from pathlib import Path

    from lookdev.pipeline.bench.usd import bench_specs
    from lookdev.pipeline.export.usd.network import Interface

    template, copy = bench_specs(1) * 2
    copy = __import__("dataclasses").replace(copy, name="copy", networks=deepcopy(copy.networks))
    signs = 0
    for net in copy.networks:
        for node in net.nodes:
            for name, (kind, value) in node.inputs.items():
                if kind == "float" and type(value) is float and value == 0.0:
                    node.inputs[name] = (kind, -0.0)
                    signs += 1
                elif kind == "float" and type(value) is Interface:
                    node.inputs[name] = (kind, Interface(value.name, -0.0))
                    signs += 1
    assert signs
    text = _written([template, copy], Path.cwd()).ExportToString()
    assert text == _naive_text([template, copy], Path.cwd())
    assert "= -0" in text
