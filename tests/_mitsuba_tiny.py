"""A tiny two-lobe Model for the Mitsuba adapter tests, independent of every shipped model.

A Lambertian reflector with a diffuse transmission lobe (weight ``translucency``) whose
value also depends on the viewer, so swapping Mitsuba's direction names wrongly would
show. ``prepare`` records the lobes it keeps, as the shipped models do.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from pydantic import Field

from lookdev.materials.bsdf import Lobe, Model, Prepared
from lookdev.materials.params import Color, Params


class TinyParams(Params):
    base_color: Color = (0.8, 0.5, 0.2)
    translucency: float = Field(0.0, ge=0.0, le=1.0)


@dataclass(frozen=True, kw_only=True)
class TinyPrepared(Prepared):
    rho: Any  # the colour
    t: Any  # the transmitted share


def _lobe_weight(xp, p, wi, wo):
    same = wi[2] * wo[2] > 0
    if "diff_trans" not in p.lobes:
        return xp.select(same, 1.0, 0.0)
    return xp.select(same, 1.0 - p.t, p.t)


def _prepare(xp, params, **maps):
    t = maps.get("translucency", params.translucency)
    lobes = ("diffuse",) if xp.known_zero(t) else ("diffuse", "diff_trans")
    return TinyPrepared(lobes=lobes, rho=xp.color(maps.get("base_color", params.base_color)), t=t)


def _view_factor(xp, wo):
    # Depends on the viewer only: non-reciprocal on purpose.
    return 0.5 + 0.5 * xp.abs(wo[2])


def _eval(xp, p, wi, wo):
    return p.rho * (_lobe_weight(xp, p, wi, wo) * _view_factor(xp, wo) / math.pi)


def _pdf(xp, p, wi, wo):
    return _lobe_weight(xp, p, wi, wo) * xp.abs(wi[2]) / math.pi


def _sample(xp, p, wo, u):
    r = xp.sqrt(u[1])
    phi = 2.0 * math.pi * u[2]
    side = xp.select(wo[2] >= 0, 1.0, -1.0)
    if "diff_trans" in p.lobes:
        side = xp.select(u[0] < p.t, -side, side)
    wi = xp.vec3(r * xp.cos(phi), r * xp.sin(phi), xp.safe_sqrt(1.0 - u[1]) * side)
    return wi, p.rho * _view_factor(xp, wo), _pdf(xp, p, wi, wo), False


LOBES = (Lobe("diffuse", "diffuse"), Lobe("diff_trans", "diffuse", transmits=True))
TINY = Model("tiny_test", TinyParams, _prepare, _eval, _pdf, _sample, lobes=LOBES)
