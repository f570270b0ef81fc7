"""Analysis: stability sweeps, albedo, plots, error against run time."""
