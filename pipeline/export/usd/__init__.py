"""USD export (usd-core, UsdShade) and import."""
