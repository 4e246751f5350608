"""navlib.methods.jit: the compiled kernels give the same numbers whatever instruction set they are compiled for."""

import json
import os
import subprocess
import sys

import pytest

#: Runs DE-BP stages (DE and ADE, through the parent cache) and the plain fitness on a population, and prints
#: the results' exact bits.
_SCRIPT = r"""
import json, numpy as np
from dataclasses import replace
from numba.core import config
from navlib.methods.bpnet import sse_objective, train_de_family
from navlib.methods.de import DEParams
from navlib.methods.seeding import generators
out = {"cpu": config.CPU_NAME or "host"}
for n in (121, 128):                                   # with and without a scalar tail
    x = np.linspace(-20.0, 380.0, n)
    t = x + 15 * np.sin(np.radians(x)) + 3 * np.cos(2 * np.radians(x))
    obj, _, _ = sse_objective(x, t, 6)
    pop = np.random.default_rng(n).uniform(-10, 10, (50, 19))
    out[f"fitness{n}"] = obj(pop).tobytes().hex()
    for adaptive in (False, True):
        p = DEParams(pop_size=20, max_generations=150, adaptive=adaptive)
        nets = train_de_family(x, t, 6, p, generators([0, 1]), variants=("pure",))
        out[f"de{n}{adaptive}"] = [n_.theta.tobytes().hex() for v in nets.values() for n_ in v]
print(json.dumps(out))
"""


#: LLVM's 'haswell' and its features (numba takes the host's features unless told): AVX2 and FMA, no AVX-512.
_HASWELL = {
    "NUMBA_CPU_NAME": "haswell",
    "NUMBA_CPU_FEATURES": "+64bit,+avx,+avx2,+bmi,+bmi2,+cmov,+cx16,+f16c,+fma,+fsgsbase,+lzcnt,+mmx,"
    "+movbe,+pclmul,+popcnt,+rdrnd,+sahf,+sse,+sse2,+sse3,+sse4.1,+sse4.2,+ssse3,"
    "+xsave,+xsaveopt",
}


def _run(env_extra):
    env = {k: v for k, v in os.environ.items() if not k.startswith("NUMBA_CPU_")}
    env.update(env_extra)
    res = subprocess.run(
        [sys.executable, "-c", _SCRIPT], env=env, capture_output=True, text=True, timeout=300
    )
    assert res.returncode == 0, res.stderr[-2000:]
    return json.loads(res.stdout.strip().splitlines()[-1])


def test_fast_math_flags_keep_every_operation_exactly_rounded():
    from navlib.methods import jit

    assert not {"arcp", "afn", "reassoc", "fast"} & set(jit.FASTMATH)
    assert "contract" in jit.FASTMATH


@pytest.mark.slow
def test_kernels_compiled_for_avx2_and_for_the_host_give_the_same_bits():
    """DE runs and the fitness compiled for LLVM's 'haswell' (AVX2: 8 floats a vector) equal the
    ones compiled for this machine (16 with AVX-512 where it has them), bit for bit: no result depends on the
    vector width.  With the approximate reciprocal (``arcp``) they differed on an AVX-512 machine."""
    from llvmlite import binding

    host = binding.get_host_cpu_features()
    if not (
        binding.get_process_triple().startswith("x86_64") and host.get("avx2") and host.get("fma")
    ):
        pytest.skip("needs an x86-64 processor with AVX2 and FMA")
    avx2 = _run(_HASWELL)
    here = _run({})
    assert avx2.pop("cpu") == "haswell" and here.pop("cpu") == "host"
    assert avx2 == here
