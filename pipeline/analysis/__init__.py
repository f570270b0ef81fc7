"""Analysis: stability sweeps, albedo, plots, reports (benchmarks: ``lookdev.pipeline.bench``)."""

__all__: list[str] = []  # its submodules are the offer
