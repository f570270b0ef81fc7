"""A Lambertian reflector written against the BSDF contract, for testing the analysis.

Independent of every shipped model, so the analysis tools can be checked against
closed forms: f = ρ/π, albedo ρ at every angle, sphere radiance ρ/π · N·L · E.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from lookdev.materials.bsdf import Model, Prepared
from lookdev.materials.params import Color, Params


class LambertParams(Params):
    base_color: Color = (0.8, 0.5, 0.2)


@dataclass(frozen=True, kw_only=True)
class LambertPrepared(Prepared):
    rho: Any  # the colour


def _prepare(xp, params, **maps):
    return LambertPrepared(
        lobes=("diffuse",), rho=xp.color(maps.get("base_color", params.base_color))
    )


def _eval(xp, prepared, wi, wo):
    upper = (wi[2] > 0) & (wo[2] > 0)
    return prepared.rho * xp.select(upper, 1.0 / math.pi, 0.0)


def _pdf(xp, prepared, wi, wo):
    return xp.select((wi[2] > 0) & (wo[2] > 0), wi[2] / math.pi, 0.0)


def _sample(xp, prepared, wo, u):
    # Malley's method: a uniform disk point lifted onto the hemisphere.
    r = xp.sqrt(u[1])
    phi = 2.0 * math.pi * u[2]
    z = xp.safe_sqrt(1.0 - u[1])
    wi = xp.vec3(r * xp.cos(phi), r * xp.sin(phi), z)
    ok = wo[2] > 0
    pdf = xp.select(ok, z / math.pi, 0.0)
    weight = prepared.rho * xp.select(ok, 1.0, 0.0)
    return wi, weight, pdf, False


LAMBERT = Model("lambert", LambertParams, _prepare, _eval, _pdf, _sample)


class PhongParams(Params):
    exponent: float = 50.0


def _mirror(xp, wo):
    return xp.vec3(-wo[0], -wo[1], wo[2])


def _phong_lobe(xp, exponent, wi, wo):
    cos_a = xp.maximum(xp.dot(wi, _mirror(xp, wo)), 0.0)
    return xp.power(cos_a, exponent) / (2.0 * math.pi)


@dataclass(frozen=True, kw_only=True)
class PhongPrepared(Prepared):
    n: float  # the exponent


def _phong_prepare(xp, params, **maps):
    return PhongPrepared(lobes=("phong",), n=params.exponent)


def _phong_eval(xp, prepared, wi, wo):
    n = prepared.n
    f = (n + 2.0) * _phong_lobe(xp, n, wi, wo) * xp.select((wi[2] > 0) & (wo[2] > 0), 1.0, 0.0)
    return xp.vec3(f, f, f)


def _phong_pdf(xp, prepared, wi, wo):
    n = prepared.n
    return (n + 1.0) * _phong_lobe(xp, n, wi, wo)


def _phong_sample(xp, prepared, wo, u):
    # Normalised Phong (Lafortune & Willems 1994): f = (n+2)/2π cos^n α around the mirror
    # direction r, sampled exactly in α with pdf (n+1)/2π cos^n α.
    n = prepared.n
    r = _mirror(xp, wo)
    cos_a = xp.power(u[1], 1.0 / (n + 1.0))
    sin_a = xp.safe_sqrt(1.0 - cos_a * cos_a)
    phi = 2.0 * math.pi * u[2]
    helper = xp.vec3(
        xp.select(xp.abs(r[0]) > 0.9, 0.0, 1.0), xp.select(xp.abs(r[0]) > 0.9, 1.0, 0.0), 0.0 * r[0]
    )
    t = xp.normalize(xp.cross(helper, r))
    b = xp.cross(r, t)
    wi = t * (sin_a * xp.cos(phi)) + b * (sin_a * xp.sin(phi)) + r * cos_a
    pdf = _phong_pdf(xp, prepared, wi, wo)
    ok = (wi[2] > 0) & (wo[2] > 0)
    w = xp.select(ok, (n + 2.0) / (n + 1.0) * wi[2], 0.0)
    return wi, xp.vec3(w, w, w), pdf, False


PHONG = Model("phong", PhongParams, _phong_prepare, _phong_eval, _phong_pdf, _phong_sample)
