"""Tests for navlib.methods.ielm: Huang's point-incremental ELM (I-ELM), against a plain-numpy reference."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.special import expit

from navlib.errors import InputError
from navlib.methods.elm import IncrementalELMParams, fit_incremental_elm
from navlib.methods.ielm import IELMParams, first_nodes, fit_ielm
from navlib.methods.seeding import generator


def sweep(n: int = 121):
    """Normalised measured heading -> normalised true heading of a compass with a one- and two-cycle
    deviation (as the turntable sweeps)."""
    h = np.linspace(0.0, 360.0, n)
    r = np.deg2rad(h)
    meas = h + 5 + 12 * np.sin(r) + 15 * np.cos(r + 0.3) + 3 * np.sin(2 * r)
    return (meas - meas.min()) / np.ptp(meas), h / 360.0


def reference_ielm(x, t, n_nodes: int, seed: int, r: float):
    """Huang et al. (2006) I-ELM written out: draw (w_L, b_L) ~ U(-r, r) (w first), fit the residual on the
    new column alone by least squares, subtract, repeat; earlier weights are never touched."""
    gen = generator(seed)
    X, e = x[:, None], t[:, None].copy()
    ws, bs, betas, losses = [], [], [], []
    for _ in range(n_nodes):
        w = gen.uniform(-r, r, size=(1, 1))
        b = gen.uniform(-r, r, size=1)
        h = expit(X @ w + b)
        beta, *_ = np.linalg.lstsq(h, e, rcond=None)
        e = e - h @ beta
        ws.append(w[0, 0])
        bs.append(b[0])
        betas.append(beta[0, 0])
        losses.append(float(np.mean(e * e)))
    return np.array(ws), np.array(bs), np.array(betas), np.array(losses)


@pytest.mark.parametrize("seed", [0, 3])
def test_ielm_matches_the_numpy_reference(seed):
    x, t = sweep()
    model, hist = fit_ielm(
        x, t, IELMParams(max_nodes=60, weight_range=5.0, bias_range=5.0), rng=seed
    )
    w, b, beta, losses = reference_ielm(x, t, 60, seed, 5.0)
    np.testing.assert_allclose(model.w[0], w, rtol=0, atol=0)
    np.testing.assert_allclose(model.b, b, rtol=0, atol=0)
    np.testing.assert_allclose(model.beta[:, 0], beta, rtol=1e-10, atol=1e-12)
    np.testing.assert_allclose(hist.loss.to_numpy(), losses, rtol=1e-9, atol=1e-15)
    assert list(hist.iteration) == list(range(1, 61)) == list(hist.n_nodes)
    # the returned network is the residual's complement: T - H beta = e_L
    assert model.loss(x, t) == pytest.approx(losses[-1], rel=1e-9)


def test_ielm_training_error_never_rises_and_earlier_weights_stay_frozen():
    x, t = sweep()
    p = IELMParams(max_nodes=80, weight_range=5.0, bias_range=5.0)
    model, hist = fit_ielm(x, t, p, rng=1)
    assert np.all(np.diff(hist.loss.to_numpy()) <= 1e-15)  # Huang et al. Lemma 1
    assert hist.loss.iloc[-1] < hist.loss.iloc[0] / 5  # it learns
    short, short_hist = fit_ielm(
        x, t, IELMParams(max_nodes=25, weight_range=5.0, bias_range=5.0), rng=1
    )
    pre = first_nodes(model, 25)  # the 80-node run's first 25 nodes are the 25-node run
    np.testing.assert_array_equal(pre.beta, short.beta)
    np.testing.assert_array_equal(pre.predict(x), short.predict(x))
    assert pre.loss(x, t) == pytest.approx(short_hist.loss.iloc[-1], rel=1e-12)
    # a refit of all output weights on the same 25 nodes (a plain ELM) fits better: the I-ELM's are not it
    H = short.hidden(x)
    ls, *_ = np.linalg.lstsq(H, t[:, None], rcond=None)
    assert float(np.mean((H @ ls - t[:, None]) ** 2)) < 0.5 * short_hist.loss.iloc[-1]


def test_ielm_stops_at_the_goal_on_a_target_its_first_node_spans():
    # t = 2.5 g(x w1 + b1) with (w1, b1) the first node the run's generator draws: one iteration, beta 2.5
    x, _ = sweep(50)
    gen = generator(7)
    w1, b1 = gen.uniform(-4, 4, size=(1, 1)), gen.uniform(-4, 4, size=1)
    t = 2.5 * expit(x[:, None] @ w1 + b1)[:, 0]
    p = IELMParams(max_nodes=30, loss_goal=1e-20, weight_range=4.0, bias_range=4.0)
    model, hist = fit_ielm(x, t, p, rng=7)
    assert len(hist) == 1 and model.n_hidden == 1
    assert model.beta[0, 0] == pytest.approx(2.5, rel=1e-12)
    # without the goal it runs to the cap
    _, hist0 = fit_ielm(x, t, IELMParams(max_nodes=30, weight_range=4.0, bias_range=4.0), rng=7)
    assert len(hist0) == 30


def test_ielm_draws_the_nodes_of_the_patents_incremental_scheme():
    # same generator -> the same first node as fit_incremental_elm's first ELM stage (before any tuning)
    x, t = sweep()
    m_i, _ = fit_ielm(x, t, IELMParams(max_nodes=1, weight_range=5.0, bias_range=5.0), rng=4)
    p = IncrementalELMParams(max_iter=1, weight_range=5.0, bias_range=5.0, loss_goal=0.0)
    m_b, _ = fit_incremental_elm(x, t, p, rng=4)
    np.testing.assert_array_equal(m_i.w, m_b.w)
    np.testing.assert_array_equal(m_i.b, m_b.b)
    np.testing.assert_allclose(m_i.beta, m_b.beta, rtol=1e-12)  # one column: the same 1-D fit


def test_ielm_scores_the_validation_set_and_fits_several_outputs():
    x, t = sweep()
    T = np.column_stack([t, t**2])
    xv = x[::3] + 0.001
    Tv = T[::3]
    model, hist = fit_ielm(x, T, IELMParams(max_nodes=15), rng=2, x_val=xv, t_val=Tv)
    assert model.beta.shape == (15, 2)
    assert model.predict(x).shape == (121, 2)
    assert hist.val_loss.iloc[-1] == pytest.approx(model.loss(xv, Tv), rel=1e-9)
    assert hist.val_loss.iloc[4] == pytest.approx(first_nodes(model, 5).loss(xv, Tv), rel=1e-9)
    _, no_val = fit_ielm(x, T, IELMParams(max_nodes=3), rng=2)
    assert no_val.val_loss.isna().all()


def test_ielm_refuses_bad_input():
    x, t = sweep(20)
    with pytest.raises(InputError, match="max_nodes"):
        IELMParams(max_nodes=0)
    with pytest.raises(InputError, match="loss_goal"):
        IELMParams(loss_goal=-1.0)
    with pytest.raises(InputError, match="samples"):
        fit_ielm(x, t[:-1])
    with pytest.raises(InputError, match="x_val"):
        fit_ielm(x, t, x_val=x)
    model, _ = fit_ielm(x, t, IELMParams(max_nodes=4))
    with pytest.raises(InputError, match="parameter n"):
        first_nodes(model, 5)
