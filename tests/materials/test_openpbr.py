"""OpenPBR Surface as a model (materials/openpbr.py): the specification's closed forms,
energy at the edges, the example materials, Dr.Jit against numpy, and against Adobe's
reference BSDF when a checkout of it is given (LOOKDEV_OPENPBR_BSDF)."""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from lookdev.materials.arrays import NumpyOps
from lookdev.materials.bsdf import evaluate
from lookdev.materials.errors import ParameterError
from lookdev.materials.openpbr import MODEL, OpenPBRParams
from lookdev.materials.openpbr_params import f82_tint, modulated_ior
from lookdev.materials.registry import live_lobes
from lookdev.pipeline.export.usd.fidelity import measure

EXAMPLES = Path(__file__).parents[1] / "data" / "openpbr_examples"
XP = NumpyOps()


def _albedo(p: OpenPBRParams, n: int = 16384):
    m = measure(MODEL, p, {}, samples=n)
    eta = MODEL.prepare(XP, p).eta
    return m.reflected, m.transmitted * eta * eta  # energy, not radiance


def test_modulated_ior_edges():
    assert modulated_ior(1.5, 1.0, 0.0, 1.6) == pytest.approx(1.5)
    assert modulated_ior(1.5, 0.0, 0.0, 1.6) == pytest.approx(1.0)
    # under a full coat the ratio is specular_ior/coat_ior, below 1
    assert modulated_ior(1.5, 1.0, 1.0, 1.6) == pytest.approx(1.5 / 1.6)
    # specular_weight above 1/F_s is clamped: F0 reaches 1, the IOR stays finite
    assert math.isfinite(modulated_ior(1.5, 1e3, 0.0, 1.6))


def test_f82_is_schlick_with_white_tint_and_meets_the_tint_at_mu_bar():
    mu = np.linspace(0.0, 1.0, 11)
    f0 = 0.6
    schlick = f0 + (1 - f0) * (1 - mu) ** 5
    np.testing.assert_allclose(f82_tint(XP, f0, 1.0, mu), schlick, atol=1e-12)
    bar = 1.0 / 7.0
    want = 0.5 * (f0 + (1 - f0) * (1 - bar) ** 5)
    assert f82_tint(XP, f0, 0.5, bar) == pytest.approx(want)


def test_default_albedo_at_normal_incidence_is_the_albedo_scaled_sum():
    r, t = _albedo(OpenPBRParams())
    assert r[0] == pytest.approx(0.04 + 0.96 * 0.8, abs=0.01)  # E_spec + (1 − E_spec)·C
    assert np.all(t == 0)


@pytest.mark.parametrize(
    "params",
    [
        OpenPBRParams(base_color=(1, 1, 1), base_diffuse_roughness=1.0, specular_weight=0.0),
        OpenPBRParams(base_color=(1, 1, 1), base_metalness=1.0, specular_roughness=1.0),
        OpenPBRParams(base_color=(1, 1, 1), base_metalness=1.0, specular_roughness=0.0),
        OpenPBRParams(transmission_weight=1.0, specular_roughness=0.0),
    ],
    ids=["white-eon-rough", "white-metal-rough", "white-metal-mirror", "clear-glass"],
)
def test_lossless_edges_keep_energy(params):
    r, t = _albedo(params)
    np.testing.assert_allclose((r + t)[:, 0], 1.0, atol=0.04)  # MC noise of near-deltas


def test_fuzz_and_coat_cover_their_base_without_gain():
    for p in (
        OpenPBRParams(base_color=(1, 1, 1), fuzz_weight=1.0, fuzz_color=(1, 1, 1)),
        OpenPBRParams(base_color=(1, 1, 1), coat_weight=1.0, coat_roughness=0.5),
    ):
        r, _ = _albedo(p)
        assert r.max() < 1.04


def test_masks_zero_and_one_switch_lobes():
    assert "coat" not in live_lobes(MODEL, OpenPBRParams(coat_weight=0.0))
    assert live_lobes(MODEL, OpenPBRParams(base_metalness=1.0)) == ("metal",)
    assert "diffuse" not in live_lobes(MODEL, OpenPBRParams(transmission_weight=1.0))
    assert "specular" not in live_lobes(MODEL, OpenPBRParams(specular_weight=0.0))


def test_grazing_and_below_the_horizon_give_zero_or_finite():
    p = OpenPBRParams(coat_weight=1.0, fuzz_weight=1.0, transmission_weight=0.5)
    wo = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 0.0, 1.0]])
    wi = np.array([[0.0, 0.0, 1.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]])
    f = evaluate(MODEL, p, wi, wo)
    assert np.all(np.isfinite(f)) and np.all(f[:2] == 0)


unit = st.floats(0.0, 1.0)


@settings(max_examples=40, deadline=None)
@given(base=unit, metal=unit, rough=unit, trans=unit, coat=unit, fuzz=unit, ior=st.floats(1.0, 3.0))
def test_random_parameters_evaluate_finite_and_non_negative(
    base, metal, rough, trans, coat, fuzz, ior
):
    p = OpenPBRParams(
        base_color=(base, 0.5, 0.2),
        base_metalness=metal,
        specular_roughness=rough,
        transmission_weight=trans,
        coat_weight=coat,
        fuzz_weight=fuzz,
        specular_ior=ior,
    )
    rng = np.random.default_rng(3)
    wi, wo = rng.normal(size=(2, 64, 3))
    wo[:, 2] = np.abs(wo[:, 2])
    wi /= np.linalg.norm(wi, axis=1, keepdims=True)
    wo /= np.linalg.norm(wo, axis=1, keepdims=True)
    f = evaluate(MODEL, p, wi, wo)
    assert np.all(np.isfinite(f)) and f.min() >= 0.0


def test_every_example_material_parses():
    from lookdev.pipeline.analysis.openpbr_reference import examples

    found = examples(EXAMPLES)
    assert len(found) == 83
    assert found["carpaint"].coat_weight == 1.0


def test_bad_value_is_one_line_naming_the_input():
    from lookdev.pipeline.export.usd.openpbr_import import params_from_values

    with pytest.raises(ParameterError, match="coat_weight"):
        params_from_values({"coat_weight": 2.0}, "m")
    _, notes = params_from_values({"no_such_input": 1.0})
    assert notes == ["no_such_input is not an OpenPBR Surface input: ignored"]


@pytest.mark.slow
@pytest.mark.skipif(not os.environ.get("LOOKDEV_OPENPBR_BSDF"), reason="no adobe/openpbr-bsdf")
def test_against_adobe_reference_on_opaque_examples(tmp_path):
    from lookdev.pipeline.analysis import openpbr_reference as ref

    binary = ref.build(Path(os.environ["LOOKDEV_OPENPBR_BSDF"]), tmp_path / "albedo")
    materials = {
        k: v
        for k, v in ref.examples(EXAMPLES).items()
        if k in ("gray_card", "gold", "carpaint", "velvet", "tire")
    }
    rows = ref.compare(binary, materials, 16384)
    assert max(r.rms_reflected for r in rows) < 0.04, [r.to_json() for r in rows]


@pytest.fixture(scope="module")
def plugin():
    from _mitsuba_helpers import mitsuba_module

    mi = mitsuba_module()
    from lookdev.pipeline.export.mitsuba.plugin import register_model

    return mi, register_model(MODEL)


@pytest.mark.parametrize(
    "values",
    [
        {"base_color": [0.8, 0.2, 0.1], "specular_roughness": 0.4},
        {"base_metalness": 1.0, "base_color": [1.0, 0.78, 0.34], "specular_roughness": 0.5},
        {"coat_weight": 1.0, "coat_roughness": 0.3, "fuzz_weight": 0.5, "specular_roughness": 0.5},
    ],
    ids=["plastic", "metal", "coated-fuzz"],
)
def test_drjit_eval_matches_numpy(plugin, values):
    from _mitsuba_helpers import interaction

    mi, name = plugin
    rng = np.random.default_rng(1)
    view, light = rng.normal(size=(2, 64, 3))
    view[:, 2], light[:, 2] = np.abs(view[:, 2]), np.abs(light[:, 2])
    view /= np.linalg.norm(view, axis=1, keepdims=True)
    light /= np.linalg.norm(light, axis=1, keepdims=True)
    d = {"type": name}
    for k, v in values.items():
        d[k] = {"type": "rgb", "value": v} if isinstance(v, list) else v
    bsdf = mi.load_dict(d)
    got = np.array(bsdf.eval(mi.BSDFContext(), interaction(mi, view), mi.Vector3f(light.T))).T
    want = evaluate(MODEL, OpenPBRParams(**values), light, view) * light[:, 2:3]
    np.testing.assert_allclose(got, want, rtol=2e-3, atol=1e-5)
