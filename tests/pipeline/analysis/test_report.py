"""The review page: built from a proof batch, opened in headless Chromium
(tests/_chromium.py; the interactive checks are in test_review.py)."""

from __future__ import annotations

import json
from pathlib import Path
from urllib.parse import unquote

import numpy as np
import OpenImageIO as oiio
import pytest
from _chromium import needs_chromium, open_in_chromium

from lookdev.pipeline.analysis import report as R


def _write_image(path: Path, pixels: np.ndarray) -> Path:
    pixels = np.ascontiguousarray(pixels)
    fmt = oiio.FLOAT if path.suffix == ".exr" else oiio.UINT8
    buf = oiio.ImageBuf(oiio.ImageSpec(pixels.shape[1], pixels.shape[0], 3, fmt))
    buf.set_pixels(oiio.ROI(), pixels)
    assert buf.write(str(path)), buf.geterror()
    return path


@pytest.fixture
def batch(tmp_path: Path) -> Path:
    """A proof batch: two materials × two IBLs, PNG and EXR frames, one contact sheet."""
    root = tmp_path / "batch one"  # a space: links must be escaped properly
    rng = np.random.default_rng(0)
    for material in ("gold", "chalk"):
        for ibl in ("studio", "sunset"):
            d = root / material / ibl
            d.mkdir(parents=True)
            frames = []
            for k in range(3):
                if k == 2:
                    frames.append(
                        _write_image(
                            d / f"frame_{k:03d}.exr", rng.random((16, 16, 3), dtype=np.float32) * 2
                        ).name
                    )
                else:
                    frames.append(
                        _write_image(
                            # '#' and a space: links must be URL-quoted
                            d
                            / (f"frame #{k}.png" if material == "chalk" else f"frame_{k:03d}.png"),
                            rng.integers(0, 255, (16, 16, 3), dtype=np.uint8),
                        ).name
                    )
            if material == "gold":  # frames as objects, as the proof module writes them
                frames = [
                    {
                        "path": f,
                        "kind": "element",
                        "angle": 120.0 * k,
                        "time_s": 0.5,
                        "noise": 0.01 * (k + 1),
                    }
                    for k, f in enumerate(frames)
                ]
            manifest = {
                "material": material,
                "ibl": ibl,
                "frames": frames,
                "spp": 16,
                "resolution": [16, 16],
                "timing": {"seconds": 1.25, "per_frame": 0.42},
                "noise": {"relative_mse": 0.0123},
            }
            (d / "manifest.json").write_text(json.dumps(manifest))
    _write_image(root / "contact_sheet.png", rng.integers(0, 255, (32, 64, 3), dtype=np.uint8))
    return root


def test_manifests_become_entries_with_their_frames(batch):
    entries = R.read_manifests(batch)
    assert [(e.material, e.ibl) for e in entries] == [
        ("chalk", "studio"),
        ("chalk", "sunset"),
        ("gold", "studio"),
        ("gold", "sunset"),
    ]
    assert all(len(e.frames) == 3 for e in entries)
    assert [c for _, c in entries[2].frames] == ["element 0°", "element 120°", "element 240°"]
    assert [c for _, c in entries[0].frames] == ["frame #0", "frame #1", "frame_002"]


def test_time_noise_table_has_every_scalar_of_the_manifests(batch):
    columns, rows = R.table_rows(R.read_manifests(batch))
    assert columns[:2] == ["material", "ibl"]
    assert {"spp", "timing.seconds", "timing.per_frame", "noise.relative_mse"} <= set(columns)
    assert rows[0][columns.index("noise.relative_mse")] == "0.0123"
    # per-frame numbers are summarised: times summed, noise averaged
    gold = rows[2]
    assert gold[columns.index("frames.time_s (sum)")] == "1.5"
    assert gold[columns.index("frames.noise (mean)")] == "0.02"
    assert gold[columns.index("frames")] == "3"


def test_exr_frames_get_srgb_thumbnails(batch, tmp_path):
    exr = next(batch.rglob("*.exr"))
    png = R.web_image(exr, tmp_path)
    assert png.suffix == ".png"
    buf = oiio.ImageBuf(str(png))
    assert buf.spec().format == oiio.UINT8 and buf.spec().width == 16


def test_bad_batches_are_one_line_errors(tmp_path):
    with pytest.raises(R.ReportError, match="no manifest.json"):
        R.write_report(tmp_path)
    (tmp_path / "m").mkdir()
    (tmp_path / "m" / "manifest.json").write_text("{not json")
    with pytest.raises(R.ReportError, match="unreadable manifest"):
        R.write_report(tmp_path)
    assert not (tmp_path / "index.html").exists()


def _page_data(index) -> dict:
    text = index.read_text()
    raw = text.split('id="lookdev-data">', 1)[1].split("</script>", 1)[0]
    return json.loads(raw)


def test_page_links_only_files_that_exist_and_nothing_remote(batch):
    index = R.write_report(batch, plots=False)
    text = index.read_text()
    assert "http://" not in text and "https://" not in text
    import re

    srcs = re.findall(r'(?:src|href)="([^"#]+)"', text)
    assert len(srcs) == 1 + 2  # contact sheet + the page's script and style sheet
    data = _page_data(index)
    frames = [f["raw"] for p in data["proofs"] for f in p["frames"]]
    assert len(frames) == 4 * 3
    for src in [*srcs, *frames]:
        assert (batch / unquote(src.replace("&amp;", "&"))).is_file(), src


# -- headless Chromium ---------------------------------------------------------------
@pytest.mark.slow
@needs_chromium
def test_the_chromium_check_itself_sees_broken_images_and_console_errors(tmp_path):
    page = tmp_path / "bad.html"
    page.write_text(
        '<!doctype html><html><body><img src="missing.png">'
        '<script>console.error("boom")</script></body></html>'
    )
    seen = open_in_chromium(page, tmp_path / "profile")
    assert seen["broken"] == ["missing.png"]
    assert seen["console"] and seen["console"][0]["args"][0]["value"] == "boom"
    assert seen["failed"] or seen["log"]  # the failed load is reported too


@pytest.mark.slow
@needs_chromium
def test_page_opens_in_chromium_without_errors_or_broken_images(batch, tmp_path):
    from lookdev.library import load_material
    from lookdev.pipeline.blend import blend

    # Plots for the blended materials given (gold); chalk is not among them: no plots.
    index = R.write_report(batch, materials={"gold": blend(load_material("gold"), 16)})
    seen = open_in_chromium(index, tmp_path / "profile")
    shot = batch / "report" / "screenshot.png"
    shot.write_bytes(seen["screenshot"])
    for problem in ("console", "exceptions", "log", "failed", "remote", "broken"):
        assert not seen[problem], (problem, seen[problem])
    # a contact sheet, 4 players, the comparison's 2 materials under one IBL, gold's plots
    assert len(seen["images"]) == 1 + 4 + 2 + len(R.PLOT_VIEWS)
    assert sorted(p.name for p in (batch / "report" / "plots").iterdir()) == sorted(
        f"gold_{view}.png" for view in R.PLOT_VIEWS
    )
    assert shot.read_bytes()[:4] == b"\x89PNG"


@pytest.mark.slow
@pytest.mark.render
@needs_chromium
def test_lookdev_proof_report_writes_a_page_that_opens_cleanly(cli, tmp_path):
    out = tmp_path / "proofs"
    res = cli(
        "proof",
        "gold",
        "plaster",
        "--ibl",
        "studio",
        "-n",
        "2",
        "-m",
        "1",
        "--spp",
        "4",
        "-r",
        "32",
        "16",
        "-o",
        str(out),
        "-j",
        "1",
        "--report",
        "--json",
    )
    assert res.code == 0, res.err
    index = Path(json.loads(res.out)["report"])
    assert index == out.resolve() / "index.html"
    text = index.read_text()
    for expected in ("gold", "plaster", "studio", "frames.noise (mean)", "contact.png"):
        assert expected in text
    seen = open_in_chromium(index, tmp_path / "profile")
    (out / "report" / "screenshot.png").write_bytes(seen["screenshot"])
    for problem in ("console", "exceptions", "log", "failed", "remote", "broken"):
        assert not seen[problem], (problem, seen[problem])
    # 2 contact sheets and their 2 denoised twins (denoising is the default), 2 players,
    # the comparison's 2 materials under studio (both on denoised frames), 2 × 4 plots
    assert len(seen["images"]) == 2 + 2 + 2 + 2 + 8
    shown = [src for src, *_ in seen["images"] if "/frame_" in src]
    assert shown and all(src.endswith("_denoised.png") for src in shown)
    # the batch recorded each material's parameters, source and USD loss notes
    data = json.loads(text.split('id="lookdev-data">', 1)[1].split("</script>", 1)[0])
    assert data["materials"]["gold"]["parameters"]["metallic"] == 1.0
    assert data["materials"]["plaster"]["source"]["file"].endswith("plaster.toml")
    assert set(data["materials"]["gold"]["usd_losses"]) == {"universal", "mtlx", "ri"}
