"""One home each (issue 12), tested at the edges: specular ↔ IOR, cones, one-line errors."""

from __future__ import annotations

import math

import numpy as np
import pytest

from lookdev.materials import pixar_lobes as pl
from lookdev.materials.arrays import NumpyOps
from lookdev.materials.errors import LookdevError, ParameterError
from lookdev.materials.fresnel import (
    ETA_MAX,
    F0_MAX,
    SPECULAR_F0_SCALE,
    f0_to_ior,
    ior_to_f0,
    ior_to_specular,
    specular_to_ior,
)
from lookdev.materials.params import DisneyParams
from lookdev.materials.pixar import PixarParams, as_lobe_weights
from lookdev.materials.pixar_lobes import reflection_cone, specular_cone

SPECULAR_CEILING = DisneyParams.model_fields["specular"].metadata[-1].le


# -- specular ↔ IOR ------------------------------------------------------------------------
def test_specular_zero_is_ior_one_and_back():
    assert specular_to_ior(0.0) == 1.0 and ior_to_specular(1.0) == 0.0
    assert f0_to_ior(0.0) == 1.0 and ior_to_f0(1.0) == 0.0


def test_burleys_default_and_range():
    """§5.4: specular 0..1 ↦ F0 0..0.08 ↦ IOR 1.0..1.8, the middle 0.5 ↦ 1.5."""
    assert specular_to_ior(0.5) == pytest.approx(1.5, abs=1e-12)
    assert specular_to_ior(1.0) == pytest.approx(1.7888, abs=1e-4)
    assert ior_to_specular(1.5) == pytest.approx(0.5, abs=1e-12)
    assert SPECULAR_F0_SCALE == 0.08


@pytest.mark.parametrize("s", [0.0, 1e-9, 0.01, 0.5, 1.0, 4.0, 12.0, 12.49])
def test_round_trip_below_the_clamp(s):
    assert ior_to_specular(specular_to_ior(s)) == pytest.approx(s, rel=1e-9, abs=1e-15)


def test_the_clamp_is_at_f0_max_and_keeps_eta_finite_in_float32():
    at_clamp = F0_MAX / SPECULAR_F0_SCALE
    assert specular_to_ior(at_clamp) == pytest.approx(ETA_MAX, rel=1e-12)
    assert specular_to_ior(SPECULAR_CEILING) == ETA_MAX == f0_to_ior(1.0)
    assert specular_to_ior(1e30) == ETA_MAX
    assert 3.9e6 < ETA_MAX < 4.1e6
    xp = NumpyOps(np.float32)
    eta = specular_to_ior(xp.asarray([0.0, 0.5, SPECULAR_CEILING]), xp)
    assert eta.dtype == np.float32 and np.isfinite(eta).all() and np.isfinite(eta * eta).all()
    assert eta[1] == pytest.approx(1.5, rel=1e-6) and eta[0] == 1.0


def test_floats_give_floats_and_arrays_keep_their_shape():
    assert type(specular_to_ior(0.5)) is float and type(f0_to_ior(0.04)) is float
    a = specular_to_ior(np.full((2, 3), 0.5, np.float32))
    assert a.shape == (2, 3) and a.dtype == np.float32


def test_every_spelling_uses_the_one_conversion():
    assert DisneyParams(specular=0.3).effective_ior == specular_to_ior(0.3)
    assert DisneyParams(ior=1.7).effective_specular == ior_to_specular(1.7)
    assert DisneyParams(specular=SPECULAR_CEILING).effective_ior == ETA_MAX
    assert PixarParams(normal_fresnel=0.8).eta == f0_to_ior(0.04)
    assert PixarParams(normal_fresnel=20.0).eta == ETA_MAX
    assert math.isfinite(PixarParams(normal_fresnel=20.0).eta)


# -- Smits' cone angles --------------------------------------------------------------------
def test_cone_angles_at_their_ends():
    """Seed: specular 5°..35° over roughness, reflection 0 (epsilon)..10°, times the scales."""
    assert specular_cone(0.0) == 5.0 and specular_cone(1.0) == 35.0
    assert reflection_cone(0.0) == 0.0 and reflection_cone(1.0) == 10.0
    assert specular_cone(1.0, 2.5) == 87.5 and reflection_cone(1.0, 0.0) == 0.0
    r = np.linspace(0.0, 1.0, 5)
    np.testing.assert_array_equal(specular_cone(r), 30.0 * r + 5.0)


def test_powers_are_the_cones_through_cone_power():
    xp = NumpyOps()
    for r in (0.0, 0.3, 1.0):
        assert pl.power_specular(xp, r, 1.5) == pl.cone_power(
            xp, r * pl.LN_10, specular_cone(r, 1.5)
        )
        assert pl.power_reflection(xp, r) == pl.cone_power(xp, pl.LN_10, reflection_cone(r))
    # roughness 0: the reflection cone is 0°, floored where the lobe is evaluated
    assert pl.power_reflection(xp, 0.0) == pl.cone_power(xp, pl.LN_10, pl.CONE_MIN_DEG)


def test_plain_materials_and_blend_layers_carry_the_same_cones():
    from lookdev.pipeline.blend.pixar_composite import layer_lobes

    p = PixarParams(roughness=0.4, specular_cone_scale=1.5, reflection_cone_scale=0.5)
    w = as_lobe_weights(p)
    lobes = layer_lobes(p, 1.0)
    assert w.specular_cone == w.specular_t_cone == lobes["specular"].cone == specular_cone(0.4, 1.5)
    assert w.reflection_cone == lobes["reflection"].cone == reflection_cone(0.4, 0.5)
    # the blend floors a 0° reflection cone (energy-weighted averaging), the material does not
    assert as_lobe_weights(PixarParams(roughness=0.0)).reflection_cone == 0.0
    assert layer_lobes(PixarParams(roughness=0.0), 1.0)["reflection"].cone == pl.CONE_MIN_DEG


# -- pydantic errors as one line -------------------------------------------------------------
def _message(fn, *args, **kw):
    with pytest.raises(LookdevError) as info:
        fn(*args, **kw)
    return info.value


def test_parameters_presets_and_layers_format_errors_the_same_way():
    from lookdev.library.preset import check_params, parse_preset

    direct = _message(DisneyParams.parse, {"roughness": 2.0}, where="a.toml")
    checked = _message(check_params, "disney", {"roughness": 2.0}, where="a.toml")
    text = (
        b'name = "a"\nmodel = "layered"\n[[layers]]\nmodel = "disney"\nparams = {roughness = 2.0}\n'
    )
    layered = _message(parse_preset, text, where="a.toml", stem="a")
    assert str(direct) == "a.toml: roughness: 2.0 is out of range; allowed [0, 1]"
    assert str(checked) == "a.toml: params.roughness: 2.0 is out of range; allowed [0, 1]"
    assert str(layered) == "a.toml: layers[0].params.roughness: 2.0 is out of range; allowed [0, 1]"
    assert isinstance(direct, ParameterError) and isinstance(checked, ParameterError)


def test_one_line_edges():
    channel = _message(DisneyParams.parse, {"base_color": [0.1, 0.2, 3.0]})
    assert channel.field == "base_color[2]" and channel.message.endswith("allowed [0, 1]")
    nan = _message(DisneyParams.parse, {"roughness": float("nan")})
    assert nan.message == "nan is not a finite number"
    long = _message(DisneyParams.parse, {"roughness": "x" * 500})
    assert "x" * 60 not in long.message and "...)" in long.message
    unknown = _message(DisneyParams.parse, {"roughnes": 0.5})
    # issue 13: a near miss of a known field is named (difflib) before the allowed list
    assert unknown.message.startswith(
        "unknown field; did you mean 'roughness'? allowed: base_color, subsurface, metallic"
    )
    both = _message(DisneyParams.parse, {"specular": 0.5, "ior": 1.5})
    assert both.field is None and "not both" in both.message


def test_ibl_definitions_use_the_same_formatter(tmp_path, monkeypatch):
    from lookdev.pipeline.proof import ibl

    (tmp_path / "bad.toml").write_text('name = "bad"\n[sun]\nazimuth = 0\nelevation = 120\n')
    monkeypatch.setattr(ibl, "definitions_folder", lambda: tmp_path)
    err = _message(ibl.resolve, "bad")
    assert isinstance(err, ibl.IblError)
    assert str(err) == f"{tmp_path / 'bad.toml'}: sun.elevation: 120 is out of range; allowed ≤ 90"
