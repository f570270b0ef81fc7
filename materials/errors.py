"""The one exception family of lookdev (:doc:`/design`, Errors).

Every error a user can cause derives from :class:`LookdevError`. Its ``str`` is a
single line naming where the problem is (a file, a layer), the field, and what is
allowed, so the CLI can print it as it is and exit with code 2.
"""

from __future__ import annotations

import difflib
import re
from collections.abc import Mapping
from typing import TYPE_CHECKING, Any, TypeVar

if TYPE_CHECKING:  # pydantic costs a command line a tenth of a second: only for types here
    from pydantic import BaseModel, ValidationError

__all__ = [
    "LookdevError",
    "ParameterError",
    "argument",
    "check_range",
    "one_line",
    "register_schema",
    "short_repr",
]

_ARGUMENT = re.compile("\ue000([A-Za-z_][A-Za-z0-9_]*)\ue001")


def argument(name: str) -> str:
    """``name``, a Python argument of the call that failed, marked for its reader.

    A message says ``argument("noise")`` where it names what the caller passed:
    ``str(error)`` (what Python shows) reads ``noise``, and the CLI, which knows which
    option fed which argument, reads ``--noise`` (:meth:`LookdevError.one_line` with
    ``options``). One message, two readers; nothing is written twice.

    >>> err = LookdevError("0 is out of range", field=argument("max_spp"))
    >>> str(err), err.one_line({"max_spp": "--max-spp"})
    ('max_spp: 0 is out of range', '--max-spp: 0 is out of range')
    """
    return f"\ue000{name}\ue001"


class LookdevError(Exception):
    """Root of every error lookdev raises on bad input.

    >>> str(LookdevError("roughness must be in [0, 1]", where="gold.toml", field="roughness"))
    'gold.toml: roughness: roughness must be in [0, 1]'
    """

    def __init__(self, message: str, *, where: str | None = None, field: str | None = None):
        self.message = " ".join(str(message).split())
        self.where = where
        self.field = field
        super().__init__(self.one_line())

    def one_line(self, options: Mapping[str, str] | None = None) -> str:
        """The error as one line. Arguments (:func:`argument`) read as Python names, or,
        given ``options`` (argument → the option that feeds it), as those options; an
        argument no option feeds reads ``--its-name``."""
        parts = [p for p in (self.where, self.field) if p]
        text = ": ".join([*parts, self.message])
        if options is None:
            return _ARGUMENT.sub(r"\1", text)
        return _ARGUMENT.sub(lambda m: options.get(m[1], "--" + m[1].replace("_", "-")), text)

    def __str__(self) -> str:
        return self.one_line()


class ParameterError(LookdevError, ValueError):
    """A material parameter is missing, of the wrong type, or outside its allowed range."""


E = TypeVar("E", bound=LookdevError)
M = TypeVar("M", bound="BaseModel")


# -- pydantic's ValidationError as one line --------------------------------------------------
_SCHEMAS: dict[str, type[BaseModel]] = {}


def register_schema(cls: type[M]) -> type[M]:
    """Make a schema's fields and ranges known to :func:`one_line` (``allowed [lo, hi]``).

    Keyed like pydantic's ``ValidationError.title``: the schema's ``title``, else its name.
    """
    _SCHEMAS[cls.model_config.get("title") or cls.__name__] = cls
    return cls


def one_line(
    exc: ValidationError,
    error: type[E] = ParameterError,
    *,
    where: str | None = None,
    prefix: str | None = None,
) -> E:
    """The first error of ``exc`` as one ``error``: "where: field: message (what is allowed)".

    The one formatter of pydantic errors (parameters, layers, preset files, IBL definitions).
    ``field`` is the error's location, ``a.b[0]``, under ``prefix``; the message says the
    value and its allowed range, that a field is unknown (and, at the top of a registered
    schema, which are allowed), missing, not finite, or what the validator said.

    >>> from pydantic import BaseModel, Field, ValidationError
    >>> class P(BaseModel):
    ...     spp: int = Field(64, ge=1, le=4096)
    >>> try:
    ...     P.model_validate({"spp": 0})
    ... except ValidationError as exc:
    ...     print(one_line(exc, where="proof.toml", prefix="render"))
    proof.toml: render.spp: 0 is out of range; allowed ≥ 1

    (With ``P`` registered the range reads ``allowed [1, 4096]``.)
    """
    err = exc.errors(include_url=False)[0]
    loc = err["loc"]
    path = "".join(f"[{p}]" if isinstance(p, int) else f".{p}" for p in loc).lstrip(".")
    field = ".".join(p for p in (prefix, path) if p) or None
    ctx = err.get("ctx") or {}
    kind = err["type"]
    given = short_repr(err.get("input"))
    if kind in ("greater_than_equal", "less_than_equal", "greater_than", "less_than"):
        msg = f"{given} is out of range; allowed {_range_text(exc, err)}"
    elif kind == "extra_forbidden":
        schema = _SCHEMAS.get(exc.title)
        known = len(loc) == 1 and schema is not None
        msg = "unknown field"
        if known:
            names = list(schema.model_fields)
            close = difflib.get_close_matches(str(loc[-1]), names, n=1, cutoff=0.6)
            msg += f"; did you mean {close[0]!r}?" if close else ""
            msg += f"{' ' if close else '; '}allowed: {', '.join(names)}"
    elif kind == "missing":
        msg = "required field is missing"
    elif kind == "finite_number":
        msg = f"{given} is not a finite number"
    elif kind == "value_error":
        msg = str(ctx.get("error", err["msg"]))
    else:
        msg = f"{err['msg']} (got {given})"
    return error(msg, where=where, field=field)


def check_range(
    value: float,
    low: float,
    high: float,
    *,
    field: str,
    error: type[LookdevError] = ParameterError,
    where: str | None = None,
) -> float:
    """``value`` when it is a finite number in ``[low, high]``; else one ``error`` line in the
    wording of :func:`one_line` (the numeric options of the API and the CLI use it).

    >>> try:
    ...     check_range(float("nan"), -32, 32, field="--exposure")
    ... except LookdevError as exc:
    ...     print(exc)
    --exposure: nan is not a finite number; allowed [-32, 32]
    """
    import math

    allowed = f"allowed [{low:g}, {high:g}]"
    try:
        number = float(value)
    except (TypeError, ValueError):
        message = f"{short_repr(value)} is not a number; {allowed}"
        raise error(message, field=field, where=where) from None
    if not math.isfinite(number):
        raise error(f"{number} is not a finite number; {allowed}", field=field, where=where)
    if not low <= number <= high:
        raise error(f"{value:g} is out of range; {allowed}", field=field, where=where)
    return value


def short_repr(value: Any, limit: int = 60) -> str:
    """``repr(value)``, cut to ``limit`` characters with ``...`` (a message stays one line).

    >>> short_repr("x" * 100, 10)
    "'xxxxxx..."
    """
    text = repr(value)
    return text if len(text) <= limit else text[: limit - 3] + "..."


def _range_text(exc: ValidationError, err: dict[str, Any]) -> str:
    """``[lo, hi]`` of the offending field, or the violated bound alone when the field's
    schema is not known here (a nested model that did not call :func:`register_schema`)."""
    ctx = err.get("ctx") or {}
    loc = err["loc"]
    if loc and isinstance(loc[-1], int):  # an element of a tuple (a colour channel, a UV)
        field = next((p for p in reversed(loc) if isinstance(p, str)), None)
        lo, hi = _element_bounds(exc.title, field)
    else:
        field = next((p for p in reversed(loc) if isinstance(p, str)), None)
        lo, hi = _bounds(exc.title, field)
    if lo is None and hi is None:
        bound = next((f"{op} {ctx[k]:g}" for k, op in _OPS if k in ctx), "")
        return bound or "a smaller or larger value"
    lo_text = "-∞" if lo is None else f"{float(lo):g}"
    hi_text = "∞" if hi is None else f"{float(hi):g}"
    return f"{'(' if isinstance(lo, _Open) else '['}{lo_text}, {hi_text}]"


_OPS = (("ge", "≥"), ("gt", ">"), ("le", "≤"), ("lt", "<"))


def _element_bounds(model_name: str, field: str | None) -> tuple[float | None, float | None]:
    """The (ge, le) bounds of the elements of the tuple field ``field`` (colour channels
    are [0, 1], texture UVs ±4096), found like :func:`_bounds`."""
    import typing

    named = _SCHEMAS.get(model_name)
    for cls in [named] * (named is not None) + list(_SCHEMAS.values()):
        if field not in cls.model_fields:
            continue
        for arg in typing.get_args(cls.model_fields[field].annotation):
            lo = hi = None
            meta = getattr(arg, "__metadata__", ())
            for m in [c for item in meta for c in (item, *getattr(item, "metadata", ()))]:
                lo = getattr(m, "ge", None) if getattr(m, "ge", None) is not None else lo
                hi = getattr(m, "le", None) if getattr(m, "le", None) is not None else hi
            if lo is not None or hi is not None:
                return lo, hi
    return 0.0, 1.0  # a colour channel of an unregistered schema


def _bounds(model_name: str, field: str | None) -> tuple[float | None, float | None]:
    """The (ge, le) bounds declared on ``field`` of the schema ``model_name``, else of the
    first registered schema that declares that field; (None, None) when none does."""
    named = _SCHEMAS.get(model_name)
    for cls in [named] * (named is not None) + list(_SCHEMAS.values()):
        if field not in cls.model_fields:
            continue
        lo = hi = None
        for m in cls.model_fields[field].metadata:
            lo = getattr(m, "ge", None) if getattr(m, "ge", None) is not None else lo
            if getattr(m, "gt", None) is not None:  # an open floor: "(0, 10]"
                lo = _Open(m.gt)
            hi = getattr(m, "le", None) if getattr(m, "le", None) is not None else hi
        if lo is not None or hi is not None:
            return lo, hi
    return None, None


class _Open(float):
    """A lower bound the value must exceed (pydantic's ``gt``)."""
