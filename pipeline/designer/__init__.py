"""The Material Designer (:cite:`Burley2012` §6.1): a local web page that edits a preset live.

``lookdev designer`` (or :func:`lookdev.designer`) serves it on 127.0.0.1 with a
per-session token. The pieces:

=====================  =================================================================
:mod:`.server`         the Starlette app, its guard middleware, the frames' websocket
:mod:`.routes`         the HTTP routes (state, edits, library, save, plots, proof, export)
:mod:`.guard`          token, Host/Origin checks and the folders the page may touch
:mod:`.session`        the edit state: schema-checked edits, undo/redo, cached blends
:mod:`.edits`          the edits the page may ask for
:mod:`.saving`         save as a child preset or over the file, through the library
:mod:`.controls`       control descriptors from each model's Pydantic JSON Schema
:mod:`.render`         the thread that owns the viewport and streams its frames
:mod:`.library_panel`  the presets on the path, with cached thumbnails
:mod:`.tasks`          BRDF views, USD loss notes, Export USD, Proof
:mod:`.viewport`       the renderer the server drives: a g-buffer relit by the model's
                       own Dr.Jit code (designer mode) or the proofs' path tracer edited
                       in place (truth mode)
=====================  =================================================================
"""

__all__: list[str] = []
