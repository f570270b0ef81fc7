"""lookdev: material presets in, USD networks and Mitsuba proofs out.

The Python API (:mod:`lookdev.pipeline.api`), for notebooks and DCCs' Python::

    import lookdev

    gold = lookdev.load("gold")
    f = lookdev.evaluate(gold, wi, wo)                    # f without the cosine, (..., 3)
    lookdev.export_usd([gold], "gold.usda")
    lookdev.proof(["gold"], ibls=["studio"], out="proofs")

    with lookdev.colour_settings(working_space="acescg", view="Un-tone-mapped"):
        lookdev.proof(["gold"], out="proofs_acescg")       # the CLI's global colour options

Names are imported on first use, so ``import lookdev`` stays cheap (no Mitsuba, USD or
even numpy until a function is called). This file lives at ``pipeline/_lookdev`` because
the repository's top level is fixed; ``pyproject.toml`` maps it to the package ``lookdev``.
"""

from __future__ import annotations

__all__ = [
    "LookdevError",
    "MitsubaExport",
    "Stability",
    "UsdExport",
    "bake",
    "blend",
    "check",
    "colour_settings",
    "evaluate",
    "export_mitsuba",
    "export_usd",
    "hub",
    "load",
    "measured",
    "models",
    "pdf",
    "plot",
    "proof",
    "sample",
]


def __getattr__(name: str) -> object:
    if name in __all__:
        from lookdev.pipeline import api

        value = getattr(api, name)
        globals()[name] = value  # later look-ups skip this function
        return value
    raise AttributeError(f"module 'lookdev' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted({*globals(), *__all__})
