"""Turntables and batch proofs, rendered tiny (32×16, 4 spp, a few frames)."""

from __future__ import annotations

import dataclasses
import json

import numpy as np
import pytest

from lookdev.materials.colour import luminance
from lookdev.pipeline.proof import batch, ibl, passes, shaderball, turntable

pytestmark = pytest.mark.render

TINY = batch.Settings(element_frames=2, light_frames=1, spp=4, resolution=(32, 16), denoise=False)
DIFFUSE = {"type": "diffuse", "reflectance": {"type": "rgb", "value": 0.5}}


@pytest.fixture(autouse=True)
def _cache(tmp_path_factory, monkeypatch):
    monkeypatch.setenv("LOOKDEV_CACHE", str(tmp_path_factory.getbasetemp() / "cache"))


@pytest.fixture(scope="module")
def mitsuba():
    from lookdev.pipeline.variant import use_mitsuba

    use_mitsuba()
    import mitsuba as mi

    return mi


@pytest.fixture(scope="module")
def gold():
    from lookdev.library import load_material
    from lookdev.pipeline.blend import blend

    return blend(load_material("gold"), 16)


def _table(mitsuba, bsdf=DIFFUSE, resolution=(32, 16)):
    return turntable.Turntable(bsdf, ibl.load("studio", 64).pixels, resolution, 3)


# -- turntable -----------------------------------------------------------------------------
def test_frames_turn_the_element_then_the_lighting():
    got = [(f.index, f.kind, f.angle) for f in turntable.frames(3, 2)]
    assert got == [
        (0, "element", 0.0),
        (1, "element", 120.0),
        (2, "element", 240.0),
        (3, "light", 0.0),
        (4, "light", 180.0),
    ]


def test_rotations_move_the_picture_and_a_full_turn_brings_it_back(mitsuba):
    table = _table(mitsuba)

    def shot(kind, angle):
        table.set_frame(turntable.Frame(0, kind, angle))
        return table.render(4, seed=7)

    rest = shot("light", 0.0)
    assert np.abs(shot("light", 90.0) - rest).mean() > 1e-3
    assert shot("light", 360.0) == pytest.approx(rest, abs=1e-4)
    assert np.abs(shot("element", 90.0) - rest).mean() > 1e-4  # the tilted cup turns
    assert shot("element", 360.0) == pytest.approx(rest, abs=1e-3)


def test_frames_after_the_first_reuse_every_compiled_kernel(mitsuba):
    import drjit as dr

    table = _table(mitsuba)
    dr.set_flag(dr.JitFlag.KernelHistory, True)
    try:
        passes.render_frame(table, turntable.Frame(0, "element", 0.0), spp=4)
        dr.kernel_history()  # drain the first frame's compilations
        for frame in turntable.frames(2, 2)[1:]:
            passes.render_frame(table, frame, spp=4)
        jit = [k for k in dr.kernel_history() if str(k["type"]).endswith("JIT")]
    finally:
        dr.set_flag(dr.JitFlag.KernelHistory, False)
    assert jit and all(k["cache_hit"] for k in jit)


@pytest.mark.slow
def test_frozen_frames_equal_plain_renders_and_stop_recording(mitsuba):
    """The frozen launch (dr.freeze) replays exactly what mi.render computes, and records
    only while the scene's first poses settle which of its values are literals, never
    once per frame: each frame's seed is an input of the recording, not part of its key."""
    table = _table(mitsuba)
    counts = []
    for _ in range(2):
        for frame in turntable.frames(3, 3):
            table.set_frame(frame)
            frozen = table.render(4, seed=frame.index)
            plain = mitsuba.render(table.scene, sensor=table.camera_index, spp=4, seed=frame.index)
            assert frozen == pytest.approx(np.array(plain)[..., :3], abs=1e-6)
            counts.append(table.recordings)
    assert counts[-1] <= 3 and counts[-1] == counts[len(counts) // 2 - 1]


_FROZEN_PRESETS = """
import sys
import numpy as np
from lookdev.pipeline.variant import use_mitsuba
use_mitsuba()
import mitsuba as mi
from lookdev.library import load_material
from lookdev.pipeline.blend import blend
from lookdev.pipeline.proof import ibl, turntable
for name in sys.argv[1:]:
    bsdf, depth = turntable.material_bsdf(blend(load_material(name), 64))
    table = turntable.Turntable(bsdf, ibl.load("studio", 64).pixels, (16, 8), depth)
    for frame in turntable.frames(2, 2):
        table.set_frame(frame)
        frozen = table.render(2, seed=frame.index)
        plain = mi.render(table.scene, sensor=table.camera_index, spp=2, seed=frame.index)
        assert np.allclose(frozen, np.array(plain)[..., :3], atol=1e-5), name
"""


@pytest.mark.slow
def test_every_kind_of_plugin_renders_frozen(tmp_path):
    """One preset per plugin and feature (Conty-Kulla sheen tables, Pixar lobes, layered
    Pixar weights, textures of a layered Disney stack, glass): a model that copied host
    memory during a render would abort the process under dr.freeze, so each runs in a
    child process and must match mi.render."""
    import os
    import subprocess
    import sys

    presets = ["velvet", "pixar_paint_red", "pixar_rusty_metal", "rusty_car_paint", "glass_clear"]
    env = {**os.environ, "LOOKDEV_CACHE": str(tmp_path)}
    run = [sys.executable, "-c", _FROZEN_PRESETS, *presets]
    done = subprocess.run(run, env=env, timeout=600, capture_output=True, text=True)
    assert done.returncode == 0, done.stderr[-2000:]


def test_every_ibl_of_a_batch_enters_the_scene_the_same_way(mitsuba):
    """Why a batch brings IBLs to one size and folds exposure into pixels (docs/design.md):
    Mitsuba compiles a new kernel for an envmap of another resolution or ``scale``. So
    every IBL, built-in or a file, at any exposure, arrives as an array of one shape and
    dtype, and two proof scenes differ in the environment's pixels and nothing else.

    (Whether Mitsuba then reuses its kernels is Mitsuba's; ``lookdev bench proof``
    measures it. Testing it here flaked: Dr.Jit's frozen renders sometimes record one
    kernel more, which is a hit only when its on-disk cache already holds it.)
    """
    envs = [ibl.load("studio", 64), ibl.load("overcast", 64, exposure=1.5), ibl.load("sky", 64)]
    assert {(e.pixels.shape, e.pixels.dtype) for e in envs} == {((32, 64, 3), np.dtype("float32"))}
    scenes = [shaderball.scene_dict(DIFFUSE, e.pixels, (32, 16), 3) for e in envs]

    def without_pixels(tree):
        return {
            k: without_pixels(v) if isinstance(v, dict) else (None if k == "bitmap" else repr(v))
            for k, v in tree.items()
        }

    assert without_pixels(scenes[0]) == without_pixels(scenes[1]) == without_pixels(scenes[2])
    assert "scale" not in scenes[0]["environment"]


@pytest.mark.slow
def test_half_sample_noise_estimate_matches_the_true_error(mitsuba):
    table = _table(mitsuba, resolution=(48, 24))
    frame = turntable.Frame(0, "element", 0.0)
    table.set_frame(frame)
    reference = luminance(table.render(1024, seed=99))
    r = passes.render_frame(table, frame, spp=8)
    true_rmse = float(np.sqrt(np.mean((luminance(r.image) - reference) ** 2)))
    assert 0.7 < r.noise_rmse / true_rmse < 1.4
    assert r.seconds > 0 and r.noise > 0


def test_a_black_frame_has_no_relative_noise(mitsuba):
    table = turntable.Turntable(DIFFUSE, np.zeros((16, 32, 3), np.float32), (16, 8), 3)
    r = passes.render_frame(table, turntable.Frame(0, "element", 0.0), spp=2)
    assert r.noise_rmse == 0.0 and r.noise is None and r.firefly_share is None


# -- jobs and resumption -------------------------------------------------------------------
def _job(material, out, settings=TINY, name="studio"):
    env = ibl.load(name, 64)
    return batch.make_jobs([material], [env], out, settings)[0]


def test_a_job_writes_frames_sheet_and_manifest(mitsuba, gold, tmp_path):
    doc = batch.run_job(_job(gold, tmp_path))
    folder = tmp_path / "gold" / "studio"
    assert doc["rendered"] == 3 and doc["skipped"] == 0
    manifest = json.loads((folder / "manifest.json").read_text())
    assert [f["kind"] for f in manifest["frames"]] == ["element", "element", "light"]
    assert manifest["ibl_orientation"] == ibl.ORIENTATION  # the convention, stated
    assert manifest["rig"]["rig"] == "full" and manifest["rig"]["grey_albedo"] == 0.18
    for f in manifest["frames"]:
        assert f["time_s"] > 0 and f["noise_rmse"] > 0
        raw = f["files"]["raw"]
        assert raw["file"] == f["images"]["raw"]
        assert (folder / raw["file"]).stat().st_size == raw["size"]
    assert (folder / "contact.png").is_file()
    assert not [p for p in folder.iterdir() if p.name.startswith(".")], "temporaries left"


def test_a_rerun_skips_verified_frames_and_redoes_damaged_ones(mitsuba, gold, tmp_path):
    job = _job(gold, tmp_path)
    batch.run_job(job)
    again = batch.run_job(job)
    assert again["rendered"] == 0 and again["skipped"] == 3
    folder = tmp_path / "gold" / "studio"
    (folder / "frame_000.exr").unlink()
    with open(folder / "frame_002.png", "ab") as f:
        f.write(b"x")  # same name, wrong size and hash
    repaired = batch.run_job(job)
    assert repaired["rendered"] == 2 and repaired["skipped"] == 1
    assert len(repaired["frames"]) == 3


def test_progress_counts_frames_from_the_manifest_of_matching_settings(mitsuba, gold, tmp_path):
    job = _job(gold, tmp_path)
    assert batch.frames_done(job) == 0
    batch.run_job(job)
    assert batch.frames_done(job) == 3
    other = dataclasses.replace(TINY, spp=6)
    assert batch.frames_done(_job(gold, tmp_path, other)) == 0


def test_changed_settings_render_everything_again_and_drop_stray_frames(mitsuba, gold, tmp_path):
    batch.run_job(_job(gold, tmp_path))
    fewer = dataclasses.replace(TINY, element_frames=1, spp=6)
    assert batch.run_job(_job(gold, tmp_path, fewer))["rendered"] == 2
    frames = sorted(p.name for p in (tmp_path / "gold" / "studio").glob("frame_*"))
    assert frames == ["frame_000.exr", "frame_000.png", "frame_001.exr", "frame_001.png"]


def test_a_relit_turntable_renders_what_a_fresh_load_of_that_ibl_does(mitsuba):
    sky = ibl.load("sky", 64).pixels
    table = _table(mitsuba)  # loaded under studio
    frames = turntable.frames(1, 1)
    for frame in frames:
        table.set_frame(frame)
        table.render_halves(2, seed=frame.index)
    table.set_environment(sky)
    fresh = turntable.Turntable(DIFFUSE, sky, (32, 16), 3)
    for frame in frames:
        table.set_frame(frame)
        fresh.set_frame(frame)
        got, want = table.render_halves(2, seed=frame.index), fresh.render_halves(2, frame.index)
        assert np.abs(got[0] - want[0]).max() <= 1e-6 and np.abs(got[1] - want[1]).max() <= 1e-6
    with pytest.raises(ValueError, match="shape"):
        table.set_environment(np.zeros((8, 16, 3), np.float32))


def test_a_worker_relights_its_last_scene_for_the_next_ibl_only(mitsuba, gold, tmp_path):
    from lookdev.pipeline.proof import uniform

    studio, overcast = ibl.load("studio", 64), ibl.load("overcast", 64)
    first = uniform.turntable_for(gold, studio.pixels, TINY)
    uniform.keep(first)
    assert uniform.turntable_for(gold, overcast.pixels, TINY) is first  # relit
    assert uniform.turntable_for(gold, overcast.pixels, TINY) is not first  # not kept
    uniform.keep(first)
    other = dataclasses.replace(TINY, resolution=(16, 8))
    assert uniform.turntable_for(gold, overcast.pixels, other) is not first  # none kept now
    alone = batch.run_job(_job(gold, tmp_path / "alone", name="overcast"))  # a fresh load
    jobs = batch.make_jobs([gold], [studio, overcast], tmp_path, TINY)
    docs = [batch.run_job(job) for job in jobs]  # each relights the last job's scene
    from lookdev.pipeline.proof.contact import read_rgb

    for relit, fresh in zip(docs[1]["frames"], alone["frames"], strict=True):
        got = read_rgb(tmp_path / "gold" / "overcast" / relit["images"]["raw"])
        want = read_rgb(tmp_path / "alone" / "gold" / "overcast" / fresh["images"]["raw"])
        assert got == pytest.approx(want, abs=1e-6)


@pytest.mark.slow
def test_a_batch_runs_on_a_dask_cluster(mitsuba, gold, tmp_path):
    from distributed import Client, LocalCluster

    envs = [ibl.load(n, 64) for n in ("studio", "overcast")]
    jobs = batch.make_jobs([gold], envs, tmp_path, TINY)
    seen = []
    with (
        LocalCluster(n_workers=1, processes=False, threads_per_worker=1) as cluster,
        Client(cluster) as client,
    ):
        results = batch.run_batch(jobs, client.get_executor(), on_done=lambda j, d: seen.append(j))
    assert [r["ibl"] for r in results] == ["studio", "overcast"] and len(seen) == 2
    doc = batch.summary(tmp_path, jobs, results, 1.0)
    assert [p["frames"] for p in doc["proofs"]] == [3, 3]
    assert json.loads((tmp_path / "manifest.json").read_text()) == doc
    assert doc["overview"] == "overview.png" and (tmp_path / "overview.png").is_file()


def test_a_crashing_job_is_one_line_with_its_traceback_kept(gold, tmp_path, monkeypatch):
    from concurrent.futures import ThreadPoolExecutor

    def crash(job, todo):
        raise RuntimeError("kernel exploded\nsecond line")
        yield

    monkeypatch.setattr(batch, "_render", crash)
    with ThreadPoolExecutor(1) as pool, pytest.raises(batch.ProofError) as info:
        batch.run_batch([_job(gold, tmp_path)], pool)
    message = str(info.value)
    assert message.startswith("gold × studio: rendering failed (RuntimeError: kernel exploded)")
    assert "\n" not in message
    assert "second line" in (tmp_path / "gold" / "studio" / "error.log").read_text()


# -- the command ---------------------------------------------------------------------------
def test_proof_command_runs_on_a_dask_scheduler(cli, tmp_path):
    from distributed import LocalCluster

    out = tmp_path / "proofs"
    args = ["gold", "--ibl", "sunset", "-n", "1", "-m", "1", "-s", "2", "-r", "32", "16"]
    with LocalCluster(n_workers=1, processes=False, threads_per_worker=1) as cluster:
        r = cli("proof", *args, "--ibl-width", "64", "-o", str(out), "--json", "--scheduler",
                cluster.scheduler_address)  # fmt: skip
    assert r.code == 0, r.err
    doc = json.loads(r.out)
    assert doc["proofs"][0]["material"] == "gold" and doc["proofs"][0]["frames"] == 2
    assert (out / "gold" / "sunset" / "contact.png").is_file()


@pytest.mark.slow
def test_proof_command_default_executor_is_a_process_pool(cli, tmp_path):
    out = tmp_path / "p"
    r = cli("proof", "gold", "--ibl", "studio", "-n", "1", "-m", "0", "-s", "2", "-r", "16", "8",
            "--ibl-width", "32", "-o", str(out), "-j", "1")  # fmt: skip
    assert r.code == 0, r.err
    assert "gold" in r.out and (out / "manifest.json").is_file()


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["no_such_preset"], "no_such_preset"),
        (["gold", "--ibl", "missing.exr"], "missing.exr: no such IBL file"),
        (["gold", "--ibl", "JUNK"], "cannot decode"),
        (["gold", "-o", "FILE/sub"], "file is a file"),
        (["gold", "--ibl", "studio", "--ibl", "STUDIO_EXR"], "two IBLs would share"),
    ],
)
def test_bad_input_is_one_line_exit_2_and_leaves_no_frames(cli, tmp_path, args, message):
    junk = tmp_path / "junk.exr"
    junk.write_bytes(b"\x76\x2f\x31\x01garbage")
    (tmp_path / "file").write_text("a file, not a folder")
    studio = tmp_path / "studio.exr"
    studio.write_bytes(ibl.resolve("studio", 32).read_bytes())
    named = {"JUNK": str(junk), "STUDIO_EXR": str(studio)}
    args = [named.get(a, a.replace("FILE", str(tmp_path / "file"))) for a in args]
    if "-o" not in args:
        args += ["-o", str(tmp_path / "out")]
    r = cli("proof", *args, "-n", "1", "-m", "0", "-s", "2", "-r", "16", "8")
    assert r.code == 2 and message in r.err
    assert len(r.err.strip().splitlines()) == 1 and "Traceback" not in r.err
    assert not list(tmp_path.rglob("*.png")) and not list(tmp_path.rglob("frame_*"))


@pytest.mark.parametrize(("in_flight", "most"), [(1, 1), (2, 2), (None, 4)])
def test_at_most_in_flight_jobs_are_queued(monkeypatch, in_flight, most):
    import threading
    import time
    from concurrent.futures import ThreadPoolExecutor
    from types import SimpleNamespace

    class Counting(ThreadPoolExecutor):
        outstanding = peak = 0
        lock = threading.Lock()

        def submit(self, fn, *args):
            with self.lock:
                Counting.outstanding += 1
                Counting.peak = max(Counting.peak, Counting.outstanding)
            fut = super().submit(fn, *args)
            fut.add_done_callback(lambda _: self._done())
            return fut

        def _done(self):
            with self.lock:
                Counting.outstanding -= 1

    def slow_job(job):
        time.sleep(0.05)  # long enough for every submission to land first
        return {"n": job.n}

    monkeypatch.setattr(batch, "run_job", slow_job)
    jobs = [SimpleNamespace(n=i) for i in range(4)]
    ticks = []
    with Counting(4) as pool:
        results = batch.run_batch(jobs, pool, in_flight=in_flight, on_tick=ticks.append)
    assert [r["n"] for r in results] == [0, 1, 2, 3]
    assert Counting.peak == most
    assert ticks and all(len(running) <= most for running in ticks)


def test_representative_set_takes_what_the_library_has():
    from types import SimpleNamespace

    from lookdev.pipeline.api import REPRESENTATIVE, representative_presets

    full = SimpleNamespace(names=lambda: sorted([*REPRESENTATIVE, "zinc"]))
    assert representative_presets(full) == list(REPRESENTATIVE)
    partial = SimpleNamespace(names=lambda: ["gold", "zinc"])
    assert representative_presets(partial) == ["gold"]
    other = SimpleNamespace(names=lambda: ["a", "b", "c", "d", "e"])
    assert representative_presets(other) == ["a", "b", "c", "d"]
