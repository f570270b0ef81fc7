"""The README's quick start, run as written in a fresh folder (renders shrunk to tiny sizes).

The commands are read from README.md between its ``quickstart`` markers, so the README
and this test cannot drift apart. Only the flags below are added, to the commands that
render: the quick start's proof and plot at full size would take minutes.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
README = (ROOT / "README.md").read_text()

# Appended to the commands that render, so the run takes seconds: one frame each way at
# 32×16, two samples, a small IBL; a plot at 16 pixels a side.
SHRINK = {
    "lookdev proof": "--frames 1 --light-frames 1 --resolution 32 16 --ibl-width 64 --spp 2",
    "lookdev plot": "--resolution 16",
    # The designer serves a page until stopped; here only its command line is checked.
    "lookdev designer": "--help",
}


def _quickstart_lines() -> list[str]:
    start = README.index("<!-- quickstart-start -->")
    end = README.index("<!-- quickstart-end -->")
    blocks = re.findall(r"```bash\n(.*?)```", README[start:end], re.S)
    assert blocks, "the quick start has commands"
    return [line for block in blocks for line in block.splitlines() if line.strip()]


def _split_comment(line: str) -> tuple[str, str]:
    """``cmd 'a#b'   # note`` → ("cmd 'a#b'", "   # note"): a # outside quotes, after a space."""
    quote = None
    for i, ch in enumerate(line):
        if quote:
            quote = None if ch == quote else quote
        elif ch in "'\"":
            quote = ch
        elif ch == "#" and (i == 0 or line[i - 1].isspace()):
            return line[:i].rstrip(), line[i:]
    return line, ""


def _shrunk(line: str) -> str:
    command, comment = _split_comment(line)
    for prefix, flags in SHRINK.items():
        if command.startswith(prefix + " "):
            command = f"{command} {flags}"
    return f"{command}  {comment}" if comment else command


def test_split_comment_respects_quotes():
    assert _split_comment("""lookdev presets set x 'c="#c08850"'  # change""") == (
        """lookdev presets set x 'c="#c08850"'""",
        "# change",
    )
    assert _split_comment("lookdev a -o b.png") == ("lookdev a -o b.png", "")


def test_the_two_commands_are_in_the_readme():
    # Not run here: run.sh is the main job (minutes of proofs) and test.sh runs this test.
    assert re.search(r"^bash scripts/run\.sh ", README, re.M)
    assert re.search(r"^bash scripts/test\.sh ", README, re.M)


@pytest.mark.slow
@pytest.mark.render
def test_quickstart_runs_as_written_in_a_fresh_folder(tmp_path):
    lines = _quickstart_lines()
    assert any(line.startswith("lookdev presets new") and "--from" in line for line in lines)
    script = [
        "set -euo pipefail",
        *(_shrunk(line) for line in lines),
    ]
    env = dict(os.environ)
    env["PATH"] = f"{Path(sys.executable).parent}{os.pathsep}{env.get('PATH', '')}"
    env.pop("LOOKDEV_LIBRARY_PATH", None)
    run = subprocess.run(
        ["bash", "-c", "\n".join(script)],
        cwd=tmp_path,
        env=env,
        capture_output=True,
        text=True,
        timeout=900,
    )
    assert run.returncode == 0, f"{run.stdout[-3000:]}\n{run.stderr[-3000:]}"

    preset = (tmp_path / "looks" / "worn_gold.toml").read_text()
    assert 'extends = "gold"' in preset
    assert "roughness = 0.45" in preset
    assert 'base_color = "#c08850"' in preset
    assert (tmp_path / "worn_gold.png").stat().st_size > 0
    assert (tmp_path / "proofs" / "index.html").is_file()
    assert (tmp_path / "proofs" / "worn_gold" / "studio" / "contact.png").is_file()
    assert "valid" in run.stdout

    from pxr import Usd, UsdShade

    stage = Usd.Stage.Open(str(tmp_path / "pub" / "worn_gold.usda"))
    material = UsdShade.Material(stage.GetPrimAtPath("/Materials/worn_gold"))
    assert material, [p.GetPath() for p in stage.Traverse()]
