"""``lookdev bench proof`` runs end to end and reports every ratio (no timed assertions)."""

from __future__ import annotations

import json

import pytest

pytestmark = pytest.mark.render


def test_bench_proof_quick_json_reports_every_measurement(cli, tmp_path, monkeypatch):
    monkeypatch.setenv("LOOKDEV_CACHE", str(tmp_path))
    r = cli("bench", "proof", "--quick", "--repeat", "1", "--preset", "gold", "--json")
    assert r.code == 0, r.err
    doc = json.loads(r.out)
    t, p = doc["turntable"], doc["pruning"]
    for key in ("pipeline_s", "bare_render_s", "naive_rebuild_s"):
        assert t[key] > 0
    assert t["speedup_vs_naive"] == pytest.approx(t["naive_rebuild_s"] / t["pipeline_s"])
    assert t["overhead_vs_bare"] == pytest.approx(t["pipeline_s"] / t["bare_render_s"] - 1)
    assert p["all_lobes_s"] > 0 and p["pruned_noise_relative"] > 0
    assert doc["settings"]["frames"] == 4


def test_interleaved_keeps_each_cases_fastest_round():
    from lookdev.pipeline.analysis.bench_proof import interleaved

    times = iter([9.0, 5.0, 3.0, 4.0, 2.0, 6.0])  # warm-up a, b; then a, b; a, b
    calls = []

    def case(name):
        def fn():
            calls.append(name)
            return next(times)

        return fn

    best = interleaved({"a": case("a"), "b": case("b")}, repeat=2)
    assert calls == ["a", "b", "a", "b", "a", "b"]
    assert best == {"a": 2.0, "b": 4.0}
