"""``lookdev check``: the stability sweep finds what it should and reports it."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from _lambert import LambertParams, LambertPrepared

from lookdev.materials import registry
from lookdev.materials.bsdf import Model
from lookdev.pipeline.analysis import stability, stability_cases


# -- a model broken on purpose, three ways ---------------------------------------------------
def _prepare(xp, params, **maps):
    return LambertPrepared(
        lobes=("diffuse",), rho=xp.color(maps.get("base_color", params.base_color))
    )


def _eval(xp, prepared, wi, wo):
    # 1.2/π: a 20% energy gain; NaN exactly at grazing light (0/0); exp(100(1 − 3 cos θi))
    # overflows float32 (not float64) for lights within about 2° of the horizon.
    upper = (wi[2] >= 0) & (wo[2] > 0)
    grazing_nan = wi[2] / wi[2]
    overflow = xp.exp(100.0 * (1.0 - 3.0 * wi[2])) * 1e-40
    f = 1.2 / math.pi * grazing_nan * (1.0 + overflow)
    return prepared.rho * xp.select(upper, f, 0.0)


def _pdf(xp, prepared, wi, wo):
    return xp.select((wi[2] > 0) & (wo[2] > 0), wi[2] / math.pi, 0.0)


def _sample(xp, prepared, wo, u):
    r, phi = xp.sqrt(u[1]), 2.0 * math.pi * u[2]
    wi = xp.vec3(r * xp.cos(phi), r * xp.sin(phi), xp.safe_sqrt(1.0 - u[1]))
    pdf = _pdf(xp, prepared, wi, wo)
    f = _eval(xp, prepared, wi, wo)
    return wi, f * xp.select(pdf > 0, wi[2] / xp.maximum(pdf, 1e-30), 0.0), pdf, False


MODEL = Model("broken", LambertParams, _prepare, _eval, _pdf, _sample)


@pytest.fixture
def broken_registered(monkeypatch):
    monkeypatch.setitem(registry.MODELS, "broken", MODEL)


# -- the sweep ------------------------------------------------------------------------------
def test_sweep_finds_nan_inf_and_energy_gain_where_they_are():
    report = stability.check_model("broken", MODEL)
    assert report.failed
    assert report.by_dtype["float32"]["nan"] > 0 and report.by_dtype["float64"]["nan"] > 0
    assert report.by_dtype["float32"]["inf"] > 0
    assert report.by_dtype["float64"]["inf"] == 0  # only float32 overflows
    assert report.counts["energy_gain"] > 0
    assert report.worst.kind == "nan"
    assert "wi=(" in report.worst.case and "float" in report.worst.case
    gain = report.failures["energy_gain"]
    assert gain.value == pytest.approx(1.2, abs=0.05)


def test_parameter_cases_cover_every_extreme_and_the_named_combinations():
    from lookdev.materials.pixar import PixarParams

    labels = [label for label, _ in stability_cases.parameter_cases(PixarParams)]
    for expected in ("roughness=0", "roughness=1", "surface_color=black", "clear=1", "ior=10"):
        assert expected in labels
    assert "roughness=0, clear=1, back=1" in labels  # a named combination
    assert not any("metallic=1, roughness" in label for label in labels)  # Disney-only combo


def test_the_sweep_switches_energy_compensation_on_alone_and_in_the_stiff_cases():
    from lookdev.materials.params import DisneyParams

    cases = dict(stability_cases.parameter_cases(DisneyParams))
    assert cases["energy_compensation=True"].energy_compensation
    on = [label for label in cases if label.startswith("energy_compensation=True, ")]
    assert len(on) >= 8  # white metal by roughness, anisotropic, every lobe, glass, γ ≠ 2
    assert all(cases[label].energy_compensation for label in on)


def test_directions_hold_the_stiff_pairs():
    d = stability_cases.directions()
    np.testing.assert_allclose(np.linalg.norm(d, axis=1), 1.0, rtol=1e-12)
    z = set(np.round(d[:, 2], 12))
    assert {1.0, 0.5, 1e-4, 1e-7, 0.0, -0.5} <= z
    as_set = {tuple(v) for v in np.round(d, 12)}
    assert all(tuple(np.round(-v, 12) + 0.0) in as_set for v in d)  # wi = −wo is a pair


def test_plausible_excludes_pushed_parameters():
    from lookdev.materials.params import DisneyParams

    assert stability_cases.plausible(DisneyParams(sheen=1.0, specular=1.0))
    assert not stability_cases.plausible(DisneyParams(sheen=10.0))
    assert stability_cases.plausible(DisneyParams(ior=10.0))  # a range that does not start at 0


# -- the command ----------------------------------------------------------------------------
@pytest.mark.slow
def test_check_json_reports_every_built_model(cli):
    result = cli("check", "--json")
    data = json.loads(result.out)
    assert result.code == 0, data
    assert set(data) == {"models", "seconds"}  # every model is in the registry: none missing
    assert set(data["models"]) == set(registry.MODELS)
    for name, m in data["models"].items():
        assert m["cases"] > 10_000, name
        found = (m["exception"], m["nan"], m["inf"], m["negative"], m["energy_gain"])
        assert found == (0, 0, 0, 0, 0), m["worst"]
        assert m["worst"]["kind"] == "max_albedo"
        assert m["worst"]["value"] <= 1.0 + m["allowance"] + 0.05
    print(f"\nlookdev check --json: {data['seconds']} s")


def test_models_named_come_from_the_registry(broken_registered):
    assert stability_cases.models_named() == registry.MODELS
    assert stability_cases.models_named(["broken"]) == {"broken": MODEL}
    with pytest.raises(stability_cases.CheckError, match="velvet"):
        stability_cases.models_named(["velvet"])


def test_check_prints_a_table_per_model(cli):
    result = cli("check", "--model", "sheen")
    assert result.code == 0
    assert "sheen: ok" in result.out
    for column in ("cases", "NaN", "inf", "negative", "energy gain", "float32", "float64"):
        assert column in result.out
    assert "highest albedo" in result.out


def test_check_exits_1_when_a_model_fails(cli, broken_registered):
    result = cli("check", "--model", "broken", "--json")
    assert result.code == 1
    data = json.loads(result.out)["models"]["broken"]
    assert data["nan"] > 0 and data["energy_gain"] > 0
    assert data["worst"]["kind"] == "nan"
    human = cli("check", "--model", "broken")
    assert human.code == 1 and "FAILED" in human.out and "worst: nan" in human.out


def test_a_model_that_raises_is_reported_not_fatal():
    def explode(xp, prepared, wi, wo):
        raise ZeroDivisionError("boom")

    model = Model("explodes", LambertParams, _prepare, explode, _pdf, _sample)
    report = stability.check_model("explodes", model)
    assert report.failed and report.counts["exception"] > 0
    assert report.worst.kind == "exception" and "ZeroDivisionError: boom" in report.worst.case


def test_unknown_model_is_one_line_and_exit_2(cli):
    result = cli("check", "--model", "velvet")
    assert result.code == 2
    assert result.err.count("\n") == 1
    assert "velvet" in result.err and "disney, sheen, pixar" in result.err
    assert "Traceback" not in result.err


# -- the furnace's azimuths (issue 17, §5) ----------------------------------------------------
def _energy_report(name: str, label: str, dtype=np.float64) -> stability.ModelReport:
    """The furnace part of the sweep for one parameter case of ``name``'s model."""
    model = registry.MODELS[name]
    params = dict(stability_cases.parameter_cases(model.params_type))[label]
    report = stability.ModelReport(name, stability_cases.allowance(name))
    report.by_dtype[np.dtype(dtype).name] = dict.fromkeys(stability.KINDS, 0)
    report.cases_by_dtype[np.dtype(dtype).name] = 0
    with np.errstate(all="ignore"):
        stability._sweep_energy(report, model, label, params, dtype)
    return report


def test_furnace_views_are_tangent_diagonal_and_bitangent():
    assert set(stability.FURNACE_PHI_DEG) >= {0.0, 45.0, 90.0}
    from lookdev.pipeline.analysis.albedo import view_direction

    t = np.radians([0.0, 45.0, 89.99])
    np.testing.assert_array_equal(view_direction(t)[:, 1], 0.0)  # φ = 0: the x-z plane
    bitangent = view_direction(t, phi=math.pi / 2)
    np.testing.assert_allclose(bitangent[:, 0], 0.0, atol=1e-16)
    np.testing.assert_allclose(np.linalg.norm(bitangent, axis=-1), 1.0, rtol=1e-15)
    assert view_direction(t, np.float32, phi=math.pi / 4).dtype == np.float32


def test_white_satin_along_the_bitangent_is_swept_and_reported():
    # The satin preset's lobes, white: 1.41 along the bitangent (the 1.40), 1.11 at
    # most along the tangent (its 1.08 is θo = 89°). Only the φo = 90° view shows it.
    label = "specular=0.6, roughness=0.35, anisotropic=0.85, sheen=0.5, sheen_tint=0.3"
    report = _energy_report("disney", label)
    by_phi = report.max_albedo_by_azimuth
    assert set(by_phi) == set(stability.FURNACE_PHI_DEG)
    assert by_phi[90.0].value == pytest.approx(1.40, abs=0.07)  # 2048 samples: σ ≈ 0.034
    assert by_phi[0.0].value < 1.2
    assert report.max_albedo is by_phi[90.0] or report.max_albedo.value == by_phi[90.0].value
    assert "φo = 90°" in report.max_albedo.case and label in report.max_albedo.case
    assert report.counts["energy_gain"] == 0
    json_by_phi = report.to_json()["max_albedo_by_azimuth"]
    assert json_by_phi["90"]["value"] == by_phi[90.0].value


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_the_largest_disney_albedo_is_within_its_documented_allowance(dtype):
    # Every lobe on, anisotropic 1: 1.783 ± 0.0014 along the bitangent at θo = 89.9999°
    # (stability_cases' docstring), above the former 0.77 allowance; 0.79 is that measure.
    label = "roughness=1, sheen=1, clearcoat=1, clearcoat_gloss=0, specular=1, anisotropic=1"
    report = _energy_report("disney", label, dtype)
    assert stability_cases.allowance("disney") == 0.79
    assert report.counts["energy_gain"] == 0
    top = report.max_albedo
    assert "φo = 90°" in top.case
    assert 1.0 + stability_cases.allowance("disney") - 0.08 < top.value < 1.79
    assert report.max_albedo_by_azimuth[0.0].value < top.value


def _interior_cases():
    from lookdev.materials.params import DisneyParams

    return [(l, p) for l, p in stability_cases.parameter_cases(DisneyParams) if "scatter" in l]


def _empty_report(dtype: str) -> stability.ModelReport:
    report = stability.ModelReport("disney", 0.79)
    report.by_dtype[dtype] = dict.fromkeys(stability.KINDS, 0)
    report.cases_by_dtype[dtype] = 0
    return report


def test_the_interior_extremes_are_swept_with_uneven_scales():
    labels = [label for label, _ in _interior_cases()]
    assert "scatter_distance=1e-06" in labels and "scatter_distance=1e+06" in labels
    uneven = [label for label in labels if "scatter_distance_scale=(" in label]
    assert any("1e-12" in label for label in uneven)  # 1e6 m × 1e-12: the floor, 1e-6 m
    assert any("1e-06, 1, 1" in label for label in uneven)


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_every_interior_case_gives_a_finite_medium(dtype):
    report = _empty_report(np.dtype(dtype).name)
    for label, params in _interior_cases():
        stability._sweep_medium(report, label, params, dtype)
    # three quantities at two units for every case with an interior (all but the three
    # of scatter_distance 0)
    assert report.cases == 6 * (len(_interior_cases()) - 3)
    assert not report.failed, report.failures


def test_a_broken_interior_is_a_finding(monkeypatch):
    import lookdev.materials.subsurface as subsurface
    from lookdev.materials.params import DisneyParams

    def overflowing(params, unit=1.0):
        return np.array([1e39, 1.0, 1.0]), np.array([0.5, 1.2, 0.5])

    monkeypatch.setattr(subsurface, "interior", overflowing)
    report = _empty_report("float32")
    stability._sweep_medium(report, "x", DisneyParams(scatter_distance=0.01), np.float32)
    assert report.counts["inf"] > 0 and report.counts["energy_gain"] > 0
