"""One BLAS thread inside the workbench's entry points for library calls (navlib.threads, issue 34)."""

import contextlib

import numpy as np
import pytest
from threadpoolctl import threadpool_info, threadpool_limits

from navlib import threads
from navlib.workbench.calibration import calibrate
from navlib.workbench.diagnose import diagnose
from navlib.workbench.fit import fit_model
from navlib.workbench.loop import loop


def blas_threads():
    return {i["num_threads"] for i in threadpool_info() if i["user_api"] == "blas"}


@pytest.fixture
def no_thread_variables(monkeypatch):
    for k in threads.THREAD_VARIABLES:
        monkeypatch.delenv(k, raising=False)


def test_the_limit_applies_inside_and_is_lifted_after(no_thread_variables):
    if not blas_threads():
        pytest.skip("no BLAS library loaded that threadpoolctl controls")
    np.ones((2, 2)) @ np.ones((2, 2))
    with threadpool_limits(limits=2, user_api="blas"):  # a caller's session with two BLAS threads
        outside = blas_threads()
        seen = threads.one_blas_thread(blas_threads)()
        assert seen == {1}
        assert blas_threads() == outside
        assert threads.one_blas_thread(blas_threads)() == {1}  # the controller kept, again
        assert blas_threads() == outside


def test_a_thread_count_the_caller_chose_is_kept(monkeypatch):
    calls = []

    class Controller:
        def limit(self, **kw):
            calls.append(kw)
            return contextlib.nullcontext()

    monkeypatch.setattr(threads, "_controller", Controller)
    monkeypatch.setenv("OPENBLAS_NUM_THREADS", "4")
    assert threads.one_blas_thread(lambda: 7)() == 7
    assert calls == []
    monkeypatch.delenv("OPENBLAS_NUM_THREADS")
    for k in threads.THREAD_VARIABLES:
        monkeypatch.delenv(k, raising=False)
    nested = threads.one_blas_thread(threads.one_blas_thread(lambda: 8))
    assert nested() == 8
    assert calls == [{"limits": 1, "user_api": "blas"}]  # nested calls set the limit once


@pytest.mark.parametrize("entry", [calibrate, diagnose, fit_model, loop])
def test_the_workbench_entry_points_run_under_the_limit(entry):
    assert getattr(entry, "__wrapped__", None) is not None
    assert entry.__module__.startswith("navlib.workbench")
