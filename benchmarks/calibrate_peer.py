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

Measured (2 cores, quiet, 17 BROAD recordings of 1,500-2,100 rows), 2026-12-03: navlib 0.14-1.05 s per fit
(median 0.26 s; before the analytic Jacobian of :mod:`navlib.workbench.free_kernel` 0.4-4 s, median about
1 s), the peer 0.5-6.6 ms (median 3.9 ms): navlib about 65 x slower (was 140-180 x).  What the rest costs:
the screen's outlier rounds (up to 13 refits on the magnet trials) and the noise model.  The issue measured
magcc's LM fit at 13-29 ms per file: against that navlib is 5-20 x.  Held-out direction: navlib made it
worse than the raw field on 12 of 17 recordings and warned on all 12 (fast rotation, magnets: the
accelerometer saw more than gravity); the peer made it worse on 11 and failed on 2.
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

import pandas as pd

from navlib.studies.workbench import MAG_DIR, calibration_beside_peer
from navlib.workbench.calibration import calibrate
from navlib.workbench.magnetometer_free import DERIVED, load_free, simulate_free


def warm_up() -> None:
    """numba kernels and imports, not timed."""
    with tempfile.TemporaryDirectory() as tmp:
        p = Path(tmp) / "warm.csv"
        simulate_free({"hard_x_ut": 5.0}, duration_s=20.0, seed=1).drop(
            columns=list(DERIVED)
        ).to_csv(p, index=False)
        calibrate(load_free(p))


def main(argv: list[str]) -> int:
    files = [Path(a) for a in argv] or None
    if files is None and not MAG_DIR.exists():
        print(f"no recordings: {MAG_DIR} is absent and no FILE was given")
        return 0
    warm_up()
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
