"""nbval settings for the stored notebooks.

Not compared: stderr (kernel warnings, tqdm bars), JavaScript, HTML (a table's HTML is the same data as its
rounded text/plain twin, which IS compared), and the images and HTML that myst-nb's ``glue`` stores under
``application/papermill.record/<mime>`` keys (a glued number, text or table keeps its text/plain record,
which is compared).  Cells tagged ``nbval-ignore-output`` (timings) run but are not compared; ``nbval-skip``
cells are not run.
"""

GLUE = "application/papermill.record/"
SKIP = ("stderr", "application/javascript", "text/html",
        *(GLUE + mime for mime in ("image/png", "image/jpeg", "image/svg+xml", "text/html",
                                   "application/javascript", "text/latex")))


def pytest_collectstart(collector):
    if collector.fspath and collector.fspath.ext == ".ipynb":
        collector.skip_compare += SKIP
