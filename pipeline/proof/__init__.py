"""Proof turntables under several IBLs: scenes, frames, batches, contact sheets."""
