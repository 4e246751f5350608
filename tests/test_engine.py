"""navlib.engine (issue 19): every Monte Carlo study on dask.distributed.

The same study gives identical numbers in this process (workers=1), on a local cluster of 2 worker
processes and on a cluster started here as separate ``dask scheduler`` and ``dask worker`` processes on
127.0.0.1; a worker killed in the middle of a study is replaced and the study completes with the same
numbers; every trial of every study has its own seed.
"""

import ast
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from navlib import engine
from navlib.errors import InputError
from navlib.studies import accelerometer as accel_study
from navlib.studies import celestial
from navlib.workbench import accelerometer as A
from navlib.workbench import trials as T

ROOT = Path(__file__).resolve().parents[1]


def _drift_study(**where):
    return T.hidden_effect_study(
        "drift",
        ratios=(3.0,),
        noises=(1e-4, 3e-4),
        seeds=range(3),
        n=6,
        none_seeds=range(5),
        **where,
    )


@pytest.fixture(scope="module")
def reference():
    """The study in this process (workers=1)."""
    return _drift_study(workers=1)


def _pid(_):
    return os.getpid()


@pytest.mark.slow
def test_local_cluster_gives_the_numbers_of_one_process(reference):
    two = _drift_study(workers=2)
    pd.testing.assert_frame_equal(reference, two)
    assert len(reference) == 2 * (4 * 3 + 5) and reference.seed.is_unique
    pids = engine.run(_pid, [(k,) for k in range(12)], workers=2, cost=list(range(12)))
    assert os.getpid() not in pids and 1 <= len(set(pids)) <= 2  # ran in the worker processes
    # results in task order whatever the priorities
    assert engine.run(
        np.sqrt, [(float(k),) for k in range(30)], workers=2, cost=[k % 7 for k in range(30)]
    ) == [np.sqrt(float(k)) for k in range(30)]


@pytest.mark.slow
def test_patent_b_paper_d_and_paper_e_studies_on_two_workers_equal_one():
    from dataclasses import replace
    from navlib.data.compass_sweeps import split_sweeps
    from navlib.methods.anfis import AnfisOptions
    from navlib.methods.fish_swarm import FishSwarmParams
    from navlib.sensors.compass import SweepConfig, simulate_train_test
    from navlib.studies.compass import StudyParams, Sweeps, elm_patent

    train, test = split_sweeps(simulate_train_test(config=SweepConfig(glitch_prob=0.05), seed=7))
    sw, p = Sweeps(train, test), StudyParams()
    p = replace(p, lm=replace(p.lm, epochs=10), adam=replace(p.adam, epochs=20))
    for study in (
        lambda w: elm_patent.node_count_curve(sw, p, seeds=range(3), max_nodes=5, workers=w),
        lambda w: elm_patent.glitch_study(train, test, p, seeds=range(3), method="elm", workers=w),
        lambda w: elm_patent.small_sample_study(
            sw, sizes=(8, 15), params=p, seeds=range(2), big_hidden=5, workers=w
        ),
    ):
        pd.testing.assert_frame_equal(study(1), study(2))
    dp = accel_study.PaperDParams(
        seeds=(0, 1),
        anfis=AnfisOptions(epochs=2),
        swarm=FishSwarmParams(n_fish=3, generations=1, try_number=1),
        mlp=replace(accel_study.PaperDParams().mlp, epochs=3),
    )
    pd.testing.assert_frame_equal(
        accel_study.errors_long(accel_study.run_study(dp, workers=1)),
        accel_study.errors_long(accel_study.run_study(dp, workers=2)),
    )
    spec = celestial.StudySpec(
        duration_s=20.0,
        n_train_runs=1,
        n_test_runs=1,
        n_repeats=2,
        epochs=3,
        n_timings=1,
        timing_epochs=1,
        settle_s=5.0,
        lm_timings=1,
        sweep_ppm=(0.0, 100.0),
        sweep_repeats=1,
        latency_ms_levels=(10.0,),
        smear_levels_arcsec_per_deg_s=(),
    )
    one, two = celestial.simulate(spec, workers=1), celestial.simulate(spec, workers=2)
    for name in ("scores", "glr", "glr_runs", "rate_corr", "traces", "sweep", "diagnosis"):
        pd.testing.assert_frame_equal(getattr(one, name), getattr(two, name))


def test_one_worker_runs_here_and_bad_settings_are_named():
    assert engine.run(_pid, [(0,), (1,)], workers=1) == [os.getpid()] * 2
    assert engine.client(1) is None
    with pytest.raises(InputError, match="workers"):
        engine.run(_pid, [(0,)], workers=0)
    for bad in ("not an address", "tcp://127.0.0.1", "http://x:1 y"):
        with pytest.raises(InputError, match="scheduler"):
            engine.run(_pid, [(0,)], scheduler=bad)


def test_without_tqdm_a_forced_progress_bar_is_quietly_left_out(monkeypatch):
    """tqdm is not a core dependency: ``NAVLIB_PROGRESS=1`` in a plain install must not stop a study."""
    monkeypatch.setitem(sys.modules, "tqdm", None)  # import tqdm fails, find_spec is None
    monkeypatch.setitem(sys.modules, "tqdm.auto", None)
    monkeypatch.setenv(engine.ENV_PROGRESS, "1")
    assert engine._show_progress(None)
    assert engine.run(np.sqrt, [(float(k),) for k in range(5)], workers=1) == [
        np.sqrt(float(k)) for k in range(5)
    ]
    assert engine.run_batches(_pid, [(k,) for k in range(5)], 2, workers=1) == [os.getpid()] * 5


def test_a_missing_optional_package_is_one_line_naming_the_extra(monkeypatch):
    """dask.distributed, papermill and torch: one message, an InputError (and a ModuleNotFoundError)."""
    from navbook import grid

    from navlib import _optional

    for module in ("distributed", "papermill", "torch"):
        monkeypatch.setitem(sys.modules, module, None)
    with pytest.raises(InputError) as err:
        engine.start(workers=3)  # checked before any cluster starts
    assert str(err.value) == (
        "workers=3 needs distributed, which is not installed: pip install 'navlib[dist]' "
        "(or run with workers=1)"
    )
    assert not engine.dask_available() and engine.default_workers() == 1
    with pytest.raises(InputError) as err:
        grid._papermill()
    assert str(err.value) == (
        "grid needs papermill, which is not installed: pip install 'navlib[book]' "
        "(or pip install papermill ipykernel)"
    )
    with pytest.raises(ModuleNotFoundError) as err:
        _optional.require("torch", "navlib.methods.mlp")
    assert isinstance(err.value, InputError) and err.value.name == "torch"
    assert (
        str(err.value)
        == "navlib.methods.mlp needs torch, which is not installed: pip install 'navlib[nets]'"
    )


BLAS_PROBE = """
import ctypes, os, sys
from navlib import engine

def threads():
    import numpy  # noqa: F401  (loads OpenBLAS, as any task does)
    libs = sorted({ln.split()[-1] for ln in open("/proc/self/maps") if "openblas" in ln.lower() and ".so" in ln})
    n = None
    for path in libs:
        lib = ctypes.CDLL(path)
        f = next((getattr(lib, s) for s in ("scipy_openblas_get_num_threads64_", "openblas_get_num_threads64_",
                                            "openblas_get_num_threads") if hasattr(lib, s)), None)
        n = int(f()) if f is not None else n
    with open("/proc/self/environ", "rb") as f:          # the environment the process started with
        start = dict(v.decode().partition("=")[::2] for v in f.read().split(b"\\0") if v)
    return os.getpid(), {k: start.get(k) for k in engine.WORKER_ENV}, n

if __name__ == "__main__":
    print((os.getpid(), engine.run(threads, [()] * 4, workers=2, progress=False)))
"""


@pytest.mark.slow
def test_local_workers_start_with_one_blas_thread(tmp_path):
    """The one-thread variables reach a local worker before numpy loads in it: they are in the environment
    its process started with (the nannies' pre-spawn environment), so a caller whose environment sets none
    of them gets workers whose OpenBLAS runs one thread."""
    script = tmp_path / "probe.py"
    script.write_text(BLAS_PROBE)
    env = {
        k: v
        for k, v in os.environ.items()
        if k not in engine.WORKER_ENV and k != engine.ENV_SCHEDULER
    }
    env["PYTHONPATH"] = os.pathsep.join(
        p for p in (str(ROOT), os.environ.get("PYTHONPATH", "")) if p
    )
    out = subprocess.run(
        [sys.executable, str(script)], capture_output=True, text=True, env=env, timeout=300
    )
    assert out.returncode == 0, out.stderr[-2000:]
    main, rows = ast.literal_eval(out.stdout.strip().splitlines()[-1])
    assert main not in {r[0] for r in rows}  # ran in the workers
    assert all(r[1] == engine.WORKER_ENV for r in rows), rows
    if rows[0][2] is not None:  # OpenBLAS's own count, where it says
        assert {r[2] for r in rows} == {1}, rows


def _raise_input_error(k):
    if k == 3:
        raise InputError("parameter k=3: refused")
    return k


def test_an_error_in_a_task_reaches_the_caller_as_raised():
    with pytest.raises(InputError, match="k=3: refused"):
        engine.run(_raise_input_error, [(k,) for k in range(6)], workers=2)


def _stamp(k, pause_s):
    """When task ``k`` started (the system's monotonic clock, shared by the processes of this machine)."""
    t = time.monotonic()
    time.sleep(pause_s)
    return k, t


def test_a_background_study_gives_the_direct_numbers_and_yields_to_the_foreground(reference):
    job = engine.background(_drift_study, workers=2)
    slow = engine.background(engine.run, _stamp, [(k, 0.2) for k in range(24)], workers=2, tier=-2)
    time.sleep(0.5)  # its tasks are queued on the workers by now
    fore = engine.run(_stamp, [(k, 0.05) for k in range(4)], workers=2)
    pd.testing.assert_frame_equal(job.result(), reference)
    back = slow.result()
    assert [k for k, _ in back] == list(range(24)) and job.done() and slow.done()
    # the foreground's tasks started before most of the queued background ones (without the tiers a
    # 4-task study's priorities, 1..4, sit below a 24-task one's, and it would start last)
    last_fore = max(t for _, t in fore)
    assert sum(t > last_fore for _, t in back) >= 12


def test_a_one_process_background_study_runs_when_asked_and_errors_come_back_as_raised():
    calls = []
    job = engine.background(lambda workers=1: calls.append(workers) or 7)
    assert calls == [] and not job.done()
    assert job.result() == 7 and calls == [1] and job.result() == 7 and calls == [1]
    bad = engine.background(engine.run, _raise_input_error, [(k,) for k in range(6)], workers=2)
    with pytest.raises(InputError, match="k=3: refused"):
        bad.result()
    for tier in (0, 1, 1.5, True):
        with pytest.raises(InputError, match="parameter tier"):
            engine.background(len, (), tier=tier)


def _trial_or_die(marker: str, *args):
    """A hidden-effect trial; the first time it is asked for the trial marked, its worker process dies."""
    m = Path(marker)
    if args[-2].spawn_key[-1] == 1 and args[1] == "bias" and not m.exists():
        m.write_text("died once")
        os.kill(os.getpid(), signal.SIGKILL)
    return T.hidden_effect_trial(*args)


def test_a_worker_killed_mid_study_is_replaced_and_the_numbers_stay(reference, tmp_path):
    args = [
        (str(tmp_path / "marker"),) + a for a in _study_args(T, "hidden_effect_trial", _drift_study)
    ]
    c = engine.client(2)
    before = set(c.scheduler_info(n_workers=-1)["workers"])
    rows = engine.run_batches(_trial_or_die, args, T.TRIAL_BATCH, workers=2)
    assert (tmp_path / "marker").exists()  # a worker did die
    pd.testing.assert_frame_equal(pd.DataFrame(rows), reference)
    c.wait_for_workers(2, timeout=60)  # its nanny started a new one
    assert set(c.scheduler_info(n_workers=-1)["workers"]) != before


# ------------------------------------------------------------------------------------------ remote


@pytest.mark.slow
def test_a_cluster_of_separate_processes_gives_the_same_numbers(reference, remote, monkeypatch):
    pd.testing.assert_frame_equal(_drift_study(scheduler=remote), reference)
    pids = engine.run(_pid, [(k,) for k in range(8)], scheduler=remote)
    assert os.getpid() not in pids
    monkeypatch.setenv(engine.ENV_SCHEDULER, remote)  # the environment variable
    pd.testing.assert_frame_equal(_drift_study(), reference)


def run_cli(*args, prog="navlib"):
    env = {k: v for k, v in os.environ.items() if k != engine.ENV_SCHEDULER}
    return subprocess.run(
        [sys.executable, "-m", prog, *map(str, args)], capture_output=True, text=True, env=env
    )


@pytest.mark.slow
def test_cli_rates_same_on_the_cluster_and_here(remote):
    here = run_cli(
        "rates",
        "drift",
        "--trials",
        "2",
        "--null-trials",
        "3",
        "--noise",
        "1e-4,3e-4",
        "--workers",
        "1",
        "--json",
    )
    assert here.returncode == 0, here.stderr
    there = run_cli(
        "rates",
        "drift",
        "--trials",
        "2",
        "--null-trials",
        "3",
        "--noise",
        "1e-4,3e-4",
        "--scheduler",
        remote,
        "--json",
    )
    assert there.returncode == 0, there.stderr
    assert json.loads(here.stdout) == json.loads(there.stdout)


# ------------------------------------------------------------------------------------------ seeds
def _study_args(module, trial_name, call):
    """The argument tuples a study hands to its trial function (run_trials intercepted)."""
    seen = []

    def collect(fn, args, *rest, **kw):
        assert fn is getattr(module, trial_name)
        seen.extend(args)
        return []

    mp = pytest.MonkeyPatch()
    mp.setattr(module, "run_trials", collect)
    try:
        call()
    finally:
        mp.undo()
    return seen


def _keys(args):
    seeds = [next(a for a in t if isinstance(a, np.random.SeedSequence)) for t in args]
    return [(s.entropy, s.spawn_key) for s in seeds]


@pytest.mark.parametrize(
    "module, trial, call, n",
    [
        (
            T,
            "hidden_effect_trial",
            lambda: T.hidden_effect_study(
                "compass",
                ratios=(5.0, 5.5),
                noises=(0.05, 0.2),
                seeds=range(3),
                none_seeds=range(4),
            ),
            2 * (4 * 2 * 3 + 4),
        ),
        (
            T,
            "out_of_catalogue_trial",
            lambda: T.out_of_catalogue_study(ratios=(5.0, 5.5), noises=(0.05, 0.2), seeds=range(3)),
            4 * 2 * 2 * 3,
        ),
        (
            T,
            "hidden_effect_trial",
            lambda: T.correlated_noise_study("compass", correlations=(0.0, 0.9), seeds=range(3)),
            2 * (4 * 3 + 3),
        ),
        (
            A,
            "hidden_effect_trial",
            lambda: A.hidden_effect_study(
                ratios=(0.1, 0.2, 0.5), noise_ug=(3.0, 5.0), seeds=range(3), none_seeds=range(4)
            ),
            2 * (len(A.ACCELEROMETER_EFFECTS) * 3 * 3 + 4),
        ),
    ],
)
def test_every_trial_of_a_study_has_its_own_seed(module, trial, call, n):
    args = _study_args(module, trial, call)
    keys = _keys(args)
    assert len(keys) == n and len(set(keys)) == n
    first = [
        np.random.default_rng(np.random.SeedSequence(e, spawn_key=k)).random() for e, k in keys
    ]
    assert len(set(first)) == n  # and so its own draws


def test_accelerometer_and_workbench_trials_share_no_seed():
    a = _keys(_study_args(A, "hidden_effect_trial", lambda: A.hidden_effect_study(seeds=range(3))))
    w = _keys(
        _study_args(
            T, "hidden_effect_trial", lambda: T.hidden_effect_study("compass", seeds=range(3))
        )
    )
    assert not set(a) & set(w)


def test_paper_d_and_e_draws_have_their_own_seeds():
    d = [accel_study.sim_seed(s, part) for s in range(6) for part in accel_study.SIM_PARTS]
    assert len({(x.entropy, x.spawn_key) for x in d}) == len(d)
    spec = celestial.StudySpec()
    e = [
        celestial.seed_of(spec, rep, "noise", k, i)
        for rep in range(spec.n_repeats)
        for k in range(2)
        for i in range(spec.n_train_runs + spec.n_test_runs)
    ]
    e += [
        celestial.seed_of(spec, rep, "manoeuvre", i)
        for rep in range(spec.n_repeats)
        for i in range(spec.n_train_runs + 1)
    ]
    e += [celestial.seed_of(spec, rep, "network") for rep in range(spec.n_repeats)]
    assert len(set(e)) == len(e)


# ------------------------------------------------------------------------------------------ rates
@pytest.mark.slow
def test_cli_rates_gives_every_rate_with_its_wilson_interval():
    from navlib import verdicts

    r = run_cli(
        "rates",
        "compass",
        "--trials",
        "1",
        "--null-trials",
        "2",
        "--noise",
        "0.1",
        "--workers",
        "1",
        "--json",
    )
    assert r.returncode == 0, r.stderr
    out = json.loads(r.stdout)
    assert out["system"] == "compass" and out["unit"] == "deg" and out["noise"] == [0.1]
    assert {(d["effect"], d["ratio"]) for d in out["detection"]} == {
        (e, q)
        for e in ("misalignment", "hard_iron", "soft_iron", "temperature")
        for q in (3.0, 10.0)
    }
    for d in out["detection"]:
        e = verdicts.wilson(d["named"], d["trials"])
        assert (d["rate"], d["low"], d["high"]) == pytest.approx((e.value, e.lo, e.hi))
    (fa,) = out["false_alarms"]
    assert fa["trials"] == 2 and fa["rate"] == fa["alarms"] / 2
    assert len(out["out_of_catalogue"]) == 4 * 2 and all(
        o["trials"] == 1 for o in out["out_of_catalogue"]
    )
    text = run_cli("rates", "drift", "--trials", "1", "--null-trials", "1", "--workers", "1")
    assert (
        text.returncode == 0
        and "false alarms" in text.stdout
        and "outside the catalogue" not in text.stdout
    )


@pytest.mark.parametrize(
    "args, names",
    [
        (("--noise", "abc"), "--noise='abc'"),
        (("--trials", "0"), "trials=0"),
        (("--ratio", "-1"), "ratio=-1"),
        (("--scheduler", "not an address"), "scheduler"),
        (("--workers", "0"), "workers=0"),
    ],
)
@pytest.mark.slow
def test_cli_rates_bad_input_is_one_line(args, names):
    r = run_cli("rates", "drift", *args)
    assert r.returncode == 2 and names in r.stderr and len(r.stderr.strip().splitlines()) == 1, (
        r.stderr
    )


# ------------------------------------------------------------------------------------------ grid
GYRO = ROOT / "notebooks" / "gyro.ipynb"


@pytest.mark.parametrize(
    "param, names",
    [
        ("n_sedes=3", "'n_sedes' is not in the parameters cell"),
        ("n_seeds=3,x", "n_seeds='x': expected a whole number"),
        ("goal_kind=", "empty value"),
        ("n_seeds", "NAME=V1,V2"),
        ("n_seeds=2,2", "value '2' given twice"),
    ],
)
@pytest.mark.slow
def test_cli_grid_refuses_bad_parameters_before_any_run(tmp_path, param, names):
    r = run_cli(
        "grid", GYRO, "--param", param, "--out", tmp_path / "out", "--workers", "1", prog="navbook"
    )
    assert r.returncode == 2 and names in r.stderr and len(r.stderr.strip().splitlines()) == 1, (
        r.stderr
    )
    assert not (tmp_path / "out").exists()


@pytest.mark.slow
def test_cli_grid_refuses_a_folder_with_files_and_says_papermill_is_missing(
    tmp_path, capsys, monkeypatch
):
    (tmp_path / "old.txt").write_text("mine")
    r = run_cli(
        "grid", GYRO, "--param", "n_seeds=2", "--out", tmp_path, "--workers", "1", prog="navbook"
    )
    assert (
        r.returncode == 2
        and "not empty" in r.stderr
        and (tmp_path / "old.txt").read_text() == "mine"
    )
    from navbook import cli

    monkeypatch.setitem(sys.modules, "papermill", None)  # import papermill fails
    assert (
        cli.main(
            [
                "grid",
                str(GYRO),
                "--param",
                "n_seeds=2",
                "--out",
                str(tmp_path / "new"),
                "--workers",
                "1",
            ]
        )
        == 2
    )
    err = capsys.readouterr().err
    assert "grid needs papermill" in err and len(err.strip().splitlines()) == 1


@pytest.mark.slow
def test_cli_grid_runs_a_chapter_on_the_cluster(remote, tmp_path):
    out = tmp_path / "grid"
    r = run_cli(
        "grid",
        GYRO,
        "--param",
        "input_unit=arcmin,deg",
        "--param",
        "n_seeds=2",
        "--out",
        out,
        "--scheduler",
        remote,
        prog="navbook",
    )
    assert r.returncode == 0, r.stderr
    assert r.stderr == ""  # the kernels' chatter stays in the runs
    rows = pd.read_csv(out / "grid.csv")
    assert list(rows["run"]) == [1, 2] and (rows["status"] == "ok").all(), rows["status"]
    assert list(zip(rows.input_unit, rows.n_seeds)) == [("arcmin", 2), ("deg", 2)]
    for k in (1, 2):
        assert (out / f"gyro_{k:03d}.ipynb").is_file() and (
            out / "results" / f"gyro_{k:03d}" / "gyro.json"
        ).is_file()
    verdict_cols = [c for c in rows if c.endswith(": verdict")]
    stat_cols = [c for c in rows if ": median_rms_" in c]
    assert verdict_cols and stat_cols and rows[verdict_cols].notna().all().all()
    # each run wrote its own results with its own parameters: the input unit changes verdicts
    assert rows.loc[0, verdict_cols].tolist() != rows.loc[1, verdict_cols].tolist()
    nb = json.loads((out / "gyro_002.ipynb").read_text())
    injected = next(
        c for c in nb["cells"] if "injected-parameters" in c["metadata"].get("tags", [])
    )
    assert 'input_unit = "deg"' in "".join(injected["source"]) and "n_seeds = 2" in "".join(
        injected["source"]
    )
    r2 = run_cli(
        "grid", GYRO, "--param", "n_seeds=2", "--out", out, "--scheduler", remote, prog="navbook"
    )
    assert r2.returncode == 2 and "not empty" in r2.stderr  # never writes over earlier outputs
