"""navlib as a library, without the book: a wheel of this checkout installed into a fresh virtual environment
that holds nothing but navlib's declared core dependencies (no torch, no dask, no book tooling) runs its command
line and reads its data files from another directory; the editable install the Makefile makes finds the data
files through importlib.resources too.

Nothing is downloaded: the wheel is built from a copy of the checkout with this environment's setuptools
(``--no-build-isolation --no-index``), installed with ``--no-index --no-deps``, and the core dependencies are
this environment's own installed copies, linked into a folder the fresh environment sees through a ``.pth``
file: exactly the closure of the wheel's unconditional ``Requires-Dist``, so an undeclared dependency (numba
before issue 19) or a module-level import of an optional one (torch, dask, papermill) fails here.
"""

from __future__ import annotations

import email
import importlib.metadata as md
import json
import os
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import pandas as pd
import pytest
from packaging.markers import Marker
from packaging.requirements import Requirement
from packaging.utils import canonicalize_name
from packaging.version import Version

pytestmark = pytest.mark.slow  # wheel and venv builds: not in make check

ROOT = Path(__file__).resolve().parent.parent
SOURCES = ("pyproject.toml", "README.md", "navlib", "data")  # what the wheel is built from
CORE = {"numpy", "scipy", "pandas", "matplotlib", "numba", "ppigrf", "threadpoolctl"}
EXTRA_ONLY = {
    "torch",
    "dask",
    "distributed",
    "papermill",
    "nbformat",
    "nbval",
    "jupyter-book",
    "myst-nb",
    "ipykernel",
    "sphinx-mathjax-offline",
    "sphinxcontrib-bibtex",
    "pytest",
}
#: modules the command line must not import (optional extras and the book's build tooling)
NOT_IMPORTED = (
    "torch",
    "dask",
    "distributed",
    "papermill",
    "nbformat",
    "myst_nb",
    "IPython",
    "navbook",
)
#: the book's tooling, which lives in book/navbook and is not part of navlib's wheel
BOOK_TOOLING = (
    "navbook",
    "navlib.booktools",
    "navlib.report",
    "navlib.report_style",
    "navlib.grid",
)


def plain_env() -> dict:
    """The caller's environment without what would let the checkout's navlib in (PYTHONPATH) or redirect
    results."""
    env = {
        k: v
        for k, v in os.environ.items()
        if k not in ("PYTHONPATH", "NAVBOOK_RESULTS_DIR", "PYTHONHOME")
    }
    env["PYTHONNOUSERSITE"] = "1"
    return env


def run(cmd, **kw):
    kw.setdefault("timeout", 300)
    kw.setdefault("env", plain_env())
    return subprocess.run([str(c) for c in cmd], capture_output=True, text=True, **kw)


def check(proc):
    assert proc.returncode == 0, f"{proc.args}\n{proc.stdout[-2000:]}\n{proc.stderr[-3000:]}"
    return proc


def copy_sources(dst: Path) -> Path:
    dst.mkdir(parents=True)
    for name in SOURCES:
        src = ROOT / name
        if src.is_dir():
            shutil.copytree(src, dst / name, ignore=shutil.ignore_patterns("__pycache__", "*.pyc"))
        else:
            shutil.copy2(src, dst / name)
    return dst


def requires(meta) -> list[Requirement]:
    return [Requirement(r) for r in meta.get_all("Requires-Dist") or []]


def unconditional(reqs, extras=()) -> list[Requirement]:
    """The requirements that apply without navlib's extras (markers evaluated for this interpreter)."""
    out = []
    for r in reqs:
        if r.marker is None or any(r.marker.evaluate({"extra": e}) for e in ("", *extras)):
            out.append(r)
    return out


def closure(reqs) -> set[str]:
    """Installed distributions needed by ``reqs``, recursively (this environment's copies)."""
    seen: set[str] = set()
    todo = [(r.name, tuple(r.extras)) for r in reqs]
    while todo:
        name, extras = todo.pop()
        key = canonicalize_name(name)
        if key in seen:
            continue
        seen.add(key)
        dist = md.distribution(name)
        todo += [(r.name, tuple(r.extras)) for r in unconditional(requires(dist.metadata), extras)]
    return seen


def link_distributions(names, folder: Path) -> None:
    """Symlink every top-level file and folder of the installed distributions ``names`` into ``folder``."""
    folder.mkdir()
    for name in names:
        dist = md.distribution(name)
        base = Path(dist.locate_file("")).resolve()
        for f in dist.files or ():
            top = Path(f).parts[0]
            if top == ".." or top.endswith(".pth") or (folder / top).exists():
                continue
            target = base / top
            if target.exists():
                (folder / top).symlink_to(target)


def fresh_venv(path: Path, deps: set[str]) -> Path:
    """A virtual environment (no system site-packages, no pip) that sees the installed distributions ``deps``."""
    check(run([sys.executable, "-m", "venv", "--without-pip", path]))
    python = path / "bin" / "python"
    site = Path(
        check(
            run([python, "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"])
        ).stdout.strip()
    )
    link_distributions(deps, path / "deps")
    (site / "navlib_test_deps.pth").write_text(str(path / "deps") + "\n")
    return python


def pip_into(python: Path, *args):
    return check(
        run(
            [
                sys.executable,
                "-m",
                "pip",
                "--python",
                python,
                "install",
                "--quiet",
                "--no-index",
                "--no-deps",
                *args,
            ]
        )
    )


@pytest.fixture(scope="module")
def wheel(tmp_path_factory) -> Path:
    tmp = tmp_path_factory.mktemp("wheel")
    src = copy_sources(tmp / "src")
    check(
        run(
            [
                sys.executable,
                "-m",
                "pip",
                "wheel",
                "--quiet",
                "--no-deps",
                "--no-build-isolation",
                "--no-index",
                "--wheel-dir",
                tmp / "out",
                src,
            ]
        )
    )
    (whl,) = (tmp / "out").glob("navlib-*.whl")
    return whl


@pytest.fixture(scope="module")
def metadata(wheel):
    with zipfile.ZipFile(wheel) as z:
        (name,) = [n for n in z.namelist() if n.endswith(".dist-info/METADATA")]
        return email.message_from_bytes(z.read(name))


@pytest.fixture(scope="module")
def installed(wheel, metadata, tmp_path_factory):
    """(python, bin folder, a working directory outside the checkout) of the plain install."""
    tmp = tmp_path_factory.mktemp("plain")
    python = fresh_venv(tmp / "venv", closure(unconditional(requires(metadata))))
    pip_into(python, wheel)
    elsewhere = tmp / "elsewhere"
    elsewhere.mkdir()
    return python, python.parent, elsewhere


def test_the_wheel_carries_every_module_and_data_file(wheel):
    with zipfile.ZipFile(wheel) as z:
        names = set(z.namelist())
    modules = {p.relative_to(ROOT).as_posix() for p in (ROOT / "navlib").rglob("*.py")}
    missing = sorted(modules - names)
    assert not missing, (
        f"not in the wheel (add the package to [tool.setuptools] packages): {missing[:5]}"
    )
    data = {p.name for p in (ROOT / "data").iterdir() if p.suffix in (".csv", ".md")}
    assert data and {f"navlib/_data/{n}" for n in data} <= names
    assert not any(
        n.startswith(("tests/", "notebooks/", "book/", "data/", "navbook/")) for n in names
    )
    tooling = [n for n in names if n.removesuffix(".py").replace("/", ".") in BOOK_TOOLING]
    assert not tooling, f"the book's tooling is in navlib's wheel: {tooling}"


def test_metadata_needs_no_torch_and_no_book_tooling(metadata):
    assert metadata["Requires-Python"] == ">=3.11"
    reqs = requires(metadata)
    plain = {canonicalize_name(r.name) for r in unconditional(reqs)}
    assert plain == CORE, (
        f"unconditional requirements {sorted(plain)}: the core must be {sorted(CORE)}"
    )
    assert not [
        r for r in reqs if r.specifier and any(s.operator == "==" for s in r.specifier)
    ]  # no exact pins
    for r in reqs:
        if canonicalize_name(r.name) in EXTRA_ONLY:
            assert r.marker is not None and "extra" in str(r.marker), f"{r} outside the extras"
    torch = [r for r in reqs if r.name == "torch"]
    assert torch and all(r.marker == Marker('extra == "nets"') for r in torch)
    assert {"nets", "dist", "book", "test"} <= set(metadata.get_all("Provides-Extra"))


def test_the_premise_the_plain_environment_has_no_optional_dependency(installed):
    python, _, elsewhere = installed
    probe = (
        "import importlib.util as u; "
        f"print([m for m in {NOT_IMPORTED[:-1]!r} if u.find_spec(m) is not None])"
    )
    assert check(run([python, "-c", probe], cwd=elsewhere)).stdout.strip() == "[]"


def test_the_command_line_runs_from_another_directory_without_torch_or_book_tooling(installed):
    python, bindir, elsewhere = installed
    sweeps = ROOT / "data" / "compass_sweeps.csv"
    out = check(
        run(
            [
                python,
                "-X",
                "importtime",
                bindir / "navlib",
                "loop",
                "compass",
                sweeps,
                "--model",
                "misalignment",
                "--json",
            ],
            cwd=elsewhere,
        )
    )
    result = json.loads(out.stdout)
    assert result["system"] == "compass" and result["rows"] == len(pd.read_csv(sweeps))
    assert len(result["steps"]) >= 2 and result["final"]["rms"] < result["steps"][0]["rms"]
    imported = {
        ln.split("|")[-1].strip() for ln in out.stderr.splitlines() if ln.startswith("import time:")
    }
    assert {"navlib.cli", "navlib.workbench.loop"} <= imported
    assert not [m for m in NOT_IMPORTED if m in imported]
    assert not list(elsewhere.iterdir())  # a loop without --report writes nothing
    # every subcommand's parser works in the plain install (its module-level imports ran above)
    code = (
        "import contextlib, io, navlib.cli as c; p = c.build_parser(); "
        "cmds = [a for a in p._actions if a.dest == 'command'][0].choices\n"
        "for n in cmds:\n"
        "    with contextlib.redirect_stdout(io.StringIO()), contextlib.suppress(SystemExit) as s:\n"
        "        p.parse_args([n, '--help'])\n"
        "    print(n)"
    )
    commands = check(run([python, "-c", code], cwd=elsewhere)).stdout.split()
    assert "loop" in commands and "diagnose" in commands
    help_ = check(run([bindir / "navlib", "--help"], cwd=elsewhere)).stdout
    assert all(c in help_ for c in commands)


def test_the_shipped_examples_run_from_a_plain_install(installed):
    """``navlib examples`` in the plain install lists files in site-packages, and each listed command runs
    from another folder (README's "Use navlib without the book")."""
    python, bindir, elsewhere = installed
    listed = check(run([bindir / "navlib", "examples"], cwd=elsewhere)).stdout
    commands = [ln.strip() for ln in listed.splitlines() if ln.startswith("    navlib ")]
    assert len(commands) >= 3 and "site-packages" in listed
    for command in commands:
        check(run([bindir / "navlib", *command.split()[1:]], cwd=elsewhere))
    assert not list(elsewhere.iterdir())


def test_data_files_are_read_from_site_packages(installed):
    python, _, elsewhere = installed
    code = (
        "import navlib, navlib.paths as p, navlib.data.gyro_tables as g, navlib.data.tumble as t; "
        "print(navlib.__file__); print(p.data_dir()); print(len(g.load_hot_train())); "
        "print(len(t.read_tumble()))"
    )
    out = check(run([python, "-c", code], cwd=elsewhere)).stdout.splitlines()
    package = Path(out[0]).parent
    assert ROOT not in package.parents and Path(out[1]) == package / "_data"
    assert int(out[2]) == len(pd.read_csv(ROOT / "data" / "gyro_table2_hot_train.csv"))
    assert int(out[3]) == len(pd.read_csv(ROOT / "data" / "accel_tumble.csv"))


def test_the_compiled_kernels_import_on_the_declared_dependencies(installed):
    """numba is a core dependency (it was undeclared before issue 19)."""
    python, _, elsewhere = installed
    code = "import sys, navlib.methods.elm, navlib.methods.de; print('numba' in sys.modules)"
    assert check(run([python, "-c", code], cwd=elsewhere)).stdout.split() == ["True"]


def test_a_torch_module_says_which_extra_to_install(installed):
    python, _, elsewhere = installed
    for module in ("navlib.methods.mlp", "navlib.methods.bpnet"):
        out = run([python, "-c", f"import {module}"], cwd=elsewhere)
        assert out.returncode == 1
        last = out.stderr.strip().splitlines()[-1]
        assert last == (
            f"navlib._optional.MissingExtra: {module} needs torch, which is not installed: "
            "pip install 'navlib[nets]'"
        )


def test_the_plain_install_has_no_book_tooling_and_judges_claims(installed):
    """navlib's claims and verdicts work without the book; the book's tooling is not there."""
    python, _, elsewhere = installed
    probe = (
        "import importlib.util as u; "
        f"print([m for m in {BOOK_TOOLING!r} if u.find_spec(m) is not None])"
    )
    assert check(run([python, "-c", probe], cwd=elsewhere)).stdout.strip() == "[]"
    code = (
        "from navlib import verdicts; from navlib.claims import Claim; "
        "c = Claim('c', 'p', statistic='x, deg', estimate=verdicts.exact(0.5), boundary=1.0, "
        "holds_when='below'); print(c.verdict)"
    )
    assert check(run([python, "-c", code], cwd=elsewhere)).stdout.strip() == "reproduced"
    assert not list(elsewhere.iterdir())


def test_the_editable_install_finds_the_data_files_through_importlib_resources(tmp_path):
    """The Makefile's ``pip install --no-deps --no-build-isolation -e .``: navlib._data maps to data/."""
    src = copy_sources(tmp_path / "src")
    build = {"setuptools", "wheel"} & {
        canonicalize_name(d.metadata["Name"]) for d in md.distributions()
    }
    python = fresh_venv(tmp_path / "venv", {"packaging", *build})
    pip_into(python, "--no-build-isolation", "-e", src)
    code = (
        "import importlib.util, navlib, navlib.paths as p; print(navlib.__file__); "
        "print(importlib.util.find_spec('navlib._data').origin); print(p.data_path('README.md'))"
    )
    out = check(run([python, "-c", code], cwd=tmp_path)).stdout.splitlines()
    assert out == [
        str(src / "navlib" / "__init__.py"),
        str(src / "data" / "__init__.py"),
        str(src / "data" / "README.md"),
    ]


def test_pyproject_lower_bounds_are_the_locked_versions():
    """Every requirement of pyproject.toml that environment.lock pins has one lower bound (``>=``), and it is
    the pinned version (its base: 2.13.0 for the lock's 2.13.0+cpu, 1.0.4 for 1.0.4.post1), which the whole
    specifier admits; the core and [nets] are pinned."""
    import tomllib

    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    lock = {}
    for line in (ROOT / "environment.lock").read_text().splitlines():
        if "==" in line and not line.startswith("#"):
            name, version = line.split("==")
            lock[canonicalize_name(name)] = version.strip()
    reqs = [Requirement(r) for r in project["dependencies"]]
    must = {canonicalize_name(r.name) for r in reqs} | {"torch"}
    for extra in project["optional-dependencies"].values():
        reqs += [Requirement(r) for r in extra if not r.startswith("navlib")]
    for r in reqs:
        key = canonicalize_name(r.name)
        if key in lock:
            assert r.specifier.contains(lock[key], prereleases=True), (
                f"{r} vs the lock's {lock[key]}"
            )
            lower = [s.version for s in r.specifier if s.operator == ">="]
            assert len(lower) == 1 and Version(lower[0]) == Version(
                Version(lock[key]).base_version
            ), f"{r}: the lower bound must be the lock's {lock[key]}"
        else:
            assert key not in must, f"{r.name} is not pinned in environment.lock"
