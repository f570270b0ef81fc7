"""The main job's benches (:mod:`lookdev.pipeline.bench.knobs` and ``.quality``): the
cost projection from timed jobs, the tables, and tiny runs of both measurements."""

from __future__ import annotations

import json

import pytest

from lookdev.pipeline.bench import knobs as K
from lookdev.pipeline.bench import quality as Q


def _frame(render: float, write: float = 0.1, denoise: float = 0.5) -> dict:
    def t(x: float) -> dict:
        return {"wall_s": 2 * x, "cpu_s": x}

    return {"spp": 4, "noise": 1.0, "render": t(render), "write": t(write), "denoise": t(denoise)}


def _job(preset: str, cap: int, setup: float, first: float, steady: float) -> dict:
    frames = [_frame(first), _frame(steady * 1.5)] + [_frame(steady) for _ in range(6)]
    return {"preset": preset, "max_spp": cap, "setup": {"wall_s": 2 * setup, "cpu_s": setup},
            "frames": frames}  # fmt: skip


ROWS = [_job("a", 4, 1.0, 3.0, 0.5), _job("a", 8, 1.0, 4.0, 1.0)]
S = K.CostSettings(presets=("a",), ibls_in_job=4)


def test_a_job_is_its_setup_its_timed_frames_and_steady_frames_beyond_them():
    row = ROWS[1]  # setup 1, first 4 + 0.1, second 1.5 + 0.1, then 1.1 each
    assert K._job_seconds(row, 8, False, "cpu_s") == pytest.approx(1 + 4.1 + 1.6 + 6 * 1.1)
    sixteen = K._job_seconds(row, 16, False, "cpu_s")
    assert sixteen == pytest.approx(1 + 4.1 + 1.6 + 6 * 1.1 + 8 * 1.1)
    assert K._job_seconds(row, 8, True, "cpu_s") == pytest.approx(1 + 4.1 + 1.6 + 6 * 1.1 + 4)
    assert K._job_seconds(row, 2, False, "cpu_s") == pytest.approx(1 + 4.1 + 1.6)


def test_candidates_are_priced_against_today_in_the_same_run():
    out = K.project(ROWS, S)
    assert len(out) == 2 * 2 * 2  # frames × caps × denoise
    today = next(c for c in out if (c["frames"], c["max_spp"], c["denoise"]) == (16, 8, False))
    assert today["over_today_cpu"] == pytest.approx(1.0)
    assert today["over_today_wall"] == pytest.approx(1.0)
    assert today["cpu_s"] == pytest.approx(4 * K._job_seconds(ROWS[1], 16, False, "cpu_s"))
    cheap = next(c for c in out if (c["frames"], c["max_spp"], c["denoise"]) == (8, 4, False))
    assert 0 < cheap["over_today_cpu"] < 0.5
    dearer = next(c for c in out if (c["frames"], c["max_spp"], c["denoise"]) == (8, 4, True))
    assert dearer["cpu_s"] > cheap["cpu_s"]
    rows = K.job_rows(ROWS)
    assert rows[0][:4] == ["a", 4, 1.0, pytest.approx(3.1)]


CASE = {
    "preset": "gold",
    "ibl": "sunset",
    "old": {"resolution": [192, 96], "filter": "gaussian", "spp": 32, "rel_mse": 0.5,
            "render": {"wall_s": 0.2, "cpu_s": 0.3}, "reference_floor": 0.001,
            "reference_spp": 4096, "estimate": 0.9, "measured": 1.0,
            "estimate_over_measured": 0.9, "denoise": False},
    "new": {"resolution": [480, 240], "filter": "box", "spp": 4, "rel_mse": 2.0,
            "denoised_rel_mse": 0.05, "render": {"wall_s": 0.5, "cpu_s": 0.8},
            "denoise_time": {"wall_s": 0.25, "cpu_s": 0.4}, "reference_floor": 0.01,
            "reference_spp": 1024, "estimate": 3.0, "measured": 2.0,
            "estimate_over_measured": 1.5, "denoise": True},
}  # fmt: skip


def test_tables_show_the_frame_as_each_default_shows_it():
    old, new = Q.error_rows([CASE])
    assert (old.method, old.error, old.seconds) == ("old default", 0.5, 0.2)
    assert (new.method, new.error, new.seconds) == ("new default", 0.05, 0.75)
    assert new.setting == "480×240 4 spp box denoised"
    t_old, t_new = Q.table_rows([CASE])
    assert t_old[1:5] == ["old", "192×96, 32 spp, gaussian", "0.2", "0.5"] and t_old[5] == ""
    assert t_new[5] == "0.05" and t_new[-1] == "1.50"


@pytest.mark.slow
def test_a_tiny_error_case_measures_both_defaults_against_references():
    from lookdev.pipeline.proof.settings import DEFAULT_MAX_SPP

    case = Q.error_case("plastic_glossy", "sky", Q.ErrorSettings.quick())
    for which, spp in (("old", 8), ("new", DEFAULT_MAX_SPP)):
        m = case[which]
        assert m["spp"] == spp and m["rel_mse"] > 0 and 0 < m["reference_floor"] < m["rel_mse"]
        assert m["estimate"] > 0 and m["measured"] > 0
    assert case["old"]["filter"] == "gaussian" and case["new"]["filter"] == "box"
    assert case["new"]["stop"] in ("target", "max_spp") and case["new"]["denoise"]
    assert case["new"]["denoised_rel_mse"] < case["new"]["rel_mse"]
    assert case["new_caps"]["8"]["spp"] == 8
    json.dumps(case)


@pytest.mark.slow
def test_the_cost_command_prints_one_json_object(cli):
    res = cli("bench", "mainjob", "--quick", "--json")
    assert res.code == 0, res.err
    data = json.loads(res.out)
    assert {j["max_spp"] for j in data["jobs"]} == {2, 4}
    assert all(len(j["frames"]) == 3 for j in data["jobs"])
    assert {(c["frames"], c["denoise"]) for c in data["candidates"]} >= {(8, True), (16, False)}
