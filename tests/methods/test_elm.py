"""Tests for navlib.methods.elm: plain ELM, back-tuning, pruning and the point-incremental scheme (patent B)."""

from __future__ import annotations

import numpy as np
import pytest

from navlib.methods.seeding import generator

from navlib.methods.elm import (
    ACTIVATIONS,
    ELMModel,
    ELMParams,
    IncrementalELMParams,
    _back_tune,
    back_tune,
    fit_elm,
    fit_incremental_elm,
    loss_and_gradients,
    prune_nodes,
)
from navlib.errors import InputError
from navlib.methods.jit import column_sums, pairwise_sum

import elm_reference as reference


def compass_like(n: int = 121, noise: float = 0.0, seed: int = 0):
    """Normalised measured heading -> normalised true heading for a compass with a one- and
    two-cycle deviation (about -8..+25 deg), as in the 121-point turntable sweeps."""
    h = np.linspace(0.0, 360.0, n)
    r = np.deg2rad(h)
    meas = h + 5 + 12 * np.sin(r) + 15 * np.cos(r + 0.3) + 3 * np.sin(2 * r) + 2 * np.cos(2 * r)
    meas = meas + np.random.default_rng(seed).normal(0.0, noise, n)
    x = (meas - meas.min()) / (meas.max() - meas.min())
    return x, h / 360.0


@pytest.mark.parametrize("seed", range(5))
def test_elm_interpolates_exactly_with_as_many_nodes_as_samples(seed):
    # Huang 2006, Thm 2.1: N distinct samples, N random sigmoid nodes -> H invertible, zero error.
    # Sigmoid H is ill-conditioned (cond ~1e9 here), so "exact" means to about 1e-6 of the target.
    x = np.linspace(0.0, 1.0, 10)
    t = np.sin(2 * np.pi * x) + 0.3 * x**2
    p = ELMParams(n_hidden=10, weight_range=10.0, bias_range=10.0, seed=seed)
    model = fit_elm(x, t, p)
    assert model.n_hidden == 10
    assert np.max(np.abs(model.predict(x) - t)) < 1e-6
    # with fewer nodes than samples the same target is not interpolated: the check above has teeth
    few = fit_elm(x, t, p, n_hidden=3)
    assert np.max(np.abs(few.predict(x) - t)) > 1e-4


def test_elm_output_weights_are_min_norm_least_squares():
    x, t = compass_like(40)
    model = fit_elm(x, t, ELMParams(n_hidden=6, seed=1))
    H = model.hidden(x)
    beta_ls, *_ = np.linalg.lstsq(H, t[:, None], rcond=None)
    np.testing.assert_allclose(model.beta, beta_ls, rtol=1e-6, atol=1e-8)
    # normal equations: the residual is orthogonal to every hidden-node column
    r = model.predict(x) - t
    assert np.max(np.abs(H.T @ r)) < 1e-8 * np.sqrt(x.size)


def test_shapes_1d_and_2d():
    x, t = compass_like(30)
    m1 = fit_elm(x, t, ELMParams(n_hidden=4))
    assert m1.predict(x).shape == (30,)
    X2 = np.column_stack([x, x**2])
    T2 = np.column_stack([t, 1 - t])
    m2 = fit_elm(X2, T2, ELMParams(n_hidden=4))
    assert (m2.n_inputs, m2.n_hidden, m2.n_outputs) == (2, 4, 2)
    assert m2.predict(X2).shape == (30, 2)
    assert m2.n_weights == 2 * 4 + 4 + 4 * 2


def test_gradients_match_finite_differences():
    rng = np.random.default_rng(5)
    X = rng.uniform(0, 1, (12, 2))
    T = rng.normal(size=(12, 2))
    for act in ("sigmoid", "tanh"):
        m = ELMModel(
            w=rng.normal(size=(2, 3)),
            b=rng.normal(size=3),
            beta=rng.normal(size=(3, 2)),
            activation=act,
            squeeze_output=False,
        )
        loss, gw, gb, gbeta = loss_and_gradients(m, X, T)
        assert loss == pytest.approx(m.loss(X, T))
        for name, grad in (("w", gw), ("b", gb), ("beta", gbeta)):
            arr = getattr(m, name)
            num = np.zeros_like(arr)
            for idx in np.ndindex(arr.shape):
                eps = 1e-6
                old = arr[idx]
                arr[idx] = old + eps
                lp = m.loss(X, T)
                arr[idx] = old - eps
                lm = m.loss(X, T)
                arr[idx] = old
                num[idx] = (lp - lm) / (2 * eps)
            np.testing.assert_allclose(grad, num, rtol=1e-5, atol=1e-9, err_msg=f"{act} d/d{name}")


def test_compiled_sums_follow_numpy_order():
    # numpy sums pairwise (blocks of 8, split above 128 entries); a plain running sum differs in the last
    # bits for most of these sizes, so equality checks the order (under the locked numpy)
    rng = np.random.default_rng(3)
    plain_differs = 0
    for n in (0, 1, 7, 8, 9, 121, 128, 129, 300, 1000, 4099):
        a = rng.normal(size=n) * 10.0 ** rng.uniform(-4, 4, n)
        assert pairwise_sum(a) == np.sum(a), n
        plain_differs += sum(a.tolist()) != np.sum(a)
        m = rng.normal(size=(max(n, 1), 3))
        np.testing.assert_array_equal(column_sums(m), m.sum(axis=0))
        np.testing.assert_array_equal(column_sums(m[:, :1].copy()), m[:, :1].sum(axis=0))
    assert plain_differs >= 3


@pytest.mark.parametrize("activation", ACTIVATIONS)
def test_compiled_loss_and_gradients_match_numpy(activation):
    # several inputs and outputs: every matrix product and sum of the compiled kernel is exercised
    rng = np.random.default_rng(8)
    X, T = rng.uniform(0, 1, (37, 3)), rng.normal(size=(37, 2))
    m = ELMModel(
        w=rng.normal(size=(3, 5)),
        b=rng.normal(size=5),
        beta=rng.normal(size=(5, 2)),
        activation=activation,
        squeeze_output=False,
    )
    ours = loss_and_gradients(m, X, T)
    ref = reference.loss_grad(m.w, m.b, m.beta, X, T, activation)
    assert ours[0] == pytest.approx(ref[0], rel=1e-13)
    for name, a, r in zip(("W", "b", "beta"), ours[1:], ref[1:]):
        assert a.shape == r.shape, name
        np.testing.assert_allclose(
            a, r, rtol=1e-12, atol=1e-15 * np.abs(r).max(), err_msg=f"dE/d{name}"
        )


@pytest.mark.parametrize("activation", ACTIVATIONS)
@pytest.mark.parametrize("lr", [1e-2, 1e3])
def test_compiled_back_tuning_matches_numpy_reference(activation, lr):
    # the same accepted steps, halvings and doublings as the plain-numpy loop, up to rounding
    x, t = compass_like(121, noise=0.05, seed=3)
    model = fit_elm(
        x, t, ELMParams(n_hidden=4, weight_range=5.0, bias_range=5.0, seed=3, activation=activation)
    )
    model.beta *= 0.8  # off the least-squares optimum, so that tuning has work to do
    X, T = x[:, None], t[:, None]
    w, b, beta, ref_losses, ref_step = reference.back_tune(
        model.w, model.b, model.beta, X, T, activation, 40, lr
    )
    tuned, losses, step = _back_tune(model, X, T, 40, lr)
    assert (
        len(ref_losses) == 41 and ref_losses[-1] < 0.5 * ref_losses[0]
    )  # the comparison has teeth
    assert len(losses) == len(ref_losses)
    np.testing.assert_allclose(losses, ref_losses, rtol=1e-10, atol=0)
    assert step == ref_step  # a power of two times lr
    for name, ref in (("w", w), ("b", b), ("beta", beta)):
        np.testing.assert_allclose(
            getattr(tuned, name), ref, rtol=1e-9, atol=1e-12 * np.abs(ref).max(), err_msg=name
        )


@pytest.mark.parametrize("lr", [1e-300, 1e-16, 1e-15])
def test_stalled_line_search_matches_numpy_reference(lr):
    # tiny trial steps: those that change no weight are skipped by the compiled loop, the step
    # bookkeeping (halvings, the step handed to the next stage) must still be the reference's
    x, t = compass_like(121, noise=0.05, seed=2)
    model = fit_elm(x, t, ELMParams(n_hidden=4, weight_range=5.0, bias_range=5.0, seed=2))
    model.beta *= 0.8
    X, T = x[:, None], t[:, None]
    *_, ref_losses, ref_step = reference.back_tune(
        model.w, model.b, model.beta, X, T, "sigmoid", 10, lr
    )
    tuned, losses, step = _back_tune(model, X, T, 10, lr)
    assert step == ref_step and len(losses) == len(ref_losses)
    np.testing.assert_allclose(losses, ref_losses, rtol=1e-10, atol=0)
    if lr == 1e-300:  # nothing can move: 40 halvings (into subnormals), then stop
        assert len(losses) == 1 and 0 < step < lr * 1e-12
        np.testing.assert_array_equal(tuned.w, model.w)
    if lr == 1e-15:  # steps of about one ulp of the weights are still taken
        assert len(losses) == 11


def test_incremental_elm_matches_numpy_reference():
    # the whole scheme (ELM, prune and tune stages, validation loss) with the numpy reference swapped in
    x, t = compass_like(121, noise=0.05, seed=5)
    p = IncrementalELMParams(
        max_nodes=6,
        loss_goal=0.0,
        max_iter=12,
        weight_range=5.0,
        bias_range=5.0,
        prune_tol=1e-2,
        seed=4,
    )
    # contiguous copies: numpy's own products round differently on strided views
    args = (x[::2].copy(), t[::2].copy(), p)
    kw = dict(x_val=x[1::2].copy(), t_val=t[1::2].copy())
    model, hist = fit_incremental_elm(*args, **kw)
    with reference.numpy_reference():
        ref_model, ref_hist = fit_incremental_elm(*args, **kw)
    assert hist[["iteration", "stage", "n_nodes"]].equals(
        ref_hist[["iteration", "stage", "n_nodes"]]
    )
    assert (hist.stage == "tune").sum() == 6 and hist.loss.iloc[-1] < 0.1 * hist.loss.iloc[1]
    np.testing.assert_allclose(
        hist[["loss", "val_loss"]], ref_hist[["loss", "val_loss"]], rtol=1e-10, atol=0
    )
    np.testing.assert_allclose(model.predict(x), ref_model.predict(x), rtol=1e-10, atol=1e-12)


@pytest.mark.parametrize("seed", range(5))
@pytest.mark.parametrize("lr", [1e-3, 1.0, 1e4])
def test_back_tuning_never_increases_training_loss(seed, lr):
    x, t = compass_like(121, noise=0.05, seed=seed)
    model = fit_elm(x, t, ELMParams(n_hidden=4, weight_range=5.0, bias_range=5.0, seed=seed))
    before = model.loss(x, t)
    tuned, losses = back_tune(model, x, t, steps=40, lr=lr)
    assert losses[0] == pytest.approx(before, rel=1e-12)
    assert np.all(np.diff(losses) < 0)  # every accepted step lowers the loss
    assert tuned.loss(x, t) == pytest.approx(losses[-1], rel=1e-12)
    assert tuned.loss(x, t) < before  # and tuning does something on a 4-node net
    assert model.loss(x, t) == before  # the input model is not modified


def test_back_tuning_moves_all_weights():
    x, t = compass_like(60)
    model = fit_elm(x, t, ELMParams(n_hidden=3, weight_range=5.0, bias_range=5.0, seed=2))
    tuned, losses = back_tune(model, x, t, steps=30, lr=0.5)
    assert len(losses) > 1
    for name in ("w", "b", "beta"):
        assert not np.array_equal(getattr(tuned, name), getattr(model, name)), name


def test_pruning_removes_node_with_zero_output_weight():
    x, t = compass_like(50)
    model = fit_elm(x, t, ELMParams(n_hidden=5, weight_range=5.0, bias_range=5.0, seed=4))
    model.beta[2, 0] = 0.0
    pruned, removed = prune_nodes(model, tol=0.0)
    assert removed.tolist() == [2]
    assert pruned.n_hidden == 4
    np.testing.assert_array_equal(pruned.w, np.delete(model.w, 2, axis=1))
    np.testing.assert_array_equal(pruned.b, np.delete(model.b, 2))
    np.testing.assert_allclose(pruned.predict(x), model.predict(x), rtol=0, atol=1e-12)
    # a tolerance below every remaining |beta| keeps them all; the last node is never pruned
    assert prune_nodes(pruned, tol=0.0)[1].size == 0
    everything, removed_all = prune_nodes(model, tol=1e12)
    assert everything.n_hidden == 1 and removed_all.size == 4


def test_incremental_history_and_monotone_stages():
    x, t = compass_like(121, noise=0.05)
    # 12 nodes at most keeps cond(H) < 1e12, where least squares is accurate to rounding
    p = IncrementalELMParams(
        max_nodes=12,
        loss_goal=0.0,
        max_iter=40,
        weight_range=5.0,
        bias_range=5.0,
        tune_steps=30,
        seed=7,
    )
    model, hist = fit_incremental_elm(x, t, p)
    assert list(hist.columns) == ["iteration", "stage", "n_nodes", "loss", "val_loss"]
    assert hist.iteration.iloc[-1] == 40 and hist.iteration.is_monotonic_increasing
    # claims reading: odd iterations solve the ELM, even iterations back-tune
    it_stage = hist[hist.stage != "prune"]
    assert set(it_stage[it_stage.iteration % 2 == 1].stage) == {"elm"}
    assert set(it_stage[it_stage.iteration % 2 == 0].stage) == {"tune"}
    # hidden nodes grow from 1, one per ELM stage
    assert hist.n_nodes.iloc[0] == 1
    assert hist.n_nodes.max() == model.n_hidden == 12
    prev = hist.loss.shift(1)
    tune = hist.stage == "tune"
    assert (hist.loss[tune] <= prev[tune]).all()
    elm = (hist.stage == "elm") & prev.notna()
    assert (hist.loss[elm] <= prev[elm] * (1 + 1e-9) + 1e-15).all()
    assert model.loss(x, t) == pytest.approx(hist.loss.iloc[-1], rel=1e-12)


def test_incremental_stops_at_loss_goal_and_fits():
    x, t = compass_like(121, noise=0.0)
    goal = 1e-7
    p = IncrementalELMParams(
        max_nodes=40, loss_goal=goal, max_iter=400, weight_range=5.0, bias_range=5.0, seed=0
    )
    model, hist = fit_incremental_elm(x, t, p)
    assert hist.loss.iloc[-1] <= goal
    assert (hist.loss.iloc[:-1].groupby(hist.iteration.iloc[:-1]).last() > goal).all()
    assert hist.iteration.iloc[-1] < 400
    assert np.sqrt(model.loss(x, t)) * 360 < 0.2  # deg, over the sweep


def test_incremental_prunes_negligible_nodes():
    x, t = compass_like(40)
    p = IncrementalELMParams(max_nodes=10, loss_goal=0.0, max_iter=9, prune_tol=1e9, seed=1)
    model, hist = fit_incremental_elm(x, t, p)
    assert (hist.stage == "prune").sum() == 4  # iterations 3, 5, 7, 9 add a node, then drop one
    assert model.n_hidden == 1 and hist.n_nodes[hist.stage == "prune"].eq(1).all()


def test_odd_nodes_schedule_tunes_at_odd_node_counts():
    x, t = compass_like(60)
    p = IncrementalELMParams(max_nodes=10, loss_goal=0.0, max_iter=6, schedule="odd_nodes", seed=2)
    _, hist = fit_incremental_elm(x, t, p)
    assert hist.stage.tolist() == ["elm", "tune", "elm", "elm", "tune", "elm", "elm", "tune", "elm"]
    assert hist[hist.stage == "tune"].n_nodes.tolist() == [1, 3, 5]


def test_validation_loss_is_recorded():
    x, t = compass_like(121, noise=0.05)
    p = IncrementalELMParams(max_nodes=5, loss_goal=0.0, max_iter=10, seed=3)
    model, hist = fit_incremental_elm(x[::2], t[::2], p, x_val=x[1::2], t_val=t[1::2])
    assert hist.val_loss.notna().all()
    assert hist.val_loss.iloc[-1] == pytest.approx(model.loss(x[1::2], t[1::2]), rel=1e-12)
    _, hist2 = fit_incremental_elm(x[::2], t[::2], p)
    assert hist2.val_loss.isna().all()


def test_determinism_with_seed():
    x, t = compass_like(121, noise=0.05)
    p = IncrementalELMParams(max_nodes=12, loss_goal=0.0, max_iter=30, seed=11)
    m1, h1 = fit_incremental_elm(x, t, p)
    m2, h2 = fit_incremental_elm(x, t, p)
    np.testing.assert_array_equal(m1.w, m2.w)
    np.testing.assert_array_equal(m1.beta, m2.beta)
    assert h1.equals(h2)
    m3, _ = fit_incremental_elm(x, t, p, rng=12)
    assert not np.array_equal(m1.w[:, :3], m3.w[:, :3])
    e1 = fit_elm(x, t, ELMParams(n_hidden=8, seed=5))
    e2 = fit_elm(
        x, t, ELMParams(n_hidden=8), rng=generator(5)
    )  # seed = run index (navlib.methods.seeding)
    np.testing.assert_array_equal(e1.w, e2.w)
    np.testing.assert_array_equal(e1.beta, e2.beta)


@pytest.mark.parametrize(
    "kwargs, word",
    [
        (dict(n_hidden=0), "n_hidden"),
        (dict(n_hidden=2.5), "n_hidden"),
        (dict(activation="relu"), "activation"),
        (dict(weight_range=0.0), "weight_range"),
        (dict(bias_range=-1.0), "bias_range"),
        (dict(seed=-1), "seed"),
    ],
)
def test_bad_elm_params(kwargs, word):
    x, t = compass_like(20)
    with pytest.raises(InputError, match=word) as err:
        fit_elm(x, t, ELMParams(**kwargs))
    assert "\n" not in str(err.value)


@pytest.mark.parametrize(
    "kwargs, word",
    [
        (dict(max_nodes=0), "max_nodes"),
        (dict(lr=0.0), "lr"),
        (dict(lr=float("nan")), "lr"),
        (dict(loss_goal=-1e-3), "loss_goal"),
        (dict(max_iter=0), "max_iter"),
        (dict(tune_steps=-1), "tune_steps"),
        (dict(prune_tol=-1.0), "prune_tol"),
        (dict(schedule="even"), "schedule"),
    ],
)
def test_bad_incremental_params(kwargs, word):
    x, t = compass_like(20)
    with pytest.raises(InputError, match=word):
        fit_incremental_elm(x, t, IncrementalELMParams(**kwargs))


def test_bad_data():
    x, t = compass_like(20)
    with pytest.raises(InputError, match="19 samples but t has 20"):
        fit_elm(x[:19], t)
    bad = x.copy()
    bad[3] = np.nan
    with pytest.raises(InputError, match="NaN"):
        fit_elm(bad, t)
    model = fit_elm(x, t)
    with pytest.raises(InputError, match="input"):
        model.predict(np.column_stack([x, x]))
    with pytest.raises(InputError, match="lr"):
        back_tune(model, x, t, lr=-1.0)
    with pytest.raises(InputError, match="x_val"):
        fit_incremental_elm(x, t, x_val=x)
