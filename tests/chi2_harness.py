"""Chi-square goodness of fit of a model's ``sample`` against its own ``pdf``.

Works for any :class:`~lookdev.materials.bsdf.Model` through the public numpy wrappers
(:func:`~lookdev.materials.bsdf.draw`, :func:`~lookdev.materials.bsdf.density`), in the
manner of Mitsuba's ``mitsuba.chi2`` (itself after Wenzel Jakob's original test):

1. The sphere is cut into ``res`` bins in cos θ ∈ [−1, 1] by ``2·res`` bins in φ: equal
   solid angle per bin, since dω = d(cos θ) dφ.
2. The expected count of a bin is ``n · ∫ pdf dω`` over it, integrated independently of
   the sampler by adaptive tensor Gauss-Legendre quadrature: a cell is split in four until
   its estimate agrees with its children's, so even the α = 10⁻³ lobe is resolved. A cell
   that holds samples but whose quadrature sees almost nothing (the peak fell between the
   nodes) is split too.
3. Samples with pdf 0 are failures, and so are delta-lobe samples (no density); their
   count is compared against ``n · (1 − ∫ pdf)`` as one more bin, so a sampler that
   loses or invents mass fails.
4. Bins expecting fewer than ``min_expected`` samples are pooled into one; Pearson's
   statistic is compared with the χ² distribution (scipy) at significance ``alpha``.

>>> from _lambert import LAMBERT, LambertParams
>>> chi2_test(LAMBERT, LambertParams(), (0.0, 0.0, 1.0), n_samples=20_000, res=8)[0]
True
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy import stats

from lookdev.materials.bsdf import Model, density, draw

TWO_PI = 2.0 * math.pi


@dataclass(frozen=True)
class Chi2Result:
    """Everything a failing test wants to print."""

    passed: bool
    p_value: float
    statistic: float
    dof: int
    observed: np.ndarray  # (res, 2·res) histogram of valid samples
    expected: np.ndarray  # (res, 2·res) integrated pdf × n
    failures: int
    expected_failures: float


def chi2_test(
    model: Model,
    params: Any,
    wo: Any,
    n_samples: int = 200_000,
    res: int = 16,
    *,
    alpha: float = 0.01,
    seed: int = 0,
    **maps: Any,
) -> tuple[bool, float]:
    """``(passed, p_value)`` of the χ² test of ``model.sample`` against ``model.pdf``."""
    r = chi2_details(model, params, wo, n_samples, res, alpha=alpha, seed=seed, **maps)
    return r.passed, r.p_value


def chi2_details(
    model: Model,
    params: Any,
    wo: Any,
    n_samples: int = 200_000,
    res: int = 16,
    *,
    alpha: float = 0.01,
    seed: int = 0,
    min_expected: float = 5.0,
    **maps: Any,
) -> Chi2Result:
    """The full χ² result; see :func:`chi2_test`."""
    wo = np.asarray(wo, dtype=np.float64)
    wo = wo / np.linalg.norm(wo)
    u = np.random.default_rng(seed).random((n_samples, 3))
    wi, _, pdf, delta = draw(model, params, wo, u, delta=True, **maps)
    # Delta-lobe samples have no density: they count with the failures, so the test
    # checks that their share is the mass the pdf leaves out.
    ok = (pdf > 0) & ~delta & np.all(np.isfinite(wi), axis=-1)
    c, p = _sphere_coords(wi[ok])
    observed = _histogram(c, p, res, 2 * res)

    def pdf_at(cos_t: np.ndarray, phi: np.ndarray) -> np.ndarray:
        s = np.sqrt(np.maximum(0.0, 1.0 - cos_t * cos_t))
        d = np.stack([s * np.cos(phi), s * np.sin(phi), cos_t], axis=-1)
        return density(model, params, d, wo, **maps)

    integral = _integrate_bins(pdf_at, res, c, p, tol=1e-3 / n_samples)
    expected = n_samples * integral
    failures = int(n_samples - ok.sum())
    expected_failures = max(0.0, n_samples - float(expected.sum()))

    obs = np.append(observed.ravel(), failures)
    exp = np.append(expected.ravel(), expected_failures)
    stat, dof = _pearson(obs, exp, min_expected)
    p_value = float(stats.chi2.sf(stat, dof)) if dof > 0 else 1.0
    return Chi2Result(
        p_value > alpha, p_value, stat, dof, observed, expected, failures, expected_failures
    )


def _sphere_coords(d: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    return np.clip(d[:, 2], -1.0, 1.0), np.mod(np.arctan2(d[:, 1], d[:, 0]), TWO_PI)


def _histogram(c: np.ndarray, p: np.ndarray, n_c: int, n_p: int) -> np.ndarray:
    ic = np.minimum(((c + 1.0) * 0.5 * n_c).astype(np.int64), n_c - 1)
    ip = np.minimum((p / TWO_PI * n_p).astype(np.int64), n_p - 1)
    return np.bincount(ic * n_p + ip, minlength=n_c * n_p).reshape(n_c, n_p).astype(float)


def _pearson(obs: np.ndarray, exp: np.ndarray, min_expected: float) -> tuple[float, int]:
    """Pearson's statistic with low-expectation bins pooled into one."""
    big = exp >= min_expected
    o = list(obs[big])
    e = list(exp[big])
    if (~big).any() and exp[~big].sum() > 0:
        o.append(obs[~big].sum())
        e.append(exp[~big].sum())
    elif obs[~big].sum() > 0:
        # Samples where the pdf integrates to nothing: the sampler is plainly wrong.
        return math.inf, max(1, len(o))
    o_, e_ = np.asarray(o), np.asarray(e)
    return float(np.sum((o_ - e_) ** 2 / e_)), len(o) - 1


_GL_X, _GL_W = np.polynomial.legendre.leggauss(4)


def _gauss_cells(pdf_at, cells: np.ndarray) -> np.ndarray:
    """∫ pdf over each cell (c0, c1, p0, p1) by the 4×4 Gauss-Legendre product rule."""
    c0, c1, p0, p1 = cells.T
    hc, hp = 0.5 * (c1 - c0), 0.5 * (p1 - p0)
    cc = (0.5 * (c0 + c1))[:, None, None] + hc[:, None, None] * _GL_X[None, :, None]
    pp = (0.5 * (p0 + p1))[:, None, None] + hp[:, None, None] * _GL_X[None, None, :]
    cc, pp = np.broadcast_arrays(cc, pp)
    vals = pdf_at(cc.ravel(), pp.ravel()).reshape(cc.shape)
    return np.einsum("nij,i,j->n", vals, _GL_W, _GL_W) * hc * hp


def _halves(cells: np.ndarray, axis: int) -> np.ndarray:
    """Each cell → its two halves along cos θ (axis 0) or φ (axis 1), as rows 2k, 2k+1."""
    lo, hi = cells[:, 2 * axis], cells[:, 2 * axis + 1]
    mid = 0.5 * (lo + hi)
    a, b = cells.copy(), cells.copy()
    a[:, 2 * axis + 1] = mid
    b[:, 2 * axis] = mid
    return np.stack([a, b], axis=1).reshape(-1, 4)


def _counts_in(cells: np.ndarray, c: np.ndarray, p: np.ndarray) -> np.ndarray:
    """Number of samples inside each cell (cells may be few; samples many)."""
    order = np.argsort(c)
    cs, ps = c[order], p[order]
    lo = np.searchsorted(cs, cells[:, 0], side="left")
    hi = np.searchsorted(cs, cells[:, 1], side="left")
    out = np.zeros(len(cells))
    for k in np.nonzero(hi > lo)[0]:
        sel = ps[lo[k] : hi[k]]
        out[k] = np.count_nonzero((sel >= cells[k, 2]) & (sel < cells[k, 3]))
    return out


def _integrate_bins(
    pdf_at, res: int, c: np.ndarray, p: np.ndarray, *, tol: float, max_depth: int = 40
) -> np.ndarray:
    """∫ pdf over every bin, by adaptive quadrature (see the module docstring).

    A cell is halved along the axis whose halving changes its estimate most, so a peak
    at the pole (narrow in cos θ only) costs two cells per level, not four.
    """
    n_c, n_p = res, 2 * res
    ec = np.linspace(-1.0, 1.0, n_c + 1)
    ep = np.linspace(0.0, TWO_PI, n_p + 1)
    ic, ip = np.meshgrid(np.arange(n_c), np.arange(n_p), indexing="ij")
    cells = np.stack([ec[ic], ec[ic + 1], ep[ip], ep[ip + 1]], axis=-1).reshape(-1, 4)
    owner = np.arange(n_c * n_p)
    coarse = _gauss_cells(pdf_at, cells)
    total = np.zeros(n_c * n_p)
    n = max(len(c), 1)
    for depth in range(max_depth):
        kids = [_halves(cells, axis) for axis in (0, 1)]
        fine = [_gauss_cells(pdf_at, k) for k in kids]
        sums = [f.reshape(-1, 2).sum(axis=1) for f in fine]
        err = [np.abs(s - coarse) for s in sums]
        converged = np.maximum(err[0], err[1]) <= tol
        if depth < max_depth - 1 and len(cells) < 50_000:
            # A cell with samples its quadrature cannot see: the peak fell between nodes.
            seen = _counts_in(cells, c, p)
            converged &= ~((seen >= 3) & (sums[0] * n < 0.1 * seen))
        else:
            converged[:] = True
        np.add.at(total, owner[converged], sums[0][converged])
        if converged.all():
            break
        axis = (err[1] > err[0]).astype(int)
        keep = ~converged
        pick = np.where(axis[keep, None] == 1, 1, 0)
        both_kids = np.stack([k.reshape(-1, 2, 4) for k in kids], axis=1)  # (m, axis, 2, 4)
        both_fine = np.stack([f.reshape(-1, 2) for f in fine], axis=1)  # (m, axis, 2)
        idx = np.nonzero(keep)[0]
        cells = both_kids[idx, pick[:, 0]].reshape(-1, 4)
        coarse = both_fine[idx, pick[:, 0]].reshape(-1)
        owner = np.repeat(owner[idx], 2)
    return total.reshape(n_c, n_p)
