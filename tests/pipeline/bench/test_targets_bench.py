"""``lookdev bench targets`` on one tiny proof: every setting runs, and what it reports
is what the proofs' manifests say."""

from __future__ import annotations

import json

import pytest

from lookdev.pipeline.bench import targets


@pytest.fixture(scope="module")
def kept(tmp_path_factory):
    return tmp_path_factory.mktemp("targets")


@pytest.fixture(scope="module")
def report(kept):
    return targets.run(targets.TargetSettings.quick(), kept)


def test_the_uniform_default_and_each_target_are_run(report):
    rows = report["rows"]
    assert [r["target"] for r in rows] == [None, 0.08]
    for r in rows:
        assert r["frames"] == 1 and r["cpu_s"] > 0 and r["wall_s"] > 0
        assert r["met"] + len(r["missed"]) == r["frames"]
        assert sum(r["stops"].values()) == r["frames"]


def test_a_frame_that_misses_its_target_says_where_it_stopped(report):
    uniform = report["rows"][0]
    # 4 samples a pixel never reach 5 % relative noise at 32 x 16: the cap stops it
    assert uniform["stops"] == {"max_spp": 1} and uniform["mean_spp"] == 4
    (frame,) = uniform["missed"]
    assert frame["material"] == "plastic_glossy" and frame["noise"] > 0.05


def test_kept_proofs_are_each_settings_own_batch(report, kept):
    for folder in ("uniform", "target_0.08"):
        assert (kept / folder / "manifest.json").is_file()
    assert not (kept / "targets.png").exists()  # none of the figure's cases was run


def test_the_command_prints_one_json_document(cli):
    r = cli("bench", "targets", "--quick", "--json")
    assert r.code == 0
    doc = json.loads(r.out)
    assert {row["setting"] for row in doc["rows"]} == {"uniform default", "per pixel, target 0.08"}


def test_a_target_out_of_range_is_one_line_before_anything_runs(cli):
    r = cli("bench", "targets", "--target", "0", "--json")
    assert r.code == 2 and "--target: 0 is out of range" in r.err and "Traceback" not in r.err
