"""Benchmarks: each measures a performance target against a baseline in the same run and
returns its figures as data; ``lookdev bench …`` (``pipeline/cli/bench.py``) prints them."""

__all__: list[str] = []  # its submodules are the offer
