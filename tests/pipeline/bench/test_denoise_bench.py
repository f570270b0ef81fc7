"""``lookdev bench error --item denoise``: equal-time curves of raw and denoised frames."""

from __future__ import annotations

import json

import pytest

from lookdev.pipeline.bench import denoise as D


def _raw(k, a=0.1, b=0.05, ladder=(4, 8, 16, 32, 64)):
    return [{"spp": s, "rel_mse": k / s, "seconds": a + b * s} for s in ladder]


def test_equal_time_reads_the_raw_fit_at_the_denoised_points_time():
    raw = _raw(2.0)
    # Denoised 16 spp costs 16 spp of rendering plus 0.6 s: raw gets 28 spp in that time.
    den = [{"spp": 16, "rel_mse": 0.002, "seconds": 0.1 + 0.05 * 16 + 0.6}]
    s = D.summarise(raw, den, 4096)
    p = s["points"][0]
    assert s["K"] == pytest.approx(2.0) and s["raw_log_slope"] == pytest.approx(-1.0)
    assert s["time_per_spp_s"] == pytest.approx(0.05) and s["time_fixed_s"] == pytest.approx(0.1)
    assert p["raw_spp_same_time"] == pytest.approx(28.0)
    assert p["raw_rel_mse_same_time"] == pytest.approx(2.0 / 28)
    assert p["ratio"] == pytest.approx(0.002 * 28 / 2.0)
    assert p["claim_met"] and s["claim_met"]
    assert p["raw_spp_to_match"] == pytest.approx(1000.0) and p["extrapolated"]


def test_process_time_and_equal_spp_ratios_sit_beside_the_wall_time_one():
    # Wall time doubled by a loaded machine, process time not: the CPU reading gives the
    # denoised 16-spp point (16 spp of rendering plus 0.3 CPU-s) 16 + 0.3/0.01 = 46 spp.
    raw = [p | {"cpu_s": 0.01 * p["spp"]} for p in _raw(2.0, a=0.0, b=0.1)]
    den = [{"spp": 16, "rel_mse": 0.004, "seconds": 0.1 * 16 + 0.5, "cpu_s": 0.16 + 0.3}]
    s = D.summarise(raw, den, 4096)
    p = s["points"][0]
    assert s["cpu_per_spp_s"] == pytest.approx(0.01) and s["cpu_fixed_s"] == pytest.approx(0.0)
    assert p["raw_spp_same_time"] == pytest.approx(21.0)
    assert p["raw_spp_same_cpu"] == pytest.approx(46.0)
    assert p["ratio_cpu"] == pytest.approx(0.004 * 46 / 2.0)
    assert p["ratio_same_spp"] == pytest.approx(0.004 / (2.0 / 16))
    assert s["claim_met_cpu"] is True
    # Points without process time (older JSON) get the wall-time reading alone.
    assert "ratio_cpu" not in D.summarise(_raw(2.0), den, 4096)["points"][0]


def test_a_denoised_point_worse_than_a_tenth_fails_the_claim():
    den = [{"spp": 4, "rel_mse": 0.05, "seconds": 0.1 + 0.05 * 8}]
    s = D.summarise(_raw(2.0), den, 4096)
    assert s["points"][0]["ratio"] == pytest.approx(0.05 / (2.0 / 8))
    assert not s["points"][0]["claim_met"] and not s["claim_met"]
    assert s["points"][0]["raw_spp_to_match"] == pytest.approx(40.0)
    assert not s["points"][0]["extrapolated"]  # 40 spp lies inside the 4..64 ladder


def test_the_table_has_a_row_per_denoised_point_and_marks_extrapolation():
    raw = _raw(2.0)
    den = [
        {"spp": s, "rel_mse": 0.01 / s, "seconds": 1.0 + 0.05 * s, "render_s": 0.05 * s}
        for s in (4, 16)
    ]
    case = D.Case("plastic_glossy", "sky", raw, den, 4096, 1e-4, D.summarise(raw, den, 4096))
    rows = D.equal_time_rows([case])
    assert len(rows) == 2 and len(rows[0]) == len(D.EQUAL_TIME_COLUMNS)
    assert rows[0][0] == "plastic_glossy × sky" and rows[1][-1].endswith("†")
    assert {r.method for r in case.rows()} == {"raw", "denoised"}
    json.dumps(case.as_json())  # plain JSON: no numpy scalars


@pytest.mark.slow
@pytest.mark.render
def test_cli_json_carries_the_equal_time_table(cli, tmp_path):
    res = cli("bench", "error", "--quick", "--item", "denoise", "--denoise-case",
              "plastic_glossy:sky", "--resolution", "24", "12", "--guide-spp", "2",
              "-o", str(tmp_path), "--json")  # fmt: skip
    assert res.code == 0, res.err
    data = json.loads(res.out)
    (case,) = data["denoise"]
    assert case["preset"] == "plastic_glossy" and case["ibl"] == "sky"
    assert [p["spp"] for p in case["raw"]] == [2, 4, 8]
    assert [p["spp"] for p in case["denoised"]] == [2, 4]
    for p in case["denoised"]:
        assert p["seconds"] == pytest.approx(p["render_s"] + p["aov_s"] + p["denoise_s"])
        assert p["aov_s"] > 0 and p["denoise_s"] > 0
        assert p["cpu_s"] == pytest.approx(p["render_cpu_s"] + p["aov_cpu_s"] + p["denoise_cpu_s"])
        assert p["guide_spp"] == 2  # min(frame spp, --guide-spp)
    assert case["resolution"] == [24, 12] and case["guide_spp"] == 2 and case["rig"] == "full"
    assert len(case["load_average"]) == 2
    assert {"K", "points", "claim_met", "claim_met_cpu"} <= set(case["summary"])
    assert {"ratio", "ratio_cpu", "ratio_same_spp"} <= set(case["summary"]["points"][0])
    assert {r["item"] for r in data["rows"]} == {"denoise"}
