"""Detection and false-alarm rates of the reference-free magnetometer system (issue 23): every effect
hidden at 3x the noise (0.3 uT), and nothing hidden, with independent noise and with AR(1) noise of lag-1
correlation 0.9; 95 % Wilson intervals.  The unit tests run a few of these trials; this is the full run.

    .venv/bin/python benchmarks/workbench_free_rates.py [trials] [workers] [duration_s] [correlations]

Run for issue 23 (100 trials, 20 s recordings), before the projected noise model: independent noise --
every effect named 100/100 (Wilson 0.963-1), quiet 98/100 (0.930-0.994); AR(0.9) -- every effect named
100/100, quiet only 86/100 (0.779-0.915), below the 95 % target: an AR model of the invariants' residuals
is misspecified (the invariants project axis-wise AR noise onto a turning direction; the estimate ran to
its bound 0.995).  With the noise modelled on the sensor's axes (navlib.workbench.serial.Projection,
the system's noise_directions hook), AR(0.9): quiet 98/100 (Wilson 0.930-0.994); the same trial seeds
(the study's trial_seed of each trial's coordinates), run in parts on a loaded machine -- see the
closing note of issue 23 for the detection rates measured.
"""

import sys
import time

import pandas as pd

from navlib.verdicts import wilson
from navlib.workbench.free_simulation import hidden_effect_study


def main():
    trials = int(sys.argv[1]) if len(sys.argv) > 1 else 100
    workers = int(sys.argv[2]) if len(sys.argv) > 2 else 1
    duration = float(sys.argv[3]) if len(sys.argv) > 3 else 20.0
    pd.set_option("display.width", 200)
    rhos = [float(v) for v in sys.argv[4].split(",")] if len(sys.argv) > 4 else [0.0, 0.9]
    for rho in rhos:
        t = time.time()
        st = hidden_effect_study(
            ratios=(3.0,),
            noises=(0.3,),
            seeds=range(trials),
            none_seeds=range(trials),
            correlation=rho,
            duration_s=duration,
            workers=workers,
        )
        rows = []
        for h, g in st.groupby("hidden", sort=False):
            k = int(g.correct.astype(bool).sum())
            e = wilson(k, len(g))
            rows.append(
                {
                    "hidden": h,
                    "rate": "quiet" if h == "(none)" else "named",
                    "trials": len(g),
                    "k": k,
                    "value": e.value,
                    "95% low": e.lo,
                    "95% high": e.hi,
                }
            )
        print(
            f"--- AR(1) correlation {rho}, {duration:g} s at 10 Hz, noise 0.3 uT, effects at 3x noise "
            f"({time.time() - t:.0f} s wall, {workers} workers)"
        )
        print(pd.DataFrame(rows).round(3).to_string(index=False), flush=True)
        wrong = st[~st.correct.astype(bool)]
        if len(wrong):
            print(wrong[["hidden", "named", "seed"]].to_string(index=False), flush=True)


if __name__ == "__main__":  # the engine's worker processes import this file
    main()
