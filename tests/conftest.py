"""Test-run order: the longest test files first.

``make test-lib`` runs the files in two processes (pytest-xdist ``--dist loadfile
--no-loadscope-reorder``), handing out whole files in collection order; a long file handed out last
would run alone while the other process idles.  Listed here, longest first (measured with
``--durations``), so the processes finish together; every other file follows in name order.  The order
changes no result: every test is independent of the others.
"""
from pathlib import Path

LONGEST_FIRST = ("test_workbench_correlated.py", "test_diagnose.py", "test_engine.py",
                 "test_workbench_screen.py", "test_celestial.py", "test_workbench_free.py",
                 "test_workbench_loop.py", "test_compass_study.py", "test_install.py")


def pytest_collection_modifyitems(items):
    rank = {name: i for i, name in enumerate(LONGEST_FIRST)}
    items.sort(key=lambda item: rank.get(Path(str(item.fspath)).name, len(rank)))
