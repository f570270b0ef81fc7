"""``mitsuba.chi2`` on the whole sphere, and zoomed onto a narrow peak.

Mitsuba's ``SphericalDomain`` bins (φ, cos θ) uniformly: a lobe with α ≲ 0.05 falls into
one or two cells (at the pole into a single cap), and the per-cell trapezoid integral of
the pdf cannot resolve it, so the test would reject correct sampling. :class:`ZoomDomain`
charts a cone around the peak's axis with Lambert's azimuthal equal-area projection, so
the same test sees the peak at any width: the chart is equal-area up to the constant
factor s², dω = s² dx dy, and samples outside the cone count with weight 0 (the test then
compares the conditional distributions inside it).
"""

from __future__ import annotations

import math

import drjit as dr
import mitsuba as mi
from mitsuba.chi2 import BSDFAdapter, ChiSquareTest, SphericalDomain


def _normalised(v):
    n = math.sqrt(sum(float(c) ** 2 for c in v))
    return [float(c) / n for c in v]


class ZoomDomain:
    """The cone of half-angle ``radius`` around ``axis`` as the square [-1, 1]²."""

    def __init__(self, axis, radius: float):
        self.axis = mi.Vector3f(*(float(c) for c in _normalised(axis)))
        self.frame = mi.Frame3f(self.axis)
        self.s = 2.0 * math.sin(radius / 2.0)  # planar radius ρ = 2 sin(θ/2) at |p| = 1

    def bounds(self):
        return mi.ScalarBoundingBox2f([-1.0, -1.0], [1.0, 1.0])

    def aspect(self):
        return 1.0

    def map_forward(self, p):
        rho2 = (p.x * p.x + p.y * p.y) * self.s**2
        k = self.s * dr.safe_sqrt(1.0 - rho2 / 4.0)  # sin θ / |p|
        return self.frame.to_world(mi.Vector3f(p.x * k, p.y * k, 1.0 - rho2 / 2.0))

    def map_backward(self, d):
        local = self.frame.to_local(d)
        f = dr.sqrt(2.0 / (1.0 + local.z)) / self.s  # ρ / sin θ / s
        return mi.Vector2f(local.x * f, local.y * f)

    def restrict(self, sample, pdf):
        """Sampling and density functions of the conditional distribution in the chart."""

        def sample_inside(u):
            wo, weight = sample(u)
            xy = self.map_backward(wo)
            inside = (dr.abs(xy.x) <= 1) & (dr.abs(xy.y) <= 1) & (self.frame.to_local(wo).z > 0)
            return dr.select(inside, wo, self.axis), dr.select(inside, weight, 0.0)

        return sample_inside, lambda wo: pdf(wo) * self.s**2


def _sample_counting_zero_values(bsdf: dict, wi, ctx):
    """Like ``BSDFAdapter``'s sampler, but a direction drawn with a density counts even
    where the BSDF's value is 0 there: ``BSDFAdapter`` drops those (weight 0), which is
    right for the delta lobes the context leaves out (their pdf is 0 too) and wrong for a
    uniform sampler of a lobe that underflows to 0 over most of the sphere (the exact-Λ
    sheen at r = 0.01: sin^100 θ is 0 in float32 below θ ≈ 50°)."""
    plugin = mi.load_dict(bsdf)

    def sample(u):
        si = dr.zeros(mi.SurfaceInteraction3f, dr.width(u))
        si.wi = mi.Vector3f(*(float(c) for c in wi))
        bs, _ = plugin.sample(ctx, si, u[0], mi.Vector2f(u[1], u[2]))
        return bs.wo, dr.select(bs.pdf > 0, 1.0, 0.0)

    return sample


def chi2(
    bsdf: dict,
    wi,
    *,
    axis=None,
    radius=None,
    test_count=1,
    sample_count=200_000,
    res=60,
    ires=8,
    count_zero_values=False,
):
    """Run the test for a BSDF dict seen from ``wi``; zoomed when ``axis`` is given.

    ``res`` is even so that on the whole sphere the horizon (cos θ = 0, where densities
    of one-sided lobes jump to zero) is a cell boundary, not the middle of a row of cells
    whose trapezoid integral would smear the jump. ``test_count`` is the number of tests
    in the family, for Šidák's correction of the 1 % significance level (as Mitsuba's own
    test suite does): a hundred correct tests at 1 % would otherwise reject one.
    """
    # Delta lobes (smooth glass, mirrors) have no density: the context leaves them out,
    # so their samples weigh 0 and the test compares the lobes that have one (their
    # share of the samples is then the pdf's integral, as it should be).
    ctx = mi.BSDFContext(mi.TransportMode.Radiance, mi.BSDFFlags.Smooth)
    sample, pdf = BSDFAdapter(bsdf["type"], bsdf, wi=[float(c) for c in wi], ctx=ctx)
    if count_zero_values:
        sample = _sample_counting_zero_values(bsdf, wi, ctx)
    domain = SphericalDomain()
    if axis is not None:
        domain = ZoomDomain(axis, radius)
        sample, pdf = domain.restrict(sample, pdf)
    test = ChiSquareTest(
        domain=domain,
        sample_func=sample,
        pdf_func=pdf,
        sample_dim=3,
        sample_count=sample_count,
        res=res,
        ires=ires,
    )
    return test.run(significance_level=0.01, test_count=test_count, quiet=True), test
