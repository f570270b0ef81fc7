"""Fitting presets to measurements: recovery, reproducibility, the command."""

from __future__ import annotations

import json

import numpy as np
import pytest

from lookdev.library.measured import MERL_SHAPE, builtin_measured, read_merl, tabulate, write_merl
from lookdev.materials import disney
from lookdev.materials.bsdf import evaluate
from lookdev.materials.measured import MeasuredTable
from lookdev.materials.params import DisneyParams
from lookdev.materials.registry import dead_parameters, live_lobes
from lookdev.pipeline.analysis.fit import FitError, fit, measured_samples

pytestmark = pytest.mark.slow


@pytest.mark.parametrize("seed", [5, 8])
def test_a_fit_to_a_merl_file_of_a_disney_preset_recovers_its_parameters(tmp_path, seed):
    rng = np.random.default_rng(seed)
    truth = DisneyParams(
        base_color=tuple(rng.uniform(0.05, 0.9, 3)),
        metallic=float(rng.choice([0.0, 1.0])),
        roughness=float(rng.uniform(0.2, 0.8)),
        specular=float(rng.uniform(0.2, 0.8)),
    )
    values = tabulate(lambda a, b: evaluate(disney.MODEL, truth, a, b), "merl", MERL_SHAPE)
    table = read_merl(write_merl(tmp_path / "truth.binary", values))
    result = fit(table, "disney", starts=2, seed=1)
    assert result.error < 1e-4
    dead = set(dead_parameters(disney.MODEL, live_lobes(disney.MODEL, truth)))
    if truth.metallic == 1.0:
        dead.add("specular")  # a metal's F0 is its base colour (Burley 2012 §5.3)
    for name in ("base_color", "metallic", "roughness", "specular"):
        if name not in dead:  # nothing can recover a parameter without effect
            np.testing.assert_allclose(
                getattr(result.params, name), getattr(truth, name), atol=2e-3
            )


def test_the_same_seed_gives_the_same_fit():
    table = MeasuredTable("mbsdf", np.full((6, 6, 8, 3), 0.2 / np.pi, dtype=np.float32))
    a = fit(table, "disney", starts=2, seed=3, samples=500)
    b = fit(table, "disney", starts=2, seed=3, samples=500)
    assert a.params == b.params and a.error == b.error


def test_a_fixed_parameter_is_held_and_an_unknown_one_refused():
    table = MeasuredTable("mbsdf", np.full((6, 6, 8, 3), 0.2 / np.pi, dtype=np.float32))
    assert (
        fit(table, "disney", fixed={"metallic": 0.5}, starts=1, samples=300).params.metallic == 0.5
    )
    with pytest.raises(FitError, match="did you mean 'metallic'"):
        fit(table, "disney", fixed={"metalic": 0.0})


def test_extrapolated_mbsdf_rows_are_not_measured_samples():
    from lookdev.library.measured import read_mbsdf

    table = read_mbsdf(next(p for p in builtin_measured() if p.suffix == ".mbsdf"))
    wi, wo, f = measured_samples(table)
    theta_i = np.degrees(np.arccos(wi[:, 2]))
    assert theta_i.max() < 70  # rows past θi ≈ 66° repeat the one before
    assert len(f) > 50_000 and np.all(f >= 0)


def test_lookdev_fit_writes_a_preset_naming_the_measurement_and_its_error(
    tmp_path, monkeypatch, cli
):
    monkeypatch.chdir(tmp_path)
    out = cli(
        "fit",
        "carpaint_red.mbsdf",
        "--starts",
        "1",
        "--fix",
        "metallic=0",
        "-o",
        "sub/red_fit.toml",
        "--json",
    )
    assert out.code == 0, out.err
    summary = json.loads(out.out)
    assert set(summary["bands"]) == {"normal", "45°", "grazing"}
    shown = cli("presets", "show", str(tmp_path / "sub/red_fit.toml"))
    assert shown.code == 0, shown.err
    text = (tmp_path / "sub/red_fit.toml").read_text()
    assert "carpaint_red.mbsdf" in text and f"{summary['error']:.4f}" in text
    assert "metallic = 0.0" in text


@pytest.mark.parametrize(
    "args, message",
    [
        (["nothing.mbsdf", "-o", "x.toml"], "nor a shipped measurement"),
        (["carpaint_red.mbsdf", "-o", "x.toml", "--fix", "metallic"], "KEY=VALUE"),
        (["carpaint_red.mbsdf", "-o", "x.toml", "--model", "sheen"], "no fit for model"),
    ],
)
def test_bad_fit_input_is_one_line_and_exit_2(tmp_path, monkeypatch, cli, args, message):
    monkeypatch.chdir(tmp_path)
    out = cli("fit", *args)
    assert out.code == 2 and message in out.err, out.err
    assert len(out.err.strip().splitlines()) == 1
    assert not (tmp_path / "x.toml").exists()


@pytest.mark.parametrize("view", ["polar", "albedo"])
def test_a_measurement_and_a_preset_overlay_on_one_axes(tmp_path, monkeypatch, cli, view):
    from PIL import Image

    monkeypatch.chdir(tmp_path)
    out = cli(
        "plot",
        "carpaint_red.mbsdf",
        "car_paint_red",
        "--view",
        view,
        "--overlay",
        "-o",
        "o.png",
        "--json",
    )
    assert out.code == 0, out.err
    assert json.loads(out.out)["materials"] == ["carpaint_red.mbsdf", "car_paint_red"]
    width, height = Image.open(tmp_path / "o.png").size
    assert width < 1.5 * height  # one axes, not two columns side by side
