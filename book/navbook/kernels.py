"""Compile the numba kernels once (``python -m navbook compile``), so the first chapter of a fresh
checkout does not pay the compilation in its execution time.

Importing this module imports a study (and with it torch): the command line imports it only for
``compile``.
"""

from __future__ import annotations

import time
from dataclasses import replace as _replace

import numpy as np
import pandas as pd

from navlib.methods.de import DEParams
from navlib.studies import (
    compass as compass_study,
)  # the compass chapter's study: the one line naming it


def compile_kernels() -> int:
    """Compile (or load from numba's on-disk cache) every compiled kernel of :mod:`navlib.methods.jit` by
    running the chapters' methods once on a tiny problem, so the first notebook of a fresh checkout does
    not pay the one-time compilation (tens of seconds) in its execution time."""
    t0 = time.perf_counter()
    x = np.linspace(-10.0, 370.0, 24)
    t = np.linspace(0.0, 360.0, 24)
    sw = compass_study.Sweeps(
        pd.DataFrame({"true_heading_deg": t, "measured_heading_deg": x}),
        pd.DataFrame({"true_heading_deg": t, "measured_heading_deg": x}),
    )
    p = compass_study.StudyParams(
        de=DEParams(pop_size=8, max_generations=3),
        lm=_replace(compass_study.StudyParams().lm, epochs=3),
    )
    compass_study.seed_study(
        sw,
        p,
        seeds=range(2),
        methods=("ade_bp_pure", "ade_bp_hybrid_trainlm", "bp_matlab_val", "elm_backtuned"),
    )
    print(f"compiled kernels ready in {time.perf_counter() - t0:.1f} s")
    return 0
