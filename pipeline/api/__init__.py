"""The Python API of lookdev: what ``import lookdev`` gives, and what the CLI calls.

Each function here is one thing a command does, without the command: a TD in a notebook
or in a DCC's Python loads, blends, evaluates, exports and proofs materials with it, and
every ``lookdev`` command only parses its options, calls one of these and prints the
result. Bad input raises the :class:`LookdevError` family, with the one-line message the
CLI prints.

=======================  ==========================================================
:func:`load`             a preset (name or ``.toml`` file) resolved into a material
:func:`blend`            a layered material blended into constants and maps
:func:`bake`             a blend's varying maps written as EXR (and a JSON sidecar)
:func:`evaluate`         f(wi, wo) without the cosine, numpy ``(..., 3)``
:func:`sample`           ``(wi, weight, pdf)`` drawn for ``wo`` and uniforms ``u``
:func:`pdf`              the density with which :func:`sample` draws ``wi``
:func:`export_usd`       UsdShade materials, and what each render context lost
:func:`export_mitsuba`   a Mitsuba 3 scene of one material
:func:`proof`            turntable proofs, materials × IBLs, resumable; the manifest
:func:`plot`             BRDF-explorer views of materials, side by side
:func:`check`            the stability sweep of every reflectance model
:func:`designer`         the Material Designer: a local web page, a live viewport
:data:`models`           the reflectance models by name
:func:`colour_settings`  a ``with`` block: OCIO config, working space, display/view/look
=======================  ==========================================================

Colour is set one way, for everything inside a ``with lookdev.colour_settings(...)``
block (what the CLI's global ``--config``, ``--working-space``, ``--display``, ``--view``
and ``--look`` do): presets load into that working space, exports and EXRs name it, and
proofs, plots and the review page show pixels through that view. Load a material inside
the block it is used in: its colours were converted into the working space in force
when it was loaded.

Materials are accepted in any form a step can use: a preset name or ``.toml`` path
(loaded through ``library``), a :class:`~lookdev.library.Material`, or where it makes
sense a :class:`~lookdev.pipeline.blend.BlendedMaterial`. ``library`` is a folder, a list
of folders or a :class:`~lookdev.library.Library`; the folders are searched before
``$LOOKDEV_LIBRARY_PATH`` and the built-in presets, as ``--library`` is by the CLI.

>>> import lookdev
>>> gold = lookdev.load("gold")
>>> lookdev.evaluate(gold, [0.0, 0.0, 1.0], [0.0, 0.0, 1.0]).shape
(3,)

Heavy dependencies (Mitsuba, usd-core, matplotlib) are imported by the functions that
need them, never by ``import lookdev``.
"""

from lookdev.library.display import register_swatch
from lookdev.materials.colour import use as colour_settings

from .analysis import Plot, Stability, check, plot
from .designer import DesignerHandle, designer
from .exports import USD_CONTEXTS, MitsubaExport, UsdExport, export_mitsuba, export_usd
from .materials import (
    EVALUATE_RESOLUTION,
    LookdevError,
    MaterialError,
    bake,
    blend,
    evaluate,
    hub,
    library_for,
    load,
    measured,
    models,
    pdf,
    sample,
)
from .preview import swatch_png
from .proofs import REPRESENTATIVE, proof, representative_presets

__all__ = [
    "EVALUATE_RESOLUTION",
    "REPRESENTATIVE",
    "LookdevError",
    "MaterialError",
    "MitsubaExport",
    "Plot",
    "Stability",
    "USD_CONTEXTS",
    "UsdExport",
    "bake",
    "blend",
    "DesignerHandle",
    "check",
    "colour_settings",
    "designer",
    "evaluate",
    "export_mitsuba",
    "export_usd",
    "hub",
    "library_for",
    "load",
    "measured",
    "models",
    "pdf",
    "plot",
    "proof",
    "representative_presets",
    "sample",
]

# A material shown in a notebook draws its swatch with the pipeline's numpy sphere.
register_swatch(swatch_png)
