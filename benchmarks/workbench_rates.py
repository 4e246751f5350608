"""The workbench's detection, false-alarm and out-of-catalogue rates from a larger run than the notebook's
(the same library functions; the closing note of issue 9 quotes this run).

    .venv/bin/python benchmarks/workbench_rates.py [seeds] [null_trials] [ooc_seeds]
"""

import sys
import time

import pandas as pd

from navlib.workbench.trials import (
    detection_rates,
    hidden_effect_study,
    out_of_catalogue_rates,
    out_of_catalogue_study,
)

seeds = int(sys.argv[1]) if len(sys.argv) > 1 else 25
nulls = int(sys.argv[2]) if len(sys.argv) > 2 else 200
ooc_seeds = int(sys.argv[3]) if len(sys.argv) > 3 else 25
pd.set_option("display.width", 200)
t = time.process_time()
ooc = out_of_catalogue_study(ratios=(5.0, 8.0), noises=(0.05, 0.2), seeds=range(ooc_seeds))
print(out_of_catalogue_rates(ooc).round(3).to_string(), flush=True)
print(ooc[~ooc.quiet | ~ooc.detected].to_string(), flush=True)
for name, kw in (
    ("compass", dict(noises=(0.05, 0.2))),
    ("drift 16", dict(noises=(1e-4, 3e-4), n=16)),
    ("drift 40", dict(noises=(1e-4, 3e-4), n=40)),
):
    st = hidden_effect_study(
        name.split()[0], ratios=(3.0, 5.0, 10.0), seeds=range(seeds), none_seeds=range(nulls), **kw
    )
    print(f"--- {name}")
    print(detection_rates(st).round(3).to_string(), flush=True)
print(f"cpu time {time.process_time() - t:.0f} s")
