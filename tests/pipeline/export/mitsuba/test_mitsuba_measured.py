"""The measured model as a Mitsuba plugin: the same values as numpy, chi-square."""

from __future__ import annotations

import numpy as np
import pytest
from _mitsuba_helpers import interaction, mitsuba_module, unit

from lookdev.library.measured import builtin_measured, read_mbsdf
from lookdev.materials.bsdf import evaluate
from lookdev.materials.measured import MODEL, MeasuredParams, MeasuredTable

pytestmark = pytest.mark.render
_mi = pytest.fixture(scope="module", name="mi")(mitsuba_module)


def _tables():
    rng = np.random.default_rng(9)
    merl = MeasuredTable("merl", rng.random((6, 5, 8, 3)).astype(np.float32), source="noise")
    carpaint = read_mbsdf(next(p for p in builtin_measured() if p.suffix == ".mbsdf"))
    return [pytest.param(carpaint, id="carpaint"), pytest.param(merl, id="merl-noise")]


def _plugin(params):
    from lookdev.pipeline.export.mitsuba.scene import bsdf_dict

    d = bsdf_dict(params, allow_principled=False)
    assert d["type"] == "lookdev_measured" and d["table"].startswith("measured:")
    return d


@pytest.mark.parametrize("table", _tables())
def test_drjit_eval_equals_numpy_eval(mi, table):
    params = MeasuredParams(table=table, scale=0.7)
    rng = np.random.default_rng(7)
    view, light = unit(rng.normal(size=(2048, 3))), unit(rng.normal(size=(2048, 3)))
    bsdf = mi.load_dict(_plugin(params))
    si = interaction(mi, view)
    got = np.array(bsdf.eval(mi.BSDFContext(), si, mi.Vector3f(light.astype(np.float32).T))).T
    view32, light32 = np.array(si.wi).T.astype(np.float64), light.astype(np.float32)
    want = evaluate(MODEL, params, light32.astype(np.float64), view32) * np.abs(light32[:, 2:3])
    scale = float(np.max(np.abs(want)))
    np.testing.assert_allclose(got, want, rtol=2e-4, atol=2e-5 * scale)


@pytest.mark.slow
@pytest.mark.parametrize("view", [[0.0, 0.0, 1.0], [0.7, 0.1, 0.3]], ids=["normal", "oblique"])
def test_chi2_whole_sphere(mi, view):
    from _mitsuba_chi2 import chi2

    params = MeasuredParams(table=_tables()[0].values[0])
    passed, test = chi2(_plugin(params), unit(view), test_count=2)
    assert passed, test.messages
