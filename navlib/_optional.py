"""Optional dependencies: a module that needs one fails to import with one line naming the extra to install."""
from __future__ import annotations

import importlib
from types import ModuleType

#: extra of navlib (pyproject.toml ``[project.optional-dependencies]``) -> the modules it provides
EXTRAS = {"nets": ("torch",), "dist": ("dask", "distributed")}


class MissingExtra(ModuleNotFoundError):
    """An optional dependency is not installed; the message says which extra of navlib brings it."""


def require(module: str, needed_by: str) -> ModuleType:
    """Import ``module`` (e.g. ``"torch"``) for ``needed_by`` (the importing module's ``__name__``), or raise
    :class:`MissingExtra`: ``navlib.methods.mlp needs torch: pip install 'navlib[nets]'``."""
    try:
        return importlib.import_module(module)
    except ModuleNotFoundError as err:
        top = module.partition(".")[0]
        if err.name != top:                  # the module is there but something it imports is broken
            raise
        extra = next((e for e, mods in EXTRAS.items() if top in mods), None)
        how = f"pip install 'navlib[{extra}]'" if extra else f"pip install {top}"
        raise MissingExtra(f"{needed_by} needs {top}, which is not installed: {how}", name=top) from None
