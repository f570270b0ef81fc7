"""Exporters: USD (UsdShade) for DCCs, Mitsuba scenes for proofs."""

__all__: list[str] = []  # its submodules are the offer
