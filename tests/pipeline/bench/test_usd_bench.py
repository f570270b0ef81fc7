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
    assert data["rounds"] == 1  # one round: the median is that round's ratio
    ratio = data["naive_s"] / data["fast_s"]
    assert data["ratio_fast_to_naive"] == pytest.approx(ratio)
    assert data["ratio_fast_to_naive_min"] == data["ratio_fast_to_naive_max"]


def test_bench_usd_reports_median_and_spread_of_interleaved_rounds(cli):
    data = json.loads(cli("bench", "usd", "-n", "10", "--repeat", "3", "--json").out)
    assert data["rounds"] == 3
    for key in ("ratio_fast_to_naive", "end_to_end_materials_per_s"):
        assert data[f"{key}_min"] <= data[key] <= data[f"{key}_max"], key
    assert data["end_to_end_materials_per_s"] == pytest.approx(10 / data["end_to_end_s"])


def test_bench_usd_table_for_people(cli):
    result = cli("bench", "usd", "-n", "5", "--repeat", "1")
    assert result.code == 0, result.err
    assert "ratio_fast_to_naive" in result.out and "materials" in result.out


def test_the_floor_creates_exactly_the_specs_the_exporter_authors():
    """The floor is only a bound if it makes the same specs as the fast path, all of them."""
    from pathlib import Path

    from lookdev.pipeline.bench.usd import (
        author_fast,
        author_floor,
        bench_specs,
        per_material,
        spec_paths,
    )

    specs = bench_specs(12)

    def every_path(layer) -> set[str]:
        found: set[str] = set()

        def visit(path) -> None:
            if path.IsPrimPath() or path.IsPrimPropertyPath():  # not connection targets
                found.add(str(path))

        layer.Traverse(layer.pseudoRoot.path, visit)
        return found

    fast = author_fast(specs, Path.cwd())
    floor = author_floor(per_material(*spec_paths(specs)))
    assert every_path(floor) == every_path(fast)
    fast_types = {
        str(p): str(fast.GetAttributeAtPath(p).typeName) for p, _, _ in spec_paths(specs)[1]
    }
    floor_types = {
        str(p): str(floor.GetAttributeAtPath(p).typeName) for p, _, _ in spec_paths(specs)[1]
    }
    assert floor_types == fast_types


def test_bench_usd_reports_the_floor_and_its_bound(cli):
    result = cli("bench", "usd", "--materials", "10", "--repeat", "1", "--json")
    data = json.loads(result.out)
    assert data["floor_empty_specs_s"] > 0
    assert data["ratio_bound"] == pytest.approx(data["naive_s"] / data["floor_empty_specs_s"])
    people = cli("bench", "usd", "-n", "5", "--repeat", "1")
    assert "target ≥ 5×" in people.out and "that floor" in people.out


def test_the_second_floor_writes_the_fast_paths_layer_byte_for_byte():
    """The set floor is only a bound on the writer's calls if it makes the same layer."""
    from pathlib import Path

    from lookdev.pipeline.bench.usd import author_fast, author_recorded, bench_specs, recorded

    layer = author_fast(bench_specs(12), Path.cwd())
    again = author_recorded(recorded(layer))
    assert again.ExportToString() == layer.ExportToString()


def test_bench_usd_reports_cpu_seconds_and_the_naive_path_on_one_thread(cli):
    """The naive path's recompositions use usd-core's worker threads: CPU seconds and the
    one-thread run are reported beside the wall-time ratio, and the limit is put back."""
    from pxr import Work

    before = Work.GetConcurrencyLimit()
    data = json.loads(cli("bench", "usd", "-n", "10", "--repeat", "1", "--json").out)
    assert Work.GetConcurrencyLimit() == before
    cpu = data["naive_cpu_s"] / data["fast_cpu_s"]
    assert data["ratio_fast_to_naive_cpu"] == pytest.approx(cpu)
    one = data["naive_one_thread_s"] / data["fast_s"]
    assert data["ratio_fast_to_naive_one_thread"] == pytest.approx(one)
