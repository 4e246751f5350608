"""navlib.methods.jit: the compiled kernels target one instruction set, so numbers do not follow the machine."""

def test_kernels_are_compiled_for_one_fixed_target_not_the_host():
    """On an x86-64 machine with AVX2 the kernels target LLVM's 'haswell' whatever the host (AVX-512 gives
    other roundings and so other DE runs); elsewhere, or when the user asks for the host, they do not."""
    import os

    from llvmlite import binding
    from numba.core import config

    from navlib.methods import jit

    host = binding.get_host_cpu_features()
    expected = (binding.get_process_triple().startswith("x86_64") and bool(host.get("avx2"))
                and bool(host.get("fma")) and not os.environ.get("NAVLIB_NUMBA_HOST")
                and not os.environ.get("NUMBA_CPU_NAME") and not os.environ.get("NUMBA_CPU_FEATURES"))
    assert jit.PINNED is expected
    if expected:
        assert config.CPU_NAME == jit.TARGET_CPU and config.CPU_FEATURES == jit.TARGET_FEATURES
        assert "-avx512" not in jit.TARGET_FEATURES and "+avx512" not in jit.TARGET_FEATURES
        ctx = jit.logsig_sse.targetctx
        assert ctx.codegen()._get_host_cpu_name() == jit.TARGET_CPU
