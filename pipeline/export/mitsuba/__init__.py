"""Mitsuba 3: BSDF plugins on the Dr.Jit backend of the shared model code, and scenes.

>>> import lookdev.pipeline.export.mitsuba as m
>>> sorted(m.__all__)[:3]
['MitsubaExportError', 'bsdf_dict', 'export_scene']
"""

from .depth import max_depth_for
from .inputs import MitsubaExportError
from .plugin import register_model
from .scene import bsdf_dict, register_plugins, scene_dict
from .xml import export_scene, write_xml

__all__ = [
    "MitsubaExportError",
    "bsdf_dict",
    "export_scene",
    "max_depth_for",
    "register_model",
    "register_plugins",
    "scene_dict",
    "write_xml",
]
