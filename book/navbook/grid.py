"""A chapter over a grid of its parameters (``python -m navbook grid NOTEBOOK --param NAME=V1,V2 ... --out DIR``).

One papermill run of the notebook per point of the grid (the Cartesian product of the values given), each a
task of :mod:`navlib.engine` (local worker processes, or the cluster at a scheduler address), each with
its own results file.  ``DIR`` (new or empty: never written into otherwise) gets

- ``<notebook>_<k>.ipynb``: run ``k``'s executed notebook;
- ``results/<notebook>_<k>/<chapter>.json``: the results file it wrote (:func:`navbook.results.write_results`);
- ``grid.csv``: one row per run: ``run``, ``notebook``, ``status`` (``ok`` or the failure in one line), the
  parameters, then every method statistic (``<method>: <statistic>``) and every claim's verdict and
  estimate (``<claim id>: verdict``, ``<claim id>: estimate``: the claims-register id, the verdict under
  the primary reading, or the claim's key where a chapter has no register) from the results file.

The folder is claimed before the first run (:func:`claim_out_dir`): it is created, or must be empty, and the
marker file ``grid.incomplete`` is created in it atomically, so a second grid on the same folder stops with
one line before writing anything.  ``grid.csv`` is written last and the marker then removed: a folder with
``grid.csv`` and no marker is complete.  A grid stopped by an error or Ctrl-C keeps the runs it finished
(their notebooks and results) and the marker, which then says the folder is incomplete and why; when no
run had finished, the folder is removed again (or left empty, as it was found).

Parameters are checked against the notebook's ``parameters`` cell before any run: an unknown name, or a
value that does not read as the type of the notebook's default (a number for a number, ``True``/``False``
for a flag, a Python list for a list ...), stops with one line naming the parameter.  A default cast in
the cell (``n = int(2)``, ``x = float("1e-3")``) or annotated (``n: int = some_call()``) has the type of
the cast or annotation, so ``--param n=4`` reaches the notebook as the number 4, never the text "4".  A value that
contains a comma goes in double quotes (``--param 'start_model="misalignment,hard_iron",misalignment'`` is
two values); a list parameter takes one list per ``--param`` (``--param 'noise_levels_ut=[0.01, 0.02]'``),
and a name given twice adds its values.  Range checks are the notebook's own (its
validation cell): such a run fails and ``grid.csv`` says why.

Each run executes in a worker with the notebook's folder as working directory (where it exists on the
worker, else a temporary one), ``NAVBOOK_RESULTS_DIR`` pointing at its own folder, ``NAVLIB_SCHEDULER``
unset (a run does not send work back to the cluster it runs on) and, for notebooks with an ``n_workers``
parameter that the grid does not set, ``n_workers=1`` (the grid's runs are the parallel work).
Needs papermill (the book's tooling: ``pip install 'navlib[book]'``).
"""

from __future__ import annotations

import ast
import contextlib
import csv
import itertools
import json
import logging
import math
import os
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

from navlib import engine
from navlib._optional import require
from navlib.data.tables import claim_folder, write_new
from navlib.errors import InputError

from .results import RESULTS_ENV

#: Parameters a grid sets in every run unless the user sets them (notebooks that have them).
RUN_DEFAULTS = {"n_workers": 1}


def _read_notebook(path: Path) -> dict:
    try:
        nb = json.loads(path.read_text(encoding="utf-8"))
    except (UnicodeDecodeError, json.JSONDecodeError) as err:
        raise InputError(f"{path}: not a Jupyter notebook ({type(err).__name__})") from None
    if not isinstance(nb, dict) or not isinstance(nb.get("cells"), list):
        raise InputError(f"{path}: not a Jupyter notebook (no cells)")
    return nb


def notebook_parameters(path: str | os.PathLike) -> dict[str, Any]:
    """The parameters of a notebook: names and default values assigned in its cell tagged ``parameters``
    (a default that is not a literal is kept as its source text)."""
    path = Path(path)
    if not path.is_file():
        raise InputError(f"{path}: no such notebook")
    nb = _read_notebook(path)
    cell = next(
        (
            c
            for c in nb["cells"]
            if c.get("cell_type") == "code"
            and "parameters" in c.get("metadata", {}).get("tags", [])
        ),
        None,
    )
    if cell is None:
        raise InputError(
            f"{path}: no cell tagged 'parameters' (papermill needs one to set parameters)"
        )
    src = "".join(cell["source"]) if isinstance(cell["source"], list) else cell["source"]
    try:
        tree = ast.parse(src)
    except SyntaxError as err:
        raise InputError(
            f"{path}: the parameters cell does not parse (line {err.lineno})"
        ) from None
    out: dict[str, Any] = {}
    for node in tree.body:
        if isinstance(node, ast.Assign):
            for target in node.targets:
                names = (
                    [target] if isinstance(target, ast.Name) else list(getattr(target, "elts", []))
                )
                values = (
                    [node.value]
                    if isinstance(target, ast.Name)
                    else list(getattr(node.value, "elts", [None] * len(names)))
                )
                for n, v in zip(names, values):
                    if isinstance(n, ast.Name):
                        out[n.id] = _default(v, src) if v is not None else None
        elif (
            isinstance(node, ast.AnnAssign)
            and isinstance(node.target, ast.Name)
            and node.value is not None
        ):
            out[node.target.id] = _default(node.value, src, node.annotation)
    return out


#: The types a parameter's default may be cast to in the parameters cell (``n = int(2)``) or annotated
#: with (``n: int = ...``): its values are read as that type.
CASTS = {"int": int, "float": float, "bool": bool, "str": str}


class Expression(str):
    """A default that is not a literal (``scale = np.sqrt(2)``): its source text; ``kind`` is the type its
    annotation names (``scale: float = np.sqrt(2)``: float), or None when nothing says."""

    kind: type | None = None


def _default(value: ast.expr, src: str, annotation: ast.expr | None = None) -> Any:
    """A parameter's default in the parameters cell: a literal's value; a cast of a literal to one of
    :data:`CASTS` (``int(2)``, ``float("1e-3")``) evaluated; an int where the annotation says float as a
    float; anything else an :class:`Expression` (its text, and the annotation's type if it names one)."""
    kind = CASTS.get(annotation.id) if isinstance(annotation, ast.Name) else None
    try:
        v = ast.literal_eval(value)
    except ValueError:
        v = Expression(ast.get_source_segment(src, value) or "")
        if (
            isinstance(value, ast.Call)
            and isinstance(value.func, ast.Name)
            and value.func.id in CASTS
            and len(value.args) == 1
            and not value.keywords
        ):
            try:
                v = CASTS[value.func.id](ast.literal_eval(value.args[0]))
            except (ValueError, TypeError, SyntaxError):
                pass
    if isinstance(v, Expression):
        v.kind = kind
    elif kind is float and isinstance(v, int) and not isinstance(v, bool):
        v = float(v)
    return v


_TRUE, _FALSE = ("true", "yes", "1"), ("false", "no", "0")


def convert(name: str, raw: str, default: Any) -> Any:
    """Read the text ``raw`` as a value of parameter ``name`` of the type of its ``default`` (int, float,
    bool, str, list or tuple; for an :class:`Expression`, the type its annotation names, else a literal or
    the text).  A value that does not convert: one-line InputError naming the parameter."""
    text = raw.strip()
    shown = str(default) if isinstance(default, Expression) else repr(default)
    if isinstance(default, Expression) and default.kind is not None:
        default = {int: 0, float: 0.0, bool: False, str: ""}[default.kind]
    elif isinstance(default, Expression):
        default = None
    try:
        if isinstance(default, bool):
            if text.lower() in _TRUE:
                return True
            if text.lower() in _FALSE:
                return False
            raise ValueError
        if isinstance(default, int):
            v = ast.literal_eval(text)
            if isinstance(v, bool) or not isinstance(v, int):
                raise ValueError
            return v
        if isinstance(default, float):
            v = float(text)
            if not math.isfinite(v):
                raise ValueError
            return v
        if isinstance(default, str):
            if len(text) >= 2 and text[0] == text[-1] and text[0] in "'\"":
                return text[1:-1]
            return text
        if isinstance(default, (list, tuple)):
            v = ast.literal_eval(text)
            if not isinstance(v, (list, tuple)):
                raise ValueError
            return type(default)(v)
        try:  # default None or an expression: a literal, else text
            return ast.literal_eval(text)
        except (ValueError, SyntaxError):
            return text
    except (ValueError, SyntaxError):
        kind = {
            bool: "True or False",
            int: "a whole number",
            float: "a number",
            list: "a Python list",
            tuple: "a Python tuple",
        }.get(type(default), "a Python literal")
        raise InputError(
            f"grid: parameter {name}={raw!r}: expected {kind} (the notebook's default is {shown})"
        ) from None


def parse_grid(
    specs: list[str], parameters: dict[str, Any], notebook: str = "the notebook"
) -> dict[str, list]:
    """``["NAME=V1,V2", ...]`` -> ``{NAME: [v1, v2]}`` checked against ``parameters`` (a name given twice
    adds values)."""
    if not specs:
        raise InputError("grid: give at least one --param NAME=V1,V2,...")
    grid: dict[str, list] = {}
    for spec in specs:
        name, sep, values = spec.partition("=")
        name = name.strip()
        if not sep or not name:
            raise InputError(f"grid: --param {spec!r}: write NAME=V1,V2,...")
        if name not in parameters:
            known = ", ".join(parameters) or "none"
            raise InputError(
                f"grid: parameter {name!r} is not in the parameters cell of {notebook} "
                f"(its parameters: {known})"
            )
        default = parameters[name]
        if isinstance(default, (list, tuple)):
            raws = [values]
        else:  # comma-separated; "a,b" in double quotes is one value
            raws = next(csv.reader([values], skipinitialspace=True), [])
        if not raws or any(not r.strip() for r in raws):
            raise InputError(f"grid: parameter {name}={values!r}: an empty value")
        for r in raws:
            v = convert(name, r, default)
            if v in grid.setdefault(name, []):
                raise InputError(f"grid: parameter {name}: value {r.strip()!r} given twice")
            grid[name].append(v)
    return grid


def points(grid: dict[str, list]) -> list[dict[str, Any]]:
    """Every point of the grid (Cartesian product), the first parameter varying slowest."""
    names = list(grid)
    return [dict(zip(names, combo)) for combo in itertools.product(*(grid[n] for n in names))]


#: The marker file :func:`run_grid` keeps in its output folder while it writes
#: (:func:`navlib.data.tables.claim_folder`): a second grid on the same folder stops before writing
#: anything; a grid stopped by an error or Ctrl-C after some runs leaves it, saying the folder is incomplete
#: (no ``grid.csv``).
MARKER = "grid.incomplete"


def claim_out_dir(out: str | os.PathLike):
    """Claim the output folder for this grid (:func:`navlib.data.tables.claim_folder`): created if missing,
    refused if it is a file, holds anything, or another grid is writing there (one line, before any work)."""
    return claim_folder(out, MARKER, what="navlib grid", label="grid --out", empty=True)


def _papermill():
    return require("papermill", "grid", alternative="pip install papermill ipykernel")


@contextlib.contextmanager
def _stderr_to(path: Path):
    """File descriptor 2 (this process's and the kernels' it starts) into ``path`` while a run executes:
    the kernel's and papermill's warnings belong to the run, not to the terminal of the grid."""
    sys.stderr.flush()
    saved = os.dup(2)
    try:
        with open(path, "ab") as f:
            os.dup2(f.fileno(), 2)
        yield
    finally:
        sys.stderr.flush()
        os.dup2(saved, 2)
        os.close(saved)


def run_point(notebook_json: str, name: str, parameters: dict, cwd: str) -> dict:
    """One run of the grid (a task of :mod:`navlib.engine`, in a worker process): execute the notebook
    ``notebook_json`` (its text) with ``parameters`` in ``cwd`` (a temporary folder where ``cwd`` does not
    exist here).  Returns ``{"notebook": executed text, "results": {file name: text}, "error": one line or
    None, "seconds": wall time}``; a failing run is reported, not raised."""
    pm = _papermill()
    t0 = time.perf_counter()
    saved = {k: os.environ.get(k) for k in (RESULTS_ENV, engine.ENV_SCHEDULER, engine.ENV_PROGRESS)}
    with tempfile.TemporaryDirectory(prefix="navlib-grid-") as tmp:
        src, dst, res = (
            Path(tmp) / f"{name}_in.ipynb",
            Path(tmp) / f"{name}.ipynb",
            Path(tmp) / "results",
        )
        src.write_text(notebook_json, encoding="utf-8")
        error = None
        os.environ[RESULTS_ENV] = str(res)  # the kernel inherits the environment
        os.environ.pop(engine.ENV_SCHEDULER, None)
        os.environ[engine.ENV_PROGRESS] = "0"
        quiet = logging.getLogger("papermill")
        level = quiet.level
        quiet.setLevel(
            logging.ERROR
        )  # "Passed unknown parameter" when it cannot parse a commented line
        try:
            with _stderr_to(Path(tmp) / "stderr.log"):
                pm.execute_notebook(
                    str(src),
                    str(dst),
                    parameters=parameters,
                    cwd=cwd if Path(cwd).is_dir() else tmp,
                    kernel_name="python3",
                    progress_bar=False,
                    log_output=False,
                )
        except pm.PapermillExecutionError as err:
            lines = [ln for ln in str(err).strip().splitlines() if ln.strip()]
            error = f"cell {err.exec_count}: {lines[-1] if lines else err.ename}"
        except (RuntimeError, OSError, TimeoutError) as err:  # kernel died, could not start ...
            error = f"{type(err).__name__}: {str(err).strip().splitlines()[0] if str(err).strip() else ''}"
        finally:
            quiet.setLevel(level)
            for k, v in saved.items():
                if v is None:
                    os.environ.pop(k, None)
                else:
                    os.environ[k] = v
        text = dst.read_text(encoding="utf-8") if dst.is_file() else None
        results = (
            {f.name: f.read_text(encoding="utf-8") for f in sorted(res.glob("*.json"))}
            if res.is_dir()
            else {}
        )
    return {
        "notebook": text,
        "results": results,
        "error": error,
        "seconds": time.perf_counter() - t0,
    }


def _flatten(results: dict[str, str]) -> dict[str, Any]:
    """Method statistics and claim verdicts of a run's results files as grid.csv columns."""
    out: dict[str, Any] = {}
    several = len(results) > 1
    for fname, text in results.items():
        data = json.loads(text)
        pre = f"{data.get('chapter', Path(fname).stem)}: " if several else ""
        for method, stats in (data.get("methods") or {}).items():
            for stat, v in stats.items():
                out[f"{pre}{method}: {stat}"] = v
        for c in data.get("claims") or []:
            # a claims-register record: its id (the same column in every run, whatever readings ran)
            key = (
                c.get("id")
                or c.get("key")
                or (f"{c['claim']} [{c['reading']}]" if c.get("reading") else c["claim"])
            )
            out[f"{pre}{key}: verdict"] = c.get("verdict")
            out[f"{pre}{key}: estimate"] = c.get("estimate")
    return out


def run_grid(
    notebook: str | os.PathLike,
    specs: list[str],
    out: str | os.PathLike,
    *,
    workers: int = 1,
    scheduler: str | None = None,
    progress: bool | None = None,
) -> list[dict]:
    """Run ``notebook`` at every point of the grid ``specs`` (``["NAME=V1,V2", ...]``) and write ``out``
    (see the module docstring).  Returns grid.csv's rows."""
    nb_path, out = Path(notebook), Path(out)
    params = notebook_parameters(nb_path)
    grid = parse_grid(list(specs), params, nb_path.name)
    engine.scheduler_address(scheduler)  # a bad address stops here, before any run
    _papermill()
    text = nb_path.read_text(encoding="utf-8")
    stem = nb_path.stem
    pts = points(grid)
    width = max(3, len(str(len(pts))))
    names = [f"{stem}_{k:0{width}d}" for k in range(1, len(pts) + 1)]
    extra = {k: v for k, v in RUN_DEFAULTS.items() if k in params}
    tasks = [
        (text, names[i], {**extra, **p}, str(nb_path.resolve().parent)) for i, p in enumerate(pts)
    ]
    rows: list[dict | None] = [None] * len(pts)

    def write(i: int, r: dict) -> None:  # as each run finishes
        if r["notebook"] is not None:
            (out / f"{names[i]}.ipynb").write_text(r["notebook"], encoding="utf-8")
        if r["results"]:
            folder = out / "results" / names[i]
            folder.mkdir(parents=True)
            for fname, content in r["results"].items():
                (folder / fname).write_text(content, encoding="utf-8")
        status = "ok" if r["error"] is None else f"failed: {r['error']}"
        if r["error"] is None and not r["results"]:
            status = "ok (no results file)"
        rows[i] = {
            "run": i + 1,
            "notebook": f"{names[i]}.ipynb" if r["notebook"] is not None else "",
            "status": status,
            "seconds": round(r["seconds"], 1),
            **pts[i],
            **_flatten(r["results"]),
        }

    def table(f) -> None:
        columns: list[str] = []
        for r in rows:
            columns += [k for k in r if k not in columns]
        w = csv.DictWriter(f, fieldnames=columns)
        w.writeheader()
        for r in rows:
            w.writerow(
                {
                    k: (json.dumps(v) if isinstance(v, (list, tuple, dict)) else v)
                    for k, v in r.items()
                }
            )

    with claim_out_dir(out):  # one grid per folder, claimed before any run
        engine.run(
            run_point,
            tasks,
            workers=workers,
            scheduler=scheduler,
            label=f"grid {stem}",
            progress=progress,
            on_result=write,
        )
        write_new(out / "grid.csv", table, newline="")  # last: a folder with grid.csv is complete
    return rows
