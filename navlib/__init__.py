"""navlib: simulators and error-compensation algorithms behind the navbook replication book."""

__version__ = "0.1.0"

#: One thread for every numerical library (BLAS, OpenMP, MKL, numexpr, Accelerate): the defaults of the
#: command line (:mod:`navlib.__main__`) and the environment of the engine's local workers.  Here, because
#: importing navlib loads no numerical library, so both can set it before numpy loads.
ONE_THREAD = {
    "OPENBLAS_NUM_THREADS": "1",
    "OMP_NUM_THREADS": "1",
    "MKL_NUM_THREADS": "1",
    "NUMEXPR_NUM_THREADS": "1",
    "VECLIB_MAXIMUM_THREADS": "1",
}
