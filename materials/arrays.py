"""The array shim: one model implementation, two array backends (:doc:`/design`).

Every reflectance model in :mod:`lookdev.materials` is written once against the small
namespace defined here, passed as ``xp`` to the model's core functions:

* :class:`NumpyOps` serves analysis, plots and tests (float64 by default, float32 too);
* :class:`DrJitOps` serves the Mitsuba BSDF plugins, so a proof renders exactly the
  model the plots describe.

Conventions inside model code (the public ``eval``/``sample``/``pdf`` wrappers convert at
the boundary):

* A *vector* or *colour* is channel-first: ``v[0], v[1], v[2]`` are its components. With
  numpy that is an array of shape ``(3, N)`` (or ``(3, 1)`` for a constant colour), with
  Dr.Jit an ``Array3f``. A *scalar field* is shape ``(N,)``, a Dr.Jit ``Float``, or a
  Python float. Scalar fields times colours then broadcast the same way on both backends.
* Branches are written with :meth:`select`, never with ``if`` on array values. Python
  ``if`` is only for things known when the code is traced (a lobe weight that is a
  constant zero, a flag such as ``thin``).

Example:

>>> import numpy as np
>>> xp = NumpyOps()
>>> v = xp.vec3(np.array([3.0]), np.array([0.0]), np.array([4.0]))
>>> xp.normalize(v)[:, 0].tolist()
[0.6, 0.0, 0.8]
>>> float(xp.log1p(np.float64(1e-20)))
1e-20
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

__all__ = ["DrJitOps", "INV_PI", "NumpyOps", "from_channel_first", "to_channel_first"]

INV_PI = 1.0 / math.pi


class NumpyOps:
    """numpy backend. ``dtype`` is the float type every array is kept in."""

    name = "numpy"

    def __init__(self, dtype: Any = np.float64):
        self.dtype = np.dtype(dtype)
        info = np.finfo(self.dtype)
        self.epsilon = float(info.eps)
        self.tiny = float(info.tiny)
        self.max = float(info.max)

    def __repr__(self) -> str:
        return f"NumpyOps({self.dtype.name})"

    # -- construction ------------------------------------------------------------------
    def asarray(self, x: Any) -> np.ndarray:
        return np.asarray(x, dtype=self.dtype)

    def scalar(self, x: Any) -> Any:
        """A scalar parameter: a Python float stays one, an array becomes this dtype."""
        return float(x) if np.ndim(x) == 0 else self.asarray(x)

    def vec3(self, x: Any, y: Any, z: Any) -> np.ndarray:
        return np.stack(np.broadcast_arrays(*(self.asarray(c) for c in (x, y, z))))

    def color(self, c: Any) -> np.ndarray:
        """A colour parameter: shape (3,) becomes (3, 1); a per-element (3, N) stays."""
        a = self.asarray(c)
        return a.reshape(3, 1) if a.ndim == 1 else a

    def zeros(self, like: Any) -> np.ndarray:
        return np.zeros_like(self.asarray(like))

    def full(self, like: Any, value: float) -> np.ndarray:
        return np.full_like(self.asarray(like), value)

    # -- elementwise -------------------------------------------------------------------
    sqrt = staticmethod(np.sqrt)
    exp = staticmethod(np.exp)
    log = staticmethod(np.log)
    log1p = staticmethod(np.log1p)
    expm1 = staticmethod(np.expm1)
    sin = staticmethod(np.sin)
    cos = staticmethod(np.cos)
    tan = staticmethod(np.tan)
    atan = staticmethod(np.arctan)
    atan2 = staticmethod(np.arctan2)
    abs = staticmethod(np.abs)
    sign = staticmethod(np.sign)
    copysign = staticmethod(np.copysign)
    minimum = staticmethod(np.minimum)
    maximum = staticmethod(np.maximum)
    isfinite = staticmethod(np.isfinite)
    floor = staticmethod(np.floor)

    @staticmethod
    def power(x: Any, y: Any) -> Any:
        return np.power(x, y)

    def safe_sqrt(self, x: Any) -> Any:
        return np.sqrt(np.maximum(x, 0))

    def acos(self, x: Any) -> Any:
        return np.arccos(np.clip(x, -1, 1))

    @staticmethod
    def clip(x: Any, lo: Any, hi: Any) -> Any:
        return np.clip(x, lo, hi)

    @staticmethod
    def select(cond: Any, a: Any, b: Any) -> Any:
        return np.where(cond, a, b)

    @staticmethod
    def lerp(a: Any, b: Any, t: Any) -> Any:
        return a + (b - a) * t

    # -- vectors -----------------------------------------------------------------------
    @staticmethod
    def dot(a: Any, b: Any) -> Any:
        return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]

    def cross(self, a: Any, b: Any) -> Any:
        return self.vec3(
            a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]
        )

    def norm(self, v: Any) -> Any:
        return np.sqrt(self.dot(v, v))

    def normalize(self, v: Any) -> Any:
        """Unit vector; the zero vector stays zero instead of becoming NaN."""
        n = self.norm(v)
        return v / np.where(n > 0, n, 1)

    # -- pruning -----------------------------------------------------------------------
    @staticmethod
    def known_zero(x: Any) -> bool:
        """True when ``x`` is zero everywhere, so a lobe it weights can be skipped."""
        return bool(np.all(np.asarray(x) == 0))


class DrJitOps:
    """Dr.Jit backend over a Mitsuba variant's types (``mi.Float``, ``mi.Vector3f`` …).

    Built with :meth:`for_mitsuba` after ``mi.set_variant``. Python floats pass through
    untouched, so constant parameters fold into the traced kernel.
    """

    name = "drjit"

    def __init__(self, Float: Any, Array3: Any, Bool: Any):
        import drjit as dr

        self.dr = dr
        self.Float = Float
        self.Array3 = Array3
        self.Bool = Bool
        self.epsilon = float(np.finfo(np.float32).eps)
        self.tiny = float(np.finfo(np.float32).tiny)
        self.max = float(np.finfo(np.float32).max)

    @classmethod
    def for_mitsuba(cls) -> DrJitOps:
        import mitsuba as mi

        return cls(mi.Float, mi.Vector3f, mi.Bool)

    def __repr__(self) -> str:
        return f"DrJitOps({self.Float.__name__})"

    # -- construction ------------------------------------------------------------------
    def asarray(self, x: Any) -> Any:
        return self.Float(x)

    def scalar(self, x: Any) -> Any:
        return float(x) if isinstance(x, int | float) else x

    def vec3(self, x: Any, y: Any, z: Any) -> Any:
        return self.Array3(x, y, z)

    def color(self, c: Any) -> Any:
        if isinstance(c, list | tuple | np.ndarray):
            return self.Array3(*(float(v) for v in c))
        return c

    def zeros(self, like: Any) -> Any:
        return (
            self.dr.zeros(type(like), self.dr.width(like))
            if not isinstance(like, int | float)
            else 0.0
        )

    def full(self, like: Any, value: float) -> Any:
        return (
            self.dr.full(type(like), value, self.dr.width(like))
            if not isinstance(like, int | float)
            else float(value)
        )

    # -- elementwise -------------------------------------------------------------------
    def __getattr__(self, name: str) -> Any:
        # sqrt, exp, log, sin, cos, tan, atan, atan2, abs, sign, copysign, minimum,
        # maximum, isfinite, floor, select, lerp, dot, cross, normalize, norm, clip:
        # Dr.Jit spells them the same way.
        if name in _DRJIT_SAME_NAME:
            return getattr(self.dr, name)
        raise AttributeError(name)

    def power(self, x: Any, y: Any) -> Any:
        return self.dr.power(x, y)

    def safe_sqrt(self, x: Any) -> Any:
        return self.dr.safe_sqrt(x)

    def acos(self, x: Any) -> Any:
        return self.dr.safe_acos(x)

    def log1p(self, x: Any) -> Any:
        # Dr.Jit has no log1p: Goldberg's trick makes log(1 + x) exact to a few ulp.
        if isinstance(x, int | float):
            return math.log1p(x)
        dr = self.dr
        u = 1.0 + x
        return dr.select(u == 1.0, x, dr.log(u) * x / (u - 1.0))

    def expm1(self, x: Any) -> Any:
        # Kahan's trick for exp(x) - 1, stable near zero.
        if isinstance(x, int | float):
            return math.expm1(x)
        dr = self.dr
        u = dr.exp(x)
        return dr.select(u == 1.0, x, dr.select(u - 1.0 == -1.0, -1.0, (u - 1.0) * x / dr.log(u)))

    def known_zero(self, x: Any) -> bool:
        """True for a Python zero and for a Dr.Jit *literal* zero (a constant such as a
        black colour folded into the kernel); an evaluated or opaque array never counts,
        since reading it would launch a kernel while the plugin is being traced."""
        if isinstance(x, int | float):
            return x == 0
        parts = [x[i] for i in range(len(x))] if isinstance(x, self.Array3) else [x]
        literal = self.dr.VarState.Literal
        return all(getattr(p, "state", None) == literal and p[0] == 0 for p in parts)


_DRJIT_SAME_NAME = frozenset(
    "sqrt exp log sin cos tan atan atan2 abs sign copysign minimum maximum isfinite floor "
    "select lerp dot cross normalize norm clip".split()
)


def to_channel_first(v: Any, dtype: Any = np.float64) -> tuple[np.ndarray, tuple[int, ...]]:
    """(..., 3) user array → ((3, N) array, leading shape), for the public wrappers."""
    a = np.asarray(v, dtype=dtype)
    if a.shape[-1:] != (3,):
        raise ValueError(f"expected an array of shape (..., 3), got {a.shape}")
    lead = a.shape[:-1]
    return a.reshape(-1, 3).T, lead


def from_channel_first(v: Any, lead: tuple[int, ...]) -> np.ndarray:
    """(3, N) or (N,) model array → (..., 3) or (...) user array."""
    a = np.asarray(v)
    if a.ndim == 2:
        return np.ascontiguousarray(a.T).reshape(*lead, 3)
    return a.reshape(lead)
