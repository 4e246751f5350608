"""The examples in the user-facing docstrings (issue 24) run and print what they say."""

import doctest

import pytest

from navlib.workbench import calibration as calibration_module
from navlib.workbench import diagnose as diagnose_module
from navlib.workbench import loop as loop_module

EXAMPLES = [loop_module.loop, diagnose_module.diagnose, calibration_module.calibrate]


@pytest.mark.parametrize("fn", EXAMPLES, ids=lambda f: f.__qualname__)
def test_docstring_example_runs_as_written(fn):
    tests = doctest.DocTestFinder().find(
        fn, globs=vars(__import__(fn.__module__, fromlist=["x"])).copy()
    )
    examples = [t for t in tests if t.examples]
    assert examples, f"{fn.__qualname__} has no example"
    runner = doctest.DocTestRunner(optionflags=doctest.ELLIPSIS)
    for t in examples:
        runner.run(t)
    assert runner.failures == 0 and runner.tries >= 3
