"""Bad input ends in one line (issue 13, the input half): ceilings on every parameter,
NaN/inf everywhere, every CLI argument error, the wrong messages, ``presets show`` piped,
``import usd``, batch pre-validation and manifest merge, and a hypothesis test driving the
CLI's argument parsing.

Run: ``.venv/bin/python -m pytest tests/pipeline/cli/test_bad_input.py -q``
"""

from __future__ import annotations

import json
import math
import tomllib
import typing
import warnings
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from lookdev.library import Library
from lookdev.library.preset import parse_preset
from lookdev.materials.errors import LookdevError, ParameterError
from lookdev.materials.layers import LayerSpec, LevelsMask, NoiseMask, RampMask, TextureMask
from lookdev.materials.params import DisneyParams
from lookdev.materials.pixar import PixarParams
from lookdev.materials.sheen import SheenParams

PRESET_SCHEMAS = (DisneyParams, PixarParams, SheenParams, TextureMask, NoiseMask, RampMask)
PRESET_SCHEMAS += (LevelsMask, LayerSpec)


def one_line_error(r, *needles: str) -> str:
    """The run failed the way bad input must: exit 2, one line on stderr, no traceback."""
    assert r.code == 2, (r.code, r.out, r.err)
    lines = r.err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("lookdev: error: "), r.err
    assert "Traceback" not in r.err + r.out
    for n in needles:
        assert n in lines[0], lines[0]
    return lines[0]


@pytest.fixture(autouse=True)
def _cache(tmp_path_factory, monkeypatch):
    monkeypatch.setenv("LOOKDEV_CACHE", str(tmp_path_factory.getbasetemp() / "cache"))
    monkeypatch.delenv("LOOKDEV_LIBRARY_PATH", raising=False)


@pytest.fixture
def no_render(monkeypatch):
    """Any attempt to render fails the test: bad input must stop before the first frame."""
    from lookdev.pipeline.proof import batch

    def forbidden(*args, **kwargs):
        raise AssertionError("rendered despite bad input")

    monkeypatch.setattr(batch, "run_job", forbidden)
    monkeypatch.setattr(batch, "proof", forbidden)


# -- ceilings ------------------------------------------------------------------------------
def _float_fields(schema):
    for name, info in schema.model_fields.items():
        args = typing.get_args(info.annotation)
        if info.annotation is float or (float in args and info.annotation is not bool):
            yield name, info


def _bounds(info):
    lo = hi = None
    for m in info.metadata:
        lo = getattr(m, "ge", None) if getattr(m, "ge", None) is not None else lo
        lo = getattr(m, "gt", None) if getattr(m, "gt", None) is not None else lo
        hi = getattr(m, "le", None) if getattr(m, "le", None) is not None else hi
    return lo, hi


def _opens(info) -> str:
    """``(`` for an open lower bound (gt, e.g. specular_gamma > 0), ``[`` for a closed one."""
    return "(" if any(getattr(m, "gt", None) is not None for m in info.metadata) else "["


FLOAT_FIELDS = [(s, n) for s in PRESET_SCHEMAS for n, _ in _float_fields(s)]


@pytest.mark.parametrize(
    "schema, name", FLOAT_FIELDS, ids=[f"{s.__name__}.{n}" for s, n in FLOAT_FIELDS]
)
def test_every_float_a_preset_accepts_has_a_ceiling(schema, name):
    lo, hi = _bounds(schema.model_fields[name])
    assert hi is not None and math.isfinite(hi), f"{schema.__name__}.{name} has no ceiling"


MODEL_FIELDS = [
    (s, n) for s in (DisneyParams, PixarParams, SheenParams) for n, _ in _float_fields(s)
]


@pytest.mark.parametrize("bad", [math.nan, math.inf, -math.inf, 1e308])
@pytest.mark.parametrize(
    "schema, name", MODEL_FIELDS, ids=[f"{s.__name__}.{n}" for s, n in MODEL_FIELDS]
)
def test_nan_inf_and_huge_values_are_one_line_naming_field_and_range(schema, name, bad):
    with pytest.raises(ParameterError) as info:
        schema.parse({name: bad}, where="p.toml")
    text = str(info.value)
    assert text.startswith(f"p.toml: {name}: ") and "\n" not in text
    if math.isfinite(bad):
        lo, hi = _bounds(schema.model_fields[name])
        assert f"allowed {_opens(schema.model_fields[name])}{lo:g}, {hi:g}]" in text
    else:
        assert "not a finite number" in text


@pytest.mark.parametrize(
    "schema, values, words",
    [
        (DisneyParams, {"sheen_lambda": "approx"}, "'fit' or 'exact'"),
        (SheenParams, {"sheen_lambda": 3}, "'fit' or 'exact'"),
        (DisneyParams, {"energy_compensation": "sometimes"}, "valid boolean"),
        (DisneyParams, {"energy_compensation": 2}, "valid boolean"),
    ],
)
def test_the_sheen_lambda_and_energy_compensation_switches_reject_in_one_line(
    schema, values, words
):
    (name,) = values
    with pytest.raises(ParameterError) as info:
        schema.parse(values, where="p.toml")
    text = str(info.value)
    assert text.startswith(f"p.toml: {name}: ") and words in text and "\n" not in text


@pytest.mark.parametrize(
    "mask, words",
    [
        ({"kind": "texture", "path": "m.png", "uv_scale": [1e9, 1.0]}, "allowed [-4096, 4096]"),
        ({"kind": "texture", "path": "m.png", "uv_scale": [math.nan, 1.0]}, "not a finite"),
        ({"kind": "texture", "path": "m.png", "uv_offset": [0.0, math.inf]}, "not a finite"),
        ({"kind": "ramp", "start": 0.0, "end": 1e300}, "allowed [-1024, 1024]"),
        ({"kind": "ramp", "start": 0.0, "end": 1e-12}, "closer than 1e-06"),
        ({"kind": "noise", "scale": math.inf}, "not a finite"),
        ({"kind": "noise", "seed": 2**40}, "out of range"),
        ({"kind": "levels", "input": 0.5, "gamma": 1e30}, "allowed (0, 10]"),
        ({"kind": "constant", "value": math.nan}, "not a finite"),
    ],
)
def test_layer_and_mask_fields_reject_nan_inf_and_huge(mask, words):
    with pytest.raises(LookdevError) as info:
        LayerSpec.parse({"preset": "gold", "mask": mask}, where="l.toml")
    text = str(info.value)
    assert text.startswith("l.toml: mask") and "\n" not in text
    assert words in text, text


def test_layer_presence_nan_is_rejected():
    with pytest.raises(LookdevError, match="presence"):
        LayerSpec.parse({"preset": "gold", "presence": math.nan}, where="l.toml")


def test_sheen_1e308_preset_is_refused_at_load_with_file_field_and_range(cli, tmp_path):
    (tmp_path / "shiny.toml").write_text(
        'name = "shiny"\nmodel = "disney"\n[params]\nsheen = 1e308\n', encoding="utf-8"
    )
    r = cli("presets", "validate", str(tmp_path / "shiny.toml"))
    assert r.code == 2 and "Traceback" not in r.err
    assert "shiny.toml: params.sheen: 1e+308 is out of range; allowed [0, 10]" in r.err
    r = cli("plot", "shiny", "-L", str(tmp_path), "-o", str(tmp_path / "x.png"))
    one_line_error(r, "shiny.toml", "sheen", "[0, 10]")
    assert not (tmp_path / "x.png").exists()


def test_pixar_specular_scale_ceiling_is_in_the_layer_error_too(cli, tmp_path):
    (tmp_path / "lay.toml").write_text(
        'name = "lay"\nmodel = "layered"\n[[layers]]\nmodel = "pixar"\n'
        "params = { specular_scale = 1e300 }\n",
        encoding="utf-8",
    )
    one_line_error(
        cli("presets", "show", "lay", "-r", "-L", str(tmp_path)), "specular_scale", "[0, 10]"
    )


def test_check_sweeps_the_ceilings_and_finds_nothing():
    from lookdev.pipeline.analysis.stability_cases import extremes

    assert extremes(DisneyParams.model_fields["sheen"]) == [0.0, 10.0]
    assert extremes(PixarParams.model_fields["specular_scale"]) == [0.0, 10.0]
    assert extremes(DisneyParams.model_fields["scatter_distance"]) == [0.0, 1e6]


# -- CLI argument errors ---------------------------------------------------------------------
CLI_ERRORS = [
    (["proof", "--spp", "0"], "--spp: 0 is out of range; allowed [2, 65536]"),
    (["proof", "--spp", "x"], "--spp"),
    (["proof", "--frames", "0"], "--frames: 0 is out of range"),
    (["proof", "--light-frames", "-1"], "--light-frames"),
    (["proof", "-j", "0"], "--workers: 0 is out of range"),
    (["proof", "--ibl-width", "4"], "--ibl-width"),
    (["proof", "--exposure", "nan"], "--exposure: nan is not a finite number"),
    (["proof", "--exposure", "inf"], "--exposure: inf is not a finite number"),
    (["proof", "--exposure", "-inf"], "not a finite number"),
    (["proof", "--exposure", "1e308"], "--exposure"),
    (["proof", "--resolution", "100000", "100000"], "--resolution: 100000 is out of range"),
    (["proof", "--resolution", "8192", "8192", "--spp", "65536"], "samples a frame"),
    (["proof", "-r", "1"], "requires 2 arguments"),
    (["proof", "--bogus"], "no such option: --bogus"),
    (["bogus"], "no such command 'bogus'"),
    (["presets", "bogus"], "no such command"),
    (["export", "usd", "gold", "-c", "bogus"], "'bogus' is not one of"),
    (["export", "mitsuba", "gold", "-o", "x.xml", "--resolution", "0", "5"], "--resolution"),
    (["export", "mitsuba", "gold", "-o", "x.xml", "--spp", "0"], "--spp"),
    (["export", "usd", "gold", "--map-resolution", "0"], "--map-resolution"),
    (["blend"], "missing argument 'preset'"),
    (["blend", "gold", "-o", "out", "--resolution", "0"], "--resolution"),
    (["blend", "gold"], "missing option"),
    (["presets", "show"], "missing argument 'name'"),
    (["presets", "set", "gold"], "missing argument"),
    (["presets", "list", "--model", "x"], "unknown model 'x'"),
    (["plot", "gold"], "missing option"),
    (["plot", "gold", "-o", "x.png", "--exposure", "nan"], "not a finite number"),
    (["plot", "gold", "-o", "x.png", "--resolution", "100000"], "--resolution"),
    (["plot", "gold", "-o", "x.png", "--view", "bogus"], "--view"),
    (["check", "--model", "bogus"], "unknown model"),
    (["import", "usd"], "missing argument"),
    (["validate", "usd"], "missing argument"),
]


@pytest.mark.parametrize("args, words", CLI_ERRORS, ids=[" ".join(a) for a, _ in CLI_ERRORS])
def test_every_argument_error_is_one_line_and_exit_2(
    cli, tmp_path, monkeypatch, no_render, args, words
):
    monkeypatch.chdir(tmp_path)
    line = one_line_error(cli(*args), words)
    assert "Usage:" not in line and "╭" not in line


def test_plot_output_that_is_a_folder_is_one_line(cli, tmp_path):
    one_line_error(cli("plot", "gold", "-o", str(tmp_path)), "is a directory", "--help")


def test_ctrl_c_exits_130_with_one_line(cli, monkeypatch):
    from lookdev.pipeline import api

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(api, "plot", interrupted)
    r = cli("plot", "gold", "-o", "x.png")
    assert r.code == 130
    assert r.err.strip().splitlines() == ["interrupted: run the same command again to resume"]


def test_numpy_runtime_warnings_stay_off_stderr(cli, monkeypatch, tmp_path):
    from lookdev.pipeline import api

    def noisy(materials, path, **kwargs):
        warnings.warn("overflow encountered in multiply", RuntimeWarning, stacklevel=1)
        np.float32(1e38) * np.float32(1e38)  # noqa: B018 - the warning itself is the point
        return api.Plot(Path(path), "slice", ["gold"])

    monkeypatch.setattr(api, "plot", noisy)
    with warnings.catch_warnings():
        warnings.simplefilter("default")
        r = cli("plot", "gold", "-o", str(tmp_path / "x.png"))
    assert r.code == 0 and r.err == ""


# -- wrong messages fixed --------------------------------------------------------------------
def test_library_that_is_a_file_says_so(cli, tmp_path):
    f = tmp_path / "looks.toml"
    f.write_text("x = 1\n")
    one_line_error(cli("presets", "list", "-L", str(f)), "is a file, not a folder")


def test_import_output_that_is_a_file_is_not_called_missing(tmp_path):
    from lookdev.pipeline.export.usd.presets import write_presets
    from lookdev.pipeline.export.usd.reader import Imported

    f = tmp_path / "out"
    f.write_text("x")
    with pytest.raises(LookdevError, match="is a file, not a folder"):
        write_presets([Imported("a", "disney", {}), Imported("b", "disney", {})], f)


def _layered(tmp_path: Path, name: str, mask: str, under: str = "plastic_glossy") -> Path:
    path = tmp_path / f"{name}.toml"
    path.write_text(
        f'name = "{name}"\nmodel = "layered"\n[[layers]]\npreset = "{under}"\n'
        f'[[layers]]\npreset = "gold"\nmask = {{ kind = "texture", path = "{mask}" }}\n',
        encoding="utf-8",
    )
    return path


def test_texture_that_is_a_folder_says_folder(cli, tmp_path):
    (tmp_path / "scratches.png").mkdir()
    _layered(tmp_path, "scratched", "scratches.png")
    r = cli("blend", "scratched", "-L", str(tmp_path), "-o", str(tmp_path / "maps"))
    one_line_error(r, "scratches.png is a folder, not an image file")


def test_a_cycle_through_layers_says_layers(cli, tmp_path):
    for a, b in (("la", "lb"), ("lb", "la")):
        (tmp_path / f"{a}.toml").write_text(
            f'name = "{a}"\nmodel = "layered"\n[[layers]]\npreset = "{b}"\n', encoding="utf-8"
        )
    line = one_line_error(cli("presets", "show", "la", "-r", "-L", str(tmp_path)))
    assert "layers: cycle of presets: la → lb → la" in line and "extends" not in line


def test_a_cycle_through_extends_still_says_extends(cli, tmp_path):
    for a, b in (("ea", "eb"), ("eb", "ea")):
        (tmp_path / f"{a}.toml").write_text(f'name = "{a}"\nextends = "{b}"\n', encoding="utf-8")
    one_line_error(cli("presets", "show", "ea", "-r", "-L", str(tmp_path)), "extends: cycle")


def test_an_empty_file_says_empty(cli, tmp_path):
    (tmp_path / "blank.toml").write_bytes(b"")
    one_line_error(cli("presets", "show", "blank", "-L", str(tmp_path)), "empty preset file")
    r = cli("presets", "list", "-L", str(tmp_path))
    assert "empty preset file" in r.err and "None" not in r.err


def test_a_utf8_bom_is_accepted(cli, tmp_path):
    text = 'name = "bom"\nmodel = "disney"\n[params]\nroughness = 0.3\n'
    (tmp_path / "bom.toml").write_bytes(b"\xef\xbb\xbf" + text.encode())
    r = cli("presets", "show", "bom", "-r", "-L", str(tmp_path), "--json")
    assert r.code == 0, r.err
    assert json.loads(r.out)["resolved"]["params"]["roughness"] == 0.3
    assert "bom" in cli("presets", "list", "-L", str(tmp_path), "--json").out


def test_an_unknown_field_close_to_a_known_one_suggests_it(cli, tmp_path):
    (tmp_path / "typo.toml").write_text(
        'name = "typo"\nmodel = "disney"\n[params]\nroughnes = 0.3\n', encoding="utf-8"
    )
    one_line_error(
        cli("presets", "show", "typo", "-r", "-L", str(tmp_path)),
        "params.roughnes: unknown field; did you mean 'roughness'?",
    )


@pytest.mark.parametrize("name", ["gold", "rusty_car_paint", "pixar_paint_red", "velvet"])
def test_presets_show_piped_is_valid_toml_and_round_trips(cli, name):
    r = cli("presets", "show", name)
    assert r.code == 0 and r.err == ""
    doc = tomllib.loads(r.out)
    assert doc["name"] == name
    path = Library().find(name)
    assert parse_preset(r.out.encode(), where="stdout") == parse_preset(
        path.read_bytes(), where=str(path)
    )
    assert max(map(len, r.out.splitlines())) == max(map(len, path.read_text().splitlines())) or (
        r.out.startswith("#")
    )


# -- import usd ------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def exported(tmp_path_factory):
    from lookdev import export_usd

    folder = tmp_path_factory.mktemp("usd")
    export_usd(["gold", "pixar_painted_metal"], folder / "two.usda", ("universal",))
    return folder / "two.usda"


def _edited(src: Path, dst: Path, value: str) -> Path:
    text = src.read_text()
    assert "inputs:roughness = 0.2" in text
    dst.write_text(text.replace("inputs:roughness = 0.2", f"inputs:roughness = {value}"))
    return dst


@pytest.mark.slow
def test_import_refuses_to_overwrite_without_force(cli, exported, tmp_path):
    (tmp_path / "gold.toml").write_text("# hand-edited\n")
    r = cli("import", "usd", str(exported), "-o", str(tmp_path))
    one_line_error(r, "gold.toml", "--force")
    assert (tmp_path / "gold.toml").read_text() == "# hand-edited\n"
    r = cli("import", "usd", str(exported), "-o", str(tmp_path), "--force")
    assert "hand-edited" not in (tmp_path / "gold.toml").read_text()


def test_import_names_the_layered_pixar_material_it_skips_and_exits_3(cli, exported, tmp_path):
    # lookdev's own export carries the layered preset whole (issue 15): both come back.
    both = tmp_path / "both"
    both.mkdir()
    assert cli("import", "usd", str(exported), "-o", str(both)).code == 0
    assert sorted(p.name for p in both.iterdir()) == ["gold.toml", "pixar_painted_metal.toml"]
    # Without that record (another tool re-wrote the file), its lobe weights are skipped.
    from pxr import Sdf

    layer = Sdf.Layer.OpenAsAnonymous(str(exported))
    prim = layer.GetPrimAtPath("/Materials/pixar_painted_metal")
    prim.customData = {"lookdev": {"model": "pixar_weights"}}
    stripped = tmp_path / "stripped.usda"
    layer.Export(str(stripped))
    out = tmp_path / "out"
    out.mkdir()
    r = cli("import", "usd", str(stripped), "-o", str(out))
    assert r.code == 3  # partly imported: the others are written, each skip one line
    lines = r.err.strip().splitlines()
    assert lines[-1] == "lookdev: partly imported: 1 of 2 materials"
    assert "pixar_painted_metal" in lines[0] and "layered Pixar" in lines[0]
    assert sorted(p.name for p in out.iterdir()) == ["gold.toml"]
    assert cli("presets", "validate", str(out / "gold.toml")).code == 0


@pytest.mark.parametrize(
    "value, words",
    [
        ("-5", "-5.0 is out of range; allowed [0, 1]"),
        ("nan", "not a finite"),
        ("inf", "not a finite"),
    ],
)
def test_import_never_writes_a_preset_validate_rejects(cli, exported, tmp_path, value, words):
    bad = _edited(exported, tmp_path / "bad.usda", value)
    out = tmp_path / "out"
    out.mkdir()
    for args in (("-o", str(out)), ()):  # the bad material refused, the others imported
        r = cli("import", "usd", str(bad), *args)
        assert r.code == 3, r.err
        (refused,) = [line for line in r.err.splitlines() if "refused" in line]
        assert "/Materials/gold" in refused and "roughness" in refused and words in refused
        assert "Traceback" not in r.err
    assert "gold.toml" not in [p.name for p in out.iterdir()]


# -- batches ---------------------------------------------------------------------------------
def test_a_missing_mask_in_the_fifth_preset_stops_the_batch_before_any_render(
    cli, tmp_path, no_render
):
    lib = tmp_path / "lib"
    lib.mkdir()
    _layered(lib, "fifth", "nowhere.png")
    r = cli(
        "proof",
        "gold",
        "velvet",
        "copper",
        "plastic_glossy",
        "fifth",
        "-L",
        str(lib),
        "--ibl",
        "studio",
        "-o",
        str(tmp_path / "out"),
        "--ibl-width",
        "16",
    )
    one_line_error(r, "nowhere.png does not exist")


def test_a_mask_under_an_opaque_layer_is_still_checked(tmp_path, no_render):
    import lookdev

    (tmp_path / "pruned.png").mkdir()
    path = _layered(tmp_path, "pruned", "pruned.png")
    with pytest.raises(LookdevError, match="is a folder"):
        lookdev.proof([str(path)], ["studio"], tmp_path / "out", ibl_width=16)


def test_an_unwritable_output_is_found_before_loading(cli, tmp_path, no_render):
    f = tmp_path / "file"
    f.write_text("x")
    one_line_error(cli("proof", "gold", "--ibl", "studio", "-o", str(f / "out")), "file is a file")


@pytest.mark.slow
def test_a_reproof_of_a_subset_keeps_the_rest_of_the_batch(tmp_path):
    import lookdev

    tiny = {"frames": 1, "light_frames": 0, "spp": 2, "resolution": (8, 8), "ibl_width": 16}
    first = lookdev.proof(["gold", "velvet"], ["studio"], tmp_path, report=True, **tiny)
    assert [p["material"] for p in first["proofs"]] == ["gold", "velvet"]
    again = lookdev.proof(["gold"], ["studio"], tmp_path, report=True, **tiny)
    assert [p["material"] for p in again["proofs"]] == ["gold", "velvet"]
    doc = json.loads((tmp_path / "manifest.json").read_text())
    assert [(p["material"], p["ibl"]) for p in doc["proofs"]] == [
        ("gold", "studio"),
        ("velvet", "studio"),
    ]
    import OpenImageIO as oiio

    spec_one = oiio.ImageBuf(str(tmp_path / "overview.png")).spec()
    assert spec_one.height > 0
    page = (tmp_path / "index.html").read_text()
    assert "velvet" in page and "gold" in page


def test_a_corrupt_cached_ibl_is_regenerated_with_a_note(tmp_path, monkeypatch, caplog):
    from lookdev.pipeline.proof import ibl

    monkeypatch.setenv("LOOKDEV_CACHE", str(tmp_path))
    good = ibl.load("studio", 16)
    cached = good.source
    cached.write_bytes(b"not an exr")
    with caplog.at_level("WARNING", logger="lookdev"):
        again = ibl.load("studio", 16)
    assert np.array_equal(again.pixels, good.pixels)
    notes = [r.getMessage() for r in caplog.records]
    assert len(notes) == 1 and "regenerated" in notes[0] and "\n" not in notes[0]
    # the wrong size (a cache copied from elsewhere) is caught too
    ibl.write_exr(np.zeros((4, 8, 3), np.float32), cached)
    assert ibl.load("studio", 16).pixels.shape == (8, 16, 3)


# -- the CLI's argument parsing under random values ------------------------------------------
@pytest.fixture
def stubbed(monkeypatch, tmp_path):
    """The expensive calls are no-ops: only parsing and validation run."""
    from lookdev.library import Library as Lib
    from lookdev.pipeline import api
    from lookdev.pipeline.analysis import plots
    from lookdev.pipeline.proof import batch, ibl

    monkeypatch.setattr(
        batch,
        "proof",
        lambda *a, **k: {"proofs": [], "wall_seconds": 0.0, "version": 1},
    )
    monkeypatch.setattr(
        ibl, "load", lambda name, width=512, exposure=0.0: ibl.Environment(str(name), Path(), None)
    )
    monkeypatch.setattr(plots, "figure", lambda *a, **k: None)
    monkeypatch.setattr(plots, "save_figure", lambda fig, out: out)

    class Exported:
        output, materials, contexts, textures, files = Path("x.usda"), [], ["universal"], [], []
        fidelity: dict = {}
        contexts_fidelity: dict = {}

        def to_json(self):
            return {}

        def loss_rows(self):
            return []

    monkeypatch.setattr(api, "export_usd", lambda *a, **k: Exported())
    monkeypatch.setattr(api, "bake", lambda *a, **k: {"sidecar": tmp_path / "x.json"})
    monkeypatch.setattr(Lib, "update", lambda self, name, changes: tmp_path / f"{name}.toml")
    monkeypatch.chdir(tmp_path)


NUMBERS = st.one_of(
    st.integers(-(10**6), 10**6).map(str),
    st.floats(allow_nan=True, allow_infinity=True).map(repr),
    st.sampled_from(["nan", "inf", "-inf", "1e308", "0", "-1", "x", "", "3.5", "--"]),
)
NAMES = st.sampled_from(["gold", "velvet", "no_such_preset", "", "-", "--bogus"])


def _option(name: str, values=NUMBERS, count: int = 1):
    return st.tuples(st.just(name), *([values] * count)).map(list)


COMMANDS = {
    "proof": [
        _option("--spp"),
        _option("--frames"),
        _option("--light-frames"),
        _option("-j"),
        _option("--exposure"),
        _option("--ibl-width"),
        _option("--resolution", count=2),
        _option("--ibl", st.sampled_from(["studio", "nowhere.exr", "bogus"])),
    ],
    "plot": [
        _option("--exposure"),
        _option("--resolution"),
        _option("--view", st.sampled_from(["slice", "albedo", "bogus"])),
        _option("-o", st.sampled_from(["x.png", "x.txt", "."])),
    ],
    "export usd": [
        _option("--map-resolution"),
        _option("-c", st.sampled_from(["universal", "mtlx", "ri", "bogus"])),
        _option("-o", st.sampled_from(["x.usda", "x.txt", "nowhere/x.usda"])),
    ],
    "blend": [
        _option("--resolution"),
        _option("--layering", st.sampled_from(["full", "simple", "bogus"])),
        _option("-o", st.sampled_from(["maps"])),
    ],
    "presets set": [
        st.tuples(st.sampled_from(["roughness", "sheen", "uv_scale", "bogus", ""]), NUMBERS).map(
            lambda kv: [f"{kv[0]}={kv[1]}"]
        ),
    ],
}


@st.composite
def command_lines(draw):
    command = draw(st.sampled_from(sorted(COMMANDS)))
    args = command.split()
    args += [draw(NAMES)] * draw(st.integers(0, 2))
    for option in draw(st.lists(st.sampled_from(COMMANDS[command]), max_size=4)):
        args += draw(option)
    return args


@pytest.mark.slow
@settings(
    max_examples=150, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(args=command_lines())
def test_random_option_values_never_give_a_traceback_or_more_than_one_line(cli, stubbed, args):
    r = cli(*args)
    assert "Traceback" not in r.err + r.out, (args, r.err)
    if r.code != 0:
        lines = r.err.strip().splitlines()
        assert len(lines) == 1, (args, r.err)
        assert lines[0].startswith("lookdev: error: ") or r.code == 130, (args, r.err)
        assert r.code == 2, (args, r.code, r.err)


def test_a_truncated_png_is_one_error_and_libpng_prints_nothing(tmp_path, capfd):
    from lookdev.pipeline.proof import contact

    good = contact.write_png(np.full((8, 16, 3), 0.5), tmp_path / "frame.png")
    cut = tmp_path / "cut.png"
    cut.write_bytes(good.read_bytes()[:60])
    capfd.readouterr()
    with pytest.raises(LookdevError) as info:
        contact.read_rgb(cut)
    assert "cut.png: cannot decode the image" in str(info.value) and "\n" not in str(info.value)
    assert contact.read_rgb(good).shape == (8, 16, 3)
    out, err = capfd.readouterr()
    assert err == "" and "libpng" not in out
