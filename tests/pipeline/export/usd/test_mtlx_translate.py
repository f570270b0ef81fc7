"""Standard Surface → OpenPBR by MaterialX's translation graph, evaluated on constants:
each case below is a line of ``NG_standard_surface_to_open_pbr_surface`` (MaterialX
1.39's data library) worked by hand."""

from __future__ import annotations

import pytest

pytest.importorskip("MaterialX")

from lookdev.pipeline.export.usd.mtlx_translate import (  # noqa: E402
    CONNECTED,
    OPS,
    standard_surface_to_openpbr,
)
from lookdev.pipeline.export.usd.network import ExportError  # noqa: E402


def test_unauthored_inputs_take_standard_surfaces_defaults():
    # Standard Surface: base 1 × base_color 0.8; the translation node's own defaults are
    # base 0.8 × base_color 1, which would darken a grey sphere's 0.18 to 0.144
    out, notes = standard_surface_to_openpbr({"base_color": (0.18, 0.18, 0.18)})
    assert out["base_weight"] == pytest.approx(1.0)
    assert out["base_color"] == pytest.approx((0.18,) * 3)
    assert out["specular_roughness"] == pytest.approx(0.2)  # Standard Surface's default
    assert notes == []


def test_a_coat_over_a_metal_tints_the_base_and_is_dropped():
    coat = (0.96, 0.38, 0.26)
    out, _ = standard_surface_to_openpbr(
        {"metalness": 1.0, "base_color": (1.0, 1.0, 1.0), "coat": 1.0, "coat_color": coat}
    )
    assert out["base_color"] == pytest.approx(coat, rel=1e-6)  # base × mix(1, coat, coat)
    assert out["coat_weight"] == 0.0  # coat × metalness > 0
    assert out["specular_weight"] == 1.0  # a metal's specular weight is 1


def test_a_coat_over_a_dielectric_stays_a_coat():
    out, _ = standard_surface_to_openpbr({"coat": 0.5, "coat_color": (0.5, 1.0, 1.0)})
    assert out["coat_weight"] == pytest.approx(0.5)
    assert out["base_color"][0] == pytest.approx(0.8 * 0.75, rel=1e-6)  # mix by coat 0.5


def test_thin_film_sheen_and_black_specular_colour():
    out, _ = standard_surface_to_openpbr(
        {
            "thin_film_thickness": 550.0,
            "sheen_roughness": 0.3,
            "specular_color": (0.0, 0.0, 0.0),
            "specular": 0.4,
        }
    )
    assert out["thin_film_thickness"] == pytest.approx(0.55)  # nm → µm
    assert out["thin_film_weight"] == 1.0  # a film of any thickness is on
    assert out["fuzz_roughness"] == pytest.approx(0.3**0.4, rel=1e-6)
    assert out["specular_color"] == (1.0, 1.0, 1.0)  # black: the weight carries it
    assert out["specular_weight"] == pytest.approx(0.4)


def test_a_connected_input_makes_what_reads_it_connected():
    out, _ = standard_surface_to_openpbr({"base_color": CONNECTED, "coat": 0.2})
    assert out["base_color"] is CONNECTED
    assert out["coat_weight"] == pytest.approx(0.2)  # not read from base_color


def test_an_input_the_translation_lacks_is_named_when_authored():
    _, notes = standard_surface_to_openpbr({"coat_rotation": 0.25, "specular_rotation": 0.0})
    assert len(notes) == 1 and "coat_rotation" in notes[0]


def test_an_unknown_node_is_an_error_not_a_guess(monkeypatch):
    monkeypatch.delitem(OPS, "power")
    with pytest.raises(ExportError, match="'power'"):
        standard_surface_to_openpbr({})
