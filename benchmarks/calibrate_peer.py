"""``navlib calibrate`` beside a dedicated calibrator's Levenberg-Marquardt ellipsoid fit on real hand-held
recordings (issue 34): time per fit and held-out accuracy, in one run.

The peer (:func:`navlib.methods.ellipsoid.lm_ellipsoid`) is what magcc's LM fit does; magcc itself is not
installed: it pulls a web stack (FastAPI, uvicorn) into the environment.  navlib is the library call the CLI
makes; it also estimates the noise model, screens outliers, gives every parameter's uncertainty, warns
(an accelerated sensor) and refuses data that cannot separate the parameters.  Fitted on the first 70 % of
each recording, judged on the last 30 % (:func:`navlib.studies.workbench.calibrations.calibration_beside_peer`,
the comparison the workbench chapter shows).  Files: ``../shared/realdata/broad/3d/*.csv`` (CC BY 4.0,
never copied here) or the files given.

    OPENBLAS_NUM_THREADS=1 .venv/bin/python benchmarks/calibrate_peer.py [FILE ...]

It first times both on 1,000 simulated rows (:data:`SIM_TRUTH`, 0.3 uT of noise; median of 9 fits each,
alternating), then on the recordings.

Measured 2026-12-04 (2 cores, quiet, one BLAS thread, the Makefile's kernel pins), before and after the
screen's refits became warm-started Gauss-Newton (the same session, the old code from git):

- 1,000 simulated rows: navlib 26-33 ms per fit (was 66-69 ms), the peer 2.6-3.6 ms: 9-11 x (was 26 x).
- 17 BROAD recordings of 1,500-2,100 rows (fitted on 70 %): navlib 0.044-0.16 s per fit, median
  0.06-0.07 s (was 0.11-0.78 s, median 0.20 s; 2026-12-03: median 0.26 s, and 1 s before the analytic
  Jacobian), the peer 0.5 ms-0.5 s, median 4.1-4.5 ms (its LM fit takes 0.4-0.5 s on four magnet trials):
  16-18 x, median over files (was 48 x in the same session, 65 x on 2026-12-03).  navlib's time includes
  reading the file (:func:`~navlib.workbench.magnetometer_free.load_free`, as the CLI does: about 12 ms
  on 1,400 rows, most of it the cell-by-cell validation), the peer's starts from the array in memory.
  The issue measured magcc's own LM fit at 13-29 ms per file: against that navlib is 2-5 x.

Measured 2026-12-05 (2 cores, quiet, one BLAS thread; magcc 0.1.1 installed in a scratch venv beside
navlib, not in the lock), CPU time of the thread, median of 25 interleaved fits on the 1,000 simulated rows:
before this day's changes navlib 27-31 ms, the stand-in 3.7-4.1 ms (7.5-8.0 x), magcc 4.3-4.7 ms
(6.4-6.7 x); after, navlib 21.6-22.6 ms, the stand-in 3.7-3.8 ms (5.9-6.0 x), magcc 4.4 ms (4.9-5.1 x).
The changes (each the same numbers, or the same to rounding): the compiled neighbour median of the
screen, the series and the structure shapes made once per screen, the shapes' Huber fit by the normal
equations, column reads without pandas' multi-column take, the profile interval without evaluating a bound
beyond an evaluated point, one thread-pool controller per process.  The issue's target, within 5 x of
magcc's LM fit, is at its edge; against the stand-in it is not met.  What costs the rest (py-spy): the noise
model's REML for the two sets of regressors, about 27 likelihood evaluations (a Kalman filter pass and a
Gram matrix each, O(n)) and the profile interval, half of the time; the orthonormal bases 10 %; the
screen's judgement 12 %; the three fits 20 %.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import pandas as pd

from navlib.methods.ellipsoid import lm_ellipsoid
from navlib.studies.workbench import MAG_DIR, calibration_beside_peer
from navlib.workbench.calibration import calibrate
from navlib.workbench.magnetometer import MAG
from navlib.workbench.free_simulation import simulate_free
from navlib.workbench.magnetometer_free import DERIVED, load_free

#: The simulated recording timed beside the peer: hard iron, scale and soft iron, 0.3 uT of noise.
SIM_TRUTH = {
    "hard_x_ut": 12.0,
    "hard_y_ut": -5.0,
    "hard_z_ut": 3.0,
    "scale_x": 0.02,
    "soft_xy": 0.01,
}


def warm_up() -> None:
    """numba kernels and imports, not timed."""
    with tempfile.TemporaryDirectory() as tmp:
        p = Path(tmp) / "warm.csv"
        simulate_free({"hard_x_ut": 5.0}, duration_s=20.0, seed=1).drop(
            columns=list(DERIVED)
        ).to_csv(p, index=False)
        calibrate(load_free(p))


def magcc_lm():
    """magcc's own LM fit, ``calibrate_lm(m, expected_field)``, where magcc is importable (it is not in
    the lock: it pulls a web stack; install it beside navlib to time it), else None."""
    try:
        from magcc.magcc import calibrate_lm  # noqa: PLC0415  # lazy: optional, outside the lock
    except ImportError:
        return None
    return calibrate_lm


def simulated(rows: int = 1000, repeats: int = 25) -> dict:
    """Median CPU seconds of this thread per fit of ``calibrate``, of the peer's LM fit and, where
    importable, of magcc's (given the recording's median ``|m|`` as the field strength) on the same
    simulated recording of ``rows`` rows (10 Hz), each timed ``repeats`` times, interleaved (the thread's
    CPU time: another process on the machine slows all three alike but adds nothing to it)."""
    d = simulate_free(SIM_TRUTH, duration_s=rows / 10.0, seed=1)
    m = d[list(MAG)].to_numpy(float)
    field = float(np.median(np.linalg.norm(m, axis=1)))
    fits = {"navlib": lambda: calibrate(d), "peer": lambda: lm_ellipsoid(m)}
    lm = magcc_lm()
    if lm is not None:
        fits["magcc"] = lambda: lm(m, field)
    for fit in fits.values():  # warm: numba kernels, imports, caches
        fit()
    times = {k: [] for k in fits}
    for _ in range(repeats):
        for k, fit in fits.items():
            t0 = time.thread_time()
            fit()
            times[k].append(time.thread_time() - t0)
    return {k: float(np.median(v)) for k, v in times.items()}


def main(argv: list[str]) -> int:
    ap = argparse.ArgumentParser(
        description="navlib calibrate beside a dedicated Levenberg-Marquardt ellipsoid fit (issue 34)"
    )
    ap.add_argument(
        "files",
        nargs="*",
        type=Path,
        metavar="FILE",
        help="recordings (navlib's free-magnetometer CSV); default: the BROAD 3d trials",
    )
    files = ap.parse_args(argv).files or None
    warm_up()
    t = simulated()
    line = (
        f"1,000 simulated rows, CPU time per fit (median of 25): navlib {1000 * t['navlib']:.1f} ms, "
        f"peer {1000 * t['peer']:.1f} ms (ratio {t['navlib'] / t['peer']:.1f}x)"
    )
    if "magcc" in t:
        line += f", magcc {1000 * t['magcc']:.1f} ms (ratio {t['navlib'] / t['magcc']:.1f}x)"
    else:
        line += "; magcc is not importable here (its LM fit not timed)"
    print(line + "\n")
    if files is None and not MAG_DIR.exists():
        print(f"no recordings: {MAG_DIR} is absent and no FILE was given")
        return 0
    r = calibration_beside_peer(files)
    pd.set_option("display.width", 250)
    print(r.accuracy.join(r.times).to_string(float_format=lambda x: f"{x:.3g}"))
    s = r.summary()
    print(
        f"\nnavlib: {s['calibrated']} of {s['trials']} calibrated ({s['warned']} with a warning), {s['refused']} "
        f"refused; made the held-out direction worse on {s['navlib_worse']}, warned on {s['navlib_worse_warned']} "
        f"of those.  Peer: failed on {s['peer_failed']}, made it worse on {s['peer_worse']}."
    )
    print(
        f"time per fit: navlib median {r.times['navlib (s)'].median():.2f} s, peer median "
        f"{1000 * r.times['peer (s)'].median():.1f} ms; ratio {s['time_ratio']:.0f}x (median over files)"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
