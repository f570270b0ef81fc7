"""Mitsuba 3: BSDF plugins on the Dr.Jit backend of the shared model code, and scenes."""
