"""The review page: built from a proof batch, opened in headless Chromium.

Chromium is driven over the DevTools protocol on a pipe (``--remote-debugging-pipe``:
fd 3 into the browser, fd 4 out of it, NUL-separated JSON), so the test sees console
messages, exceptions, failed loads, every request and every image's decoded size, and
saves a screenshot. No port is opened and nothing leaves the machine.
"""

from __future__ import annotations

import base64
import fcntl
import json
import os
import select
import shutil
import subprocess
import time
from pathlib import Path
from urllib.parse import unquote

import numpy as np
import OpenImageIO as oiio
import pytest

from lookdev.pipeline.analysis import report as R

CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")


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
                        "seconds": 0.5,
                        "noise_relative": 0.01 * (k + 1),
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
    assert gold[columns.index("frames.seconds (sum)")] == "1.5"
    assert gold[columns.index("frames.noise_relative (mean)")] == "0.02"
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


def test_page_links_only_files_that_exist_and_nothing_remote(batch):
    index = R.write_report(batch, plots=False)
    text = index.read_text()
    assert "http://" not in text and "https://" not in text
    import re

    srcs = re.findall(r'src="([^"]+)"', text)
    assert len(srcs) == 1 + 4 * 3  # contact sheet + frames
    for src in srcs:
        assert (batch / unquote(src.replace("&amp;", "&"))).is_file(), src


# -- headless Chromium -----------------------------------------------------------------
class DevTools:
    """A minimal DevTools-protocol client over Chromium's debugging pipe."""

    def __init__(self, user_dir: Path):
        to_browser_r, self._w = os.pipe()
        self._r, from_browser_w = os.pipe()

        def wire():  # in the child: fd 3 reads our commands, fd 4 writes replies
            # Copy both above 10 first: either may already sit on 3 or 4, and dup2 onto
            # itself would keep the close-on-exec flag.
            a = fcntl.fcntl(to_browser_r, fcntl.F_DUPFD, 10)
            b = fcntl.fcntl(from_browser_w, fcntl.F_DUPFD, 10)
            os.dup2(a, 3)
            os.dup2(b, 4)

        self.proc = subprocess.Popen(
            [
                CHROMIUM,
                "--headless",
                "--no-sandbox",
                "--disable-gpu",
                "--disable-quic",
                "--no-first-run",
                "--disable-background-networking",
                "--disable-component-update",
                "--disable-sync",
                "--disable-dev-shm-usage",
                f"--user-data-dir={user_dir}",
                "--remote-debugging-pipe",
                "about:blank",
            ],
            close_fds=False,  # the pipe ends must survive until wire() has run
            preexec_fn=wire,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.PIPE,
        )
        os.close(to_browser_r)
        os.close(from_browser_w)
        self._buf = b""
        self._id = 0
        self.events: list[dict] = []

    def send(
        self,
        method: str,
        params: dict | None = None,
        session: str | None = None,
        timeout: float = 30.0,
    ) -> dict:
        self._id += 1
        msg = {"id": self._id, "method": method, "params": params or {}}
        if session:
            msg["sessionId"] = session
        os.write(self._w, json.dumps(msg).encode() + b"\0")
        while True:
            reply = self._next(timeout)
            if reply.get("id") == self._id:
                if "error" in reply:
                    raise RuntimeError(f"{method}: {reply['error']}")
                return reply["result"]
            self.events.append(reply)

    def wait_for(self, method: str, timeout: float = 30.0) -> dict:
        for e in self.events:
            if e.get("method") == method:
                return e
        while True:
            e = self._next(timeout)
            self.events.append(e)
            if e.get("method") == method:
                return e

    def _next(self, timeout: float) -> dict:
        deadline = time.monotonic() + timeout
        while b"\0" not in self._buf:
            left = deadline - time.monotonic()
            if left <= 0 or not select.select([self._r], [], [], left)[0]:
                raise TimeoutError("Chromium did not answer")
            chunk = os.read(self._r, 1 << 16)
            if not chunk:
                raise RuntimeError(
                    "Chromium closed the pipe: " + self.proc.stderr.read().decode()[-500:]
                )
            self._buf += chunk
        raw, self._buf = self._buf.split(b"\0", 1)
        return json.loads(raw)

    def close(self) -> None:
        try:
            self.send("Browser.close", timeout=5)
        except (RuntimeError, TimeoutError, OSError):
            pass
        try:
            self.proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            self.proc.kill()
        os.close(self._w)
        os.close(self._r)


def open_in_chromium(page: Path, profile: Path) -> dict:
    """Load ``page`` and collect what a reviewer would trip over, plus a screenshot."""
    browser = DevTools(profile)
    try:
        target = browser.send("Target.createTarget", {"url": "about:blank"})["targetId"]
        session = browser.send("Target.attachToTarget", {"targetId": target, "flatten": True})
        session = session["sessionId"]
        for domain in ("Runtime", "Log", "Page", "Network"):
            browser.send(f"{domain}.enable", session=session)
        browser.send("Page.navigate", {"url": page.as_uri()}, session=session)
        browser.wait_for("Page.loadEventFired")
        images = browser.send(
            "Runtime.evaluate",
            {
                "expression": "JSON.stringify([...document.images].map(i => "
                "[i.getAttribute('src'), i.complete, i.naturalWidth]))",
                "returnByValue": True,
            },
            session=session,
        )["result"]["value"]
        shot = browser.send(
            "Page.captureScreenshot",
            {"format": "png", "captureBeyondViewport": True},
            session=session,
        )["data"]
    finally:
        browser.close()

    def params(method: str) -> list[dict]:
        return [e["params"] for e in browser.events if e.get("method") == method]

    images = json.loads(images)
    return {
        "console": [
            p
            for p in params("Runtime.consoleAPICalled")
            if p["type"] in ("error", "assert", "warning")
        ],
        "exceptions": params("Runtime.exceptionThrown"),
        "log": [
            p["entry"]
            for p in params("Log.entryAdded")
            if p["entry"]["level"] in ("error", "warning")
        ],
        "failed": params("Network.loadingFailed"),
        "remote": [
            p["request"]["url"]
            for p in params("Network.requestWillBeSent")
            if not p["request"]["url"].startswith(("file:", "data:"))
        ],
        "images": images,
        "broken": [src for src, done, width in images if not done or width == 0],
        "screenshot": base64.b64decode(shot),
    }


needs_chromium = pytest.mark.skipif(
    CHROMIUM is None, reason="chromium not installed (scripts/setup.sh installs it)"
)


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
    # a contact sheet, 12 frames and gold's plots
    assert len(seen["images"]) == 13 + len(R.PLOT_VIEWS)
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
    for expected in ("gold", "plaster", "studio", "frames.noise_relative (mean)", "contact.png"):
        assert expected in text
    seen = open_in_chromium(index, tmp_path / "profile")
    (out / "report" / "screenshot.png").write_bytes(seen["screenshot"])
    for problem in ("console", "exceptions", "log", "failed", "remote", "broken"):
        assert not seen[problem], (problem, seen[problem])
    # 2 contact sheets, 2 × 3 frames, 2 × 4 plots
    assert len(seen["images"]) == 2 + 6 + 8
