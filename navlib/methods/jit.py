"""Compiled (numba) inner loops of the optimisers and networks: what runs millions of times per chapter.

Everything here is an exact restatement of a numpy formulation documented elsewhere (the module that calls
it says which); the tests compare each kernel with that numpy reference.

- :func:`logsig_sse`: the fitness ``J = sum_k (d_k - o_k)^2`` of many 1-M-1 logsig networks
  (:func:`navlib.methods.bpnet.sse_objective`), hidden layer in single precision.  The sigmoid is
  evaluated as ``1 / (1 + 2^y)``, ``y = -z log2(e)``, with ``2^y`` from Cephes' ``exp2f`` polynomial
  (Moshier 1992: range reduction to ``y = k + f``, ``|f| <= 1/2``, degree-6 polynomial for ``2^f``, and the
  exponent ``k`` written into the float's bits), so the loop over the training points vectorises (libm's
  ``expf`` does not): absolute error of the sigmoid <= 2e-7 over all inputs, the accuracy of float32.
- :func:`logsig_sse_keep`, :func:`logsig_sse_trials`, :func:`hidden_accept`: the same fitness evaluated
  from a DE trial's parent (:class:`navlib.methods.bpnet.LogsigSSE`): a hidden unit whose weights the
  trial kept has its parent's outputs, which are kept, not recomputed; the same numbers bit for bit.
- :func:`de_trials`, :func:`de_select`: one generation of DE/rand/1/bin (with per-individual F and CR) for
  all runs of a batch (:func:`navlib.methods.de.evolve_many`), each run drawing from its own xoshiro256**
  stream (:func:`xoshiro_states`, seeded from the run's numpy Generator).
- :func:`elm_back_tune` (with :func:`elm_loss`, :func:`elm_loss_grad`): patent B's back-tuning of an ELM,
  the whole Armijo line-search loop of :func:`navlib.methods.elm.back_tune` in one call, in double
  precision and numpy's order of operations (:func:`pairwise_sum`, :func:`column_sums`,
  :func:`blas_matmul`), without fast-math: the same numbers as the numpy loop (bit for bit on our machine).

Kernels are compiled on first use and cached on disk (``cache=True``; about 1 s per kernel the first
time), for the machine they run on (numba's default: AVX2 vectors of 8 floats, or AVX-512 vectors of 16
where the processor has them).  ``error_model='numpy'``: a float division never raises (it cannot divide
by zero here), which lets the compiler vectorise it.

Same numbers on every machine: every floating-point operation of the kernels is exactly rounded IEEE
arithmetic in a fixed order (:data:`FASTMATH`; none at all in the ELM kernels), so the vector width and
the split between vectorised loop and scalar tail do not change a bit; a test compiles the kernels for
LLVM's ``haswell`` (AVX2) and for the host and compares DE runs bit for bit.  The fused multiply-add
(``contract``) needs an FMA unit (every x86-64 processor since 2013): on a machine without one the DE runs,
which are chaotic, differ.  Earlier versions allowed an approximate reciprocal (``arcp``), which
the compiler used in the vectorised sigmoid but not in its scalar tail; its rounding follows the
processor (the ``rcpps`` estimate is not specified by the instruction set), so the kernels were pinned to
``haswell`` and still could differ between processor makers.
"""

from __future__ import annotations

import numpy as np
from llvmlite import ir
from numba import njit, types
from numba.extending import intrinsic

#: Fast-math flags that keep every operation exactly rounded: no reassociation, no approximate reciprocal
#: (``arcp``) or functions (``afn``); only the fused multiply-add (``contract``) and the promises of no NaN,
#: no infinity and no signed zero that matters.  So a vectorised loop computes each element as its scalar
#: tail does, whatever the vector width, and the numbers do not follow the machine (module docstring).
FASTMATH = {"nnan", "ninf", "nsz", "contract"}

_F = np.float32
_LOG2E = _F(1.4426950408889634)
# Cephes exp2f: 2^f = 1 + f P(f), |f| <= 1/2, relative error ~2e-7.
_P0, _P1, _P2 = _F(1.535336188319500e-4), _F(1.339887440266574e-3), _F(9.618437357674640e-3)
_P3, _P4, _P5 = _F(5.550332471162809e-2), _F(2.402264791363012e-1), _F(6.931472028550421e-1)


@intrinsic
def _bits_to_f32(typingctx, i):
    """Reinterpret the bits of an int32 as a float32 (a bit cast, no conversion)."""
    sig = types.float32(types.int32)

    def codegen(context, builder, signature, args):
        return builder.bitcast(args[0], ir.FloatType())

    return sig, codegen


@njit(fastmath=FASTMATH, error_model="numpy", inline="always", cache=True)
def logsig32(z):
    """``1 / (1 + exp(-z))`` in float32 (see the module docstring)."""
    y = min(max(z * -_LOG2E, _F(-126.0)), _F(126.0))
    k = np.int32(y + _F(127.5))  # y + 127.5 > 0, so truncation = floor: k - 127 = round(y)
    f = y - (_F(k) - _F(127.0))
    q = _P0
    q = q * f + _P1
    q = q * f + _P2
    q = q * f + _P3
    q = q * f + _P4
    q = q * f + _P5
    q = q * f + _F(1.0)
    return _F(1.0) / (_F(1.0) + q * _bits_to_f32(k << np.int32(23)))


@njit(fastmath=FASTMATH, error_model="numpy", cache=True)
def logsig_vec(z):
    """:func:`logsig32` over a float32 array (for tests)."""
    out = np.empty_like(z)
    for i in range(z.size):
        out.flat[i] = logsig32(z.flat[i])
    return out


@njit(fastmath=FASTMATH, error_model="numpy", cache=True)
def logsig_sse(thetas, xn, t, lo, span, n_hidden):
    """Sum of squared errors of many 1-M-1 logsig nets, ``thetas (P, 3M+1) = [w, b, v, c]``:

        o_k = lo + span (sum_j v_j sigmoid(w_j x'_k + b_j) + c),     J = sum_k (o_k - t_k)^2

    with ``x'`` the normalised inputs ``xn (N,)``, ``t (N,)`` the targets and ``lo``/``span`` the target's
    min-max scaler.  Hidden layer and output sum in float32, the error and its square in float64.

    Single-threaded on purpose: on a machine whose cores are shared, numba's thread barrier waited for
    descheduled threads (a 2-thread run was up to 15x slower than 1 thread under load); the chapters use
    processes where they run things in parallel."""
    none = np.empty((0, n_hidden, xn.shape[0]), np.float32)
    changed = np.empty((thetas.shape[0], n_hidden), np.bool_)
    return logsig_sse_trials(thetas, thetas[:0], none, xn, t, lo, span, n_hidden, none, changed)


@njit(fastmath=FASTMATH, error_model="numpy", cache=True)
def logsig_sse_keep(thetas, xn, t, lo, span, n_hidden, hidden):
    """:func:`logsig_sse` that also keeps every net's hidden-layer outputs, ``hidden (P, M, N)`` float32
    (written): the parents' layers that :func:`logsig_sse_trials` reuses.  :func:`logsig_sse_trials`
    without parents: every unit computed."""
    changed = np.empty((thetas.shape[0], n_hidden), np.bool_)
    return logsig_sse_trials(thetas, thetas[:0], hidden, xn, t, lo, span, n_hidden, hidden, changed)


@njit(fastmath=FASTMATH, error_model="numpy", cache=True)
def logsig_sse_trials(trials, parents, hidden, xn, t, lo, span, n_hidden, trial_hidden, changed):
    """:func:`logsig_sse` of DE's trial nets ``trials (P, 3M+1)``, trial ``p`` made from parent ``p`` of
    ``parents``, whose hidden-layer outputs are ``hidden (P, M, N)`` (:func:`logsig_sse_keep`).

    A hidden unit whose input weight and bias are, in float32, the parent's has the parent's outputs
    (the sigmoid sees the same ``w x' + b``), so they are read, not recomputed; only the other units'
    sigmoids are evaluated (into ``trial_hidden``, with ``changed[p, j] = True``).  The output sum runs
    over the units in the same order with the same operations, so every fitness equals
    :func:`logsig_sse`'s bit for bit.  DE's crossover keeps a gene of the parent with probability
    ``1 - CR``, so both genes of a unit with ``(1 - CR)^2``: 0.16 of the sigmoids at DE's CR = 0.6, most
    of them at ADE's CR near ``CR_min`` = 0.1.  With no parents (``parents`` of 0 rows) every unit is
    computed (:func:`logsig_sse_keep`); with ``trial_hidden`` of 0 rows none is kept (:func:`logsig_sse`)."""
    m = n_hidden
    n_pop, n = trials.shape[0], xn.shape[0]
    reuse, store = parents.shape[0] > 0, trial_hidden.shape[0] > 0
    out = np.empty(n_pop)
    x32 = np.empty(n, np.float32)
    for k in range(n):
        x32[k] = xn[k]
    acc = np.empty(n, np.float32)
    for p in range(n_pop):
        for k in range(n):
            acc[k] = 0.0
        for j in range(m):
            w, b, v = _F(trials[p, j]), _F(trials[p, m + j]), _F(trials[p, 2 * m + j])
            if reuse and w == _F(parents[p, j]) and b == _F(parents[p, m + j]):
                changed[p, j] = False
                for k in range(n):
                    acc[k] += v * hidden[p, j, k]
            else:
                changed[p, j] = True
                if store:
                    for k in range(n):
                        h = logsig32(w * x32[k] + b)
                        trial_hidden[p, j, k] = h
                        acc[k] += v * h
                else:
                    for k in range(n):
                        acc[k] += v * logsig32(w * x32[k] + b)
        c = lo + span * trials[p, 3 * m]
        s = 0.0
        for k in range(n):
            e = c + span * np.float64(acc[k]) - t[k]
            s += e * e
        out[p] = s
    return out


@njit(cache=True)
def hidden_accept(hidden, trial_hidden, changed, accepted):
    """Trial ``p`` replaced its parent (``accepted[p]``): its recomputed hidden units
    (``changed[p, j]``) become the parent's in ``hidden``."""
    n_pop, m, n = hidden.shape
    for p in range(n_pop):
        if accepted[p]:
            for j in range(m):
                if changed[p, j]:
                    for k in range(n):
                        hidden[p, j, k] = trial_hidden[p, j, k]


# ----------------------------------------------------------------------------------------------- random
# xoshiro256** (Blackman & Vigna 2018, "Scrambled linear pseudorandom number generators"): one 256-bit
# state per DE run, seeded from that run's numpy Generator, so the kernels draw a run's random numbers
# in the order the run needs them, whatever other runs share the batch.
_U = np.uint64


def xoshiro_states(rngs) -> np.ndarray:
    """One xoshiro256** state per numpy Generator in ``rngs``: ``(S, 4)`` uint64, each drawn from its
    generator (never all zero)."""
    out = np.stack([g.integers(1, 2**63, size=4, dtype=np.int64).astype(np.uint64) for g in rngs])
    return np.ascontiguousarray(out)


@njit(inline="always", cache=True)
def _rotl(x, k):
    return (x << _U(k)) | (x >> _U(64 - k))


@njit(inline="always", cache=True)
def next_u64(state, s):
    """Next 64-bit output of run ``s``'s xoshiro256** state (``state (S, 4)``, advanced in place)."""
    s0, s1, s2, s3 = state[s, 0], state[s, 1], state[s, 2], state[s, 3]
    result = _rotl(s1 * _U(5), 7) * _U(9)
    t = s1 << _U(17)
    s2 ^= s0
    s3 ^= s1
    s1 ^= s2
    s0 ^= s3
    s2 ^= t
    s3 = _rotl(s3, 45)
    state[s, 0], state[s, 1], state[s, 2], state[s, 3] = s0, s1, s2, s3
    return result


@njit(inline="always", cache=True)
def _below(x32, m):
    """Integer in [0, m) from 32 random bits (multiply-shift; bias below m / 2^32)."""
    return np.int64((x32 * _U(m)) >> _U(32))


@njit(inline="always", cache=True)
def _parents(state, s, i, n):
    """Three indices distinct from each other and from ``i`` in [0, n), and a gene index source: the
    offsets o1 in 1..n-1, o2 in 1..n-2 (skipping o1), o3 in 1..n-3 (skipping both) from ``(i + o) mod n``,
    (multiply-shift on 32-bit halves).  Returns ``(r1, r2, r3, x)`` with ``x`` 32
    unused random bits."""
    a, b = next_u64(state, s), next_u64(state, s)
    o1 = 1 + _below(a >> _U(32), n - 1)
    o2 = 1 + _below(a & _U(0xFFFFFFFF), n - 2)
    if o2 >= o1:
        o2 += 1
    lo, hi = min(o1, o2), max(o1, o2)
    o3 = 1 + _below(b >> _U(32), n - 3)
    if o3 >= lo:
        o3 += 1
    if o3 >= hi:
        o3 += 1
    return (i + o1) % n, (i + o2) % n, (i + o3) % n, b & _U(0xFFFFFFFF)


@njit(cache=True)
def sample_parents(state, n, count):
    """``count`` parent triples for individual 0 of a population of ``n`` and the j_rand draws for
    ``D = 7`` genes, from run 0 of ``state`` (for tests of the kernel's sampling)."""
    out = np.empty((count, 4), np.int64)
    for k in range(count):
        r1, r2, r3, x = _parents(state, 0, 0, n)
        out[k, 0], out[k, 1], out[k, 2], out[k, 3] = r1, r2, r3, _below(x, 7)
    return out


@njit(cache=True)
def sample_uniform(state, count):
    """``count`` uniforms in [0, 1) (53 bits) from run 0 of ``state`` (for tests)."""
    out = np.empty(count)
    for k in range(count):
        out[k] = np.float64(next_u64(state, 0) >> _U(11)) * 2.0**-53
    return out


@njit(error_model="numpy", cache=True)
def de_trials(pop, state, f, cr, bound, trial):
    """Trial vectors of one DE/rand/1/bin generation for every run of a batch (written into ``trial``).

    ``pop (S, NP, D)``, ``state (S, 4)`` the runs' xoshiro256** states (advanced in place), ``f (S, NP)``
    and ``cr (S, NP)`` every individual's mutation factor and crossover rate (fixed for DE; ADE's readings
    are computed by :func:`navlib.methods.de.ade_rates`).  Per individual: parents r1, r2, r3 (distinct,
    != i) and j_rand uniformly at random, then

        v_ij = x_r1,j + F_i (x_r2,j - x_r3,j);  u_ij = v_ij if U_ij < CR_i or j = j_rand(i) else x_ij;
        u_ij <- U(-bound, bound)   (a fresh uniform)   if abs(u_ij) > bound

    with ``U_ij`` uniform at 16-bit resolution (``k / 2^16``)."""
    n_runs, n_pop, dim = pop.shape
    for s in range(n_runs):
        for i in range(n_pop):
            fi = f[s, i]
            threshold = np.int64(np.ceil(cr[s, i] * 65536.0))  # U < c  <=>  k < ceil(c 2^16)
            r1, r2, r3, x = _parents(state, s, i, n_pop)
            jr = _below(x, dim)
            n_out = 0
            bits = _U(0)
            for j in range(dim):
                if j % 4 == 0:
                    bits = next_u64(state, s)
                k16 = np.int64((bits >> _U(16 * (j % 4))) & _U(0xFFFF))
                if k16 < threshold or j == jr:
                    u = pop[s, r1, j] + fi * (pop[s, r2, j] - pop[s, r3, j])
                else:
                    u = pop[s, i, j]
                trial[s, i, j] = u
                n_out += abs(u) > bound
            if n_out:
                for j in range(dim):
                    if abs(trial[s, i, j]) > bound:
                        unit = np.float64(next_u64(state, s) >> _U(11)) * 2.0**-53
                        trial[s, i, j] = -bound + 2.0 * bound * unit


@njit(error_model="numpy", cache=True)
def ade_rates_into(fit, f_gen, f_min, f_max, cr_min, cr_max, f_mode, cr_rank, f_out, cr_out):
    """ADE's per-individual ``F_i`` and ``CR_i`` of every run (``fit (S, NP)``) written into ``f_out`` and
    ``cr_out``: the compiled form of :func:`navlib.methods.de.ade_rates` (its numpy reference, with the same
    operations in the same order).  ``f_mode`` 0 = by generation (``f_gen`` for all), 1 = per individual
    ``f_min + (f_max - f_min) q_i``, 2 = combined ``f_min + (f_gen - f_min) q_i``; ``cr_rank`` False = by
    value ``cr_min + (cr_max - cr_min) q_i``, True = by rank ``cr_min + (cr_max - cr_min) r_i / (NP - 1)``
    (ties by index), with ``q_i = (f_i - f_min)/(f_max - f_min)`` (0 when all are equal)."""
    n_runs, n_pop = fit.shape
    top = f_max if f_mode == 1 else f_gen
    for s in range(n_runs):
        lo, hi = fit[s, 0], fit[s, 0]
        for i in range(1, n_pop):
            lo = min(lo, fit[s, i])
            hi = max(hi, fit[s, i])
        for i in range(n_pop):
            if f_mode == 0:
                f_out[s, i] = f_gen
            else:
                q = (fit[s, i] - lo) / (hi - lo) if hi > lo else 0.0
                f_out[s, i] = f_min + (top - f_min) * q
            if not cr_rank:
                cr_out[s, i] = (
                    cr_min + (cr_max - cr_min) * (fit[s, i] - lo) / (hi - lo) if hi > lo else cr_min
                )
        if cr_rank:
            order = np.argsort(fit[s], kind="mergesort")
            for r in range(n_pop):
                cr_out[s, order[r]] = cr_min + (cr_max - cr_min) * r / (n_pop - 1)


@njit(cache=True)
def de_select(pop, fit, trial, tfit, best, accepted):
    """Greedy selection ``x_i <- u_i if J(u_i) <= J(x_i)`` in place; ``best[s]`` = run s's best fitness,
    ``accepted[s, i]`` = whether trial i replaced its parent."""
    n_runs, n_pop, dim = pop.shape
    for s in range(n_runs):
        b = np.inf
        for i in range(n_pop):
            accepted[s, i] = tfit[s, i] <= fit[s, i]
            if accepted[s, i]:
                fit[s, i] = tfit[s, i]
                for j in range(dim):
                    pop[s, i, j] = trial[s, i, j]
            b = min(b, fit[s, i])
        best[s] = b


# ----------------------------------------------------------------------------------------------- trainlm
#: Stop reasons of :func:`lm_1m1`, by code (0 = still training).
LM_STOPS = (
    "",
    "maximum epoch",
    "performance goal",
    "maximum mu",
    "minimum gradient",
    "validation stop",
)


@njit(cache=True)
def _net_residuals(theta, xn, t, m, tansig, lo, out_lo, gain, r, h):
    """Residuals (target units) of one 1-M-1 net, as :func:`navlib.methods.bpnet.forward_population`
    computes the output, ``lo + (o' - out_lo) gain - t``; ``h (N, M)`` receives the hidden layer's tanh
    values (of ``z`` for tansig, of ``z/2`` for logsig), which :func:`_net_jacobian` reuses."""
    k = 1.0 if tansig else 0.5
    bias = theta[3 * m]
    if not tansig:
        for j in range(m):
            bias += 0.5 * theta[2 * m + j]
    for i in range(xn.shape[0]):
        o = 0.0
        for j in range(m):
            h[i, j] = np.tanh((k * theta[j]) * xn[i] + k * theta[m + j])
            o += (k * theta[2 * m + j]) * h[i, j]
        r[i] = lo + (o + bias - out_lo) * gain - t[i]


@njit(cache=True)
def _net_jacobian(theta, xn, m, tansig, gain, h, jac):
    """Jacobian of the residuals (``gain`` times :func:`navlib.methods.bpnet.output_jacobian`), from the
    hidden tanh values ``h`` of :func:`_net_residuals` at the same ``theta``."""
    for i in range(xn.shape[0]):
        for j in range(m):
            if tansig:
                g = h[i, j]
                dg = 1.0 - g * g
            else:
                g = 0.5 * (1.0 + h[i, j])
                dg = g * (1.0 - g)
            vd = dg * theta[2 * m + j]
            jac[i, j] = gain * (vd * xn[i])
            jac[i, m + j] = gain * vd
            jac[i, 2 * m + j] = gain * g
        jac[i, 3 * m] = gain


@njit(cache=True)
def _wmse(r, w, wsum):
    s = 0.0
    for i in range(r.shape[0]):
        s += w[i] * r[i] * r[i]
    return s / wsum


@njit(cache=True)
def lm_1m1(
    theta0,
    xn,
    t,
    m,
    tansig,
    lo,
    out_lo,
    gain,
    wt,
    wv,
    do_val,
    epochs_max,
    goal,
    mu0,
    mu_dec,
    mu_inc,
    mu_max,
    min_grad,
    max_fail,
):
    """MATLAB's ``trainlm`` for S independent 1-M-1 nets (the algorithm, stop tests and their order as in
    :func:`navlib.methods.lm.levenberg_marquardt`, which is the generic reference this kernel is tested
    against), compiled for the network of :mod:`navlib.methods.bpnet`: one net after another, each with
    its own training weights ``wt[s]`` and validation weights ``wv[s]`` (0/1).

    Returns ``(theta (S, D), epochs (S,), stop codes (S,) into LM_STOPS, perf (S, E+1), val_perf (S, E+1),
    best_epoch (S,))``; histories are NaN after the stop."""
    n_nets, dim = theta0.shape
    n = xn.shape[0]
    out = theta0.copy()
    epochs = np.zeros(n_nets, np.int64)
    stop = np.zeros(n_nets, np.int64)
    hist = np.full((n_nets, epochs_max + 1), np.nan)
    vhist = np.full((n_nets, epochs_max + 1), np.nan)
    best_epoch = np.zeros(n_nets, np.int64)
    r = np.empty(n)
    r2 = np.empty(n)
    h = np.empty((n, m))
    h2 = np.empty((n, m))
    jac = np.empty((n, dim))
    jw = np.empty((n, dim))
    a = np.empty((dim, dim))
    for s in range(n_nets):
        theta = theta0[s].copy()
        w, v = wt[s], wv[s]
        wsum, vsum = w.sum(), v.sum()
        _net_residuals(theta, xn, t, m, tansig, lo, out_lo, gain, r, h)
        perf = _wmse(r, w, wsum)
        vperf = _wmse(r, v, vsum) if do_val else np.nan
        hist[s, 0], vhist[s, 0] = perf, vperf
        best, best_v, fails, mu = theta.copy(), vperf, 0, mu0
        _net_jacobian(theta, xn, m, tansig, gain, h, jac)
        for epoch in range(epochs_max + 1):
            for i in range(n):
                for p in range(dim):
                    jw[i, p] = w[i] * jac[i, p]
            jj = np.dot(jw.T, jac)  # J' W J and J' W e (BLAS)
            je = np.dot(jw.T, r)
            g2 = 0.0
            for p in range(dim):
                g2 += (2.0 * je[p] / wsum) ** 2
            why = (
                1
                if epoch == epochs_max
                else 2
                if perf <= goal
                else 3
                if mu > mu_max
                else 4
                if np.sqrt(g2) <= min_grad
                else 5
                if do_val and fails >= max_fail
                else 0
            )
            if why:
                stop[s] = why
                break
            while True:
                for p in range(dim):
                    for q in range(dim):
                        a[p, q] = jj[p, q]
                    a[p, p] += mu
                try:
                    step = -np.linalg.solve(a, je)
                except Exception:  # singular: a NaN step fails the test below and raises mu
                    step = np.full(dim, np.nan)
                trial = theta + step
                _net_residuals(trial, xn, t, m, tansig, lo, out_lo, gain, r2, h2)
                perf2 = _wmse(r2, w, wsum)
                if perf2 < perf:
                    theta, perf = trial, perf2
                    r[:] = r2
                    h[:, :] = h2
                    mu = max(mu * mu_dec, 1e-20)
                    break
                mu *= mu_inc
                if mu > mu_max:
                    break
            epochs[s] = epoch + 1
            hist[s, epoch + 1] = perf
            _net_jacobian(theta, xn, m, tansig, gain, h, jac)
            if do_val:
                vperf = _wmse(r, v, vsum)
                vhist[s, epoch + 1] = vperf
                if vperf < best_v:
                    best[:], best_v, best_epoch[s], fails = theta, vperf, epoch + 1, 0
                elif vperf > best_v:
                    fails += 1
        if do_val:
            out[s] = best
        else:
            out[s] = theta
            best_epoch[s] = epochs[s]
    return out, epochs, stop, hist, vhist, best_epoch


# ----------------------------------------------------------------------------------------------- ELM back-tuning
# The numpy expressions of navlib.methods.elm (loss, gradients, the Armijo line search of ``_back_tune``)
# in numpy's order, so that the results equal numpy's up to rounding (on our machine: bit for bit with the
# sigmoid and contiguous inputs): sigmoid as 1 / (1 + exp(-z)) (scipy's ``expit``, libm's exp); every
# matrix product by the BLAS routine numpy's ``@`` calls for those shapes (dot, gemv or gemm; numba calls it
# through scipy's BLAS); sums in numpy's order (pairwise in blocks of 8 over a contiguous run, column sums
# row after row).  No fast-math flags at all, not even ``contract``: a fused multiply-add rounds once where
# numpy rounds twice.


@njit(cache=True, error_model="numpy")
def _block_sum(a: np.ndarray, lo: int, n: int) -> float:
    """Sum of a[lo:lo+n], n <= 128, in numpy's order: 8 running sums combined pairwise, then the rest."""
    if n < 8:
        res = 0.0
        for i in range(lo, lo + n):
            res += a[i]
        return res
    r0, r1, r2, r3 = a[lo], a[lo + 1], a[lo + 2], a[lo + 3]
    r4, r5, r6, r7 = a[lo + 4], a[lo + 5], a[lo + 6], a[lo + 7]
    i = 8
    while i < n - (n % 8):
        j = lo + i
        r0 += a[j]
        r1 += a[j + 1]
        r2 += a[j + 2]
        r3 += a[j + 3]
        r4 += a[j + 4]
        r5 += a[j + 5]
        r6 += a[j + 6]
        r7 += a[j + 7]
        i += 8
    res = ((r0 + r1) + (r2 + r3)) + ((r4 + r5) + (r6 + r7))
    while i < n:
        res += a[lo + i]
        i += 1
    return res


@njit(cache=True, error_model="numpy")
def pairwise_sum(a: np.ndarray) -> float:
    """``np.sum(a)`` of a contiguous array in numpy's order (numpy's ``pairwise_sum``: halve, rounded to
    a multiple of 8, until a block has at most 128 entries); without recursion, which numba's cache
    does not handle."""
    a = a.ravel()
    los, ns, ops = np.empty(128, np.int64), np.empty(128, np.int64), np.empty(128, np.int64)
    vals = np.empty(128)
    los[0], ns[0], ops[0] = 0, a.size, 0
    top, nv = 1, 0
    while top > 0:
        top -= 1
        lo, n, op = los[top], ns[top], ops[top]
        if op == 1:  # both halves done: left + right
            nv -= 1
            vals[nv - 1] = vals[nv - 1] + vals[nv]
        elif n <= 128:
            vals[nv] = _block_sum(a, lo, n)
            nv += 1
        else:
            n2 = n // 2
            n2 -= n2 % 8
            ops[top] = 1  # stays below the halves, so it runs after both
            los[top + 1], ns[top + 1], ops[top + 1] = lo + n2, n - n2, 0
            los[top + 2], ns[top + 2], ops[top + 2] = lo, n2, 0
            top += 3
    return vals[0]


@njit(cache=True, error_model="numpy")
def column_sums(a: np.ndarray) -> np.ndarray:
    """``a.sum(axis=0)`` of a C-contiguous (N, L) array in numpy's order: row after row, or pairwise when
    there is a single column."""
    if a.shape[1] == 1:
        return np.full(1, pairwise_sum(a))
    out = a[0].copy()
    for n in range(1, a.shape[0]):
        out += a[n]
    return out


@njit(cache=True, error_model="numpy")
def blas_matmul(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``a @ b`` for 2-D contiguous arrays by the BLAS call numpy's matmul makes for these shapes:
    dot for (1, q) @ (q, 1), gemv when one side is a single row or column, gemm otherwise."""
    p, q = a.shape
    r = b.shape[1]
    if p == 1 and r == 1:
        return np.full(
            (1, 1), np.dot(np.ascontiguousarray(a).reshape(q), np.ascontiguousarray(b).reshape(q))
        )
    if p == 1:
        return np.dot(np.ascontiguousarray(a).reshape(q), b).reshape(1, r)
    if r == 1:
        return np.dot(a, np.ascontiguousarray(b).reshape(q)).reshape(p, 1)
    return np.dot(a, b)


@njit(cache=True, error_model="numpy")
def elm_hidden(w, b, X, sigmoid):
    """H = g(X W + b) (sigmoid as scipy's ``expit``: 1 / (1 + exp(-z)))."""
    z = blas_matmul(X, w) + b
    return 1.0 / (1.0 + np.exp(-z)) if sigmoid else np.tanh(z)


@njit(cache=True, error_model="numpy")
def elm_loss(w, b, beta, X, T, sigmoid) -> float:
    """E = mean((g(X W + b) beta - T)^2)."""
    r = blas_matmul(elm_hidden(w, b, X, sigmoid), beta) - T
    return pairwise_sum(r * r) / r.size


@njit(cache=True, error_model="numpy")
def elm_loss_grad(w, b, beta, X, T, sigmoid):
    """(E, dE/dW, dE/db, dE/dbeta), the equations of :func:`navlib.methods.elm.loss_and_gradients`."""
    a2 = elm_hidden(w, b, X, sigmoid)
    r = blas_matmul(a2, beta) - T
    loss = pairwise_sum(r * r) / r.size
    d3 = (2.0 / r.size) * r
    d2 = blas_matmul(d3, np.ascontiguousarray(beta.T)) * (
        a2 * (1.0 - a2) if sigmoid else 1.0 - a2 * a2
    )
    return loss, blas_matmul(X.T, d2), column_sums(d2), blas_matmul(a2.T, d3)


@njit(cache=True, error_model="numpy")
def elm_back_tune(w, b, beta, X, T, sigmoid, steps, step, max_halvings, armijo):
    """The loop of ``navlib.methods.elm._back_tune`` in one compiled call: returns the tuned (w, b, beta), the losses
    (the starting loss, then one per accepted step) and the trial step for the next call."""
    loss, gw, gb, gbeta = elm_loss_grad(w, b, beta, X, T, sigmoid)
    losses = np.empty(steps + 1)
    losses[0] = loss
    count = 1
    w1, b1, beta1 = w, b, beta
    for _ in range(steps):
        g2 = pairwise_sum(gw * gw) + pairwise_sum(gb * gb) + pairwise_sum(gbeta * gbeta)
        if g2 == 0.0:
            break
        found = False
        for _ in range(max_halvings):
            w1, b1, beta1 = w - step * gw, b - step * gb, beta - step * gbeta
            # A step too small to change any weight gives exactly the current loss (the same
            # computation on the same numbers), which the test below rejects: skip evaluating it.
            if not (
                np.array_equal(w1, w) and np.array_equal(b1, b) and np.array_equal(beta1, beta)
            ):
                new = elm_loss(w1, b1, beta1, X, T, sigmoid)
                if new <= loss - armijo * step * g2 and new < loss:
                    found = True
                    break
            step *= 0.5
        if (
            not found
        ):  # no decrease found at any step size: (numerically) stationary, stop this stage
            break
        w, b, beta = w1, b1, beta1
        loss, gw, gb, gbeta = elm_loss_grad(w, b, beta, X, T, sigmoid)
        losses[count] = loss
        count += 1
        step *= 2.0  # let the step grow again; the line search halves it back when needed
    return w.copy(), b.copy(), beta.copy(), losses[:count].copy(), step
