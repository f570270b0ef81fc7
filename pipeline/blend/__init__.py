"""Blending engine: masks, Disney parameter blending, Pixar lobe compositing."""
