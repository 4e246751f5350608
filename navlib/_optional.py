"""Optional dependencies: a missing one stops with one line naming the package and the extra of navlib that
brings it (``navlib.methods.mlp needs torch, which is not installed: pip install 'navlib[nets]'``).

:func:`require` imports the package (a module that needs an extra imports it this way); :func:`need` only
checks that it is installed, without importing it (the engine checks for dask.distributed before it starts a
cluster in the background).  Both raise :class:`MissingExtra`.
"""

from __future__ import annotations

import importlib
import importlib.util
from types import ModuleType

from .errors import InputError

#: extra of navlib (pyproject.toml ``[project.optional-dependencies]``) -> the modules it provides that navlib
#: asks for through this module
EXTRAS = {"nets": ("torch",), "dist": ("dask", "distributed"), "book": ("papermill", "nbformat")}


class MissingExtra(ModuleNotFoundError, InputError):
    """An optional dependency is not installed; the one-line message says which extra of navlib brings it.
    A ``ModuleNotFoundError`` (an import failed) and an :class:`~navlib.errors.InputError` (the CLI and the
    notebooks show it as one line)."""


def installed(module: str) -> bool:
    """True when the top-level package of ``module`` can be imported (looked up, not imported)."""
    return importlib.util.find_spec(module.partition(".")[0]) is not None


def _missing(top: str, needed_by: str, alternative: str | None) -> MissingExtra:
    extra = next((e for e, mods in EXTRAS.items() if top in mods), None)
    how = f"pip install 'navlib[{extra}]'" if extra else f"pip install {top}"
    more = f" (or {alternative})" if alternative else ""
    return MissingExtra(f"{needed_by} needs {top}, which is not installed: {how}{more}", name=top)


def need(module: str, needed_by: str, alternative: str | None = None) -> None:
    """Raise :class:`MissingExtra` unless ``module`` is installed (without importing it).

    Parameters
    ----------
    module : str
        The package, e.g. ``"distributed"``.
    needed_by : str
        What needs it, as the message's subject (e.g. ``"workers=2"``).
    alternative : str, optional
        Another way out, added to the message in parentheses (e.g. ``"run with workers=1"``).
    """
    if not installed(module):
        raise _missing(module.partition(".")[0], needed_by, alternative)


def require(module: str, needed_by: str, alternative: str | None = None) -> ModuleType:
    """Import ``module`` and return it, or raise :class:`MissingExtra` when its top-level package is not
    installed (``navlib.methods.mlp needs torch, which is not installed: pip install 'navlib[nets]'``).  A
    package that is installed but fails to import something of its own raises that error unchanged.

    Parameters
    ----------
    module : str
        The module to import, e.g. ``"torch"``.
    needed_by : str
        What needs it, as the message's subject: the importing module's ``__name__``, or a command (``"grid"``).
    alternative : str, optional
        Another way out, added to the message in parentheses.

    Returns
    -------
    module
        The imported module.
    """
    try:
        return importlib.import_module(module)
    except ModuleNotFoundError as err:
        top = module.partition(".")[0]
        if err.name != top:  # the module is there but something it imports is broken
            raise
        raise _missing(top, needed_by, alternative) from None
