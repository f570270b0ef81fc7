"""The measured size of each Disney → OpenPBR loss (:data:`.openpbr_map.LOSSES`).

Each loss is measured on a material where its term is on and as little else as
possible: a base material (grey 0.5, roughness 0.4, Burley's defaults) with the term's
parameters set, Burley's model against the OpenPBR model of the mapped values
(:func:`~lookdev.pipeline.export.usd.openpbr_map.openpbr_values`), directional albedo
0–85° (RMS and worst over angles × channels) and the 30° highlight's energy ratio. The
base material's own difference (the diffuse and the specular terms, always on for a
dielectric) is the first row, so a term's own share is its row less the base's.

``python -m lookdev.pipeline.analysis.openpbr_losses`` prints the table as JSON.
"""

from __future__ import annotations

from typing import Any

from lookdev.materials.openpbr import MODEL as OPENPBR
from lookdev.materials.params import DisneyParams
from lookdev.materials.registry import MODELS

__all__ = ["CASES", "term_losses"]

BASE = {"base_color": (0.5, 0.5, 0.5), "roughness": 0.4}
CASES: dict[str, dict[str, Any]] = {
    "diffuse+specular (base)": {},
    "diffuse at roughness 1": {"roughness": 1.0},
    "specular 1": {"specular": 1.0},
    "specular_tint": {"base_color": (0.8, 0.3, 0.1), "specular_tint": 1.0},
    "metallic": {"base_color": (0.9, 0.6, 0.3), "metallic": 1.0},
    "metallic, roughness 0.1": {"base_color": (0.9, 0.6, 0.3), "metallic": 1.0, "roughness": 0.1},
    "metallic 0.5 + specular_tint": {
        "base_color": (0.9, 0.6, 0.3),
        "metallic": 0.5,
        "specular_tint": 1.0,
    },
    "anisotropic": {"metallic": 1.0, "anisotropic": 0.8},
    "clearcoat": {"clearcoat": 1.0, "clearcoat_gloss": 0.9},
    "sheen (Burley)": {"sheen": 1.0},
    "sheen (Conty-Kulla)": {"sheen": 1.0, "sheen_model": "conty_kulla", "sheen_roughness": 0.3},
    "spec_trans": {"spec_trans": 1.0, "roughness": 0.1},
    "diff_trans (thin)": {"diff_trans": 0.6, "thin": True},
    "scatter_distance": {"diff_trans": 1.0, "scatter_distance": 0.01},
    "flatness (thin)": {"flatness": 1.0, "thin": True},
    "subsurface (2012)": {"subsurface": 1.0},
}
"""Case → the Disney parameters set over :data:`BASE`."""


def term_losses(samples: int = 16384) -> list[dict[str, Any]]:
    """One row per case: albedo RMS and worst, and the highlight energy ratio."""
    from lookdev.pipeline.export.usd.fidelity import compared, measure
    from lookdev.pipeline.export.usd.lobes import active_lobes, canonical, effective
    from lookdev.pipeline.export.usd.openpbr_import import params_from_values
    from lookdev.pipeline.export.usd.openpbr_map import losses_of, openpbr_values

    rows = []
    for name, changes in CASES.items():
        disney = DisneyParams(**{**BASE, **changes})
        values = canonical(disney)
        lobes = active_lobes(values)
        live = effective(values, "disney", lobes)
        mapped = openpbr_values(live, lobes)
        params, _ = params_from_values(mapped, name)
        src = measure(MODELS["disney"], disney, {}, samples=samples)
        got = measure(OPENPBR, params, {}, samples=samples)
        f = compared(name, src, got)
        rows.append(
            {
                "case": name,
                "losses": [loss.name for loss in losses_of(live, lobes)],
                "rms": round(f.rms, 4),
                "worst": round(f.worst, 4),
                "worst_at": f.worst_at,
                "highlight_ratio": round(f.highlight_ratio, 3),
            }
        )
    return rows


if __name__ == "__main__":
    import json

    print(json.dumps(term_losses(), indent=1))
