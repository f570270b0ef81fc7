"""``lookdev bench proof`` runs end to end and reports every ratio (no timed assertions)."""

from __future__ import annotations

import json

import pytest

pytestmark = pytest.mark.render


@pytest.mark.slow
def test_bench_proof_quick_json_reports_every_measurement(cli, tmp_path, monkeypatch):
    monkeypatch.setenv("LOOKDEV_CACHE", str(tmp_path))
    r = cli("bench", "proof", "--quick", "--repeat", "1", "--preset", "gold", "--json")
    assert r.code == 0, r.err
    doc = json.loads(r.out)
    t, p = doc["turntable"], doc["pruning"]
    for key in ("pipeline", "bare_render", "naive_rebuild"):
        assert t[key]["wall_s"] > 0 and t[key]["cpu_s"] > 0
    for prefix, unit in (("", "wall_s"), ("cpu_", "cpu_s")):
        got = {k: t[k][unit] for k in ("pipeline", "bare_render", "naive_rebuild")}
        speedup = got["naive_rebuild"] / got["pipeline"]
        assert t[f"{prefix}speedup_vs_naive"] == pytest.approx(speedup)
        overhead = got["pipeline"] / got["bare_render"] - 1
        assert t[f"{prefix}overhead_vs_bare"] == pytest.approx(overhead)
    assert p["all_lobes"]["cpu_s"] > 0 and p["pruned"]["noise_relative"] > 0
    assert doc["settings"]["frames"] == 4
    rig = doc["rig"]  # the calibrated rig's cost, measured against none in the same run
    assert rig["full"] == t["pipeline"] and rig["none"]["wall_s"] > 0
    assert rig["cost_full_vs_none"] == pytest.approx(rig["full"]["wall_s"] / rig["none"]["wall_s"])
    # the floor: kernel run time from Dr.Jit's history bounds every speed-up
    assert 0 < t["kernels_s"] and t["bound_vs_naive"] == pytest.approx(
        t["naive_rebuild"]["wall_s"] / t["kernels_s"]
    )
    rows = doc["by_frame_size"]
    assert [r["resolution"] for r in rows] == [[16, 8], [32, 16]]  # the sweep, then the main
    assert [r["samples_per_frame"] for r in rows] == [16 * 8 * 2, 32 * 16 * 4]
    assert rows[-1]["speedup_vs_naive"] == t["speedup_vs_naive"]
    met = [r["samples_per_frame"] for r in rows if r["speedup_vs_naive"] >= 3]
    assert doc["speedup_target_met_up_to_samples_per_frame"] == max(met, default=None)


@pytest.mark.slow
def test_bench_proof_table_names_the_floor_and_the_frame_sizes(cli, tmp_path, monkeypatch):
    monkeypatch.setenv("LOOKDEV_CACHE", str(tmp_path))
    r = cli("bench", "proof", "--quick", "--repeat", "1", "--preset", "gold")
    assert r.code == 0, r.err
    assert "render kernels alone" in r.out and "by frame size" in r.out
    assert "no pipeline can be much more" in r.out and "3× target is met" in r.out
    assert "the calibrated rig" in r.out


def test_interleaved_keeps_each_cases_fastest_round():
    from lookdev.pipeline.bench.proof import Timing, interleaved

    wall = iter([9.0, 5.0, 3.0, 4.0, 2.0, 6.0])  # warm-up a, b; then a, b; a, b
    calls = []

    def case(name):
        def fn():
            calls.append(name)
            return Timing(wall=next(wall), cpu=1.0)

        return fn

    best = interleaved({"a": case("a"), "b": case("b")}, repeat=2)
    assert calls == ["a", "b", "a", "b", "a", "b"]
    assert {k: v.wall for k, v in best.items()} == {"a": 2.0, "b": 4.0}
