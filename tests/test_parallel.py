"""navlib.studies.parallel: tasks on this process and spawned workers, results in task order."""
import math
import os

import pytest

from navlib.errors import InputError
from navlib.studies.parallel import run_tasks, start


def test_results_come_back_in_task_order_from_any_process():
    start(2)
    tasks = [(float(k),) for k in range(40)]
    cost = [k % 7 for k in range(40)]
    assert run_tasks(math.sqrt, tasks, workers=2, cost=cost) == [math.sqrt(k) for k in range(40)]
    pids = run_tasks(os.getpid, [()] * 30, workers=2)
    assert os.getpid() in pids                      # this process works too
    assert len(set(pids)) <= 2


def test_one_worker_runs_inline_and_bad_worker_count_is_named():
    assert run_tasks(os.getpid, [()] * 3, workers=1) == [os.getpid()] * 3
    with pytest.raises(InputError, match="workers"):
        run_tasks(os.getpid, [()], workers=0)
