"""The Makefile pins numpy, OpenBLAS and torch to their AVX2 kernels so that CI's machine computes the stored
notebook outputs bit for bit (Makefile, "The same floating-point kernels").  A pin that a library no longer
honours (a renamed numpy feature group, a new variable name) would fail silently, CI would compute other
numbers, and nbval would fail on the other machine only: this checks, in a fresh interpreter started with the
Makefile's variables, that each library reports the pinned path."""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PINS = ("NPY_DISABLE_CPU_FEATURES", "OPENBLAS_CORETYPE", "MKL_CBWR", "ATEN_CPU_CAPABILITY")

PROBE = """
import json
import numpy, scipy.linalg
from numpy._core._multiarray_umath import __cpu_features__
from threadpoolctl import threadpool_info
out = {"x86_v4": bool(__cpu_features__.get("X86_V4")), "avx512f": bool(__cpu_features__.get("AVX512F")),
       "openblas": sorted({i.get("architecture") for i in threadpool_info() if i["internal_api"] == "openblas"})}
try:
    import torch
    out["aten"] = torch.backends.cpu.get_cpu_capability()
except ImportError:
    out["aten"] = None
print(json.dumps(out))
"""


def makefile_pins() -> dict[str, str]:
    text = (ROOT / "Makefile").read_text()
    pins = dict(re.findall(r"^export (\w+) := (.*)$", text, flags=re.M))
    missing = [k for k in PINS if k not in pins]
    assert not missing, f"Makefile exports no {missing}"
    return {k: pins[k].strip() for k in PINS}


def test_each_library_takes_the_pinned_kernels():
    pins = makefile_pins()
    env = {k: v for k, v in os.environ.items() if k not in PINS} | pins
    run = subprocess.run(
        [sys.executable, "-c", PROBE],
        env=env,
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )
    assert run.returncode == 0, run.stderr
    assert "cannot" not in run.stderr.lower(), run.stderr  # numpy's warning for a pin it refuses
    got = json.loads(run.stdout)
    assert got["x86_v4"] is False  # numpy's AVX-512 loops are off
    assert got["openblas"] == [pins["OPENBLAS_CORETYPE"]]  # both OpenBLAS copies (numpy's, scipy's)
    if got["aten"] is not None:
        assert got["aten"] in ("AVX2", "DEFAULT"), got[
            "aten"
        ]  # DEFAULT only on a machine without AVX2


def test_the_probe_sees_the_native_kernels_without_the_pins():
    """The control: without the variables, a machine with AVX-512 reports it (so the check above can fail)."""
    env = {k: v for k, v in os.environ.items() if k not in PINS}
    run = subprocess.run(
        [sys.executable, "-c", PROBE],
        env=env,
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )
    got = json.loads(run.stdout)
    if not got["avx512f"]:
        pytest.skip(
            "this processor has no AVX-512: the pinned and native kernels are the same here"
        )
    assert got["x86_v4"] is True
