"""Property tests: generated and mutated preset files either load or fail in one line.

Whatever bytes sit in a preset file, the loader (and the listing, and ``presets
validate``) ends in a :class:`Material` or in a one-line :class:`LookdevError`;
never another exception, never a multi-line message.
"""

from __future__ import annotations

import tomllib
from pathlib import Path

import jsonschema
import pytest
import tomli_w
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st

from lookdev.library import Library, Material, PresetFile, dump_preset, read_preset, resolve
from lookdev.library.index import read_header, simple_header
from lookdev.library.library import apply_changes
from lookdev.library.preset import build_preset
from lookdev.library.schema import preset_schema
from lookdev.materials.errors import LookdevError
from lookdev.materials.params import DisneyParams

PARAM_NAMES = list(DisneyParams.model_fields)
KEYS = ["name", "model", "description", "tags", "source", "extends", "params", "layers"]

scalars = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True),
    st.integers(min_value=-(2**63), max_value=2**63 - 1),
    st.booleans(),
    st.text(max_size=12),
    st.sampled_from(["#aa8844", "#fff", "conty_kulla", "disney", "gold", "p"]),
)
wild_values = st.one_of(scalars, st.lists(scalars, max_size=4), st.dictionaries(st.text(), scalars))
unit = st.floats(0.0, 1.0)
plausible_params = st.dictionaries(
    st.sampled_from(PARAM_NAMES),
    st.one_of(unit, st.lists(unit, min_size=3, max_size=3)),
    max_size=5,
)
masks = st.one_of(
    unit,
    st.builds(
        lambda s, seed: {"kind": "noise", "scale": s, "seed": seed},
        st.floats(0.5, 64),
        st.integers(0, 9),
    ),
    st.builds(lambda lo: {"kind": "levels", "low": lo, "input": {"kind": "ramp"}}, unit),
)
layer_entries = st.one_of(
    st.builds(
        lambda p, m: {"preset": p, "mask": m}, st.sampled_from(["gold", "rusty_iron"]), masks
    ),
    st.builds(lambda q, m: {"model": "disney", "params": q, "mask": m}, plausible_params, masks),
)


@st.composite
def documents(draw) -> dict:
    """A plausible preset document, then zero to two fields broken, dropped or added."""
    doc = {"name": "p", "description": draw(st.text(max_size=20)), "tags": ["t"]}
    if draw(st.booleans()):
        doc["model"] = "layered"
        doc["layers"] = draw(st.lists(layer_entries, min_size=1, max_size=3))
    else:
        doc["model"] = draw(st.sampled_from(["disney", "pixar"]))
        doc["params"] = draw(plausible_params)
        if draw(st.booleans()):
            doc["extends"] = draw(st.sampled_from(["gold", "p", "nope", "rusty_iron"]))
    for _ in range(draw(st.integers(0, 2))):
        key = draw(st.sampled_from([*KEYS, *PARAM_NAMES, "junk"]))
        how = draw(st.sampled_from(["replace", "drop", "param"]))
        if how == "drop":
            doc.pop(key, None)
        elif how == "param" and isinstance(doc.get("params"), dict):
            doc["params"][key] = draw(wild_values)
        else:
            doc[key] = draw(wild_values)
    return doc


@st.composite
def mutated(draw) -> bytes:
    """A generated preset's TOML, then maybe truncated, corrupted, or given a random key."""
    data = tomli_w.dumps(draw(documents())).encode()
    how = draw(st.sampled_from(["as is", "truncate", "flip", "insert", "key", "random"]))
    if how == "truncate":
        return data[: draw(st.integers(0, len(data)))]
    if how in ("flip", "insert") and data:
        i = draw(st.integers(0, len(data) - 1))
        b = draw(st.binary(min_size=1, max_size=4))
        return data[:i] + b + data[i + (how == "flip") :]
    if how == "key":
        key = draw(st.sampled_from([*KEYS, *PARAM_NAMES, "zzz"]))
        value = draw(st.sampled_from(["1", "[", '"x"', "{a=1}", "nan"]))
        return data + f"\n{key} = {value}\n".encode()
    if how == "random":
        return draw(st.binary(max_size=200))
    return data


def loads_or_fails_in_one_line(library: Library, path) -> Material | None:
    try:
        material = library.load_file(path)
    except LookdevError as exc:
        assert "\n" not in str(exc) and str(exc).strip()
        event(f"error: {type(exc).__name__}")
        return None
    event(f"loaded: {material.model}")
    return material


SETTINGS = settings(
    max_examples=250, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)


@pytest.mark.slow
@SETTINGS
@given(data=mutated())
def test_any_file_loads_or_fails_in_one_line(tmp_path, data):
    path = tmp_path / "p.toml"
    path.write_bytes(data)
    library = Library([tmp_path], use_env=False)
    material = loads_or_fails_in_one_line(library, path)
    if material is not None:
        assert material.name == "p" and material.model in ("disney", "pixar", "layered")
    header = read_header(path)
    assert header.error is None or "\n" not in header.error
    try:
        library.entries()
    except LookdevError as exc:  # only a cycle or missing folder may stop a listing
        raise AssertionError(f"listing raised {exc}") from exc


@pytest.mark.slow
@SETTINGS
@given(doc=documents())
def test_generated_documents_that_load_round_trip(tmp_path, doc):
    path = tmp_path / "p.toml"
    path.write_bytes(tomli_w.dumps(doc).encode())
    library = Library([tmp_path], use_env=False)
    material = loads_or_fails_in_one_line(library, path)
    if material is None or material.model == "layered":
        return
    again = tmp_path / "again" / "p.toml"
    again.parent.mkdir(exist_ok=True)
    again.write_text(dump_preset(read_preset(path)))
    assert library.load_file(again).params == material.params


SCHEMA = jsonschema.Draft202012Validator(preset_schema())


@pytest.mark.slow
@SETTINGS
@given(doc=documents())
def test_the_json_schema_accepts_every_file_the_loader_accepts(doc):
    # Editors must never flag a preset lookdev loads (the converse needs other files).
    try:
        build_preset(doc, where="p.toml")
    except LookdevError:
        return
    errors = [e.message for e in SCHEMA.iter_errors(doc)]
    assert not errors, errors


@pytest.mark.slow
@SETTINGS
@given(
    changes=st.dictionaries(
        st.sampled_from([*PARAM_NAMES, "description", "tags", "extends", "name", "params.x"]),
        st.one_of(st.none(), wild_values, unit),
        max_size=3,
    )
)
def test_any_set_either_applies_or_fails_in_one_line(changes):
    base = PresetFile(name="p", extends="gold", params={"roughness": 0.3})
    builtin = Library(use_env=False)
    try:
        edited = apply_changes(base, changes, where="p.toml")
        # As a save does: the edited file must resolve against its parent.
        material = resolve("p", lambda n: (edited, Path("p.toml")) if n == "p" else builtin.read(n))
    except LookdevError as exc:
        assert "\n" not in str(exc)
        return
    for key, value in changes.items():
        if value is not None and key in PARAM_NAMES:
            assert edited.params[key] == value and key in material.params.model_fields_set


TOMLISH = st.text(alphabet=list("name=\"'#[],\\ \t\nabxé\x00\r\x7ftagsdcriptoulx"), max_size=60)
header_values = st.one_of(st.text(max_size=12), st.lists(st.text(max_size=6), max_size=3))
header_docs = st.dictionaries(st.sampled_from(["name", "model", "tags", "source"]), header_values)


@settings(max_examples=400, deadline=None)
@given(
    text=st.one_of(
        TOMLISH,
        header_docs.map(tomli_w.dumps),
        st.builds(
            lambda d, pad, note: "\n".join(
                f"{pad}{k}{pad}={pad}'{v}'{pad}#{note}"
                if isinstance(v, str) and "'" not in v
                else f"{k} = {tomli_w.dumps({'v': v})[4:].strip()}"
                for k, v in d.items()
            ),
            header_docs,
            st.sampled_from(["", " ", "\t"]),
            st.text(max_size=5),
        ),
    )
)
def test_the_fast_header_parse_agrees_with_tomllib(text):
    fast = simple_header(text)
    event("plain" if fast is not None else "not plain")
    if fast is None:
        return  # not plain: the listing parses it with tomllib instead
    assert fast == tomllib.loads(text)
