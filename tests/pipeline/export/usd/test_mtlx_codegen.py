"""MaterialX code generation succeeds for every built-in preset as lookdev exports it.

The exported ``.mtlx`` is what a MaterialX renderer reads; each material's shader nodes
must validate against MaterialX's own libraries and generate GLSL and OSL source (the
shading languages of the viewers and offline renderers that take MaterialX).
"""

from __future__ import annotations

import pytest

pytest.importorskip("MaterialX")
import MaterialX as mx  # noqa: E402
from MaterialX import PyMaterialXGenGlsl as glsl  # noqa: E402
from MaterialX import PyMaterialXGenOsl as osl  # noqa: E402
from MaterialX import PyMaterialXGenShader as gen  # noqa: E402


@pytest.mark.slow
@pytest.mark.parametrize("generator", [glsl.GlslShaderGenerator, osl.OslShaderGenerator])
def test_every_exported_material_generates_shader_code(exported, generator):
    result, doc = exported
    valid, message = doc.validate()
    assert valid, message
    materials = doc.getMaterialNodes()
    assert len(materials) == len(result.materials) > 60
    shader_gen = generator.create()
    context = gen.GenContext(shader_gen)
    context.registerSourceCodeSearchPath(mx.getDefaultDataSearchPath())
    failed = []
    for material in materials:
        for shader in mx.getShaderNodes(material):
            try:
                code = shader_gen.generate(shader.getName(), shader, context)
                assert code.getSourceCode(gen.PIXEL_STAGE)
            except Exception as exc:  # MaterialX raises its own types; name the material
                failed.append(f"{material.getName()}: {str(exc).splitlines()[0]}")
    assert not failed, failed
