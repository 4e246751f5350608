"""Cost of ``navlib calibrate magnetometer`` against the number of rows (issue 34): the library call the
CLI makes (:func:`navlib.workbench.calibration.calibrate`) on simulated hand-held magnetometer recordings
(:func:`navlib.workbench.free_simulation.simulate_free`, 10 Hz, AR(1) noise of lag-1 correlation 0.9, an
accelerometer, so two invariants per row), each size in a fresh process: wall time of the call, the growth
of the process's peak resident memory during it, and the exponent ``a`` of ``time ~ rows^a`` fitted by
least squares on the log-log points.  A warm-up call on a short recording comes first (numba kernels
compiled or loaded from their cache, imports), so the times are the calibration's own.

    OPENBLAS_NUM_THREADS=1 .venv/bin/python benchmarks/rows_scaling.py [rows, e.g. 1000,3000,10000,30000]

Measured (2 cores shared with other work, load average ~13): before the Kalman filter (the dense n x n
Cholesky factor) 1,000 rows 36-39 s and 345 MiB, 2,000 rows 398 s and 1,350 MiB (time ~ rows^3.4); after,
1,000 rows 0.7 s and 4 MiB, 2,000 0.8 s and 9 MiB, 3,000 0.9 s and 14 MiB, 10,000 2.2 s and 46 MiB,
30,000 6.4 s and 138 MiB (exponent 0.95 between 10,000 and 30,000 rows; 0.69 fitted over all sizes).
"""

import json
import os
import resource
import subprocess
import sys
import time

import numpy as np

RATE_HZ = 10.0
TRUTH = {"hard_x_ut": 12.0, "hard_y_ut": -5.0, "hard_z_ut": 3.0, "scale_x": 0.02, "soft_xy": 0.01}


def one(rows: int) -> dict:
    """Time one calibration of ``rows`` rows in this process (after a warm-up)."""
    from navlib.workbench.calibration import calibrate
    from navlib.workbench.free_simulation import simulate_free

    calibrate(simulate_free(TRUTH, duration_s=300 / RATE_HZ, noise_correlation=0.9, seed=0))
    data = simulate_free(
        TRUTH, duration_s=rows / RATE_HZ, rate_hz=RATE_HZ, noise_correlation=0.9, seed=1
    )
    before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    t = time.perf_counter()
    cal = calibrate(data)
    wall = time.perf_counter() - t
    after = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    return {
        "rows": len(data),
        "seconds": wall,
        "peak_rss_mib": after / 1024,
        "rss_growth_mib": (after - before) / 1024,
        "noise": cal["noise"],
    }


def main() -> None:
    if len(sys.argv) > 2 and sys.argv[1] == "--one":
        print(json.dumps(one(int(sys.argv[2]))))
        return
    sizes = (
        [int(x) for x in sys.argv[1].split(",")]
        if len(sys.argv) > 1
        else [1000, 3000, 10000, 30000]
    )
    env = {**os.environ, "OPENBLAS_NUM_THREADS": os.environ.get("OPENBLAS_NUM_THREADS", "1")}
    import navlib

    print(
        f"navlib from {os.path.dirname(navlib.__file__)}; OPENBLAS_NUM_THREADS={env['OPENBLAS_NUM_THREADS']}"
    )
    print(f"{'rows':>7} {'seconds':>9} {'peak RSS MiB':>13} {'RSS growth MiB':>15}  noise model")
    out = []
    for n in sizes:
        res = subprocess.run(
            [sys.executable, __file__, "--one", str(n)], env=env, capture_output=True, text=True
        )
        if res.returncode:
            print(f"{n:>7} failed: {res.stderr.strip().splitlines()[-1]}")
            continue
        r = json.loads(res.stdout.strip().splitlines()[-1])
        out.append(r)
        print(
            f"{r['rows']:>7} {r['seconds']:>9.2f} {r['peak_rss_mib']:>13.0f} {r['rss_growth_mib']:>15.0f}  "
            f"{r['noise'][:60]}",
            flush=True,
        )
    if len(out) >= 2:
        a, _ = np.polyfit(np.log([r["rows"] for r in out]), np.log([r["seconds"] for r in out]), 1)
        print(f"fitted exponent: time ~ rows^{a:.2f}", end="")
        (n1, t1), (n2, t2) = [(r["rows"], r["seconds"]) for r in out[-2:]]
        print(
            f" (between the two largest sizes: {np.log(t2 / t1) / np.log(n2 / n1):.2f}; fixed costs weigh on the "
            f"small ones)"
        )


if __name__ == "__main__":
    main()
