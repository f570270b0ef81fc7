"""The Material Designer (Burley 2012 §6.1): a local web page that edits a preset live.

``lookdev designer`` (or :func:`lookdev.designer`) serves it on 127.0.0.1 with a
per-session token. The pieces:

==================  =============================================================