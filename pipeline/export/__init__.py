"""Exporters: USD (UsdShade) for DCCs, Mitsuba scenes for proofs."""
