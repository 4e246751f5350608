"""Speed of the workbench loop on large files (issue 18: a 100k-row compass file under 10 s, a 20k-row
magnetometer file under 20 s), each against a peer in the same run.

Ours: ``python -m navlib loop SYSTEM FILE --json`` end to end (a fresh process: reading and checking the
file, the outlier screen, the noise model, every fit, candidate and structure test of the loop).
Peer: what any calibration script does once on the same file, in the same process start-up: read the CSV
with pandas and solve one linear least-squares problem with numpy (compass: heading error on harmonics 0..2
of the true heading; magnetometer: the algebraic ellipsoid fit, 9 quadric coefficients).  The ratio says
what the loop's diagnosis costs over one fit.  Files are simulated here (no real data copied) in a
temporary folder; prints both times per file and their ratio.
"""

import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import pandas as pd

from navlib.workbench.magnetometer import simulate_hand_turned

PEER_COMPASS = """
import sys, numpy as np, pandas as pd
d = pd.read_csv(sys.argv[1])
h = np.radians(d.true_heading_deg.to_numpy())
e = (d.measured_heading_deg.to_numpy() - d.true_heading_deg.to_numpy() + 180) % 360 - 180
X = np.column_stack([np.ones_like(h), np.cos(h), np.sin(h), np.cos(2 * h), np.sin(2 * h)])
print(np.linalg.lstsq(X, e, rcond=None)[0])
"""
PEER_MAG = """
import sys, numpy as np, pandas as pd
d = pd.read_csv(sys.argv[1])
x, y, z = (d[c].to_numpy() for c in ("mag_x_ut", "mag_y_ut", "mag_z_ut"))
D = np.column_stack([x * x, y * y, z * z, 2 * x * y, 2 * x * z, 2 * y * z, 2 * x, 2 * y, 2 * z])
print(np.linalg.lstsq(D, np.ones_like(x), rcond=None)[0])
"""


def compass_file(path: Path, n: int = 100_000) -> None:
    rng = np.random.default_rng(np.random.SeedSequence(18, spawn_key=(1,)))
    t = rng.uniform(0, 360, n)
    h = np.radians(t)
    meas = (
        t + 1.0 + 0.8 * np.sin(h) + 0.3 * np.cos(h) + 0.2 * np.sin(2 * h) + rng.normal(0, 0.1, n)
    ) % 360
    pd.DataFrame(
        {
            "true_heading_deg": t,
            "measured_heading_deg": meas,
            "sweep": np.r_[np.ones(n // 2, int), np.full(n - n // 2, 2)],
            "time_s": 0.1 * np.arange(n),
        }
    ).to_csv(path, index=False)


def magnetometer_file(path: Path, n: int = 20_000) -> None:
    params = {"hard_x_ut": 3.0, "hard_y_ut": -2.0, "hard_z_ut": 1.5}
    simulate_hand_turned(
        params, duration_s=n / 10.0, noise_ut=0.1, seed=np.random.SeedSequence(18, spawn_key=(2,))
    ).to_csv(path, index=False)


def timed(cmd: list[str]) -> float:
    t0 = time.perf_counter()
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    return time.perf_counter() - t0


def main() -> int:
    with tempfile.TemporaryDirectory() as tmp:
        cases = [
            ("compass", Path(tmp) / "compass_100k.csv", compass_file, PEER_COMPASS, "misalignment"),
            ("magnetometer", Path(tmp) / "magnetometer_20k.csv", magnetometer_file, PEER_MAG, ""),
        ]
        for system, path, make, peer, model in cases:
            make(path)
            rows = sum(1 for _ in open(path)) - 1
            ours_cmd = [sys.executable, "-m", "navlib", "loop", system, str(path), "--json"]
            if model:
                ours_cmd += ["--model", model]
            ours = timed(ours_cmd)
            base = timed([sys.executable, "-c", peer, str(path)])
            print(f"{system}: {rows} rows: loop {ours:.2f} s, one least-squares fit {base:.2f} s")
            print(f"{system}_loop_over_one_fit={ours / base:.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
