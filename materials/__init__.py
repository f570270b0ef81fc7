"""What a material is and how it reflects light: models, lobes, the array shim (no I/O)."""

__all__: list[str] = []  # its submodules are the offer
