"""Blending, textures, exporters, proofs, analysis, benchmarks and the command line."""
