"""The package, its CLI root, the error family, the parameter schema and the array shim."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from lookdev.materials.arrays import NumpyOps, from_channel_first, to_channel_first
from lookdev.materials.colour import decode_hex
from lookdev.materials.errors import LookdevError, ParameterError
from lookdev.materials.params import DisneyParams


def test_version_and_help(cli):
    r = cli("--version")
    assert r.code == 0 and r.out.startswith("lookdev ")
    r = cli("--help")
    assert r.code == 0 and "bench" in r.out


def test_unknown_command_exits_2(cli):
    assert cli("no-such-command").code == 2


def test_errors_are_one_line():
    e = ParameterError("is out of range;\n allowed [0, 1]", where="a.toml", field="roughness")
    assert isinstance(e, LookdevError) and "\n" not in str(e)
    assert str(e) == "a.toml: roughness: is out of range; allowed [0, 1]"


def test_disney_defaults_are_burleys():
    p = DisneyParams()
    assert p.specular == 0.5 and not p.uses_ior
    assert p.effective_ior == pytest.approx(1.5, abs=1e-9)
    assert DisneyParams(ior=1.5).effective_specular == pytest.approx(0.5)


@pytest.mark.parametrize(
    "data, field, allowed",
    [
        ({"roughness": -0.1}, "roughness", "[0, 1]"),
        ({"roughness": math.nan}, "roughness", "finite"),
        ({"metallic": math.inf}, "metallic", "finite"),
        ({"base_color": [0.5, -1, 0.5]}, "base_color[1]", "[0, 1]"),
        ({"specular": 13.0}, "specular", "[0, 12.5]"),
        ({"ior": 0.9}, "ior", "[1, 10]"),
        ({"sheen": -1}, "sheen", "[0, 10]"),  # sheen has a ceiling now (issue 13)
        ({"specular": 0.5, "ior": 1.5}, None, "not both"),
        ({"glossiness": 1}, "glossiness", "unknown field; allowed: base_color, subsurface"),
    ],
)
def test_bad_parameters_name_field_and_range(data, field, allowed):
    with pytest.raises(ParameterError) as info:
        DisneyParams.parse(data, where="p.toml")
    text = str(info.value)
    assert text.startswith("p.toml: ") and allowed in text and "\n" not in text
    if field:
        assert f": {field}: " in text


def test_colours_decode_srgb_once():
    assert DisneyParams(base_color="#ffffff").base_color == (1.0, 1.0, 1.0)
    c = DisneyParams(base_color="#808080").base_color
    assert c == decode_hex("#808080") and c[0] == pytest.approx(0.2158605, abs=1e-6)
    assert DisneyParams(base_color=[0.1, 0.2, 0.3]).base_color == (0.1, 0.2, 0.3)


@given(st.dictionaries(st.sampled_from(list(DisneyParams.model_fields)), st.floats()))
def test_any_float_input_loads_or_fails_in_one_line(data):
    try:
        DisneyParams.parse(data)
    except ParameterError as exc:
        assert "\n" not in str(exc)


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_shim_stable_forms(dtype):
    xp = NumpyOps(dtype)
    tiny = xp.asarray([1e-30, 1e-8, 0.5])
    assert np.allclose(xp.log1p(tiny) / tiny, [1, 1, np.log1p(0.5) / 0.5], rtol=1e-6)
    z = xp.normalize(xp.vec3(tiny * 0, tiny * 0, tiny * 0))
    assert np.all(z == 0) and z.dtype == dtype


def test_channel_first_round_trip():
    v = np.arange(24, dtype=float).reshape(2, 4, 3)
    cf, lead = to_channel_first(v)
    assert cf.shape == (3, 8)
    assert np.array_equal(from_channel_first(cf, lead), v)


def test_drjit_shim_matches_numpy_on_stable_forms():
    from lookdev.pipeline.variant import use_mitsuba

    use_mitsuba()
    from lookdev.materials.arrays import DrJitOps

    dj = DrJitOps.for_mitsuba()
    x = [1e-9, 1e-4, 0.3, 2.0]
    got = np.array(dj.log1p(dj.Float(x)))
    assert np.allclose(got, np.log1p(x), rtol=1e-6)
    got = np.array(dj.expm1(dj.Float(x)))
    assert np.allclose(got, np.expm1(x), rtol=1e-5)


def test_drjit_stable_forms_take_python_floats():
    from lookdev.materials.arrays import DrJitOps
    from lookdev.pipeline.variant import use_mitsuba

    use_mitsuba()
    dj = DrJitOps.for_mitsuba()
    for x in (0.0, 1e-12, 0.5):
        assert dj.log1p(x) == math.log1p(x) and dj.expm1(x) == math.expm1(x)


def test_nested_range_errors_name_the_fields_own_range():
    from lookdev.materials.layers import LayerSpec

    with pytest.raises(LookdevError) as info:
        LayerSpec.parse({"preset": "gold", "mask": {"kind": "constant", "value": -1}})
    assert "-∞" not in str(info.value) and "\n" not in str(info.value)


def test_drjit_known_zero_sees_literal_constants_only():
    import drjit as dr

    from lookdev.materials.arrays import DrJitOps
    from lookdev.pipeline.variant import use_mitsuba

    use_mitsuba()
    dj = DrJitOps.for_mitsuba()
    assert dj.known_zero(0.0) and dj.known_zero(dj.color([0.0, 0.0, 0.0]))
    assert not dj.known_zero(dj.color([0.0, 0.5, 0.0]))
    assert not dj.known_zero(dr.opaque(dj.Float, 0.0))  # force_all_lobes keeps such a lobe
