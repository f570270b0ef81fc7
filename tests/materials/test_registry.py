"""The model registry's light tables (:mod:`lookdev.materials.model_names`) agree with the
models they name, and the registry imports a model only when it is asked for."""

from __future__ import annotations

import subprocess
import sys

import pytest

from lookdev.library import preset
from lookdev.materials import model_names, registry
from lookdev.materials.model_names import Imported


@pytest.mark.parametrize("name", list(model_names.HOMES))
def test_each_home_holds_the_model_of_that_name(name):
    assert registry.MODELS[name].name == name


@pytest.mark.parametrize("name", model_names.PRESET_MODELS)
def test_each_preset_schema_is_its_models_params_type(name):
    assert preset.MODELS[name] is registry.MODELS[name].params_type


def test_the_schema_table_names_exactly_the_preset_models():
    assert tuple(model_names.PARAMS) == model_names.PRESET_MODELS


def test_asking_for_one_model_imports_only_its_module():
    code = (
        "import sys; from lookdev.materials import registry;"
        "assert 'disney' in registry.MODELS and sorted(registry.MODELS);"
        "assert 'lookdev.materials.disney' not in sys.modules;"
        "registry.MODELS['sheen'];"
        "print(sorted(m for m in ('disney', 'openpbr', 'pixar', 'measured', 'sheen')"
        " if 'lookdev.materials.' + m in sys.modules))"
    )
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert r.stdout.split() == ["['sheen']"]


def test_an_entry_set_at_run_time_is_held_and_removed():
    table = Imported({"disney": "params:DisneyParams"})
    table["toy"] = toy = object()
    assert table["toy"] is toy and list(table) == ["disney", "toy"] and len(table) == 2
    del table["toy"]
    assert "toy" not in table and len(table) == 1
    with pytest.raises(KeyError):
        table["toy"]
    with pytest.raises(KeyError):
        del table["toy"]
