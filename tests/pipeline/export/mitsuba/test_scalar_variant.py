"""The Conty-Kulla sheen on Mitsuba's ``scalar_rgb`` (the fallback without a usable libLLVM).

The sheen reads its albedo table with a gather; on ``scalar_rgb`` Dr.Jit's ``Float`` is
Python's ``float`` and there is no array to gather from. The plugins run in a subprocess
that sets ``scalar_rgb`` before anything else touches Mitsuba, so the test does not
depend on which variant this process (or an earlier test) made live. (Switching a live
process from ``llvm_ad_rgb`` to ``scalar_rgb`` and back did work in Mitsuba 3.9.1 when
checked; a fresh process is the set-up a user without libLLVM actually has.)
"""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest

from lookdev.materials.bsdf import evaluate
from lookdev.materials.disney import MODEL as DISNEY
from lookdev.materials.params import DisneyParams
from lookdev.materials.sheen import MODEL as SHEEN
from lookdev.materials.sheen import SheenParams

pytest.importorskip("mitsuba")

CASES = {
    "sheen": (SHEEN, {"roughness": 0.3, "color": [0.9, 0.5, 0.3]}),
    "sheen_r0": (SHEEN, {"roughness": 0.0}),
    "disney_ck": (
        DISNEY,
        {
            "base_color": [0.3, 0.05, 0.1],
            "sheen": 1.0,
            "sheen_tint": 0.6,
            "sheen_model": "conty_kulla",
            "sheen_roughness": 0.5,
        },
    ),
}
PARAMS = {"sheen": SheenParams, "sheen_r0": SheenParams, "disney_ck": DisneyParams}
VIEWS = [(0.0, 0.0, 1.0), (0.6, 0.0, 0.8), (0.999, 0.0, 0.045)]
LIGHTS = [(0.0, 0.0, 1.0), (-0.8, 0.0, 0.6), (0.3, 0.9, 0.316), (-0.99, 0.0, 0.14)]

SCRIPT = """
import json, sys
import mitsuba as mi
mi.set_variant("scalar_rgb")
from lookdev.pipeline.export.mitsuba.scene import bsdf_dict
from lookdev.materials.params import DisneyParams
from lookdev.materials.sheen import SheenParams

cases, views, lights = json.loads(sys.argv[1])
kinds = {"sheen": SheenParams, "sheen_r0": SheenParams, "disney_ck": DisneyParams}
out = {"variant": mi.variant()}
for name, values in cases.items():
    bsdf = mi.load_dict(bsdf_dict(kinds[name].parse(values), allow_principled=False))
    rows = []
    for v in views:
        si = mi.SurfaceInteraction3f()
        si.wi = mi.Vector3f(*v)
        for light in lights:
            f = bsdf.eval(mi.BSDFContext(), si, mi.Vector3f(*light))
            rows.append([float(f[0]), float(f[1]), float(f[2])])
    sample, weight = bsdf.sample(mi.BSDFContext(), si, 0.3, mi.Point2f(0.4, 0.7))
    out[name] = {"eval": rows, "sample_pdf": float(sample.pdf), "weight": float(weight[0])}
print(json.dumps(out))
"""


def _unit(v):
    v = np.asarray(v, dtype=np.float64)
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


@pytest.fixture(scope="module")
def scalar_run():
    views, lights = _unit(VIEWS).tolist(), _unit(LIGHTS).tolist()
    arg = json.dumps([{k: v for k, (_, v) in CASES.items()}, views, lights])
    run = subprocess.run(
        [sys.executable, "-c", SCRIPT, arg], capture_output=True, text=True, timeout=300
    )
    assert run.returncode == 0, run.stderr[-3000:]
    return json.loads(run.stdout.strip().splitlines()[-1]), views, lights


@pytest.mark.slow
@pytest.mark.parametrize("name", list(CASES))
def test_sheen_plugins_evaluate_on_scalar_rgb_as_numpy_does(scalar_run, name):
    """Mitsuba's eval (f·cos θ of the light) on scalar_rgb = the numpy model's f·cos θ."""
    result, views, lights = scalar_run
    assert result["variant"] == "scalar_rgb"
    model, values = CASES[name]
    params = PARAMS[name].parse(values)
    wo = np.repeat(np.array(views), len(lights), axis=0)  # ours: wo = viewer
    wi = np.tile(np.array(lights), (len(views), 1))
    want = evaluate(model, params, wi, wo) * wi[:, 2:3]
    got = np.array(result[name]["eval"])
    assert np.sum(want.max(axis=1) > 1e-3) >= 2  # not a comparison of zeros
    np.testing.assert_allclose(got, want, rtol=1e-4, atol=1e-7)
    sampled = result[name]
    assert sampled["sample_pdf"] > 0 and np.isfinite(sampled["weight"])
