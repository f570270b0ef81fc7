"""Rendering to a noise target: the estimator, the pass loop's stops, fireflies, the options.

The pass loop runs against a fake turntable whose images are a known picture plus seeded
Gaussian noise, so every stop is deterministic: no timing is asserted (a fake clock
drives the time budget) and the true error of every image is known.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from lookdev.materials.colour import luminance
from lookdev.pipeline.proof import passes, settings, shaderball
from lookdev.pipeline.proof.turntable import Frame

FRAME = Frame(3, "light", 90.0)
TRUTH = np.full((24, 48, 3), 0.5, np.float32)
TRUTH[:, 24:] = 2.0  # two halves of different brightness: the mean is 1.25


class FakeTable:
    """Stands in for a Turntable: ``render_halves(n)`` gives two images with per-pixel
    noise of standard deviation ``sigma / √n`` (what n samples of one pixel give)."""

    def __init__(self, sigma: float = 1.0, hot: float = 0.0):
        self.sigma, self.hot = sigma, hot
        self.calls: list[tuple[int, int]] = []
        self.posed = None

    def set_frame(self, frame):
        self.posed = frame

    def render_halves(self, spp, seed):
        self.calls.append((spp, seed))
        rng = np.random.default_rng(seed)
        a, b = (
            TRUTH + rng.normal(0.0, self.sigma / math.sqrt(spp), TRUTH.shape).astype(np.float32)
            for _ in range(2)
        )
        if self.hot:  # one firefly per pass, in A
            a[seed % 24, 7] += self.hot / spp
        return a, b


def _true_relative_error(image):
    err = luminance(image.astype(np.float64) - TRUTH)
    return math.sqrt(float(np.mean(err**2))) / float(np.mean(luminance(TRUTH)))


# -- the estimator -------------------------------------------------------------------------
def test_the_estimate_is_the_noise_of_the_combined_image_not_of_a_half():
    """Var((A + B)/2) = E[(A − B)²]/4; a half alone has √2 times the combined noise."""
    rng = np.random.default_rng(1)
    a, b = (TRUTH + rng.normal(0, 0.1, TRUTH.shape) for _ in range(2))
    e = passes.estimate(a, b)
    true = _true_relative_error(0.5 * (a + b))
    assert e.relative == pytest.approx(true, rel=0.05)
    assert e.relative == pytest.approx(_true_relative_error(a) / math.sqrt(2), rel=0.05)


def test_accumulated_passes_estimate_what_they_add_up_to():
    table = FakeTable(sigma=1.0)
    r = passes.render_frame(table, FRAME, noise=1e-6, max_spp=64, pass_spp=8)
    assert r.passes == 8 and r.spp == 64
    assert r.noise == pytest.approx(_true_relative_error(r.image), rel=0.1)
    one = passes.render_frame(FakeTable(sigma=1.0), FRAME, spp=8)
    assert r.noise == pytest.approx(one.noise / math.sqrt(8), rel=0.1)  # 1/√spp


def test_a_black_frame_has_no_relative_noise_and_needs_no_more_passes():
    e = passes.estimate(np.zeros((4, 4, 3)), np.zeros((4, 4, 3)))
    assert (e.rmse, e.relative, e.firefly_share) == (0.0, None, None)


def test_firefly_share_is_small_for_grain_and_near_one_for_a_hot_pixel():
    grain = np.random.default_rng(2).normal(0, 1, 100_000) ** 2
    assert 0.005 < passes.firefly_share(grain) < 0.03  # χ²₁ tail beyond its 99.9th percentile
    hot = np.ones(10_000)
    hot[123] = 1e6
    assert passes.firefly_share(hot) == pytest.approx((1e6 + 9) / (1e6 + 9_999))  # top 10
    assert passes.firefly_share(np.zeros(10)) is None
    assert passes.firefly_share(np.array([0.0, 2.0])) == 1.0  # at least one pixel counts


def test_a_frame_with_a_firefly_reports_it():
    r = passes.render_frame(FakeTable(sigma=0.05, hot=400.0), FRAME, spp=8)
    assert r.firefly_share > 0.5
    calm = passes.render_frame(FakeTable(sigma=0.05), FRAME, spp=8)
    assert calm.firefly_share < 0.05


# -- the pass loop -------------------------------------------------------------------------
def test_passes_stop_at_the_target_with_new_seeds_and_one_pass_size():
    table = FakeTable(sigma=1.0)
    first = passes.estimate(*table.render_halves(4, seed=passes.seed_for(FRAME, 0))).relative
    table.calls.clear()
    target = first / 3.0  # needs ≈ 9 passes of 8: 1/√9
    r = passes.render_frame(table, FRAME, noise=target, max_spp=1024, pass_spp=8)
    assert r.stop == "target" and r.noise <= target
    assert 6 <= r.passes <= 14 and r.spp == 8 * r.passes
    assert {spp for spp, _ in table.calls} == {4}  # one size: one frozen recording
    seeds = [seed for _, seed in table.calls]
    assert len(set(seeds)) == len(seeds) and table.posed == FRAME


def test_passes_stop_at_max_spp_shortening_the_last_pass():
    table = FakeTable(sigma=1.0)
    r = passes.render_frame(table, FRAME, noise=1e-6, max_spp=20, pass_spp=8)
    assert (r.stop, r.spp, r.passes) == ("max_spp", 20, 3)
    assert [spp for spp, _ in table.calls] == [4, 4, 2]
    assert r.noise > 1e-6


def test_passes_stop_before_a_pass_would_overrun_the_time_budget():
    ticks = iter(range(100))  # one second per call of the clock

    def clock():
        return float(next(ticks))

    # Each pass costs one tick, so after pass k the clock says k s; a budget of 3.5 s
    # allows a pass that would end at 3 s but not one that would end at 4 s.
    r = passes.render_frame(
        FakeTable(), FRAME, noise=1e-6, max_spp=1024, time_budget=3.5, clock=clock
    )
    assert (r.stop, r.passes, r.seconds) == ("time_budget", 3, 3.0)


def test_the_first_pass_always_runs_even_past_the_budget():
    ticks = iter([0.0, 50.0])
    r = passes.render_frame(
        FakeTable(), FRAME, noise=1e-6, time_budget=1.0, clock=lambda: next(ticks)
    )
    assert (r.stop, r.passes) == ("time_budget", 1)


def test_a_fixed_spp_is_one_pass_and_says_so():
    table = FakeTable()
    r = passes.render_frame(table, FRAME, spp=33)  # odd: rounded down to even
    assert (r.stop, r.spp, r.passes) == ("spp", 32, 1) and table.calls[0][0] == 16


def test_spp_and_a_target_are_exclusive():
    with pytest.raises(ValueError, match="exactly one"):
        passes.render_frame(FakeTable(), FRAME, spp=8, noise=0.1)
    with pytest.raises(ValueError, match="exactly one"):
        passes.render_frame(FakeTable(), FRAME)


# -- settings and the scene ----------------------------------------------------------------
def test_settings_default_to_a_noise_target_with_a_cap_and_spp_to_a_fixed_count():
    s = settings.Settings()
    assert (s.spp, s.noise, s.max_spp) == (
        None,
        settings.UNIFORM_NOISE,
        settings.DEFAULT_MAX_SPP,
    )
    assert s.sampling() == {"noise": s.noise, "max_spp": s.max_spp, "time_budget": None}
    assert s.resolution == settings.DEFAULT_RESOLUTION and s.pixel_filter == "box"
    fixed = settings.Settings(spp=16)
    assert (fixed.noise, fixed.max_spp) == (None, None) and fixed.sampling() == {"spp": 16}
    fixed_count = "^spp: spp is a fixed count; noise go with a noise target"
    with pytest.raises(settings.ProofError, match=fixed_count):
        settings.Settings(spp=16, noise=0.1)


@pytest.mark.parametrize(
    ("given", "field"),
    [
        ({"noise": 0.0}, "noise"),
        ({"noise": -0.1}, "noise"),
        ({"noise": float("nan")}, "noise"),
        ({"max_spp": 1}, "max_spp"),
        ({"time_budget": 0.0}, "time_budget"),
        ({"time_budget": float("inf")}, "time_budget"),
        ({"clamp": -1.0}, "clamp"),
        ({"pixel_filter": "tent"}, "pixel_filter"),
    ],
)
def test_bad_settings_are_one_line_errors_naming_the_argument(given, field):
    with pytest.raises(settings.ProofError) as info:
        settings.check(settings.Settings(**given))
    assert str(info.value).startswith(field + ": ") and "\n" not in str(info.value)
    option = "--" + field.replace("_", "-")  # what the CLI, whose options these are, says
    assert info.value.one_line({field: option}).startswith(option + ": ")


def test_the_proof_camera_uses_a_box_filter_unless_asked(tmp_path, monkeypatch):
    monkeypatch.setenv("LOOKDEV_CACHE", str(tmp_path))
    pytest.importorskip("mitsuba")
    from lookdev.pipeline.variant import use_mitsuba

    use_mitsuba()
    env = np.zeros((8, 16, 3), np.float32)
    bsdf = {"type": "diffuse"}
    scene = shaderball.scene_dict(bsdf, env, (16, 8), 3)
    assert scene["sensor"]["film"]["rfilter"] == {"type": "box"}
    assert scene["integrator"] == {"type": "path", "max_depth": 3}
    gauss = shaderball.scene_dict(bsdf, env, (16, 8), 3, pixel_filter="gaussian", clamp=4.0)
    assert gauss["sensor"]["film"]["rfilter"] == {"type": "gaussian"}
    assert gauss["integrator"] == {"type": "lookdev_clamped_path", "max_depth": 3, "clamp": 4.0}
