"""Detection and false-alarm rates of the workbench on serially correlated noise (issue 18), larger than the
chapter's run: hand-turned 10 Hz magnetometer recordings and compass sweeps read every 5 s, AR(1) noise of
each lag-1 correlation, every catalogued effect hidden at 3 x the noise and nothing hidden; 95 % Wilson
intervals.  Also the cost: process time per trial.

    .venv/bin/python benchmarks/workbench_correlated.py [trials per case] [correlations, e.g. 0,0.9] [workers]
"""

import sys
import time

import pandas as pd

from navlib.workbench.trials import correlated_noise_rates, correlated_noise_study


def main() -> None:
    trials = int(sys.argv[1]) if len(sys.argv) > 1 else 100
    rhos = tuple(float(x) for x in sys.argv[2].split(",")) if len(sys.argv) > 2 else (0.0, 0.9)
    workers = int(sys.argv[3]) if len(sys.argv) > 3 else 2
    pd.set_option("display.width", 200)
    for system in ("magnetometer", "compass"):
        t = time.perf_counter()
        study = correlated_noise_study(
            system, correlations=rhos, seeds=range(trials), workers=workers
        )
        wall = time.perf_counter() - t
        print(
            f"--- {system}: {len(study)} trials in {wall:.0f} s wall ({workers} processes, "
            f"{workers * wall / len(study):.2f} process-s per trial)"
        )
        print(correlated_noise_rates(study).round(3).to_string(), flush=True)
        wrong = study[~study.correct.astype(bool)]
        if len(wrong):
            print(
                wrong[["correlation", "hidden", "named", "ar_order", "lag1", "seed"]].to_string(),
                flush=True,
            )


if __name__ == "__main__":  # worker processes are spawned: they import this file
    main()
