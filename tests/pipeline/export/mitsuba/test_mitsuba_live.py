"""The plugin's ``live`` form (the designer's truth mode): traversed, opaque parameters,
every lobe traced; the same values as the plain plugin, edits in place, chi-square."""

from __future__ import annotations

import numpy as np
import pytest
from _mitsuba_helpers import interaction as _interaction
from _mitsuba_helpers import mitsuba_module
from _mitsuba_helpers import unit as _unit

from lookdev.materials.params import DisneyParams

pytestmark = pytest.mark.render
_mi = pytest.fixture(scope="module", name="mi")(mitsuba_module)


def _dicts(params):
    from lookdev.pipeline.export.mitsuba.scene import bsdf_dict

    return bsdf_dict(params, allow_principled=False), bsdf_dict(params, live=True)


def _eval(mi, bsdf, view, light):
    si = _interaction(mi, view)
    value = bsdf.eval(mi.BSDFContext(), si, mi.Vector3f(light.astype(np.float32).T))
    return np.array(value).T


def _pairs(seed=5, n=1024):
    rng = np.random.default_rng(seed)
    return _unit(rng.normal(size=(n, 3))), _unit(rng.normal(size=(n, 3)))


@pytest.mark.parametrize(
    "params",
    [
        DisneyParams(base_color=(0.8, 0.3, 0.1), roughness=0.4),
        DisneyParams(metallic=1.0, roughness=0.3, anisotropic=0.5),
        DisneyParams(roughness=0.2, spec_trans=0.7, clearcoat=0.4, sheen=0.5),
        DisneyParams(thin=True, diff_trans=0.4, flatness=0.3, roughness=0.5),
    ],
    ids=["plastic", "metal", "glass_coat_sheen", "thin"],
)
def test_live_plugin_equals_the_plain_plugin(mi, params):
    plain, live = (mi.load_dict(d) for d in _dicts(params))
    view, light = _pairs()
    np.testing.assert_allclose(
        _eval(mi, live, view, light), _eval(mi, plain, view, light), rtol=2e-5, atol=1e-6
    )
    assert live.flags() & mi.BSDFFlags.GlossyTransmission  # every lobe is traced


def test_live_edits_through_traverse_match_a_fresh_plugin(mi):
    start = DisneyParams(base_color=(0.8, 0.3, 0.1), roughness=0.4)
    edited = DisneyParams(base_color=(0.2, 0.5, 0.9), roughness=0.1, clearcoat=1.0, sheen=0.3)
    live = mi.load_dict(_dicts(start)[1])
    params = mi.traverse(live)
    params["base_color"] = mi.Vector3f(0.2, 0.5, 0.9)
    params["roughness"] = mi.Float(0.1)
    params["clearcoat"] = mi.Float(1.0)  # a lobe switched on from 0
    params["sheen"] = mi.Float(0.3)
    params.update()
    view, light = _pairs(9)
    fresh = mi.load_dict(_dicts(edited)[0])
    np.testing.assert_allclose(
        _eval(mi, live, view, light), _eval(mi, fresh, view, light), rtol=2e-5, atol=1e-6
    )


def test_live_parameters_are_every_continuous_field_defaults_included(mi):
    from lookdev.materials.textures import texturable

    live = mi.load_dict(_dicts(DisneyParams(roughness=0.4))[1])
    keys = set(mi.traverse(live).keys())
    expected = {k for k in texturable(DisneyParams) if getattr(DisneyParams(), k) is not None}
    assert expected <= keys
    assert "thin" not in keys and "sheen_model" not in keys  # switches: a new BSDF


@pytest.mark.slow
@pytest.mark.parametrize("view", [(0.3, 0.2, 0.93), (0.3, 0.2, -0.93)], ids=["above", "below"])
def test_chi2_of_a_live_plugin_with_every_lobe(mi, view):
    from _mitsuba_chi2 import chi2

    params = DisneyParams(
        base_color=(0.7, 0.5, 0.3), roughness=0.5, spec_trans=0.4, clearcoat=0.5, sheen=0.5
    )
    passed, test = chi2(_dicts(params)[1], _unit(view), test_count=2)
    assert passed, test.messages
