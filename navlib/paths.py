"""Where navlib's files are, independent of the caller's working directory.

- :func:`data_path` -- a data file shipped with navlib: the checkout's top-level ``data/`` folder, installed
  as the package ``navlib._data`` and read through ``importlib.resources`` (so the loaders work from
  site-packages, an editable install or a checkout alike).  Every read of a shipped data file in the library
  goes through it.
- ``DATA_DIR`` -- the folder :func:`data_path` reads from (:func:`data_dir`, resolved once at import; the
  compass chapter names a file in it).
- ``ROOT`` -- the folder that holds the ``navlib`` package: the source checkout when navlib runs from one,
  site-packages when it is installed.  The library uses it in two places: :func:`data_dir` falls back to
  ``ROOT / "data"`` in a checkout that was never installed, and :mod:`navlib.studies.workbench.parameters`
  looks for the third-party measurements beside the checkout (``ROOT.parent / "shared" / "realdata"``;
  absent in an install, where the workbench chapter marks its real-data claims not judged).  ``NOTEBOOK_DIR`` (``ROOT /
  "notebooks"``) means something only in a checkout (tests).

Results files go where the caller says (the book's ``navbook.report.results_dir``), never into the package.
"""

from __future__ import annotations

import importlib.resources
import os
from pathlib import Path

# (no doc comments on the paths: the API page would print this machine's folders)
ROOT = Path(__file__).resolve().parent.parent
NOTEBOOK_DIR = ROOT / "notebooks"
#: The package the data files are installed as (pyproject.toml maps it to the checkout's ``data/``).
DATA_PACKAGE = "navlib._data"


def data_dir() -> Path:
    """The folder of navlib's data files: the package ``navlib._data`` (installed or editable), or, when
    navlib is imported from a checkout that was never installed (``PYTHONPATH=checkout``), its ``data/``."""
    try:
        folder = importlib.resources.files(DATA_PACKAGE)
    except ModuleNotFoundError as err:
        if err.name not in (DATA_PACKAGE, "navlib"):
            raise
        return ROOT / "data"
    return Path(
        os.fspath(folder)
    )  # a folder on disk: navlib is installed unzipped (zip-safe = false)


# the folder data_path reads from, found once (notebooks/compass.ipynb names a file in it)
DATA_DIR = data_dir()


def data_path(name: str) -> Path:
    """The path of the shipped data file ``name`` (e.g. ``"compass_sweeps.csv"``; see ``data/README.md``)."""
    return DATA_DIR / name
