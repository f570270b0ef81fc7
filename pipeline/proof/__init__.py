"""Proof turntables under several IBLs: scenes, frames, batches, contact sheets."""

__all__: list[str] = []  # its submodules are the offer
