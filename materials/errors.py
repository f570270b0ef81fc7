"""The one exception family of lookdev (DESIGN.md, Errors).

Every error a user can cause derives from :class:`LookdevError`. Its ``str`` is a
single line naming where the problem is (a file, a layer), the field, and what is
allowed, so the CLI can print it as it is and exit with code 2.
"""

from __future__ import annotations


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

    def one_line(self) -> str:
        parts = [p for p in (self.where, self.field) if p]
        return ": ".join([*parts, self.message])


class ParameterError(LookdevError, ValueError):
    """A material parameter is missing, of the wrong type, or outside its allowed range."""
