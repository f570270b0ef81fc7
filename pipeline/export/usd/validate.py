"""``lookdev validate usd``: every usd-core validator, then MaterialX's own check.

usd-core's ``UsdValidation`` registry runs on the whole stage. Its one expected error
is ``MissingShaderIdInRegistry`` for MaterialX (``ND_*``) and RenderMan (``Pxr*``)
shader ids: the pip build ships without UsdMtlx and RenderMan's node definitions, so
Sdr cannot know them. Those networks are checked instead by converting each MaterialX
network back into a MaterialX document and running MaterialX's ``validate``.

Every shader's authored inputs are then checked against the node's own definition,
because renderers ignore an input they do not know, silently: ``Pxr*`` against
RenderMan's input names kept in ``renderman_inputs.json``, ``ND_*`` against MaterialX's
node definitions (``getActiveInputs``), and Sdr-registered ids (``UsdPreviewSurface``,
``UsdUVTexture``, ``UsdPrimvarReader_*``) against usd-core's Sdr registry. An unknown
input is an error naming the prim and the input. So is an authored value that is not a
finite number (NaN or infinite, in any component), or one outside the input's range:
below MaterialX's ``uimin`` for ``ND_*`` nodes (above ``uimax``, where the UI's slider
ends, is a warning), outside the UsdPreviewSurface specification's range for that surface
(:data:`PREVIEW_SURFACE_RANGES`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import cache
from pathlib import Path

from .network import ExportError

__all__ = [
    "ALLOWED",
    "FOREIGN_ID_PREFIXES",
    "PREVIEW_SURFACE_RANGES",
    "Report",
    "input_range",
    "known_inputs",
    "validate_usd",
]

ALLOWED = "MissingShaderIdInRegistry"
FOREIGN_ID_PREFIXES = ("ND_", "Pxr")
PREVIEW_SURFACE_RANGES: dict[str, tuple[float, float]] = {
    **dict.fromkeys(("diffuseColor", "emissiveColor", "specularColor", "ior"), (0.0, math.inf)),
    **dict.fromkeys(
        ("metallic", "roughness", "clearcoat", "clearcoatRoughness", "opacity"), (0.0, 1.0)
    ),
    **dict.fromkeys(("opacityThreshold", "occlusion"), (0.0, 1.0)),
}
"""UsdPreviewSurface inputs' valid values (UsdPreviewSurface specification 2.x): colours
and ``ior`` non-negative, the weights, roughnesses and opacity in [0, 1]; Sdr carries no
ranges, so they are written here."""


@dataclass
class Report:
    """Validation outcome: errors (fail), warnings, and the errors allowed as expected."""

    path: str
    errors: list[str] = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)
    allowed: list[str] = field(default_factory=list)
    validators: int = 0
    mtlx_networks: int = 0
    inputs_checked: int = 0

    @property
    def ok(self) -> bool:
        return not self.errors


def validate_usd(path: Path) -> Report:
    """Run every registered usd-core validator and MaterialX's ``validate`` on ``path``."""
    from pxr import Tf, Usd, UsdValidation

    path = Path(path)
    if not path.is_file():
        raise ExportError("file does not exist", where=str(path))
    try:
        stage = Usd.Stage.Open(str(path))
    except Tf.ErrorException as exc:
        raise ExportError(f"USD cannot open it: {_first_line(exc)}", where=str(path)) from None
    validators = UsdValidation.ValidationRegistry().GetOrLoadAllValidators()
    report = Report(str(path), validators=len(validators))
    for error in UsdValidation.ValidationContext(validators).Validate(stage):
        _file(report, error)
    _check_mtlx(stage, report)
    _check_inputs(stage, report)
    return report


def _check_inputs(stage, report: Report) -> None:
    """Every authored shader input against its node's definition (see the module note)."""
    from pxr import Usd, UsdShade

    for prim in stage.Traverse(Usd.TraverseInstanceProxies()):
        if not prim.IsA(UsdShade.Shader):
            continue
        shader = UsdShade.Shader(prim)
        ident = str(shader.GetIdAttr().Get() or "")
        names = [i.GetBaseName() for i in shader.GetInputs() if i.GetAttr().IsAuthored()]
        known = known_inputs(ident)
        if known is None:
            if names and ident.startswith(FOREIGN_ID_PREFIXES):
                report.warnings.append(
                    f"UnknownShaderInputs: {prim.GetPath()} ({ident}): no definition of its "
                    "inputs to check them against"
                )
            continue
        report.inputs_checked += len(names)
        for name in names:
            if name not in known:
                report.errors.append(
                    f"UnknownShaderInput: {prim.GetPath()} ({ident}) has no input '{name}'"
                )
        for given in shader.GetInputs():
            # the value a renderer reads: the input's own, or a material interface input's
            # it is connected to (a texture's output is no authored value)
            for attr in given.GetValueProducingAttributes():
                if not UsdShade.Input.IsInput(attr) or not attr.HasAuthoredValue():
                    continue
                problem = _value_problem(ident, given.GetBaseName(), attr.Get())
                if problem:
                    kind, text, fails = problem
                    via = "" if attr.GetPrim() == prim else f" (from {attr.GetPath()})"
                    found = report.errors if fails else report.warnings
                    found.append(f"{kind}: {prim.GetPath()} ({ident}) {text}{via}")


def _numbers(value) -> list[float] | None:
    """The components of a numeric input value (scalar, vector, colour); None otherwise."""
    if isinstance(value, bool) or value is None or isinstance(value, str):
        return None
    if isinstance(value, int | float):
        return [float(value)]
    try:
        items = list(value)
    except TypeError:
        return None
    if items and all(isinstance(v, int | float) and not isinstance(v, bool) for v in items):
        return [float(v) for v in items]
    return None


def _value_problem(ident: str, name: str, value) -> tuple[str, str, bool] | None:
    """(kind, text, is an error) when ``value`` of input ``name`` is not finite or out of its
    range. Above a MaterialX ``uimax`` is a warning: that is where the UI's slider ends, and
    Burley's parameters may go beyond it on purpose (a diamond's ``specular`` > 1)."""
    numbers = _numbers(value)
    if numbers is None:
        return None
    shown = ", ".join(f"{v:g}" for v in numbers)
    if not all(math.isfinite(v) for v in numbers):
        return "NonFiniteShaderInput", f"input '{name}' is ({shown}): not a finite number", True
    bounds = input_range(ident, name)
    if bounds is None:
        return None
    low, high = bounds
    text = f"input '{name}' is ({shown}): allowed [{low:g}, {high:g}]"
    if any(v < low for v in numbers) or (ident == "UsdPreviewSurface" and max(numbers) > high):
        return "ShaderInputOutOfRange", text, True
    if max(numbers) > high:
        return "ShaderInputAboveUiMax", text, False
    return None


def input_range(ident: str, name: str) -> tuple[float, float] | None:
    """The valid range of input ``name`` of node ``ident``, where a definition gives one."""
    if ident == "UsdPreviewSurface":
        return PREVIEW_SURFACE_RANGES.get(name)
    if ident.startswith("ND_"):
        return _mtlx_range(ident, name)
    return None


@cache
def _mtlx_range(ident: str, name: str) -> tuple[float, float] | None:
    from .mtlx import _library

    nodedef = _library().getNodeDef(ident)
    found = nodedef.getActiveInput(name) if nodedef is not None else None
    if found is None:
        return None
    low, high = (_first(found.getAttribute(a)) for a in ("uimin", "uimax"))
    if low is None and high is None:
        return None
    return (-math.inf if low is None else low, math.inf if high is None else high)


def _first(text: str) -> float | None:
    """A MaterialX ``uimin``/``uimax`` value ("0.0", "0,0,0") as one bound; None if absent."""
    parts = {p.strip() for p in text.split(",") if p.strip()}
    try:
        values = {float(p) for p in parts}
    except ValueError:
        return None
    return values.pop() if len(values) == 1 else None


def known_inputs(ident: str) -> frozenset[str] | None:
    """The input names the node ``ident`` defines; None when no definition is known."""
    if ident.startswith("Pxr"):
        from .ri import renderman_inputs

        return renderman_inputs().get(ident)
    if ident.startswith("ND_"):
        return _mtlx_inputs(ident)
    return _sdr_inputs(ident)


@cache
def _mtlx_inputs(ident: str) -> frozenset[str] | None:
    from .mtlx import _library

    nodedef = _library().getNodeDef(ident)
    if nodedef is None:
        return None
    return frozenset(i.getName() for i in nodedef.getActiveInputs())


@cache
def _sdr_inputs(ident: str) -> frozenset[str] | None:
    from pxr import Sdr

    node = Sdr.Registry().GetShaderNodeByIdentifier(ident) if ident else None
    if node is None:
        return None
    return frozenset(str(n) for n in node.GetShaderInputNames())


def _file(report: Report, error) -> None:
    from pxr import UsdValidation

    text = f"{error.GetIdentifier()}: {error.GetMessage()}"
    kind = error.GetType()
    if kind == UsdValidation.ValidationErrorType.Error:
        if _expected(error):
            report.allowed.append(text)
        else:
            report.errors.append(text)
    elif kind == UsdValidation.ValidationErrorType.Warn:
        report.warnings.append(text)


def _expected(error) -> bool:
    """A missing Sdr entry for a MaterialX or RenderMan id, and nothing else."""
    from pxr import UsdShade

    if ALLOWED not in str(error.GetIdentifier()):
        return False
    for site in error.GetSites():
        prim = site.GetProperty().GetPrim() if site.IsProperty() else site.GetPrim()
        if not prim or not prim.IsA(UsdShade.Shader):
            return False
        ident = UsdShade.Shader(prim).GetIdAttr().Get() or ""
        if not str(ident).startswith(FOREIGN_ID_PREFIXES):
            return False
    return True


def _check_mtlx(stage, report: Report) -> None:
    from . import mtlx
    from .stage_read import read_networks

    specs = [s for s in read_networks(stage) if any(n.context == "mtlx" for n in s.networks)]
    report.mtlx_networks = len(specs)
    if not specs:
        return
    try:
        doc = mtlx.document(specs, Path(stage.GetRootLayer().realPath).parent)
        problems = mtlx.validate_document(doc)
    except Exception as exc:  # a network MaterialX cannot even build
        problems = [f"cannot build a MaterialX document: {_first_line(exc)}"]
    report.errors += [f"MaterialX: {p}" for p in problems]


def _first_line(exc: BaseException) -> str:
    lines = [line.strip() for line in str(exc).splitlines() if line.strip()]
    return lines[-1] if lines else type(exc).__name__
