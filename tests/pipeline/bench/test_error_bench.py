"""``lookdev bench error`` with tiny settings: every item measured, outputs written."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from _lambert import LAMBERT, PHONG

from lookdev.pipeline.bench import error as E
from lookdev.pipeline.bench import measure as M
from lookdev.pipeline.bench import quality as Q

TINY = E.Settings(
    render_ladder=(1, 4, 16),
    render_reference_spp=128,
    render_resolution=12,
    quadrature=(8, 32),
    samples=(64, 1024),
    albedo_reference_nodes=128,
    albedo_reference_samples=4096,
    lambda_nodes=(4, 16),
    lambda_reference_nodes=512,
    precision_pairs=500,
    mainjob=Q.ErrorSettings.quick(),
    adaptive=E.adaptive_bench.AdaptiveSettings.quick(),
    detail=E.detail_bench.DetailSettings.quick(),
)


def test_the_lambda_reference_matches_an_independent_double_integral():
    from lookdev.pipeline.analysis.sheen_fit import lambda_integrated

    integrate = pytest.importorskip("scipy.integrate")
    r, ct = 0.3, 0.5
    st = math.sqrt(1 - ct * ct)

    def integrand(phi, tm):
        d = (2 + 1 / r) * math.sin(tm) ** (1 / r) / (2 * math.pi)  # Conty-Kulla eq. 2
        return max(0.0, st * math.sin(tm) * math.cos(phi) + ct * math.cos(tm)) * d * math.sin(tm)

    area, _ = integrate.dblquad(integrand, 0, math.pi / 2, -math.pi, math.pi, epsabs=1e-11)
    assert lambda_integrated([ct], r, 512)[0] == pytest.approx(area / ct - 1, rel=1e-8)


def test_lambda_rows_converge_and_measure_the_shipped_fit():
    from lookdev.materials import sheen

    rows = M.bench_lambda(sheen.lambda_fit, nodes=(4, 16), reference_nodes=512)
    for r in M.LAMBDA_ROUGHNESS:
        case = [row for row in rows if row.case == f"r = {r:g}"]
        fit, n4, n16 = case
        assert fit.method.startswith("fit") and n4.error > n16.error and n16.error < 1e-6
        assert 0 < fit.error < 0.5  # a fit: close, not exact (Table 1 interpolated in r)
        assert all(row.seconds > 0 for row in case)


def test_albedo_rows_compare_each_estimator_with_the_converged_quadrature():
    rows = M.bench_albedo(
        "phong",
        PHONG,
        PHONG.params_type(exponent=30.0),
        quadrature=(8, 64),
        samples=(64, 4096),
        reference_nodes=256,
    )
    by = {(r.method, r.setting): r for r in rows}
    assert by[("quadrature", "64×64")].error < by[("quadrature", "8×8")].error
    assert by[("monte carlo", "4096 spp")].error < by[("monte carlo", "64 spp")].error
    assert all(r.seconds > 0 and r.evaluations > 0 for r in rows)
    assert rows[0].reference == "quadrature 256×256"  # a smooth lobe: the grid converges
    assert all(r.reference_seconds > 0 and r.speedup > 0 for r in rows)


def test_a_near_delta_lobe_is_measured_against_monte_carlo_not_an_unresolved_grid():
    # exponent 1e5: a lobe ~0.3° wide that a 64×64 grid cannot see
    ref, how, seconds = M.albedo_reference(
        PHONG, PHONG.params_type(exponent=1e5), np.radians([0.0, 40.0]), 64, 4096
    )
    assert how == "monte carlo 4096 spp" and seconds > 0
    np.testing.assert_allclose(ref[:, 0], [1.0, math.cos(math.radians(40))], rtol=1e-3)


def test_float32_against_float64_of_lambert_is_within_float32_precision():
    rows = M.bench_precision("lambert", LAMBERT, LAMBERT.params_type(), n=1000)
    f32 = next(r for r in rows if r.method == "float32")
    assert 0 < f32.error < 1e-6


def test_direction_pairs_cover_the_edges():
    wi, wo = M.direction_pairs(100)
    np.testing.assert_allclose(np.linalg.norm(wi, axis=-1), 1, atol=1e-12)
    assert (wo[:, 2] < 0).any()  # transmission
    assert np.any(np.all(wi == -wo, axis=-1))  # wi = −wo
    assert (np.abs(wi[:, 2]) <= 1.0001e-4).any()  # grazing


@pytest.mark.render
def test_render_error_falls_like_one_over_spp():
    from lookdev.pipeline.variant import use_mitsuba

    use_mitsuba()
    rows = M.bench_render(
        "diffuse",
        {"type": "diffuse"},
        np.ones((16, 32, 3)),
        ladder=(1, 16),
        reference_spp=512,
        resolution=16,
    )
    e1, e16 = (r.error for r in rows)
    assert 6 < e1 / e16 < 40  # 16× the samples: relMSE ÷ ~16 (Monte Carlo variance)


@pytest.mark.slow
def test_run_measures_every_item_and_writes_outputs(tmp_path):
    from lookdev.pipeline.variant import use_mitsuba

    use_mitsuba()
    report = E.run(
        TINY,
        environment=np.ones((16, 32, 3)),
        render=[("diffuse", {"type": "diffuse"}, 2)],
        models={"lambert": LAMBERT, "phong": PHONG},
    )
    assert {r.item for r in report.rows} == set(E.ITEMS)
    paths = E.write_outputs(report, TINY, tmp_path)
    data = json.loads(paths["json"].read_text())
    assert len(data["rows"]) == len(report.rows)
    assert data["settings"]["render_ladder"] == [1, 4, 16]
    assert paths["plot"].read_bytes()[:4] == b"\x89PNG"


def test_cli_prints_one_json_object(cli, tmp_path, monkeypatch):
    # The command's own work (options, JSON, files) at the unit tests' TINY settings: the
    # numbers themselves are checked above. (With the real --quick settings this test
    # took 102 s of a loaded machine for what test_lambda_rows_… shows in 1.4 s.)
    monkeypatch.setattr(E.Settings, "quick", classmethod(lambda cls: TINY))
    res = cli("bench", "error", "--quick", "--item", "lambda", "-o", str(tmp_path), "--json")
    assert res.code == 0, res.err
    data = json.loads(res.out)
    assert {r["item"] for r in data["rows"]} == {"lambda"}
    assert (tmp_path / "error_bench.json").exists() and (tmp_path / "error_bench.png").exists()


def test_cli_rejects_an_unknown_item_in_one_line(cli, tmp_path):
    res = cli("bench", "error", "--item", "speed", "-o", str(tmp_path))
    assert res.code == 2
    assert "allowed render, albedo, lambda, precision, denoise, sheen_lambda" in res.err
    assert "Traceback" not in res.err


def test_float32_overflow_where_float64_is_finite_is_an_infinite_error():
    from lookdev.materials.bsdf import Model

    def prepare(xp, params, **maps):
        return {}

    def eval_(xp, prepared, wi, wo):
        v = xp.exp(100.0 * wi[2])  # e^100 ≈ 2.7e43: finite in float64, inf in float32
        return xp.vec3(v, v, v)

    steep = Model("steep", LAMBERT.params_type, prepare, eval_, LAMBERT.pdf, LAMBERT.sample)
    f32 = M.bench_precision("steep", steep, LAMBERT.params_type(), n=200)[1]
    assert f32.error == math.inf and "non-finite" in f32.setting


def test_model_cases_cover_the_roughness_edges_and_every_optional_lobe():
    from lookdev.materials.params import DisneyParams

    disney = type("M", (), {"params_type": DisneyParams})()
    labels = [label for label, _, _ in E.model_cases({"disney": disney})]
    assert labels == [
        "disney default",
        "disney roughness 0",
        "disney roughness 1",
        "disney clearcoat 1",
        "disney sheen 1",
        "disney spec_trans 1",
    ]


def test_a_failing_case_is_reported_and_the_others_still_measured():
    from lookdev.materials.bsdf import Model

    def broken_eval(xp, prepared, wi, wo):
        raise ZeroDivisionError("model bug")

    broken = Model(
        "broken", LAMBERT.params_type, LAMBERT.prepare, broken_eval, LAMBERT.pdf, LAMBERT.sample
    )
    report = E.run(TINY, ("precision",), models={"broken": broken, "lambert": LAMBERT})
    assert report.skipped == {"precision broken default": "failed: ZeroDivisionError: model bug"}
    assert {r.case for r in report.rows} == {"lambert default"}


@pytest.mark.slow
def test_sheen_lambda_rows_show_both_modes_against_the_integral():
    rows = M.bench_sheen_lambda(roughness=(0.01, 0.3), reference_nodes=512)
    by = {(r.case, r.method, r.setting.rsplit(", ", 1)[1]): r for r in rows}
    for backend in {k[2] for k in by}:
        for case in ("r = 0.01", "r = 0.3"):
            table, fit = by[(case, "table", backend)], by[(case, "fit (eq. 3)", backend)]
            assert table.error < 2e-3 < 0.1 < fit.error  # the fit reads r = 0.01 as 0.08
            assert table.seconds > 0 and fit.seconds > 0


@pytest.mark.render
def test_the_detail_item_measures_glass_against_spp_and_the_pebbles_high_pass(tmp_path):
    from lookdev.pipeline.bench import detail

    s = detail.DetailSettings.quick()
    report = E.run(E.Settings(detail=s), items=("detail",))
    assert not report.skipped, report.skipped
    glass, pebble = report.detail["glass"], report.detail["pebble"]
    assert [r["spp"] for r in glass["ladder"]] == list(s.ladder)
    assert all(r[k] > 0 for r in glass["ladder"] for k in ("raw", "oidn", "checked"))
    assert pebble["reference_high_pass"] > 0
    assert all(r[k]["ratio"] > 0 for r in pebble["ladder"] for k in ("raw", "oidn", "checked"))
    paths = E.write_outputs(report, E.Settings(detail=s), tmp_path)
    assert "images" not in json.loads(paths["json"].read_text())["detail"]["pebble"]
    assert paths["glass"].read_bytes()[:4] == paths["pebble"].read_bytes()[:4] == b"\x89PNG"
