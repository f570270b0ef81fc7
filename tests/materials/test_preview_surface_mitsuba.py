"""UsdPreviewSurface's BRDF (materials/preview_surface.py) on Mitsuba's Dr.Jit backend: the
same model as numpy, and its sampler passes ``mitsuba.chi2`` (issue 15 §3)."""

from __future__ import annotations

import numpy as np
import pytest
from _mitsuba_helpers import interaction as _interaction
from _mitsuba_helpers import mitsuba_module
from _mitsuba_helpers import unit as _unit

from lookdev.materials.bsdf import evaluate
from lookdev.materials.preview_surface import MODEL, PreviewParams

_mi = pytest.fixture(scope="module", name="mi")(mitsuba_module)

CASES = {
    "plastic": {"diffuse_color": [0.8, 0.2, 0.1], "roughness": 0.4},
    "metal": {"diffuse_color": [1.0, 0.78, 0.34], "metallic": 1.0, "roughness": 0.6},
    "coated": {"diffuse_color": [0.5, 0.05, 0.05], "metallic": 0.3, "roughness": 0.5,
               "clearcoat": 0.5, "clearcoat_roughness": 0.6},
}  # fmt: skip
"""Lobes wide enough for the whole-sphere chi-square grid (α ≥ 0.25: a narrower peak falls
into one or two of its cells, tests/_mitsuba_chi2.py)."""


@pytest.fixture(scope="module")
def plugin(mi):
    from lookdev.pipeline.export.mitsuba.plugin import register_model

    return register_model(MODEL)


def _bsdf(mi, plugin, values):
    d = {"type": plugin}
    for k, v in values.items():
        d[k] = {"type": "rgb", "value": v} if isinstance(v, list) else v
    return mi.load_dict(d)


@pytest.mark.parametrize("case", sorted(CASES))
def test_drjit_eval_matches_numpy(mi, plugin, case):
    rng = np.random.default_rng(1)
    view = rng.normal(size=(64, 3))
    view[:, 2] = np.abs(view[:, 2])
    view /= np.linalg.norm(view, axis=1, keepdims=True)
    light = rng.normal(size=(64, 3))
    light[:, 2] = np.abs(light[:, 2])
    light /= np.linalg.norm(light, axis=1, keepdims=True)
    bsdf = _bsdf(mi, plugin, CASES[case])
    got = np.array(bsdf.eval(mi.BSDFContext(), _interaction(mi, view), mi.Vector3f(light.T))).T
    want = evaluate(MODEL, PreviewParams(**CASES[case]), light, view) * light[:, 2:3]
    np.testing.assert_allclose(got, want, rtol=1e-4, atol=1e-6)


@pytest.mark.slow
@pytest.mark.parametrize("case", sorted(CASES))
@pytest.mark.parametrize("wi", [(0, 0, 1), (0.48, 0, 0.877), (0.95, 0, 0.31)])
def test_chi2(mi, plugin, case, wi):
    from mitsuba.chi2 import BSDFAdapter, ChiSquareTest, SphericalDomain

    d = {"type": plugin}
    for k, v in CASES[case].items():
        d[k] = {"type": "rgb", "value": v} if isinstance(v, list) else v
    sample, pdf = BSDFAdapter(plugin, d, wi=_unit(wi).tolist())
    test = ChiSquareTest(domain=SphericalDomain(), sample_func=sample, pdf_func=pdf, sample_dim=3)
    assert test.run(), test.messages
