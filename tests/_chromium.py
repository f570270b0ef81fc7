"""Headless Chromium for the review-page tests, driven over the DevTools protocol on a pipe.

``--remote-debugging-pipe``: fd 3 into the browser, fd 4 out of it, NUL-separated JSON.
The tests see console messages, exceptions, failed loads, every request and every image's
decoded size, can run script in the page and save screenshots. No port is opened and
nothing leaves the machine (the launch flags turn off every background request). No
browser is downloaded: Debian's ``chromium`` (scripts/setup.sh installs it) or none, and
the tests that need it are skipped with the reason.
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

import pytest

CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
needs_chromium = pytest.mark.skipif(
    CHROMIUM is None, reason="chromium not installed (scripts/setup.sh installs it)"
)
PROBLEMS = ("console", "exceptions", "log", "failed", "remote", "broken")


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


class Page:
    """One page open in a fresh headless Chromium: run script, take screenshots, and at
    the end the problems a reviewer would trip over (:meth:`problems`)."""

    def __init__(self, url: str, profile: Path):
        self.browser = DevTools(profile)
        try:
            target = self.browser.send("Target.createTarget", {"url": "about:blank"})
            session = self.browser.send(
                "Target.attachToTarget", {"targetId": target["targetId"], "flatten": True}
            )
            self.session = session["sessionId"]
            for domain in ("Runtime", "Log", "Page", "Network"):
                self.browser.send(f"{domain}.enable", session=self.session)
            self.browser.send(
                "Emulation.setDeviceMetricsOverride",
                {"width": 1400, "height": 1000, "deviceScaleFactor": 1, "mobile": False},
                session=self.session,
            )
            self.browser.send("Page.navigate", {"url": url}, session=self.session)
            self.browser.wait_for("Page.loadEventFired")
        except BaseException:
            self.browser.close()
            raise

    def __enter__(self) -> Page:
        return self

    def __exit__(self, *exc) -> None:
        self.browser.close()

    def js(self, expression: str):
        """The value of ``expression`` in the page (awaited when it is a promise)."""
        reply = self.browser.send(
            "Runtime.evaluate",
            {"expression": expression, "returnByValue": True, "awaitPromise": True},
            session=self.session,
        )
        if "exceptionDetails" in reply:
            raise AssertionError(f"{expression}: {reply['exceptionDetails']}")
        return reply["result"].get("value")

    def scroll_through(self) -> None:
        """Scroll the page top to bottom a view at a time, so that what loads when scrolled
        to (the review page's players) has loaded, then back to the top."""
        height = self.js("document.documentElement.scrollHeight") or 0
        step = max(self.js("window.innerHeight") or 600, 100) // 2
        for y in range(0, int(height) + int(step), int(step)):
            self.js(f"window.scrollTo(0, {y})")
            time.sleep(0.05)
        # the observer reports on a later frame: bring each image still waiting into view
        # until none is (or a few seconds pass, and the check then sees it)
        waiting = "document.querySelectorAll('img[data-lazy=\"wait\"]')"
        deadline = time.monotonic() + 5.0
        while self.js(f"{waiting}.length") and time.monotonic() < deadline:
            self.js(f"{waiting}[0].scrollIntoView()")
            time.sleep(0.1)
        self.js("window.scrollTo(0, 0)")

    def images_loaded(self, timeout: float = 10.0) -> list:
        """``[src, complete, naturalWidth]`` of every image, once all have settled (after
        scrolling through the page: an image not yet scrolled to has nothing to load)."""
        self.scroll_through()
        deadline = time.monotonic() + timeout
        while True:
            images = self.js(
                "[...document.images].map(i => [i.getAttribute('src'), i.complete, i.naturalWidth])"
            )
            if all(done for _, done, _ in images) or time.monotonic() > deadline:
                return images
            time.sleep(0.05)

    def screenshot(self, selector: str | None = None) -> bytes:
        """A PNG of the element matching ``selector`` (scrolled to the middle of the view,
        clear of the page's sticky toolbar), or of the whole page."""
        params: dict = {"format": "png", "captureBeyondViewport": True}
        if selector is not None:
            box = self.js(
                f"(() => {{ const e = document.querySelector({json.dumps(selector)}); "
                "e.scrollIntoView({block: 'center'}); const r = e.getBoundingClientRect(); "
                "return [r.x + scrollX, r.y + scrollY, r.width, r.height]; })()"
            )
            x, y, w, h = box
            params["clip"] = {"x": x, "y": y, "width": w, "height": h, "scale": 1}
        data = self.browser.send("Page.captureScreenshot", params, session=self.session)
        return base64.b64decode(data["data"])

    def problems(self) -> dict[str, list]:
        """Console errors and warnings, exceptions, failed loads, remote requests and
        broken images seen so far."""

        def params(method: str) -> list[dict]:
            return [e["params"] for e in self.browser.events if e.get("method") == method]

        images = self.images_loaded()
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
            "broken": [src for src, done, width in images if not done or width == 0],
        }


def open_in_chromium(page: Path, profile: Path) -> dict:
    """Load ``page``; what a reviewer would trip over, its images and a screenshot."""
    with Page(page.as_uri(), profile) as p:
        seen = p.problems()
        seen["images"] = p.images_loaded()
        seen["screenshot"] = p.screenshot()
    return seen
