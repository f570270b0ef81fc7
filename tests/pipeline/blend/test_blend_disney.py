"""Disney parameter blending (Burley 2012 §5.7): lerp bottom to top, pruning, maps."""

from __future__ import annotations

import numpy as np
import pytest
from _blend_helpers import disney, layer, layered, write_image
from hypothesis import given, settings
from hypothesis import strategies as st

from lookdev.library import Library, Material
from lookdev.materials.layers import ConstantMask, NoiseMask, RampMask, TextureMask
from lookdev.materials.params import DisneyParams
from lookdev.materials.pixar import PixarParams
from lookdev.pipeline.blend import BlendError, TextureError, blend, engine
from lookdev.pipeline.blend.sheen import base_scale as sheen_base_scale

GOLD = disney("gold", base_color=(1.0, 0.78, 0.34), metallic=1.0, roughness=0.2)
RUBBER = disney("rubber", base_color=(0.05, 0.1, 0.6), roughness=0.9, specular=0.3)


@pytest.fixture
def halves(tmp_path):
    """A 4×4 mask: 0 in the bottom half of the UV square (v < ½), 1 in the top half."""
    file_rows = np.array([1, 1, 0, 0], dtype=np.float32)[:, None] * np.ones(4)
    return TextureMask(path=write_image(tmp_path / "halves.exr", file_rows))


def test_a_plain_material_blends_to_its_own_params():
    out = blend(GOLD, 32)
    assert out.maps == {} and out.normal_map is None and out.model == "disney"
    assert out.to_params() == GOLD.params
    assert out.resolution == (32, 32)


def test_single_layer_reproduces_that_layer_exactly():
    out = blend(layered(layer(GOLD)), 16)
    assert out.maps == {} and out.to_params() == GOLD.params


def test_uniform_mask_folds_into_constants_by_hand():
    out = blend(layered(layer(GOLD), layer(RUBBER, 0.25)), 8)
    assert out.maps == {}
    p = out.to_params()
    # lerp(gold, rubber, ¼) = ¾ gold + ¼ rubber, per parameter and per colour channel.
    assert p.roughness == pytest.approx(0.75 * 0.2 + 0.25 * 0.9)  # 0.375, in roughness (not α)
    assert p.metallic == pytest.approx(0.75)
    assert p.specular == pytest.approx(0.75 * 0.5 + 0.25 * 0.3)  # 0.45
    assert p.base_color == pytest.approx((0.7625, 0.61, 0.405))


def test_masks_exactly_zero_and_one_drop_layers():
    hidden = blend(layered(layer(RUBBER), layer(GOLD, 1.0)), 8)
    assert hidden.to_params() == GOLD.params
    assert [(d.layer, d.kept) for d in hidden.decisions] == [("rubber", False), ("gold", True)]
    absent = blend(layered(layer(GOLD), layer(RUBBER, 0.0)), 8)
    assert absent.to_params() == GOLD.params
    assert absent.decisions[1].reason == "coverage is zero everywhere"


def test_a_texture_mask_makes_maps_only_for_what_differs(halves):
    rougher = disney("rough_gold", base_color=(1.0, 0.78, 0.34), metallic=1.0, roughness=0.8)
    out = blend(layered(layer(GOLD), layer(rougher, halves)), 4)
    assert list(out.maps) == ["roughness"]
    r = out.maps["roughness"]
    assert r.dtype == np.float32 and r.shape == (4, 4)
    assert np.all(r[:2] == np.float32(0.2)) and np.all(r[2:] == np.float32(0.8))
    assert out.constants["metallic"] == 1.0
    assert out.params_at(3, 0).roughness == pytest.approx(0.8)


def test_texels_at_mask_0_and_1_equal_the_layers_exactly(halves):
    out = blend(layered(layer(GOLD), layer(RUBBER, halves)), 4)
    for name in ("roughness", "metallic", "specular"):
        assert np.all(out.maps[name][:2] == np.float32(getattr(GOLD.params, name)))
        assert np.all(out.maps[name][2:] == np.float32(getattr(RUBBER.params, name)))
    assert np.all(out.maps["base_color"][0] == np.float32(GOLD.params.base_color))
    assert np.all(out.maps["base_color"][3] == np.float32(RUBBER.params.base_color))


def test_worked_three_layer_example_by_hand(halves):
    # Bottom to top: roughness 0.2 (base), 0.9 under ½, 0.5 under the halves mask.
    mid = disney("mid", roughness=0.5)
    a, b = disney("a", roughness=0.2), disney("b", roughness=0.9)
    out = blend(layered(layer(a), layer(b, 0.5), layer(mid, halves)), 4)
    r = out.maps["roughness"]
    # Where the top mask is 0: lerp(0.2, 0.9, ½) = 0.55. Where it is 1: 0.5.
    assert np.allclose(r[:2], 0.55) and np.all(r[2:] == np.float32(0.5))


def test_many_layers_at_half_coverage():
    # 20 layers each under ½: the weight of layer i (0 = base) is ½^(20 − i), base ½^19.
    mats = [disney(f"l{i}", roughness=i / 19) for i in range(20)]
    out = blend(layered(layer(mats[0]), *(layer(m, 0.5) for m in mats[1:])), 2)
    weights = [0.5**19] + [0.5 ** (20 - i) for i in range(1, 20)]
    assert sum(weights) == pytest.approx(1.0)
    expected = sum(w * i / 19 for i, w in enumerate(weights))
    assert out.to_params().roughness == pytest.approx(expected, rel=1e-12)


def test_many_varying_layers_stay_inside_the_layers_range(tmp_path):
    rng = np.random.default_rng(5)
    layers = [layer(disney("b", roughness=0.1, base_color=(0.1, 0.1, 0.1)))]
    for i in range(12):
        path = write_image(tmp_path / f"m{i}.exr", rng.random((8, 8)) * 3 - 1)  # −1..2
        mat = disney(f"l{i}", roughness=0.1 + 0.8 * i / 11, base_color=(0.9, 0.5, 0.1))
        layers.append(layer(mat, TextureMask(path=path)))
    out = blend(layered(*layers), 8)
    ulp = 1e-7  # float32 weights sum to 1 within an ulp
    r = out.maps["roughness"]
    assert r.min() >= 0.1 - ulp and r.max() <= 0.9 + ulp  # masks were clamped to 0..1
    c = out.maps["base_color"]
    assert c.min() >= 0.1 - ulp and c[..., 0].max() <= 0.9 + ulp


def test_pruning_changes_nothing(tmp_path, halves):
    noise = NoiseMask(scale=3, seed=1)
    stack = layered(
        layer(RUBBER),
        layer(GOLD, noise),
        layer(disney("same", **RUBBER.params.model_dump(exclude={"ior"})), 0.0),
        layer(RUBBER.model_copy(update={"name": "rubber2"}), 0.3),
        layer(GOLD.model_copy(update={"name": "top"}), halves),
    )
    pruned = blend(stack, 8)
    naive = blend(stack, 8, prune=False)
    assert set(pruned.maps) < set(naive.maps)
    for name, full in naive.maps.items():
        mine = pruned.maps.get(name, pruned.constants.get(name))
        assert np.allclose(full, np.asarray(mine, dtype=np.float32), atol=1e-6), name


def test_a_layer_that_sets_what_is_below_is_dropped(halves):
    twin = GOLD.model_copy(update={"name": "twin"})
    out = blend(layered(layer(GOLD), layer(twin, halves)), 4)
    assert out.maps == {}
    assert out.decisions[-1].reason == "sets what is already below it"


def test_full_coverage_texture_hides_what_is_below(tmp_path):
    ones = TextureMask(path=write_image(tmp_path / "ones.exr", np.ones((4, 4))))
    out = blend(
        layered(layer(RUBBER), layer(disney("x", roughness=0.7), 0.5), layer(GOLD, ones)), 4
    )
    assert out.maps == {} and out.to_params() == GOLD.params
    assert [d.kept for d in out.decisions] == [False, False, True]


def test_zero_everywhere_texture_layer_is_dropped_without_maps(tmp_path):
    zeros = TextureMask(path=write_image(tmp_path / "zeros.exr", np.zeros((4, 4))))
    out = blend(layered(layer(GOLD), layer(RUBBER, zeros)), 4)
    assert out.maps == {} and out.to_params() == GOLD.params


def test_tiles_match_one_pass(monkeypatch):
    stack = layered(layer(GOLD), layer(RUBBER, NoiseMask(seed=3)), layer(GOLD, RampMask(axis="v")))
    whole = blend(stack, (13, 11))
    monkeypatch.setattr(engine, "TILE_TEXELS", 13 * 2)  # 2 rows per tile, last tile 1 row
    tiled = blend(stack, (13, 11))
    assert whole.resolution == (13, 11) and whole.maps["roughness"].shape == (11, 13)
    for name in whole.maps:
        assert np.array_equal(whole.maps[name], tiled.maps[name])


def test_progress_reports_rows():
    seen = []
    blend(
        layered(layer(GOLD), layer(RUBBER, NoiseMask())),
        8,
        progress=lambda a, b: seen.append((a, b)),
    )
    assert seen[-1] == (8, 8)


# -- ior / specular ------------------------------------------------------------------------
def test_one_shared_ior_passes_through_exactly():
    water = disney("water", ior=1.333, roughness=0.0)
    still = disney("still", ior=1.333, roughness=0.5)
    p = blend(layered(layer(water), layer(still, 0.5)), 4).to_params()
    assert p.ior == 1.333 and p.roughness == 0.25


def test_different_iors_blend_as_specular():
    a, b = disney("a", ior=1.0), disney("b", ior=1.8)
    p = blend(layered(layer(a), layer(b, 0.5)), 4).to_params()
    # specular(1.0) = 0, specular(1.8) = ((0.8/2.8)²)/0.08; the mix is their mean.
    s = 0.5 * ((0.8 / 2.8) ** 2 / 0.08)
    assert p.effective_specular == pytest.approx(s)


def test_mixed_spellings_blend_to_specular():
    p = blend(layered(layer(disney("a", ior=1.5)), layer(GOLD, 0.5)), 4).to_params()
    assert p.ior is None and p.specular == pytest.approx(0.5, abs=1e-9)


# -- normals -------------------------------------------------------------------------------
def _normal_file(tmp_path, name, n):
    n = np.asarray(n, dtype=np.float32) / np.linalg.norm(n)
    return TextureMask(path=write_image(tmp_path / name, np.broadcast_to(0.5 * n + 0.5, (4, 4, 3))))


def test_normal_maps_blend_and_renormalise(tmp_path):
    tilt = _normal_file(tmp_path, "tilt.exr", (1.0, 0.0, 1.0))
    out = blend(layered(layer(GOLD, normal_map=tilt), layer(RUBBER, 0.5)), 4)
    n = out.normal_map
    # ½ (1/√2, 0, 1/√2) + ½ (0, 0, 1), renormalised.
    expected = np.array([0.5 / np.sqrt(2), 0.0, 0.5 / np.sqrt(2) + 0.5])
    assert np.allclose(n, expected / np.linalg.norm(expected), atol=1e-6)
    assert np.allclose(np.linalg.norm(n, axis=-1), 1.0, atol=1e-6)
    assert out.specular_normal_map is None


def test_opposite_normals_fall_back_to_the_geometric_normal(tmp_path):
    left = _normal_file(tmp_path, "l.exr", (1.0, 0.0, 0.0))
    right = _normal_file(tmp_path, "r.exr", (-1.0, 0.0, 0.0))
    out = blend(layered(layer(GOLD, normal_map=left), layer(RUBBER, 0.5, normal_map=right)), 4)
    assert np.allclose(out.normal_map, (0.0, 0.0, 1.0))


def test_separate_specular_normal(tmp_path):
    sparkle = _normal_file(tmp_path, "s.exr", (0.0, 1.0, 1.0))
    out = blend(layered(layer(GOLD), layer(RUBBER, 1.0, specular_normal_map=sparkle)), 4)
    assert out.normal_map is None
    assert np.allclose(out.specular_normal_map, (0.0, 2**-0.5, 2**-0.5), atol=1e-6)
    flipped = sparkle.model_copy(update={"invert": True})  # DirectX convention: y flipped
    out = blend(layered(layer(GOLD), layer(RUBBER, 1.0, specular_normal_map=flipped)), 4)
    assert np.allclose(out.specular_normal_map, (0.0, -(2**-0.5), 2**-0.5), atol=1e-6)


# -- bad input -----------------------------------------------------------------------------
def test_mixed_models_name_the_layer():
    pixar = Material(name="plastic_pixar", model="pixar", params=PixarParams())
    with pytest.raises(BlendError, match=r"layer 'top': is pixar .* layer 'gold' is disney"):
        blend(layered(layer(GOLD), layer(pixar, 0.5, name="top")), 4)


def test_discrete_parameters_must_agree():
    leaf = disney("leaf", thin=True)
    with pytest.raises(BlendError, match=r"layer 'leaf': thin: thin = True differs"):
        blend(layered(layer(GOLD), layer(leaf, 0.5)), 4)
    # …but a layer hidden under a full-coverage one does not vote.
    assert blend(layered(layer(GOLD), layer(leaf, 1.0)), 4).constants["thin"] is True


def test_bad_texture_names_layer_and_file_even_when_pruned(tmp_path):
    missing = TextureMask(path=tmp_path / "gone.png")
    with pytest.raises(TextureError, match=r"layer 'rust': texture file .*gone\.png"):
        blend(layered(layer(GOLD), layer(RUBBER, missing, name="rust"), layer(GOLD, 1.0)), 4)


def test_uniform_result_refuses_to_flatten_maps(halves):
    out = blend(layered(layer(GOLD), layer(RUBBER, halves)), 4)
    with pytest.raises(BlendError, match="vary across the surface"):
        out.to_params()


# -- properties and presets ----------------------------------------------------------------
@settings(max_examples=40, deadline=None)
@given(
    st.lists(st.tuples(st.floats(0, 1), st.floats(0, 1), st.floats(0, 1)), min_size=1, max_size=6)
)
def test_blend_is_a_convex_combination(spec):
    layers = [
        layer(disney(f"l{i}", roughness=r, metallic=m), cov) for i, (r, m, cov) in enumerate(spec)
    ]
    p = blend(layered(*layers), 2).to_params()
    rough, metal = [r for r, _, _ in spec], [m for _, m, _ in spec]
    assert min(rough) - 1e-9 <= p.roughness <= max(rough) + 1e-9
    assert min(metal) - 1e-9 <= p.metallic <= max(metal) + 1e-9


@pytest.mark.parametrize("name", ["rusty_iron", "dust_over_plastic", "rusty_car_paint"])
def test_builtin_layered_presets_blend(name):
    out = blend(Library(use_env=False).load(name), 32)
    assert out.maps and all(np.isfinite(a).all() for a in out.maps.values())
    assert isinstance(out.params_at(5, 7), DisneyParams)


def test_base_mask_is_documented_as_unused():
    out = blend(layered(layer(GOLD, ConstantMask(value=0.3)), layer(RUBBER, 0.5)), 2)
    assert "not used" in out.decisions[0].reason


# -- Conty-Kulla sheen over the blended base ------------------------------------------------
def test_sheen_scales_the_blended_base_per_texel():
    lib = Library(use_env=False)
    velvet, plastic = lib.load("velvet"), lib.load("plastic_glossy")
    ramp = RampMask(axis="u", start=0.2, end=0.8)  # exactly 0 in column 0, 1 in column 3
    out = blend(layered(layer(plastic), layer(velvet, ramp)), 4)
    assert "sheen" in out.maps and out.constants["sheen_model"] == "conty_kulla"
    scale = sheen_base_scale(out, 0.7)
    assert scale.shape == (4, 4, 3) and scale.dtype == np.float32
    assert np.all(scale[:, 0] == 1.0)  # no sheen there: the base is untouched
    alone = sheen_base_scale(blend(velvet, 1), 0.7)
    assert np.allclose(scale[:, 3], alone, atol=1e-6)
    # In between, the factor is that of the texel's blended parameters.
    mid = Material(name="mid", model="disney", params=out.params_at(2, 1))
    assert np.allclose(scale[2, 1], sheen_base_scale(blend(mid, 1), 0.7), atol=1e-6)
    assert np.all(scale <= 1.0) and np.all(scale > 0.5)


def test_no_conty_kulla_sheen_means_no_scaling():
    assert sheen_base_scale(blend(GOLD, 4)) == (1.0, 1.0, 1.0)


def test_presence_scales_disney_coverage_too():
    out = blend(layered(layer(GOLD), layer(RUBBER, 1.0, presence=0.5)), 2)
    assert [d.kept for d in out.decisions] == [True, True]  # ½ coverage hides nothing
    assert out.to_params().roughness == pytest.approx(0.55)


def test_sheen_model_is_voted_only_by_layers_with_sheen():
    velvet = disney("velvet", sheen=1.0, sheen_model="conty_kulla")
    cloth = disney("cloth", sheen=0.5, sheen_model="disney")
    assert blend(layered(layer(GOLD), layer(velvet, 0.5)), 2).constants["sheen_model"] == (
        "conty_kulla"
    )
    with pytest.raises(BlendError, match="sheen_model"):
        blend(layered(layer(cloth), layer(velvet, 0.5)), 2)


def test_minified_normal_maps_average_then_renormalise(tmp_path):
    n = np.zeros((8, 8, 3), dtype=np.float32)
    n[:, 0::2] = (0.6, 0.0, 0.8)
    n[:, 1::2] = (-0.6, 0.0, 0.8)
    tex = TextureMask(path=write_image(tmp_path / "bumps.exr", 0.5 * n + 0.5))
    out = blend(layered(layer(GOLD, normal_map=tex)), 2)
    assert np.allclose(out.normal_map, (0.0, 0.0, 1.0), atol=1e-6)  # bumps filter out flat


_coverage = st.one_of(
    st.sampled_from([0.0, 1.0, 0.5]),
    st.integers(0, 5).map(lambda seed: NoiseMask(scale=2, octaves=2, seed=seed)),
)


@pytest.fixture(scope="module")
def bumps(tmp_path_factory):
    """A varying tangent-space normal map (encoded), 4×4."""
    rng = np.random.default_rng(9)
    n = np.concatenate([rng.uniform(-0.5, 0.5, (4, 4, 2)), np.ones((4, 4, 1))], axis=-1)
    n /= np.linalg.norm(n, axis=-1, keepdims=True)
    path = tmp_path_factory.mktemp("bumps") / "bumps.exr"
    return TextureMask(path=write_image(path, 0.5 * n + 0.5))


@settings(max_examples=30, deadline=None)
@given(
    st.lists(
        st.tuples(
            st.sampled_from([0.1, 0.5, 0.9]),
            st.sampled_from([0.0, 1.0]),
            _coverage,
            st.booleans(),
        ),
        min_size=1,
        max_size=5,
    )
)
def test_pruning_never_changes_a_texel(bumps, spec):
    layers = [
        layer(disney(f"l{i}", roughness=r, metallic=m), cov, normal_map=bumps if bumpy else None)
        for i, (r, m, cov, bumpy) in enumerate(spec)
    ]
    stack = layered(*layers)
    pruned, naive = blend(stack, 4), blend(stack, 4, prune=False)
    for name, full in naive.maps.items():
        mine = pruned.maps.get(name, pruned.constants.get(name))
        assert np.allclose(full, np.asarray(mine, dtype=np.float32), atol=1e-6), name
    if naive.normal_map is None:
        assert pruned.normal_map is None
    else:
        mine = pruned.normal_map if pruned.normal_map is not None else np.array([0.0, 0.0, 1.0])
        assert np.allclose(naive.normal_map, mine, atol=1e-5)


def test_a_flat_twin_over_a_normal_map_is_kept(tmp_path):
    tilt = _normal_file(tmp_path, "tilt.exr", (1.0, 0.0, 1.0))
    twin = GOLD.model_copy(update={"name": "twin"})
    out = blend(layered(layer(GOLD, normal_map=tilt), layer(twin, 0.5)), 4)
    assert out.decisions[-1].kept  # same parameters, but it flattens the normals below
    expected = np.array([0.5 / np.sqrt(2), 0.0, 0.5 / np.sqrt(2) + 0.5])
    assert np.allclose(out.normal_map, expected / np.linalg.norm(expected), atol=1e-6)


def test_sheen_lambda_is_voted_only_by_layers_with_sheen():
    exact = disney("velvet", sheen=1.0, sheen_model="conty_kulla", sheen_lambda="exact")
    fitted = disney("cloth", sheen=0.5, sheen_model="conty_kulla")
    out = blend(layered(layer(GOLD), layer(exact, 0.5)), 2)
    assert out.constants["sheen_lambda"] == "exact"
    with pytest.raises(BlendError, match="sheen_lambda"):
        blend(layered(layer(fitted), layer(exact, 0.5)), 2)


def test_energy_compensation_is_one_switch_the_layers_agree_on():
    on = disney("gold_ms", metallic=1.0, roughness=0.6, energy_compensation=True)
    rough = disney("rough_ms", metallic=1.0, roughness=0.9, energy_compensation=True)
    out = blend(layered(layer(on), layer(rough, 0.5)), 2)
    assert out.constants["energy_compensation"] is True and out.params.energy_compensation
    with pytest.raises(BlendError, match="energy_compensation"):
        blend(layered(layer(GOLD), layer(rough, 0.5)), 2)
