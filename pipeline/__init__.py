"""Blending, textures, exporters, proofs, analysis, benchmarks and the command line."""

__all__: list[str] = []  # its submodules are the offer
