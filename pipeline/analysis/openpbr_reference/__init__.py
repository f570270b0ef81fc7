"""lookdev's OpenPBR model against Adobe's OpenPBR BSDF, an implementation it did not write.

Adobe's ``openpbr-bsdf`` (Apache 2.0) is the BSDF of Adobe's production renderer,
published as portable headers; it implements the specification's physical description
(a volume under the dielectric, tabulated energy compensation, Zeltner's fuzz), not the
mixture-of-lobes reduction, so it is the stricter reference of the three candidates: a
renderer's answer rather than a second derivation of the same reduction (MaterialX's
generated code is the reduction again; Mitsuba's draft BSDF is unmerged). The harness
``albedo.cpp`` beside this module is compiled against a checkout of it; its sampler gives
the directional albedo, split into the light leaving above (R) and below (T) the
surface, at the view angles of :data:`lookdev.pipeline.export.usd.fidelity.ANGLES`.

Compared: R + T (what either model scatters at all) and R alone (what an opaque view
shows). Adobe sends subsurface light *into* a volume (T), where the reduction reflects
it as a Lambertian (R): for materials with subsurface or transmission R differs by
construction, and the summary keeps opaque materials apart.
"""

from __future__ import annotations

import math
import shutil
import subprocess
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from lookdev.materials.arrays import NumpyOps
from lookdev.materials.errors import LookdevError
from lookdev.materials.openpbr import MODEL, OpenPBRParams

__all__ = [
    "Comparison",
    "ReferenceError",
    "build",
    "compare",
    "examples",
    "main",
    "model_albedo",
    "random_params",
    "reference_albedo",
    "summary",
]

HARNESS = Path(__file__).with_name("albedo.cpp")


class ReferenceError(LookdevError):
    """The reference cannot be built or run (no compiler, no checkout, no GLM)."""


def build(checkout: Path, out: Path) -> Path:
    """Compile the harness against ``checkout`` (a work tree of adobe/openpbr-bsdf)."""
    compiler = shutil.which("g++") or shutil.which("clang++")
    if compiler is None:
        raise ReferenceError("no C++ compiler (g++ or clang++) to build the reference")
    if not (checkout / "openpbr.h").is_file():
        raise ReferenceError(f"{checkout} is not a checkout of adobe/openpbr-bsdf")
    cmd = [compiler, "-O2", "-std=c++17", f"-I{checkout}", str(HARNESS), "-o", str(out)]
    done = subprocess.run(cmd, capture_output=True, text=True)
    if done.returncode != 0:
        first = (done.stderr.strip().splitlines() or ["failed"])[0]
        raise ReferenceError(f"building the reference failed: {first}")
    return out


def _line(name: str, params: OpenPBRParams) -> str:
    words = [name]
    for key, value in params.model_dump().items():
        if isinstance(value, tuple):
            words.append(f"{key}=" + ",".join(f"{float(v):.9g}" for v in value))
        else:
            words.append(f"{key}={float(value):.9g}")
    return " ".join(words)


def reference_albedo(
    binary: Path, materials: dict[str, OpenPBRParams], samples: int = 65536
) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """name → (R, T), each (angles, RGB), from the reference's own sampler."""
    text = "\n".join(_line(f"m{i}", p) for i, p in enumerate(materials.values())) + "\n"
    done = subprocess.run(
        [str(binary), str(samples)], input=text, capture_output=True, text=True, check=False
    )
    if done.returncode != 0:
        raise ReferenceError(f"the reference failed: {done.stderr.strip()[:200]}")
    rows: dict[str, list[list[float]]] = {}
    for line in done.stdout.splitlines():
        words = line.split()
        rows.setdefault(words[0], []).append([float(w) for w in words[2:]])
    out = {}
    for i, name in enumerate(materials):
        a = np.asarray(rows[f"m{i}"])
        out[name] = (a[:, :3], a[:, 3:])
    return out


def model_albedo(params: OpenPBRParams, samples: int = 65536) -> tuple[np.ndarray, np.ndarray]:
    """(R, T) of lookdev's OpenPBR model by its own sampler (fixed seed)."""
    from lookdev.pipeline.export.usd.fidelity import measure

    m = measure(MODEL, params, {}, samples=samples)
    # lookdev's BTDF carries radiance's 1/η² into a denser medium; the reference's
    # sampler weights carry energy: compare energies
    eta = MODEL.prepare(NumpyOps(), params).eta
    return m.reflected, m.transmitted * eta * eta


@dataclass(frozen=True)
class Comparison:
    """Per material: RMS and worst |difference| over angles × channels."""

    name: str
    rms_total: float
    worst_total: float
    rms_reflected: float
    worst_reflected: float
    opaque: bool

    def to_json(self) -> dict[str, Any]:
        return self.__dict__.copy()


def _stats(d: np.ndarray) -> tuple[float, float]:
    return float(np.sqrt(np.mean(d * d))), float(np.max(np.abs(d)))


def compare(binary: Path, materials: dict[str, OpenPBRParams], samples: int = 65536):
    """:class:`Comparison` per material, model against reference."""
    ref = reference_albedo(binary, materials, samples)
    out = []
    for name, p in materials.items():
        r, t = model_albedo(p, samples)
        rr, rt = ref[name]
        rms_t, worst_t = _stats((r + t) - (rr + rt))
        rms_r, worst_r = _stats(r - rr)
        opaque = p.transmission_weight == 0.0 and p.subsurface_weight == 0.0
        out.append(Comparison(name, rms_t, worst_t, rms_r, worst_r, opaque))
    return out


def random_params(n: int, seed: int = 26) -> dict[str, OpenPBRParams]:
    """``n`` materials with every BSDF input drawn uniformly over its range (IORs 1–3;
    thin film, emission, opacity and thin walls at their defaults, which neither side
    compares)."""
    rng = np.random.default_rng(seed)
    out = {}
    for i in range(n):

        def col() -> tuple[float, float, float]:
            return tuple(float(x) for x in rng.random(3))

        def on(p: float = 0.5) -> float:
            return float(rng.random()) if rng.random() < p else 0.0

        out[f"random_{i:03d}"] = OpenPBRParams(
            base_weight=float(rng.uniform(0.5, 1.0)),
            base_color=col(),
            base_metalness=on(0.4),
            base_diffuse_roughness=on(),
            specular_weight=float(rng.uniform(0.0, 1.0)),
            specular_color=col(),
            specular_roughness=float(rng.random()),
            specular_roughness_anisotropy=on(0.3),
            specular_ior=float(rng.uniform(1.0, 3.0)),
            transmission_weight=on(0.25),
            transmission_color=col(),
            subsurface_weight=on(0.25),
            subsurface_color=col(),
            coat_weight=on(),
            coat_color=col(),
            coat_roughness=float(rng.random()),
            coat_ior=float(rng.uniform(1.0, 3.0)),
            coat_darkening=float(rng.random()),
            fuzz_weight=on(0.3),
            fuzz_color=col(),
            fuzz_roughness=float(rng.random()),
        )
    return out


def summary(rows: list[Comparison]) -> dict[str, Any]:
    """Worst and RMS (over materials' RMS) of R + T and, for opaque materials, of R."""

    def agg(values: list[float]) -> dict[str, float]:
        return {"max": max(values), "rms": math.sqrt(sum(v * v for v in values) / len(values))}

    opaque = [r for r in rows if r.opaque]
    return {
        "materials": len(rows),
        "opaque": len(opaque),
        "total_rms": agg([r.rms_total for r in rows]),
        "total_worst": max(r.worst_total for r in rows),
        "opaque_reflected_rms": agg([r.rms_reflected for r in opaque]) if opaque else None,
        "opaque_reflected_worst": max((r.worst_reflected for r in opaque), default=None),
    }


def examples(folder: Path) -> dict[str, OpenPBRParams]:
    """The specification's example materials in ``folder`` (``open_pbr_*.mtlx``)."""
    from lookdev.pipeline.export.usd.openpbr_import import read_mtlx

    out = {}
    for path in sorted(folder.glob("open_pbr_*.mtlx")):
        for name, (params, _) in read_mtlx(path).items():
            out[path.stem.removeprefix("open_pbr_") or name] = params
    return out


def main(argv: list[str] | None = None) -> int:
    """``python -m lookdev.pipeline.analysis.openpbr_reference CHECKOUT EXAMPLES [N]``:
    the comparison as JSON (per material and the summary of each set)."""
    import json
    import sys
    import tempfile

    args = sys.argv[1:] if argv is None else argv
    checkout, folder = Path(args[0]), Path(args[1])
    n = int(args[2]) if len(args) > 2 else 65536
    with tempfile.TemporaryDirectory() as tmp:
        binary = build(checkout, Path(tmp) / "albedo")
        report = {}
        for label, materials in (("examples", examples(folder)), ("random", random_params(64))):
            rows = compare(binary, materials, n)
            report[label] = {"summary": summary(rows), "rows": [r.to_json() for r in rows]}
    print(json.dumps(report, indent=1))
    return 0
