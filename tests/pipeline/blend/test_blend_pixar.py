"""Pixar layers: Smits' lobe-weight compositing (simple and full layering)."""

from __future__ import annotations

import numpy as np
import pytest
from _blend_helpers import layer, layered, write_image
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from lookdev.library import Material
from lookdev.materials.layers import NoiseMask, TextureMask
from lookdev.materials.pixar import PixarParams, lobe_weights
from lookdev.materials.pixar_scatter import LOBES, PREFIX
from lookdev.pipeline.blend import BlendError, blend
from lookdev.pipeline.blend.pixar_composite import Part, composite, energy_sum, layer_lobes

GLAZE = PixarParams(surface_color=(0.9, 0.8, 0.7), roughness=0.1, clear=0.6, back=0.3)
CLAY = PixarParams(surface_color=(0.6, 0.3, 0.2), roughness=0.7)


def pixar(name: str, params: PixarParams) -> Material:
    return Material(name=name, model="pixar", params=params)


def grey(x: float) -> np.ndarray:
    return np.full(3, x)


def hand_lobes(weights: dict[str, float], cones: dict[str, float]) -> dict[str, Part]:
    """Lobes with N = G = the given grey weight (0 where not given)."""
    return {
        lobe: Part(grey(weights.get(lobe, 0.0)), grey(weights.get(lobe, 0.0)), cones.get(lobe, 0.0))
        for lobe in LOBES
    }


# A: a half-transmitting coat; B: an opaque base. Σ A = 1.0, Σ B = 0.7.
A = hand_lobes(
    {
        "reflection": 0.1,
        "specular": 0.2,
        "diffuse": 0.3,
        "reflection_t": 0.2,
        "specular_t": 0.1,
        "diffuse_t": 0.1,
    },
    {"reflection": 2.0, "specular": 20.0, "reflection_t": 2.0, "specular_t": 20.0},
)
B = hand_lobes(
    {"reflection": 0.05, "specular": 0.15, "diffuse": 0.5},
    {"reflection": 4.0, "specular": 30.0},
)


def test_worked_two_layer_example_full_layering_by_hand():
    out, _ = composite([(A, 0.5), (B, 1.0)], "full")  # top first, α_A = ½
    # Reflection: ½·R_A + ½·(refraction_A × reflection_B) + ½ (uncovered)·reflection_B
    #           = ½·0.1 + ½·(0.2·0.05) + ½·0.05 = 0.05 + 0.005 + 0.025 = 0.08
    assert out["reflection"].n == pytest.approx(grey(0.08))
    # Specular: ½·0.2 + ½·(refr_A·spec_B + tspec_A·refl_B + tspec_A·spec_B) + ½·spec_B
    #         = 0.1 + ½·(0.03 + 0.005 + 0.015) + 0.075 = 0.2   (Smits: three interactions)
    assert out["specular"].n == pytest.approx(grey(0.2))
    # Diffuse: ½·0.3 + ½·(refr_A·diff_B + tspec_A·diff_B + tdiff_A·(refl+spec+diff)_B)
    #          + ½·diff_B = 0.15 + ½·(0.1 + 0.05 + 0.07) + 0.25 = 0.51   (five interactions)
    assert out["diffuse"].n == pytest.approx(grey(0.51))
    for lobe in ("reflection_t", "specular_t", "diffuse_t"):  # B transmits nothing
        assert np.all(out[lobe].n == 0.0)
    # Σ = ½·(R_A 0.6 + T_A 0.4 · Σ_B 0.7) + ½·Σ_B = 0.44 + 0.35 = 0.79 ≤ 1.
    assert energy_sum(out)[0] == pytest.approx(grey(0.79))
    # Cones by energy: reflection (0.05·2 + 0.005·max(2,4) + 0.025·4) / 0.08 = 2.75°;
    # specular (0.1·20 + 0.015·30 + 0.0025·20 + 0.0075·max(20,30) + 0.075·30) / 0.2
    #          = 4.975 / 0.2 = 24.875° (transmitted spec × reflection keeps its 20°).
    assert out["reflection"].cone == pytest.approx(2.75)
    assert out["specular"].cone == pytest.approx(24.875)


def test_worked_two_layer_example_simple_layering_by_hand():
    out, _ = composite([(A, 0.5), (B, 1.0)], "simple")
    # A over B: c_A = ½, c_B = (1 − ½)·1 = ½; every weight is ½ W_A + ½ W_B.
    assert out["reflection"].n == pytest.approx(grey(0.075))
    assert out["specular"].n == pytest.approx(grey(0.175))
    assert out["diffuse"].n == pytest.approx(grey(0.4))
    assert out["reflection_t"].n == pytest.approx(grey(0.1))
    # Energy-weighted cone of reflection: (0.05·2 + 0.025·4)/0.075 = 8/3°.
    assert out["reflection"].cone == pytest.approx(8 / 3)


@pytest.mark.parametrize("mode", ["full", "simple"])
@pytest.mark.parametrize("cos_view", [1.0, 0.5, 0.0])
def test_single_layer_with_presence_1_reproduces_it_exactly(mode, cos_view):
    lobes = layer_lobes(GLAZE, cos_view)
    out, _ = composite([(lobes, 1.0)], mode)
    for lobe in LOBES:
        assert np.array_equal(out[lobe].n, lobes[lobe].n)
        assert np.array_equal(out[lobe].g, lobes[lobe].g)
        assert out[lobe].cone == lobes[lobe].cone


def test_single_layer_stack_blends_to_its_own_weights_exactly():
    out = blend(layered(layer(pixar("glaze", GLAZE))), 4)
    assert out.representation == "lobe_weights" and out.maps == {}
    for suffix, cos_view in (("", 1.0), ("_grazing", 0.0)):
        w = lobe_weights(GLAZE, cos_view)
        for name, value in w.items():
            assert out.constants[name + suffix] == pytest.approx(tuple(value), rel=1e-12), name


def test_presence_below_one_lets_light_through():
    lobes = layer_lobes(CLAY, 1.0)  # opaque clay
    out, _ = composite([(lobes, 0.6)], "full")
    for lobe in ("diffuse", "specular", "reflection"):
        assert out[lobe].n == pytest.approx(0.6 * lobes[lobe].n)
    # The uncovered 40 % leaves unscattered: a refraction lobe with cone 0.
    assert out["reflection_t"].n == pytest.approx(grey(0.4))
    assert out["reflection_t"].cone == 0.0


def test_masks_exactly_0_and_1_give_each_layer_exactly(tmp_path):
    file_rows = np.array([1, 1, 0, 0], dtype=np.float32)[:, None] * np.ones(4)
    halves = TextureMask(path=write_image(tmp_path / "h.exr", file_rows))
    out = blend(
        layered(
            layer(pixar("clay", CLAY)),
            layer(pixar("clay2", CLAY.replace(surface_color=(0.1, 0.5, 0.9))), halves),
        ),
        4,
    )
    top = lobe_weights(CLAY.replace(surface_color=(0.1, 0.5, 0.9)), 1.0)
    bottom = lobe_weights(CLAY, 1.0)
    diff = out.maps["diffN"]
    assert np.array_equal(diff[2:], np.broadcast_to(np.float32(top["diffN"]), (2, 4, 3)))
    assert np.array_equal(diff[:2], np.broadcast_to(np.float32(bottom["diffN"]), (2, 4, 3)))


def test_opaque_full_coverage_hides_below_but_a_transmissive_one_does_not():
    hidden = blend(layered(layer(pixar("g", GLAZE)), layer(pixar("c", CLAY))), 2)
    assert [d.kept for d in hidden.decisions] == [False, True]
    seen = blend(layered(layer(pixar("c", CLAY)), layer(pixar("g", GLAZE))), 2)
    assert [d.kept for d in seen.decisions] == [True, True]
    assert seen.constants["diffN"] != tuple(np.float32(lobe_weights(GLAZE)["diffN"]).tolist())


def test_simple_layering_is_selectable_and_differs_for_transmissive_tops():
    stack = layered(layer(pixar("c", CLAY)), layer(pixar("g", GLAZE), 0.5))
    full, simple = blend(stack, 2), blend(stack, 2, layering="simple")
    assert simple.constants["layering"] == "simple" and full.constants["layering"] == "full"
    assert full.constants["diffN"] != simple.constants["diffN"]
    with pytest.raises(BlendError, match="unknown Pixar layering"):
        blend(stack, 2, layering="weird")


def test_normals_blend_by_energy(tmp_path):
    def normal_file(name, n):
        n = np.asarray(n, dtype=np.float32) / np.linalg.norm(n)
        return TextureMask(path=write_image(tmp_path / name, np.ones((2, 2, 3)) * (0.5 * n + 0.5)))

    left, right = normal_file("l.exr", (1, 0, 1)), normal_file("r.exr", (-1, 0, 1))
    dull = CLAY.replace(roughness=1.0)  # all diffuse: diffuse energy = Σ weights
    bright = dull.replace(surface_color=(0.9, 0.9, 0.9))
    stack = layered(
        layer(pixar("d", dull), normal_map=left),
        layer(pixar("b", bright), 0.5, normal_map=right),
    )
    out = blend(stack, 2, layering="simple")
    e_dull = np.mean(lobe_weights(dull)["diffN"] + lobe_weights(dull)["diffG"]) / 2 * 0.5
    e_bright = np.mean(lobe_weights(bright)["diffN"] + lobe_weights(bright)["diffG"]) / 2 * 0.5
    expected = e_dull * np.array([1, 0, 1]) / 2**0.5 + e_bright * np.array([-1, 0, 1]) / 2**0.5
    expected /= np.linalg.norm(expected)
    assert np.allclose(out.normal_map, expected, atol=1e-6)
    assert out.normal_map[0, 0, 0] < 0  # the brighter layer pulls harder


def test_plain_pixar_material_stays_parameters():
    out = blend(pixar("clay", CLAY), 8)
    assert out.representation == "params" and out.to_params() == CLAY
    with pytest.raises(BlendError, match="lobe weights, not parameters"):
        blend(layered(layer(pixar("clay", CLAY))), 2).to_params()


def test_varying_masks_make_maps_and_uniform_outputs_stay_constants():
    stack = layered(layer(pixar("c", CLAY)), layer(pixar("g", GLAZE), NoiseMask(seed=1)))
    out = blend(stack, 8)
    assert "diffN" in out.maps and out.maps["diffN"].shape == (8, 8, 3)
    assert out.params_at(1, 2)["layering"] == "full"
    assert all(np.isfinite(a).all() for a in out.maps.values())


# -- energy: property tests ----------------------------------------------------------------
_unit = st.floats(0.0, 1.0)
_alpha = st.one_of(st.sampled_from([0.0, 1.0]), _unit)
_params = st.builds(
    PixarParams,
    surface_color=st.tuples(_unit, _unit, _unit),
    metallic=_unit,
    roughness=_unit,
    clear=_unit,
    back=_unit,
    normal_fresnel=st.floats(0.0, 20.0),
    grazing_fresnel=_unit,
)


@settings(max_examples=80, deadline=None)
@given(
    st.lists(st.tuples(_params, _alpha), min_size=1, max_size=5),
    st.sampled_from(["full", "simple"]),
    st.sampled_from([1.0, 0.3, 0.0]),
)
def test_energy_never_grows_through_a_stack(stack, mode, cos_view):
    layers = [(layer_lobes(p, cos_view), a) for p, a in stack]
    sums = [energy_sum(lobes) for lobes, _ in layers]
    assume(all(np.all(n <= 1.0) and np.all(g <= 1.0) for n, g in sums))
    out, normals = composite(layers, mode)
    n, g = energy_sum(out)
    assert np.all(n <= 1.0 + 1e-12) and np.all(g <= 1.0 + 1e-12)  # ≤ the incident light
    if mode == "simple":  # a convex mix: never above the most reflective layer
        assert np.all(n <= np.max([s[0] for s in sums], axis=0) + 1e-12)
    assert all(np.all(np.isfinite(p.n)) and np.isfinite(p.cone) for p in out.values())
    for v in normals.values():
        assert np.linalg.norm(v) == pytest.approx(1.0)


@settings(max_examples=60, deadline=None)
@given(st.lists(st.tuples(st.lists(_unit, min_size=6, max_size=6), _alpha), min_size=1, max_size=5))
def test_full_layering_loses_nothing_when_every_layer_conserves(stack):
    layers = []
    for raw, alpha in stack:
        w = np.asarray(raw) + 1e-3
        w /= w.sum()  # Σ = 1: the layer scatters everything it receives
        layers.append((hand_lobes(dict(zip(LOBES, w, strict=True)), {}), alpha))
    out, _ = composite(layers, "full")
    assert energy_sum(out)[0] == pytest.approx(grey(1.0))


def test_layer_lobes_match_the_model_weights():
    lobes = layer_lobes(GLAZE, 0.4)
    w = lobe_weights(GLAZE, 0.4)
    for lobe in LOBES:
        assert np.array_equal(lobes[lobe].n, w[PREFIX[lobe] + "N"])
    assert lobes["specular"].cone == pytest.approx(30 * 0.1 + 5)
    assert lobes["reflection"].cone == pytest.approx(1.0)


def test_tiles_match_one_pass(monkeypatch):
    from lookdev.pipeline.blend import pixar as pixar_path

    stack = layered(
        layer(pixar("c", CLAY)),
        layer(pixar("g", GLAZE), NoiseMask(seed=2), presence=0.8),
        layer(pixar("c2", CLAY.replace(roughness=0.2)), NoiseMask(seed=5)),
    )
    whole = blend(stack, (20, 16))
    monkeypatch.setattr(pixar_path, "TILE_TEXELS", 20 * 3)  # 3 rows a tile, the last one 1 row
    tiled = blend(stack, (20, 16))
    assert whole.maps.keys() == tiled.maps.keys() and whole.maps["diffN"].shape == (16, 20, 3)
    for name in whole.maps:
        assert np.array_equal(whole.maps[name], tiled.maps[name]), name


@pytest.mark.parametrize("mode", ["full", "simple"])
def test_pruning_changes_nothing(mode):
    stack = layered(
        layer(pixar("g0", GLAZE)),
        layer(pixar("c", CLAY), 1.0),  # opaque, full coverage: hides g0
        layer(pixar("g", GLAZE), NoiseMask(scale=2, seed=4), presence=0.7),
        layer(pixar("none", CLAY.replace(roughness=0.1)), 0.0),
    )
    pruned, naive = blend(stack, 8, layering=mode), blend(stack, 8, layering=mode, prune=False)
    assert [d.kept for d in pruned.decisions] == [False, True, True, False]
    for name, full in naive.maps.items():
        mine = pruned.maps.get(name, pruned.constants.get(name))
        assert np.allclose(full, np.asarray(mine, dtype=np.float32), atol=1e-6), name
