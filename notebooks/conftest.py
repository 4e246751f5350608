"""nbval settings for the stored notebooks.

Not compared: stderr (kernel warnings, tqdm bars), JavaScript, HTML (a table's HTML is the same data as its
rounded text/plain twin, which IS compared), and the images and HTML that myst-nb's ``glue`` stores under
``application/papermill.record/<mime>`` keys (a glued number, text or table keeps its text/plain record,
which is compared).  Cells tagged ``nbval-ignore-output`` (timings) run but are not compared; ``nbval-skip``
cells are not run.

``make test-notebooks`` runs two notebooks at a time (pytest-xdist ``--dist loadfile
--no-loadscope-reorder``), in the order below: the longest chapters first, so the two processes finish
together (a chapter's cells always run in their own order).
"""
from pathlib import Path

LONGEST_FIRST = ("celestial.ipynb", "compass.ipynb", "workbench.ipynb", "accelerometer.ipynb", "gyro.ipynb")

GLUE = "application/papermill.record/"
SKIP = ("stderr", "application/javascript", "text/html",
        *(GLUE + mime for mime in ("image/png", "image/jpeg", "image/svg+xml", "text/html",
                                   "application/javascript", "text/latex")))


def pytest_collectstart(collector):
    if collector.fspath and collector.fspath.ext == ".ipynb":
        collector.skip_compare += SKIP


def pytest_collection_modifyitems(items):
    rank = {name: i for i, name in enumerate(LONGEST_FIRST)}
    items.sort(key=lambda item: rank.get(Path(str(item.fspath)).name, len(rank)))
