"""The parts of ``lookdev bench dcc`` that need no renderer: the IBL resampled to
Blender's lat-long, the ball's pixels, and the comparison."""

from __future__ import annotations

import math

import numpy as np
import pytest

from lookdev.materials.colour import luminance
from lookdev.pipeline.bench import dcc
from lookdev.pipeline.proof import ibl


@pytest.mark.parametrize(("azimuth", "elevation"), [(0.0, 10.0), (90.0, 30.0), (200.0, -20.0)])
def test_a_light_stays_in_its_direction_in_blenders_convention(azimuth, elevation):
    width = 128
    d, _ = ibl.directions(width)
    target = ibl.direction(azimuth, elevation)
    env = np.exp(200.0 * (d @ target - 1.0))[..., None].repeat(3, -1).astype(np.float32)
    out = dcc.blender_environment(env)
    j, i = np.unravel_index(np.argmax(out[..., 0]), out.shape[:2])
    h, w = out.shape[:2]
    u, theta = (i + 0.5) / w, math.pi * (j + 0.5) / h
    phi = math.pi * (1.0 - 2.0 * u)  # Blender: azimuth atan2(y, x), z up
    blender = np.array([math.cos(phi) * math.sin(theta), math.sin(phi) * math.sin(theta)])
    blender = np.append(blender, math.cos(theta))
    back = dcc.Y_UP_TO_Z_UP.T @ blender
    assert math.degrees(math.acos(min(1.0, float(back @ target)))) < 4.0


def test_a_constant_environment_stays_constant():
    env = np.full((16, 32, 3), 0.25, np.float32)
    assert np.allclose(dcc.blender_environment(env), 0.25)


def test_the_ball_mask_covers_the_left_ball_only():
    mask = dcc.ball_mask((200, 100))
    rows, cols = np.nonzero(mask)
    assert 500 < mask.sum() < 5000
    assert cols.max() < 100  # the ball stands left of the cup
    assert not mask[0].any() and not mask[-1].any()


def test_compare_reads_a_uniform_gain_as_that_gain_and_noise_as_noise():
    rng = np.random.default_rng(3)
    base = rng.uniform(0.2, 0.8, (20, 30, 3)).astype(np.float32)
    mask = np.zeros((20, 30), bool)
    mask[5:15, 5:25] = True
    renders = {"universal": base, "proof_a": base, "proof_b": base}
    renders |= {"cycles_a": 1.1 * base, "cycles_b": 1.1 * base}
    _, mean_diff, pixel, noise = dcc.compare(renders, mask)
    assert mean_diff["cycles-universal"] == pytest.approx(0.1, rel=1e-5)
    assert set(noise.values()) == {0.0}
    lum = np.asarray(luminance(base[mask]))
    rms = 0.1 * np.sqrt(np.mean(lum**2)) / lum.mean()  # relative to the mean luminance
    assert pixel["cycles-proof"] == pytest.approx(rms, rel=1e-4)
