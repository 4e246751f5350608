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

The issue's target, within 5 x of the peer's LM fit on 1,000 rows, is not met.  What costs the rest, on
the 1,000 simulated rows (27 ms, cProfile): the noise model 15-18 ms -- REML of the AR(1) noise on the
sensor's axes (a Kalman filter per likelihood, O(n)) for the two sets of regressors the screen chooses
between (the richest model's Jacobian, and with the structure shapes) and the profile-likelihood interval
of the lag-1 correlation for the chosen one: about 47 likelihood evaluations of 0.25 ms and 3 ms for the
two orthonormal bases; the outlier screen's judgement 6 ms per round (leverages, the structure shapes'
Huber fit, robust z, the neighbours' medians); the three fits (the model, the richest model from its
optimum, the refit on the rows kept) 4 ms together.  On the magnet trials the screen iterates up to 13
rounds (each a judgement and a warm refit, 8-10 ms).  Held-out direction: navlib made it worse than the
raw field on 12 of 17 recordings and warned on all 12 (fast rotation, magnets: the accelerometer saw more
than gravity); the peer made it worse on 11 and failed on 2 (the same as before the change).
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


def simulated(rows: int = 1000, repeats: int = 9) -> tuple[float, float]:
    """Median seconds per fit of ``calibrate`` and of the peer's LM fit on the same simulated recording
    of ``rows`` rows (10 Hz), each timed ``repeats`` times, alternating."""
    d = simulate_free(SIM_TRUTH, duration_s=rows / 10.0, seed=1)
    m = d[list(MAG)].to_numpy(float)
    ours, peer = [], []
    for _ in range(repeats):
        t0 = time.perf_counter()
        calibrate(d)
        ours.append(time.perf_counter() - t0)
        t0 = time.perf_counter()
        lm_ellipsoid(m)
        peer.append(time.perf_counter() - t0)
    return float(np.median(ours)), float(np.median(peer))


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
    ours, peer = simulated()
    print(
        f"1,000 simulated rows: navlib {1000 * ours:.1f} ms, peer {1000 * peer:.1f} ms per fit "
        f"(median of 9); ratio {ours / peer:.1f}x\n"
    )
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
