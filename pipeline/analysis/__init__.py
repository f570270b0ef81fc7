"""Analysis: stability sweeps, albedo, plots, reports (benchmarks: ``lookdev.pipeline.bench``)."""
