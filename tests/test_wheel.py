"""A wheel a studio can deploy: built without setuptools warnings, installed (not
editable) into a fresh virtual environment, and used from there, away from the checkout:
``presets list``, a USD export, a tiny proof and its review page, every data file found
from the installed package.

The fresh environment borrows the dependencies (Mitsuba, usd-core, …) of the one running
the tests through a ``.pth`` path line, so no package index is needed; lookdev itself
comes only from the wheel (a path line does not run the checkout's editable finder, and
the test checks where ``lookdev`` was imported from).
"""

from __future__ import annotations

import json
import os
import site
import subprocess
import sys
import tomllib
import venv
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def test_every_preset_folder_is_declared_as_package_data():
    config = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]
    # __pycache__: Python's byte-code of presets/__init__.py, written by any import of it
    folders = {p.name for p in (ROOT / "presets").iterdir() if p.is_dir()} - {"__pycache__"}
    declared = {p.removeprefix("lookdev.presets.") for p in config["packages"]}
    assert folders <= declared, folders - declared
    for folder in folders:
        assert "*.toml" in config["package-data"][f"lookdev.presets.{folder}"]


def _run(argv, cwd, env=None, timeout=900):
    r = subprocess.run(argv, cwd=cwd, env=env, capture_output=True, text=True, timeout=timeout)
    assert r.returncode == 0, (argv, r.stdout[-2000:], r.stderr[-2000:])
    return r


@pytest.fixture(scope="module")
def installed(tmp_path_factory):
    """(python, lookdev, env) of a fresh venv holding the wheel built from this checkout."""
    tmp = tmp_path_factory.mktemp("wheel")
    build = _run(
        [sys.executable, "-m", "pip", "wheel", "--no-deps", "--no-build-isolation",
         "-w", str(tmp / "dist"), str(ROOT)],
        cwd=tmp,
    )  # fmt: skip
    assert "absent from the `packages` configuration" not in build.stdout + build.stderr
    assert "BuildBackendWarning" not in build.stdout + build.stderr
    wheel = next((tmp / "dist").glob("lookdev-*.whl"))
    env_dir = tmp / "venv"
    venv.EnvBuilder(with_pip=False).create(env_dir)
    python = env_dir / "bin" / "python"
    purelib = Path(
        _run(
            [str(python), "-c", "import sysconfig; print(sysconfig.get_path('purelib'))"], tmp
        ).stdout.strip()
    )
    # dependencies from this environment, as paths only (its .pth files, the checkout's
    # editable finder among them, are not run from a path line)
    (purelib / "borrowed.pth").write_text("\n".join(site.getsitepackages()) + "\n")
    _run(
        [sys.executable, "-m", "pip", "--python", str(python), "install", "--no-deps",
         "--no-index", str(wheel)],
        cwd=tmp,
    )  # fmt: skip
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "VIRTUAL_ENV")}
    env |= {"LOOKDEV_CACHE": str(tmp / "cache"), "COLUMNS": "200"}
    env.pop("LOOKDEV_LIBRARY_PATH", None)
    return python, env_dir / "bin" / "lookdev", env, tmp


@pytest.mark.slow
def test_lookdev_comes_from_the_wheel_not_the_checkout(installed):
    python, _, env, tmp = installed
    where = _run([str(python), "-c", "import lookdev; print(lookdev.__file__)"], tmp, env)
    assert Path(where.stdout.strip()).is_relative_to(tmp / "venv"), where.stdout
    assert not Path(where.stdout.strip()).is_relative_to(ROOT)


@pytest.mark.slow
def test_the_installed_lookdev_lists_exports_proofs_and_writes_its_review_page(installed):
    python, lookdev, env, tmp = installed
    work = tmp / "work"
    work.mkdir()
    listing = json.loads(_run([str(lookdev), "presets", "list", "--json"], work, env).stdout)
    assert len(listing) == len(list((ROOT / "presets").rglob("*.toml"))) - len(
        list((ROOT / "presets" / "ibl").glob("*.toml"))
    )
    _run([str(lookdev), "export", "usd", "gold", "rusty_iron", "-o", "looks.usda"], work, env)
    assert (work / "looks.usda").stat().st_size > 0
    _run(
        [str(lookdev), "proof", "gold", "--ibl", "studio", "-o", "proofs", "--frames", "1",
         "--light-frames", "0", "--spp", "2", "--resolution", "16", "8", "--rig", "none",
         "--no-denoise", "--report"],
        work,
        env,
    )  # fmt: skip
    page = work / "proofs" / "index.html"
    text = page.read_text()
    for asset in ("review.js", "review.css"):
        assert (work / "proofs" / "report" / asset).stat().st_size > 0
        assert f"report/{asset}" in text
    assert "1 material, each under 1 IBL (1 proof)" in text
