"""notebooks/conftest.py and sanitize.cfg: glued images and HTML are not compared, glued text is, and the
cell tag nbval-ignore-output works."""

import json
import shutil
import subprocess
import sys

import nbformat
import pytest

from navbook.execute import execute
from navlib.paths import NOTEBOOK_DIR

CELLS = [
    (
        "import random\nimport matplotlib\nmatplotlib.use('Agg')\nimport matplotlib.pyplot as plt\n"
        "from IPython.display import HTML\nfrom myst_nb import glue",
        [],
    ),
    # a glued figure and a glued HTML object whose bytes change on every run
    (
        "fig, ax = plt.subplots()\nax.plot([random.random() for _ in range(5)])\nglue('fig-x', fig, display=False)\n"
        "glue('html-x', HTML(f'<b>{random.random()}</b>'), display=False)\nplt.close(fig)",
        [],
    ),
    ("glue('n', '4.20', display=False)", []),  # a glued number: compared
    ("print(f'{random.random():.6f} s')", ["nbval-ignore-output"]),  # a timing cell
]


@pytest.fixture
def stored(tmp_path):
    nb = nbformat.v4.new_notebook()
    for src, tags in CELLS:
        cell = nbformat.v4.new_code_cell(src)
        if tags:
            cell.metadata["tags"] = tags
        nb.cells.append(cell)
    path = tmp_path / "demo.ipynb"
    nbformat.write(nb, path)
    assert execute([path], None, in_place=True) == 0
    for f in ("conftest.py", "sanitize.cfg"):
        shutil.copy(NOTEBOOK_DIR / f, tmp_path / f)
    return path


def nbval(path):
    return subprocess.run(
        [
            sys.executable,
            "-m",
            "pytest",
            "-q",
            "-p",
            "no:cacheprovider",
            "--nbval",
            "--nbval-current-env",
            "--nbval-sanitize-with",
            "sanitize.cfg",
            path.name,
        ],
        cwd=path.parent,
        capture_output=True,
        text=True,
        timeout=300,
    )


@pytest.mark.slow
def test_nbval_skips_glued_images_and_html_and_tagged_cells_but_compares_glued_text(stored):
    run = nbval(stored)
    assert run.returncode == 0, run.stdout[-2000:]
    nb = json.loads(stored.read_text())
    glued = nb["cells"][2]["outputs"][0]["data"]
    glued["application/papermill.record/text/plain"] = (
        "'4.21'"  # the stored number no longer matches
    )
    stored.write_text(json.dumps(nb))
    run = nbval(stored)
    assert run.returncode != 0 and "1 failed" in run.stdout
