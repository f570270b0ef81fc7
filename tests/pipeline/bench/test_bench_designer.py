"""``lookdev bench designer``: its random edits and its command line (the figures
themselves are measured, not tested)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from lookdev.materials.params import DisneyParams
from lookdev.pipeline.bench.designer import EDITABLE, random_edit


@given(st.integers(0, 2**32 - 1))
def test_a_random_edit_moves_one_to_three_sliders_within_range(seed):
    rng = np.random.default_rng(seed)
    start = DisneyParams(roughness=0.4)
    edited = random_edit(rng, start)
    changed = [k for k in EDITABLE if getattr(edited, k) != getattr(start, k)]
    assert len(changed) <= 3
    for name in EDITABLE:
        value = np.atleast_1d(getattr(edited, name))
        assert np.all((value >= 0.0) & (value <= 1.0))
    DisneyParams.parse(edited.model_dump(exclude_none=True))  # the schema accepts it


def test_an_unknown_item_is_one_line_and_exit_2(cli):
    result = cli("bench", "designer", "--item", "nope")
    assert result.code == 2
    assert "nope" in result.err and len(result.err.strip().splitlines()) == 1


@pytest.mark.render
def test_an_edit_through_the_server_reaches_the_page():
    from lookdev.pipeline.bench.designer import client_edit

    result = client_edit((32, 18), edits=3)
    assert result["count"] == 3
    assert 0 < result["median_s"] <= result["p90_s"]
