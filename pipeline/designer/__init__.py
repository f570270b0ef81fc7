"""The Material Designer (:cite:`Burley2012` §6.1): a live viewport of a material being edited.

:mod:`.viewport` is the renderer the designer's server drives: a g-buffer relit by the
model's own Dr.Jit code (designer mode) or the proofs' path tracer edited in place
(truth mode).
"""
