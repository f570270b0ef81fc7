"""The built-in presets (data files: ``*.toml``, IBL definitions), found through this
package's ``__path__`` from a checkout and from an installed wheel alike."""

__all__: list[str] = []
