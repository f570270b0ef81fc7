"""The Python API speaks Python: errors name arguments (the CLI names its options from
the same message), ``proof`` runs from a plain script, materials show themselves in a
notebook, and a layered material evaluated at a uv converges to one truth."""

from __future__ import annotations

import base64
import re
import subprocess
import sys
import textwrap

import numpy as np
import pytest

import lookdev
from lookdev.materials.errors import LookdevError, argument
from lookdev.pipeline.api import EVALUATE_RESOLUTION


# -- errors: one message, two readers ---------------------------------------------------------
def test_an_argument_reads_as_python_from_python_and_as_an_option_from_the_cli():
    err = LookdevError(f"{argument('spp')} is fixed; drop it", field=argument("max_spp"))
    assert str(err) == "max_spp: spp is fixed; drop it"
    assert err.one_line({"max_spp": "--max-spp"}) == "--max-spp: --spp is fixed; drop it"
    # an argument the command has no option for still reads as an option
    assert LookdevError("bad", field=argument("time_budget")).one_line({}) == "--time-budget: bad"


def test_proof_from_python_names_the_argument(tmp_path):
    with pytest.raises(LookdevError) as info:
        lookdev.proof("gold", "studio", tmp_path, noise=0, ibl_width=32)
    assert str(info.value).startswith("noise: 0 is out of range; allowed [0.0001, 10]")
    assert "--" not in str(info.value)
    with pytest.raises(LookdevError, match=r"^jobs: 0 is out of range"):
        lookdev.proof("gold", "studio", tmp_path, jobs=0, ibl_width=32)
    with pytest.raises(LookdevError, match=r"^spp: spp is a fixed count; noise go with"):
        lookdev.proof("gold", "studio", tmp_path, spp=16, noise=0.1, ibl_width=32)
    assert not any(tmp_path.iterdir())


def test_the_cli_names_its_options_from_the_same_message(cli, tmp_path):
    r = cli(
        "proof", "gold", "--ibl", "studio", "-o", str(tmp_path), "--spp", "16", "--noise", "0.1"
    )
    assert r.code == 2
    assert r.err.strip() == (
        "lookdev: error: --spp: --spp is a fixed count; --noise go with a noise target (drop --spp)"
    )


def test_plot_and_export_name_their_arguments(tmp_path):
    with pytest.raises(LookdevError, match=r"^ibl: ibl only applies to view sphere"):
        lookdev.plot("gold", tmp_path / "p.png", view="slice", ibl="studio")
    with pytest.raises(LookdevError, match=r"^exposure: "):
        lookdev.plot("gold", tmp_path / "p.png", exposure=float("nan"))
    with pytest.raises(LookdevError, match=r"^ibl_rotation: 400 is out of range"):
        lookdev.export_mitsuba("gold", tmp_path / "s.xml", ibl_rotation=400)


def test_the_cli_plot_error_keeps_its_option_names(cli, tmp_path):
    r = cli("plot", "gold", "--view", "slice", "--ibl", "studio", "-o", str(tmp_path / "p.png"))
    assert r.code == 2 and "--ibl only applies to --view sphere" in r.err


# -- proof from a plain script ------------------------------------------------------------------
SCRIPT = """
import sys
from pathlib import Path
with Path(sys.argv[1]).open("a") as f:  # one line per execution of this file
    f.write("ran\\n")
import lookdev
doc = lookdev.proof(["gold"], ["studio"], sys.argv[2], frames=1, light_frames=0, spp=2,
                    resolution=(16, 8), ibl_width=32, rig="none", denoise=False)
print(doc["proofs"][0]["rendered"])
"""


@pytest.mark.render
@pytest.mark.slow
def test_proof_from_a_script_without_a_main_guard_runs_the_script_once(tmp_path):
    script = tmp_path / "plain.py"
    script.write_text(textwrap.dedent(SCRIPT))
    counter = tmp_path / "executions.txt"
    r = subprocess.run(
        [sys.executable, str(script), str(counter), str(tmp_path / "out")],
        capture_output=True,
        text=True,
        timeout=600,
        cwd=tmp_path,
    )
    assert r.returncode == 0, r.stderr
    assert r.stdout.split()[-1] == "1"  # the worker rendered the frame
    assert counter.read_text().splitlines() == ["ran"]  # and did not re-run the script


def test_worker_processes_are_told_no_main_script():
    import multiprocessing.spawn as spawn

    from lookdev.pipeline.proof.spawn import CONTEXT

    seen = {}

    class Probe(CONTEXT.Process):
        def _Popen(self, process_obj):  # noqa: N802 (multiprocessing's name)
            seen.update(spawn.get_preparation_data(self._name))
            raise RuntimeError("stop before starting a process")

    with pytest.raises(RuntimeError, match="stop before"):
        Probe(target=print).start()
    assert "init_main_from_path" not in seen and "init_main_from_name" not in seen
    assert sys.modules["__main__"].__name__ == "__main__"  # the real one is back


# -- repr and the notebook view ------------------------------------------------------------------
def test_repr_is_one_short_line():
    gold, rusty = lookdev.load("gold"), lookdev.load("rusty_iron")
    assert repr(gold) == "<Material gold: disney, 23 parameters from gold.toml>"
    assert repr(rusty).startswith("<Material rusty_iron: layered, 2 layers: iron, rust")
    assert max(len(repr(gold)), len(repr(rusty))) < 120


def test_repr_html_shows_parameters_their_source_and_a_swatch(tmp_path):
    parent = tmp_path / "warm_gold.toml"
    parent.write_text('name = "warm_gold"\nextends = "gold"\n[params]\nroughness = 0.4\n')
    m = lookdev.load(parent, library=tmp_path)
    page = m._repr_html_()
    rows = dict(re.findall(r"<tr><td>(\w+)</td><td>[^<]*</td><td>([^<]*)</td></tr>", page))
    assert rows["roughness"] == "warm_gold.toml" and rows["metallic"] == "gold.toml"
    assert rows["sheen"] == "default"
    png = base64.b64decode(re.search(r"base64,([A-Za-z0-9+/=]+)", page)[1])
    assert png[:8] == b"\x89PNG\r\n\x1a\n"


def test_repr_html_of_a_layered_material_lists_its_layers_and_escapes_names():
    page = lookdev.load("rusty_iron")._repr_html_()
    assert "levels(noise(" in page and "<td>rust</td>" in page
    assert "<script" not in page


def test_swatch_is_the_lit_sphere_of_the_material(monkeypatch):
    from lookdev.pipeline.api.preview import swatch_png

    png = swatch_png(lookdev.load("gold"), size=24)
    assert png[:4] == b"\x89PNG"


# -- evaluate(layered, uv) and evaluate(blend(layered), uv) --------------------------------------
def test_evaluating_at_a_uv_converges_to_the_material_at_that_point():
    m = lookdev.load("rusty_iron")
    wi = np.array([0.3, 0.2, 0.93]) / np.linalg.norm([0.3, 0.2, 0.93])
    wo, uv = np.array([0.0, 0.0, 1.0]), [0.25, 0.5]
    # Texel centres fall on (0.25, 0.5) at W = 4k + 2 and odd H; above the noise's finest
    # octave the blend there is the material at the point, whatever the size.
    exact = [
        lookdev.evaluate(lookdev.blend(m, res), wi, wo, uv) for res in ((386, 193), (770, 385))
    ]
    np.testing.assert_allclose(exact[0], exact[1], rtol=1e-6)
    truth = exact[0]
    errors = {
        r: float(np.abs(lookdev.evaluate(lookdev.blend(m, r), wi, wo, uv) - truth).max())
        for r in (256, 512, 1024)
    }
    assert errors[256] > errors[512] > errors[1024]
    # evaluate(layered, uv) is the blend at EVALUATE_RESOLUTION, no other approximation
    shorthand = lookdev.evaluate(m, wi, wo, uv)
    at_512 = lookdev.evaluate(lookdev.blend(m, EVALUATE_RESOLUTION), wi, wo, uv)
    np.testing.assert_allclose(shorthand, at_512, rtol=1e-12)
