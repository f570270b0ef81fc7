"""How a resolved material presents itself: a one-line ``repr``, a notebook's HTML, and
the parameter rows ``lookdev presets show --resolved`` prints.

Each parameter is shown with the file of the ``extends`` chain that set it (the child
wins), or ``default``. The notebook view adds a small rendered swatch when a renderer has
been registered (:func:`register_swatch`): rendering is the pipeline's business, and the
library, which the pipeline builds on, only knows that one may be available.
"""

from __future__ import annotations

import base64
import html
from collections.abc import Callable
from pathlib import Path
from typing import Any

__all__ = [
    "layer_rows",
    "mask_text",
    "material_html",
    "material_repr",
    "parameter_rows",
    "register_swatch",
    "set_by",
    "value_text",
]

_SWATCH: list[Callable[[Any], bytes]] = []


def register_swatch(render: Callable[[Any], bytes]) -> None:
    """Make ``render(material) -> PNG bytes`` draw the swatch of :func:`material_html`."""
    _SWATCH[:] = [render]


def value_text(v: Any) -> str:
    """A parameter value for people: 4 significant digits, colours as ``[r, g, b]``.

    >>> value_text((1.0, 0.766, 0.336)), value_text(0.25), value_text(True)
    ('[1, 0.766, 0.336]', '0.25', 'True')
    """
    if isinstance(v, tuple | list):
        return "[" + ", ".join(f"{x:.4g}" for x in v) + "]"
    return f"{v:.4g}" if isinstance(v, float) else str(v)


def mask_text(mask: Any) -> str:
    """A mask tree as a call expression: ``levels(noise(scale=6.0, seed=7), low=0.42)``."""
    from lookdev.materials.layers import children

    fields = mask.model_dump(
        mode="json", exclude_defaults=True, exclude={"kind", "input", "inputs"}
    )
    if "path" in fields:
        fields["path"] = Path(fields["path"]).name
    args = [mask_text(c) for c in children(mask)] + [f"{k}={v}" for k, v in fields.items()]
    return f"{mask.kind}({', '.join(args)})"


def parameter_rows(m: Any) -> list[tuple[str, str, str]]:
    """(parameter, value, set by) of a non-layered material: the file of the ``extends``
    chain that gave each value, ``(from ior)`` for a Disney specular given as ``ior``,
    ``default`` for the rest; textured parameters name their texture."""
    origin = {k: p.name for k, p in set_by(m).items()}
    values = m.params.model_dump()
    if getattr(m.params, "uses_ior", False):  # Disney: one parameter, two spellings
        values["specular"], origin["specular"] = m.params.effective_specular, "(from ior)"
    values |= {k: f"texture {t.texture}" for k, t in m.textures.items()}
    return [(k, value_text(v), origin.get(k, "default")) for k, v in values.items()]


def set_by(material: Any) -> dict[str, Path]:
    """For each parameter a file of the extends chain gives: the file that wins (the child's)."""
    from .preset import read_preset

    out: dict[str, Path] = {}
    for path in material.chain:
        out |= {key: path for key in read_preset(path).params if key not in out}
    return out


def layer_rows(m: Any) -> list[tuple[str, ...]]:
    """(#, layer, material, model, mask, presence) of a layered material, bottom first."""
    return [
        (str(i), layer.name or "", layer.material.name, layer.material.model,
         mask_text(layer.mask), value_text(layer.presence))
        for i, layer in enumerate(m.layers)
    ]  # fmt: skip


def material_repr(m: Any) -> str:
    """``<Material gold: disney, 23 parameters from gold.toml>``: one short line.

    The parent, when the chain has one, and the layers of a layered material are named.
    """
    chain = [p.name for p in m.chain]
    if m.params is None:
        what = f"layered, {len(m.layers)} layers: {', '.join(_layer_names(m))}"
    else:
        what = f"{m.model}, {len(type(m.params).model_fields)} parameters"
    where = f" from {' ← '.join(chain)}" if chain else ""
    return f"<Material {m.name}: {what}{where}>"


def _layer_names(m: Any) -> list[str]:
    names = [layer.name or layer.material.name for layer in m.layers]
    return names if len(names) <= 4 else [*names[:3], f"… {len(names) - 3} more"]


def material_html(m: Any) -> str:
    """A notebook's view of ``m``: name, description, the ``extends`` chain, a swatch, and
    the parameters (or layers) with the file that set each. Names are escaped."""
    esc = html.escape
    head = f"<b>{esc(m.name)}</b> <i>({esc(m.model)})</i>"
    if m.description:
        head += f"<br>{esc(m.description)}"
    if m.chain:
        head += "<br><small>extends chain, child first: "
        head += " ← ".join(f"<code>{esc(str(p))}</code>" for p in m.chain) + "</small>"
    if m.params is None:
        columns = ("#", "layer", "material", "model", "mask", "presence")
        rows = layer_rows(m)
    else:
        columns, rows = ("parameter", "value", "set by"), parameter_rows(m)
    table = "<table><thead><tr>" + "".join(f"<th>{c}</th>" for c in columns) + "</tr></thead>"
    table += "<tbody>" + "".join(
        "<tr>" + "".join(f"<td>{esc(c)}</td>" for c in row) + "</tr>" for row in rows
    )
    table += "</tbody></table>"
    return (
        '<div class="lookdev-material" style="display:flex;gap:12px;align-items:flex-start">'
        f"{_swatch(m)}<div>{head}{table}</div></div>"
    )


def _swatch(m: Any) -> str:
    if not _SWATCH:
        return ""
    from lookdev.materials.errors import LookdevError

    try:
        png = _SWATCH[0](m)
    except LookdevError as exc:  # a texture that cannot be read: the table still shows
        return f"<small>no swatch: {html.escape(str(exc))}</small>"
    data = base64.b64encode(png).decode("ascii")
    return f'<img alt="{html.escape(m.name)} swatch" src="data:image/png;base64,{data}">'
