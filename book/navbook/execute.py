"""Execute the chapter notebooks with papermill (``python -m navbook execute``), and find the chapter name
a notebook writes its results file under.

``execute --out book/_generated notebooks/*.ipynb``
    Execute each notebook with papermill into the book's generated folder (one progress line per notebook);
    stop with a non-zero exit at the first failing notebook.  ``--in-place`` re-executes the stored
    notebooks instead (how the outputs that nbval checks are regenerated) and also stores each chapter's
    results file as ``notebooks/results/<chapter>.json`` (the committed reference ``make test`` compares
    with).  With ``--out DIR`` the results files go to ``DIR/results/``.
"""

from __future__ import annotations

import os
import re
import shutil
import sys
import tempfile
import time
from pathlib import Path

import nbformat

from .results import RESULTS_ENV

VOLATILE_NB_KEYS = ("papermill",)
VOLATILE_CELL_KEYS = ("papermill", "execution", "collapsed", "scrolled")


def strip_metadata(nb) -> None:
    """Remove timing and run-specific metadata so a re-executed notebook diffs only where outputs changed.

    Execution counts stay: nbval treats a cell without one as never run (they are sequential anyway)."""
    for key in VOLATILE_NB_KEYS:
        nb.metadata.pop(key, None)
    for cell in nb.cells:
        for key in VOLATILE_CELL_KEYS:
            cell.metadata.pop(key, None)


def missing_figures(nb) -> list[int]:
    """Indices of code cells that call ``plt.show()`` but carry no image output."""
    bad = []
    for i, cell in enumerate(nb.cells):
        if cell.cell_type == "code" and "plt.show()" in cell.source:
            if not any("image/png" in out.get("data", {}) for out in cell.get("outputs", [])):
                bad.append(i)
    return bad


_WRITE_RESULTS = re.compile(r"""write_results\(\s*(?:chapter\s*=\s*)?["']([A-Za-z_]\w*)["']""")


def results_chapter(nb_path: Path) -> str | None:
    """The chapter name a notebook passes to ``report.write_results`` (None if it never calls it)."""
    nb = nbformat.read(nb_path, as_version=4)
    for cell in nb.cells:
        if cell.cell_type == "code":
            m = _WRITE_RESULTS.search(cell.source)
            if m:
                return m.group(1)
    return None


def execute(
    notebooks: list[Path], out_dir: Path | None, in_place: bool, parameters: dict | None = None
) -> int:
    """Execute notebooks with papermill (see the module docstring); 0 on success, 1 at the first failure.

    Each notebook runs with ``NAVBOOK_RESULTS_DIR`` pointing at a fresh temporary folder; the results
    files it writes are then copied to ``notebooks/results/`` (``in_place``) or ``out_dir/results/``."""
    import papermill as pm  # noqa: PLC0415  # lazy: papermill costs ~1 s; only execute needs it

    for i, nb_path in enumerate(notebooks, 1):
        nb_path = Path(nb_path).resolve()
        target = nb_path if in_place else (out_dir / nb_path.name)
        results_target = (nb_path.parent if in_place else Path(out_dir)) / "results"
        target.parent.mkdir(parents=True, exist_ok=True)
        print(f"[{i}/{len(notebooks)}] executing {nb_path.name} -> {target}", flush=True)
        t0 = time.perf_counter()
        old_env = os.environ.get(RESULTS_ENV)
        with tempfile.TemporaryDirectory() as tmp:
            tmp_out = Path(tmp) / nb_path.name
            tmp_results = Path(tmp) / "results"
            os.environ[RESULTS_ENV] = str(tmp_results)  # the kernel inherits the environment
            try:
                pm.execute_notebook(
                    str(nb_path),
                    str(tmp_out),
                    cwd=str(nb_path.parent),
                    parameters=parameters or {},
                    kernel_name="python3",
                    progress_bar=False,
                    log_output=False,
                )
            except pm.PapermillExecutionError as err:
                lines = [ln for ln in str(err).strip().splitlines() if ln.strip()]
                print(
                    f"FAILED {nb_path.name}: cell {err.exec_count}: {lines[-1] if lines else err.ename}",
                    file=sys.stderr,
                )
                return 1
            finally:
                if old_env is None:
                    os.environ.pop(RESULTS_ENV, None)
                else:
                    os.environ[RESULTS_ENV] = old_env
            nb = nbformat.read(tmp_out, as_version=4)
            missing = missing_figures(nb)
            if missing:
                print(
                    f"FAILED {nb_path.name}: cell {missing[0]} calls plt.show() but produced no figure "
                    f"(is MPLBACKEND set to a non-inline backend?)",
                    file=sys.stderr,
                )
                return 1
            strip_metadata(nb)
            nbformat.write(nb, target)
            written = sorted(tmp_results.glob("*.json")) if tmp_results.is_dir() else []
            if written:
                results_target.mkdir(parents=True, exist_ok=True)
            for f in written:
                shutil.copyfile(f, results_target / f.name)
        names = (
            ", ".join(f.name for f in written)
            or "none (the chapter does not call report.write_results)"
        )
        print(f"    done in {time.perf_counter() - t0:.1f} s; results: {names}", flush=True)
    return 0
