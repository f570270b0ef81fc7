"""``lookdev bench usd`` runs both paths on identical networks and reports the ratio."""

from __future__ import annotations

import json

import pytest

pytest.importorskip("pxr")


def test_bench_usd_json_reports_both_paths_on_the_same_networks(cli):
    result = cli("bench", "usd", "--materials", "20", "--repeat", "1", "--json")
    assert result.code == 0, result.err
    data = json.loads(result.out)
    assert data["materials"] == 20 and data["contexts"] == 3
    assert data["same_layers"] is True  # the naive reference authors exactly our networks
    assert data["fast_s"] > 0 and data["naive_s"] > 0
    ratio = (
        data["naive_materials_per_s"]
        and data["fast_materials_per_s"] / data["naive_materials_per_s"]
    )
    assert data["ratio_fast_to_naive"] == pytest.approx(ratio)


def test_bench_usd_table_for_people(cli):
    result = cli("bench", "usd", "-n", "5", "--repeat", "1")
    assert result.code == 0, result.err
    assert "ratio_fast_to_naive" in result.out and "materials" in result.out
