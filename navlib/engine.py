"""The one engine of navlib's Monte Carlo work (seed studies, rate trials, notebook grids): dask.distributed.

A study is a list of independent tasks ``fn(*args)``; :func:`run` returns ``[fn(*a) for a in tasks]`` in
task order, wherever the tasks ran:

- ``workers=1`` and no scheduler: in this process, in order (dask is not even imported, so a plain
  ``pip install navlib`` without the ``dist`` extra runs every study);
- ``workers=N`` > 1: a ``dask.distributed.LocalCluster`` of ``N`` single-threaded worker processes
  (OpenBLAS, OpenMP, MKL and torch on one thread each), started on first use and reused by every later
  study of this process (:func:`start` starts it in the background, and lets the workers import the
  modules a chapter needs while the chapter goes on); a script that asks for it runs under
  ``if __name__ == "__main__":`` (the workers are spawned processes);
- a scheduler address (``scheduler="tcp://host:8786"``, or the environment variable ``NAVLIB_SCHEDULER``)
  sends the same tasks to an existing cluster (``dask scheduler`` and ``dask worker`` processes started by
  the user, on this machine or others; ``workers`` is then ignored).

Numbers never depend on where a task ran: every task carries its own seed (a ``numpy.random.SeedSequence``
spawn key of its coordinates in its study, see :mod:`navlib.methods.seeding`), and tasks are cut into
batches of a fixed size (:func:`run_batches`), never into one batch per worker.  So 1 worker, N workers
and a remote cluster give identical results (tested).

Scheduling: tasks with a ``cost`` estimate get dask priorities, the most expensive first (longest
processing time first), so no worker idles at the end while another still runs a long task.  A worker
that dies (killed, out of memory) is restarted by its nanny and the scheduler re-runs its tasks on
another worker (up to :data:`ALLOWED_FAILURES` deaths per task); an exception raised by a task (bad
input) is not retried: it reaches the caller as raised.  :func:`background` starts a whole study and
returns at once: its tasks wait below the foreground's, and fill the workers while the caller does other
work (a chapter drawing its figures); the numbers are those of the direct call.

Progress: a tqdm bar on stderr for studies that run longer than :data:`PROGRESS_DELAY_S`, only when stderr
is a terminal (never in a notebook's stored outputs) unless ``NAVLIB_PROGRESS=1`` asks for it (``0``
turns it off everywhere); no bar, and no error, when tqdm is not installed (it is not a core dependency).
"""

from __future__ import annotations

import atexit
import importlib
import itertools
import logging
import os
import re
import socket
import struct
import sys
import threading
import time
import uuid
from concurrent.futures import ThreadPoolExecutor
from typing import Any, Callable, Iterable, Sequence

from . import ONE_THREAD
from ._optional import installed, need
from .errors import InputError, check_param

#: Environment variable holding a scheduler address (``tcp://host:port``) every study sends its tasks to.
ENV_SCHEDULER = "NAVLIB_SCHEDULER"
#: Environment variable forcing the progress bar on (``1``) or off (``0``).
ENV_PROGRESS = "NAVLIB_PROGRESS"
#: The progress bar appears only for studies still running after this many seconds.
PROGRESS_DELAY_S = 3.0
#: How many worker deaths a task may see before the scheduler gives up on it (dask's ``allowed-failures``).
ALLOWED_FAILURES = 3
#: Environment of every local worker process: one thread for every numerical library.  Set by the nannies
#: before they spawn a worker (``distributed.nanny.pre-spawn-environ`` in :data:`LOCAL_CONFIG`), so BLAS and
#: OpenMP read it when they load; a value the caller's environment already has wins (dask's rule, as in
#: ``python -m navlib``).
WORKER_ENV = dict(ONE_THREAD)
#: dask settings of the local cluster (its scheduler, nannies and workers): no statistical profiler (it
#: samples every worker's stack every 10 ms) and slower housekeeping loops (dask's defaults cost an idle
#: 2-worker cluster about 12 % of a core, these 1 %); glibc's malloc as in this process.
LOCAL_CONFIG = {
    "distributed.scheduler.allowed-failures": ALLOWED_FAILURES,
    "distributed.worker.profile.enabled": False,
    "distributed.admin.tick.interval": "1s",
    "distributed.admin.system-monitor.interval": "2s",
    "distributed.worker.memory.monitor-interval": "1s",
    # dask's workers start with MALLOC_TRIM_THRESHOLD_=65536, which also fixes glibc's mmap threshold
    # at 128 kB: every numpy temporary above it is mmap'ed and zeroed afresh (paper E's filter ran 1.4x
    # slower in a worker than in this process); the workers keep glibc's adaptive defaults
    "distributed.nanny.pre-spawn-environ": dict(WORKER_ENV),
}
#: Seconds to wait for a scheduler at an address before giving up.
CONNECT_TIMEOUT_S = 10.0
#: Seconds an address has to accept a TCP connection, and then again to send the first message of dask's
#: handshake, before a command stops with one line (:func:`probe_scheduler`): dask itself waits for that
#: message without a limit, so a port that accepts and never answers would hang the command.  A scheduler
#: sends it at once (on the same machine within milliseconds); 5 s covers a slow network, and the two
#: waits together stay within 10 s.
PROBE_TIMEOUT_S = 5.0
#: Largest first message (bytes) the probe accepts: a scheduler's handshake is under a hundred bytes (its
#: compression, Python version and pickle protocol); the first 8 bytes of anything else read as a length of
#: up to 2^64, which dask would try to allocate.
PROBE_MAX_BYTES = 1 << 16
#: Most frames the probe accepts in that first message (dask's handshake has one or two).
PROBE_MAX_FRAMES = 64

_ADDRESS = re.compile(r"^(tcp|tls|ws|wss|inproc|ucx)://\S+$")
_CLIENTS: dict[tuple, Any] = {}  # ("local", n) or ("remote", address) -> Client
_CLUSTERS: dict[tuple, Any] = {}  # ("local", n) -> LocalCluster
_PRELOADS: list = []  # futures of start()'s imports (a released future is cancelled)
_STARTING: dict[tuple, Any] = {}  # key -> concurrent.futures.Future of a start() in the background
_LOCK = threading.RLock()
_TIER = threading.local()  # .tier of the study this thread runs (background(); 0 otherwise)
#: Priority distance between tiers of :func:`background` studies: every task of a higher tier outranks every
#: task of a lower one (a study's own priorities are at most its number of tasks).
TIER_STEP = 10**6


# ------------------------------------------------------------------------------------------ where
def scheduler_address(scheduler: str | None = None) -> str | None:
    """The scheduler address tasks go to: ``scheduler``, else ``$NAVLIB_SCHEDULER``, else None (local).
    ``host:port`` is read as ``tcp://host:port``; anything else that is not an address is refused."""
    addr = scheduler if scheduler is not None else os.environ.get(ENV_SCHEDULER) or None
    if addr is None:
        return None
    if not isinstance(addr, str) or not addr.strip():
        raise InputError(f"scheduler {addr!r}: give an address such as tcp://127.0.0.1:8786")
    given = addr.strip()
    addr = given if "://" in given else "tcp://" + given
    if not _ADDRESS.match(addr) or (addr.startswith("tcp://") and not re.search(r":\d+$", addr)):
        raise InputError(
            f"scheduler {given!r}: give an address such as tcp://127.0.0.1:8786 (host and port)"
        )
    return addr


def _recv(sock, n: int, deadline: float, addr: str, timeout: float) -> bytes:
    """Exactly ``n`` bytes from ``sock`` before ``deadline`` (``time.monotonic``); one-line InputError when the
    peer is silent or hangs up."""
    buf = b""
    while len(buf) < n:
        left = deadline - time.monotonic()
        if left <= 0:
            raise InputError(
                f"scheduler {addr}: accepts connections but sent no dask handshake within {timeout:g} s "
                f"(not a dask scheduler, or a stuck one)"
            )
        sock.settimeout(left)
        try:
            chunk = sock.recv(n - len(buf))
        except socket.timeout:
            continue  # the deadline check above says it
        if not chunk:
            raise InputError(
                f"scheduler {addr}: closed the connection without a dask handshake (not a dask "
                f"scheduler?)"
            )
        buf += chunk
    return buf


def probe_scheduler(addr: str, timeout: float | None = None) -> None:
    """Check that ``addr`` answers like a dask scheduler before dask connects to it, in at most twice
    ``timeout`` seconds (default :data:`PROBE_TIMEOUT_S`): a TCP connection within ``timeout``, then,
    within ``timeout`` again, the first message of dask's handshake, which a scheduler sends as soon as it
    accepts a connection.  The message is read as dask's TCP comm frames it
    (``distributed.comm.tcp.TCP.read``): an 8-byte length (native byte order), then the number of frames
    and their lengths (8 bytes each), then the frames; the length must be at most :data:`PROBE_MAX_BYTES`,
    the frames between 1 and :data:`PROBE_MAX_FRAMES` and their lengths must add up to it.  Anything else
    (silence, a closed connection, another protocol, random bytes) is a one-line InputError, before dask
    would wait for ever or allocate what the garbage announces.  The connection is then closed (the
    scheduler logs a handshake cut short).  Only ``tcp://`` addresses are probed (TLS, websockets and UCX
    speak their own protocol first: dask's ``timeout`` is their only guard)."""
    if not addr.startswith("tcp://"):
        return
    timeout = PROBE_TIMEOUT_S if timeout is None else float(timeout)
    host, _, port = addr[len("tcp://") :].rpartition(":")
    host = host.strip("[]")  # an IPv6 address in brackets
    try:
        sock = socket.create_connection((host, int(port)), timeout=timeout)
    except socket.timeout:
        raise InputError(f"scheduler {addr}: no connection within {timeout:g} s") from None
    except OSError as err:
        raise InputError(
            f"scheduler {addr}: cannot connect ({err.strerror or type(err).__name__})"
        ) from None
    with sock:
        deadline = time.monotonic() + timeout
        (total,) = struct.unpack("Q", _recv(sock, 8, deadline, addr, timeout))
        if not 16 <= total <= PROBE_MAX_BYTES:
            raise InputError(
                f"scheduler {addr}: answered something that is not dask's handshake (a first message "
                f"of {total} bytes; a scheduler's is at most {PROBE_MAX_BYTES}): not a dask scheduler"
            )
        body = _recv(sock, total, deadline, addr, timeout)
        (n,) = struct.unpack_from("Q", body)
        head = 8 * (1 + n) if 1 <= n <= PROBE_MAX_FRAMES else None
        ends = (
            []
            if head is None or head > total
            else list(itertools.accumulate(struct.unpack_from(f"{n}Q", body, 8), initial=head))
        )
        if total not in ends:
            raise InputError(
                f"scheduler {addr}: answered something that is not dask's handshake (its frames do not "
                f"add up): not a dask scheduler"
            )


def dask_available() -> bool:
    """True when dask.distributed can be imported (``pip install navlib[dist]``)."""
    return installed("distributed")


def default_workers() -> int:
    """Worker processes a command uses when not told: the cores this process may run on, or 1 when
    dask.distributed is not installed."""
    if not dask_available():
        return 1
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # not on Linux
        return max(1, os.cpu_count() or 1)


def _need_dask(why: str):
    need("distributed", why, alternative="run with workers=1")


def _one_thread() -> None:
    """One thread for torch in this process when torch is already loaded (never imports it)."""
    torch = sys.modules.get("torch")
    if torch is not None and torch.get_num_threads() != 1:
        torch.set_num_threads(1)


def _worker_plugin():
    from distributed import WorkerPlugin  # noqa: PLC0415  # lazy: dask is an extra ([dist])

    class OneThread(WorkerPlugin):
        """Every worker: numerical libraries on one thread (the environment before they load; torch's
        own setting when it is importable)."""

        def setup(self, worker):
            for k, v in WORKER_ENV.items():  # read by OpenMP (torch) and BLAS when they load later
                os.environ.setdefault(k, v)
            _one_thread()  # torch already loaded: its own setting

    return OneThread()


def _key(workers: int, addr: str | None) -> tuple:
    """The cache key of a client: ``("remote", address)``, or ``("local", workers)`` without an address."""
    return ("remote", addr) if addr else ("local", int(workers))


def client(workers: int = 1, scheduler: str | None = None):
    """The ``dask.distributed.Client`` tasks go to, or None when they run in this process (``workers=1``
    and no scheduler address).  Clients and local clusters are made once per process and reused (a
    cluster :func:`start` is still starting is waited for)."""
    check_param("workers", workers, lo=1, integer=True)
    addr = scheduler_address(scheduler)
    if addr is None and int(workers) == 1:
        return None
    key = _key(workers, addr)
    starting = _STARTING.pop(key, None)
    if starting is not None:
        starting.result()  # raises what the start raised
    with _LOCK:
        c = _CLIENTS.get(key)
        if c is not None and c.status == "running":
            return c
        _need_dask(f"scheduler {addr}" if addr else f"workers={workers}")
        return _new_client(key, addr, int(workers))


def _new_client(key, addr, workers):
    import dask  # noqa: PLC0415  # lazy: dask is an extra ([dist])
    from distributed import Client, LocalCluster  # noqa: PLC0415  # lazy: as above

    if addr:
        probe_scheduler(addr)  # a silent or foreign peer: one line, not a hang
        try:
            c = Client(addr, timeout=f"{CONNECT_TIMEOUT_S}s", set_as_default=False)
        except (OSError, TimeoutError) as err:
            raise InputError(
                f"scheduler {addr}: cannot connect ({type(err).__name__}: "
                f"{str(err).splitlines()[0] if str(err) else 'no answer'})"
            ) from None
    else:
        for other in [k for k in _CLUSTERS if k[0] == "local"]:  # one local cluster at a time
            _close(other)
        with dask.config.set(LOCAL_CONFIG):
            cluster = LocalCluster(
                n_workers=workers,
                threads_per_worker=1,
                processes=True,
                host="127.0.0.1",
                dashboard_address=None,
                silence_logs=logging.ERROR,
                scheduler_kwargs={"dashboard_address": ":0"},
            )  # no dashboard; no fixed port
        _CLUSTERS[key] = cluster
        c = Client(cluster, set_as_default=False)
    c.register_plugin(_worker_plugin(), name="navlib-one-thread")
    _CLIENTS[key] = c
    return c


def _close(key) -> None:
    c = _CLIENTS.pop(key, None)
    cluster = _CLUSTERS.pop(key, None)
    for obj in (c, cluster):
        if obj is not None:
            try:
                obj.close()
            except (
                OSError,
                RuntimeError,
                TimeoutError,
            ):  # already gone (interpreter exit, dead loop)
                pass


def shutdown() -> None:
    """Close every client and stop every local cluster this process started (also done at exit)."""
    for f in list(_STARTING.values()):
        try:
            f.result()
        except (
            InputError,
            OSError,
            RuntimeError,
            TimeoutError,
        ):  # reported by client(), if ever asked
            pass
    _STARTING.clear()
    _PRELOADS.clear()
    for key in list(_CLIENTS) + list(_CLUSTERS):
        _close(key)


atexit.register(shutdown)


def _import(modules: Sequence[str]) -> bool:
    for m in modules:
        importlib.import_module(m)
    _one_thread()
    return True


def start(
    workers: int = 1, scheduler: str | None = None, preload: Sequence[str] = (), wait: bool = False
) -> None:
    """Start the local cluster (or connect to the scheduler) in the background and let every worker import
    the modules ``preload`` once it is up: a chapter goes on loading its data meanwhile, and its first
    study waits for the cluster only if it is not up yet.  ``workers`` and the address are checked here;
    a cluster that then fails to start (or a scheduler that does not answer) raises at the first study
    (or here with ``wait=True``).  Nothing happens for ``workers=1`` without a scheduler."""
    check_param("workers", workers, lo=1, integer=True)
    addr = scheduler_address(scheduler)
    if addr is None and int(workers) == 1:
        return
    _need_dask(f"scheduler {addr}" if addr else f"workers={workers}")
    key = _key(workers, addr)
    if key in _STARTING or (key in _CLIENTS and _CLIENTS[key].status == "running"):
        return
    pool = ThreadPoolExecutor(max_workers=1, thread_name_prefix="navlib-engine-start")
    _STARTING[key] = pool.submit(_start, int(workers), addr, tuple(preload))
    pool.shutdown(wait=False)
    if wait:
        client(workers, addr)


def _start(workers: int, addr: str | None, preload: tuple) -> None:
    with _LOCK:
        key = _key(workers, addr)
        c = _CLIENTS.get(key)
        if c is None or c.status != "running":
            c = _new_client(key, addr, workers)
    if preload:
        _PRELOADS[:] = [f for f in _PRELOADS if not f.done()]
        for w in c.scheduler_info(n_workers=-1)["workers"]:
            _PRELOADS.append(
                c.submit(
                    _import,
                    preload,
                    workers=[w],
                    pure=False,
                    allow_other_workers=False,
                    priority=10**9,
                    key=f"navlib-preload-{uuid.uuid4().hex[:8]}",
                )
            )


# ------------------------------------------------------------------------------------------ running
def _show_progress(progress: bool | None) -> bool:
    if progress is not None:
        return bool(progress)
    env = os.environ.get(ENV_PROGRESS)
    if env is not None and env.strip():
        return env.strip().lower() not in ("0", "false", "no", "off")
    return sys.stderr is not None and hasattr(sys.stderr, "isatty") and sys.stderr.isatty()


def _bar(total: int, label: str, show: bool):
    if not show or not installed("tqdm"):  # tqdm is not a core dependency: no bar
        return None
    from tqdm.auto import tqdm  # noqa: PLC0415  # lazy: optional, only for a progress bar

    return tqdm(
        total=total,
        desc=label or "navlib",
        delay=PROGRESS_DELAY_S,
        file=sys.stderr,
        leave=False,
        dynamic_ncols=True,
    )


def _call(fn: Callable, args: tuple):
    _one_thread()
    return fn(*args)


def _batch(fn: Callable, batch: list) -> list:
    return [fn(*a) for a in batch]  # a task of run(): _call has set the threads


def run(
    fn: Callable,
    tasks: Iterable[tuple],
    *,
    workers: int = 1,
    scheduler: str | None = None,
    cost: Sequence[float] | None = None,
    label: str = "",
    progress: bool | None = None,
    weight: Sequence[int] | None = None,
    on_result: Callable[[int, Any], None] | None = None,
) -> list:
    """``[fn(*args) for args in tasks]`` on the engine (see the module docstring), results in task order.

    Parameters
    ----------
    fn : callable
        A module-level function (it is sent to worker processes by reference).
    tasks : iterable of tuple
        The arguments of each call.
    workers : int
        Worker processes of the local cluster; 1 runs in this process.
    scheduler : str, optional
        Address of an existing dask scheduler (default ``$NAVLIB_SCHEDULER``); overrides ``workers``.
    cost : sequence of float, optional
        Estimated cost of each task: the most expensive start first (dask priorities).
    label : str
        Name shown on the progress bar.
    progress : bool, optional
        Force the progress bar on or off (default: see the module docstring).
    weight : sequence of int, optional
        What each task counts for on the progress bar (e.g. the trials in a batch).
    on_result : callable, optional
        ``on_result(i, result)`` is called in this process as soon as task ``i`` is done (e.g. to write
        its output while the others still run).

    Returns
    -------
    list
        One result per task, in the order of ``tasks``.  The first exception a task raised is raised here
        (the other tasks are cancelled).
    """
    tasks = [tuple(t) for t in tasks]
    if cost is not None and len(cost) != len(tasks):
        raise InputError(f"engine.run: {len(cost)} costs for {len(tasks)} tasks")
    weight = [1] * len(tasks) if weight is None else [int(w) for w in weight]
    addr = scheduler_address(scheduler)
    check_param("workers", workers, lo=1, integer=True)
    bar = _bar(sum(weight), label, _show_progress(progress))
    try:
        if addr is None and (int(workers) == 1 or len(tasks) <= 1):
            out = []
            for i, (t, w) in enumerate(zip(tasks, weight)):
                out.append(_call(fn, t))
                if on_result is not None:
                    on_result(i, out[-1])
                if bar is not None:
                    bar.update(w)
            return out
        return _run_dask(client(workers, addr), fn, tasks, cost, label, bar, weight, on_result)
    finally:
        if bar is not None:
            bar.close()


def _run_dask(c, fn, tasks, cost, label, bar, weight, on_result) -> list:
    from distributed import as_completed  # noqa: PLC0415  # lazy: dask is an extra ([dist])

    n = len(tasks)
    order = sorted(range(n), key=lambda i: -cost[i]) if cost is not None else list(range(n))
    tier = getattr(_TIER, "tier", 0) * TIER_STEP  # background studies: below the foreground
    priority = {i: tier + n - rank for rank, i in enumerate(order)}  # higher runs first
    tag = re.sub(r"[^A-Za-z0-9_]+", "_", label or getattr(fn, "__name__", "task"))[:40]
    run_id = uuid.uuid4().hex[:10]
    futures = [None] * n
    for i in order:
        futures[i] = c.submit(
            _call,
            fn,
            tasks[i],
            priority=priority[i],
            retries=0,
            pure=False,
            key=f"navlib-{tag}-{run_id}-{i}",
        )
    index = {f.key: i for i, f in enumerate(futures)}
    try:
        for f in as_completed(futures, loop=c.loop):
            if f.status == "error":
                f.result()  # raises the task's exception here
            if on_result is not None:
                on_result(index[f.key], f.result())
            if bar is not None:
                bar.update(weight[index[f.key]])
        return c.gather(futures)
    finally:
        pending = [f for f in futures if f is not None and not f.done()]
        if pending:
            c.cancel(pending)


class Job:
    """A study started by :func:`background`: :meth:`result` waits for it and returns what the call
    returned (or raises what it raised)."""

    def __init__(self, fn: Callable, args: tuple, kwargs: dict, tier: int, threaded: bool):
        self._call = (fn, args, kwargs)
        self._tier = int(tier)
        self._done = threading.Event()
        self._value: Any = None
        self._error: BaseException | None = None
        self._thread = None
        if threaded:
            self._thread = threading.Thread(
                target=self._run, name=f"navlib-background-{fn.__name__}", daemon=True
            )
            self._thread.start()

    def _run(self) -> None:
        fn, args, kwargs = self._call
        _TIER.tier = self._tier
        try:
            self._value = fn(*args, **kwargs)
        except BaseException as err:  # handed to result(), in the caller's thread, as raised
            self._error = err
        finally:
            self._done.set()

    def done(self) -> bool:
        """True once the study has finished (always False for a deferred one-process study)."""
        return self._done.is_set()

    def result(self):
        """The study's return value (a one-process study runs now, in this thread)."""
        if self._thread is None and not self._done.is_set():
            self._run()
        self._done.wait()
        if self._error is not None:
            raise self._error
        return self._value


def background(fn: Callable, *args, tier: int = -1, **kwargs) -> Job:
    """Start the study ``fn(*args, **kwargs)`` (a function that sends its tasks to :func:`run`) now and
    return at once: its tasks queue on the workers below every task of the foreground (``tier`` < 0;
    between background studies, the higher tier first), so a chapter's later cells keep the workers busy
    while it draws and tabulates what is already done.  ``Job.result()`` collects it.

    The tasks, and so the numbers, are those of calling ``fn(*args, **kwargs)`` directly.  With one worker
    and no scheduler (``workers``/``scheduler`` in ``kwargs``, as ``fn`` takes them) the study has nowhere
    to run beside this process: it runs when ``result()`` is first asked, as the direct call would."""
    if not isinstance(tier, int) or isinstance(tier, bool) or tier >= 0:
        raise InputError(
            f"engine.background: parameter tier must be a negative integer, got {tier!r}"
        )
    workers = kwargs.get("workers", 1)
    check_param("workers", workers, lo=1, integer=True)
    threaded = scheduler_address(kwargs.get("scheduler")) is not None or int(workers) > 1
    return Job(fn, args, kwargs, tier, threaded)


def run_batches(
    fn: Callable,
    items: Sequence[tuple],
    batch_size: int,
    *,
    workers: int = 1,
    scheduler: str | None = None,
    cost: Sequence[float] | None = None,
    label: str = "",
    progress: bool | None = None,
) -> list:
    """``[fn(*args) for args in items]``, sent in batches of ``batch_size`` consecutive items (one task
    each; the batches depend on ``batch_size`` only, never on the number of workers).  ``cost``: per
    item; a batch costs the sum of its items."""
    check_param("batch_size", batch_size, lo=1, integer=True)
    items = [tuple(a) for a in items]
    if cost is not None and len(cost) != len(items):
        raise InputError(f"engine.run_batches: {len(cost)} costs for {len(items)} items")
    bounds = [
        (s, min(s + int(batch_size), len(items))) for s in range(0, len(items), int(batch_size))
    ]
    batches = [(fn, items[a:b]) for a, b in bounds]
    bcost = None if cost is None else [float(sum(cost[a:b])) for a, b in bounds]
    parts = run(
        _batch,
        batches,
        workers=workers,
        scheduler=scheduler,
        cost=bcost,
        label=label or getattr(fn, "__name__", ""),
        progress=progress,
        weight=[b - a for a, b in bounds],
    )
    return [r for part in parts for r in part]
