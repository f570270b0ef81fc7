"""The measured model and its file formats: conventions checked, not assumed."""

from __future__ import annotations

import math
import struct

import numpy as np
import pytest

from lookdev.library.measured import (
    MERL_SHAPE,
    MeasuredFileError,
    builtin_measured,
    read_mbsdf,
    read_measured,
    read_merl,
    tabulate,
    write_mbsdf,
    write_merl,
)
from lookdev.materials import disney
from lookdev.materials.bsdf import density, draw, evaluate
from lookdev.materials.measured import MODEL, MeasuredParams, MeasuredTable
from lookdev.materials.params import DisneyParams

CARPAINT = next(p for p in builtin_measured() if p.name == "carpaint_red.mbsdf")


def _hemisphere(n: int, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    z, phi = rng.random(n), 2 * np.pi * rng.random(n)
    r = np.sqrt(1 - z * z)
    return np.stack([r * np.cos(phi), r * np.sin(phi), z], -1)


def _albedo_by_theta(table: MeasuredTable) -> np.ndarray:
    """∫ f cos θo dωo per θi sample of an MBSDF table, by the trapezoid rule on its grid."""
    n_t, _, n_p = table.shape
    theta = np.linspace(0, np.pi / 2, n_t)
    w_t = np.full(n_t, np.pi / 2 / (n_t - 1))
    w_t[[0, -1]] /= 2
    w_p = np.full(n_p, np.pi / (n_p - 1))
    w_p[[0, -1]] /= 2
    f = np.maximum(table.values.astype(np.float64), 0)
    # both halves of the azimuth circle: φ and −φ are one sample of an isotropic BRDF
    return 2 * np.einsum("ijkc,j,k->ic", f, np.cos(theta) * np.sin(theta) * w_t, w_p)


# -- MBSDF ---------------------------------------------------------------------------------------
def test_the_shipped_car_paint_reads_as_the_mdl_specification_lays_it_out():
    table = read_mbsdf(CARPAINT)
    assert table.grid == "mbsdf" and table.shape == (45, 45, 90)
    # its size is the header, the block identifier, three uint32 and 45·45·90·3 floats
    assert CARPAINT.stat().st_size == 20 + 23 + 12 + 4 * 45 * 45 * 90 * 3
    assert table.negative > 0  # measurement noise below zero, clamped when evaluated


def test_the_car_paint_read_as_f_reflects_at_most_what_it_receives():
    albedo = _albedo_by_theta(read_mbsdf(CARPAINT))
    assert albedo.max() <= 1.0
    # read as f·cos instead, it would be divided by cos θo: near grazing it would blow up
    assert 0.05 < albedo.max() < 0.5


def test_the_car_paint_peaks_in_the_mirror_direction_at_phi_pi():
    """The third index is the azimuth between the two directions, π being the mirror."""
    values = read_mbsdf(CARPAINT).values.sum(-1)
    for ti in (5, 10, 20, 30):
        i_o, i_p = np.unravel_index(values[ti].argmax(), values[ti].shape)
        assert i_p >= values.shape[2] - 2  # within a step (2°) of φ = π
        assert abs(int(i_o) - ti) <= 1


def test_mbsdf_written_and_read_back_is_the_same_table(tmp_path):
    values = np.random.default_rng(3).random((6, 6, 9, 3)).astype(np.float32)
    path = write_mbsdf(tmp_path / "t.mbsdf", values, meta={"name": "noise"})
    assert np.array_equal(read_mbsdf(path).values, values)


@pytest.mark.parametrize(
    "data, message",
    [
        (b"hello", "not an MBSDF file"),
        (
            b"NVIDIA ARC MBSDF V1\nMBSDF_DATA_REFLECTION=\n" + struct.pack("<III", 1, 4, 4),
            "truncated",
        ),
        (b"NVIDIA ARC MBSDF V1\nMBSDF_DATA_REFLECTION=\n" + struct.pack("<III", 7, 4, 4), "type 7"),
        (b'NVIDIA ARC MBSDF V1\nname="x"\n', "no reflection"),
    ],
)
def test_a_bad_mbsdf_is_one_line_naming_the_file(tmp_path, data, message):
    path = tmp_path / "bad.mbsdf"
    path.write_bytes(data)
    with pytest.raises(MeasuredFileError) as err:
        read_measured(path)
    assert message in str(err.value) and str(path) in str(err.value)
    assert "\n" not in str(err.value)


def test_a_nan_in_a_measurement_is_refused(tmp_path):
    values = np.zeros((3, 3, 4, 3), dtype=np.float32)
    values[1, 1, 1, 0] = np.nan
    with pytest.raises(MeasuredFileError, match="1 values are NaN"):
        read_mbsdf(write_mbsdf(tmp_path / "nan.mbsdf", values))


# -- MERL ----------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def disney_merl(tmp_path_factory):
    params = DisneyParams(base_color=(0.6, 0.3, 0.2), roughness=0.5, specular=0.5)
    values = tabulate(lambda a, b: evaluate(disney.MODEL, params, a, b), "merl", MERL_SHAPE)
    path = write_merl(tmp_path_factory.mktemp("merl") / "disney.binary", values)
    return params, path


def test_a_merl_file_written_from_the_disney_model_reproduces_it(disney_merl):
    params, path = disney_merl
    table = read_merl(path)
    assert table.grid == "merl" and table.shape == MERL_SHAPE and table.negative == 0
    wi, wo = _hemisphere(20000, 1), _hemisphere(20000, 2)
    keep = (wi[:, 2] > 0.05) & (wo[:, 2] > 0.05)
    measured = evaluate(MODEL, MeasuredParams(table=table), wi, wo)[keep]
    model = evaluate(disney.MODEL, params, wi, wo)[keep]
    rel = np.abs(measured - model) / model
    # trilinear between samples 1° (θd), 1° (φd) and ≤ 2° (θh) apart
    assert np.median(rel) < 1e-3 and np.percentile(rel, 95) < 5e-3 and rel.max() < 0.02


def test_a_merl_file_of_the_wrong_size_is_refused(tmp_path):
    path = tmp_path / "short.binary"
    path.write_bytes(struct.pack("<iii", 90, 90, 180) + b"\0" * 64)
    with pytest.raises(MeasuredFileError, match="not a MERL file"):
        read_merl(path)


def test_unmeasured_merl_directions_read_as_zero(tmp_path):
    values = np.full((4, 4, 6, 3), -1.0)  # MERL marks unmeasured directions negative
    table = read_merl(write_merl(tmp_path / "gap.binary", values))
    assert table.negative == table.values.size
    f = evaluate(MODEL, MeasuredParams(table=table), [0, 0.6, 0.8], [0.6, 0, 0.8])
    assert np.all(f == 0)


# -- the model -----------------------------------------------------------------------------------
@pytest.mark.parametrize("grid", ["mbsdf", "merl"])
def test_a_tabulated_lambertian_is_lambertian_everywhere_above(grid):
    table = MeasuredTable(grid, np.full((5, 5, 7, 3), 0.3 / np.pi, dtype=np.float32))
    wi, wo = _hemisphere(500, 4), _hemisphere(500, 5)
    f = evaluate(MODEL, MeasuredParams(table=table), wi, wo)
    assert np.allclose(f, 0.3 / np.pi, rtol=1e-12)


def test_edges_normal_grazing_below_and_opposite_are_finite_and_zero_where_they_should():
    params = MeasuredParams(table=read_mbsdf(CARPAINT))
    n = [0.0, 0.0, 1.0]
    tangent = [1.0, 0.0, 0.0]
    below = [0.0, 0.6, -0.8]
    f = evaluate(
        MODEL, params, [n, tangent, below, n, [0.6, 0, 0.8]], [n, n, n, below, [-0.6, 0, -0.8]]
    )
    assert np.all(np.isfinite(f))
    assert np.all(f[0] >= 0) and f[0].max() > 0  # its green is noise below 0, clamped
    assert np.all(f[1:] == 0)


def test_sampling_is_cosine_weighted_and_its_weight_is_f_cos_over_pdf():
    params = MeasuredParams(table=read_mbsdf(CARPAINT))
    wo = np.broadcast_to([0.3, 0.2, math.sqrt(1 - 0.13)], (4000, 3))
    u = np.random.default_rng(6).random((4000, 3))
    wi, weight, pdf = draw(MODEL, params, wo, u)
    assert np.allclose(pdf, wi[:, 2] / np.pi)
    assert np.allclose(pdf, density(MODEL, params, wi, wo))
    f = evaluate(MODEL, params, wi, wo)
    assert np.allclose(weight, f * wi[:, 2:3] / pdf[:, None])


def test_scale_zero_leaves_no_live_lobe():
    from lookdev.materials.registry import live_lobes

    table = MeasuredTable.constant(0.1)
    assert live_lobes(MODEL, MeasuredParams(table=table, scale=0.0)) == ()
    assert live_lobes(MODEL, MeasuredParams(table=table)) == ("measured",)
