"""``lookdev bench noise`` runs end to end and reports every measurement (no timed assertions)."""

from __future__ import annotations

import json

import pytest

pytestmark = pytest.mark.render


@pytest.mark.slow
def test_bench_noise_quick_json_reports_filter_traces_and_candidates(cli, tmp_path, monkeypatch):
    monkeypatch.setenv("LOOKDEV_CACHE", str(tmp_path))
    r = cli("bench", "noise", "--quick", "--json")
    assert r.code == 0, r.err
    doc = json.loads(r.out)
    (f,) = doc["filter"]
    assert f["gaussian_over_box_wall"] > 0 and f["gaussian_over_box_cpu"] > 0
    pc = doc["pass_cost"]
    assert (pc["spp"], pc["pass_spp"]) == (8, 4) and pc["passes_over_one_cpu"] > 0
    (row,) = doc["traces"]
    assert [p["spp"] for p in row["trace"]] == [4, 8]  # passes of 4 up to trace_spp
    assert all(p["noise"] > 0 and 0 < p["firefly_share"] <= 1 for p in row["trace"])
    assert row["trace"][1]["noise"] < row["trace"][0]["noise"] * 1.2
    by_cap = {c["max_spp"]: c for c in doc["candidates"]}
    assert set(by_cap) == {4, 8}
    for cap, c in by_cap.items():
        (stop,) = c["frames"]
        assert stop["spp"] <= cap and stop["stop"] in ("target", "max_spp")
        assert c["new_over_old_wall"] > 0 and c["new_over_old_cpu"] > 0
