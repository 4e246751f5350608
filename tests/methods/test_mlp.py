"""The generic MLP (:mod:`navlib.methods.mlp`): it fits a smooth map, is seeded, and checks its parameters
and shapes."""

import numpy as np
import pytest
import torch

from navlib.errors import InputError
from navlib.methods.mlp import MLPParams, train_mlp as train

torch.set_num_threads(1)


@pytest.mark.slow
@pytest.mark.parametrize("hidden", ["tansig", "logsig"])
def test_mlp_fits_a_smooth_map_and_is_seeded(hidden):
    rng = np.random.default_rng(0)
    X = rng.uniform(-1, 1, (200, 2))
    Y = np.c_[np.sin(2 * X[:, 0]) + X[:, 1], X[:, 0] * X[:, 1], X[:, 1] ** 2]
    p = MLPParams(n_in=2, n_hidden=10, n_out=3, hidden=hidden, epochs=40)
    a, b = train(X, Y, p, seed=1), train(X, Y, p, seed=1)
    np.testing.assert_array_equal(a.predict(X), b.predict(X))
    assert np.sqrt(np.mean((a.predict(X) - Y) ** 2)) < 0.02
    assert a.loss_history[-1] < a.loss_history[0]


@pytest.mark.parametrize(
    "kw, word",
    [
        (dict(n_hidden=0), "n_hidden"),
        (dict(hidden="relu"), "hidden"),
        (dict(trainer="sgd"), "trainer"),
        (dict(epochs=0), "epochs"),
    ],
)
def test_mlp_bad_params(kw, word):
    with pytest.raises(InputError, match=word):
        MLPParams(**kw)


def test_mlp_shape_checks():
    with pytest.raises(InputError, match="inputs have 3 columns"):
        train(np.zeros((5, 3)), np.zeros(5), MLPParams(n_in=2))
    with pytest.raises(InputError, match="do not match the targets"):
        train(np.zeros((5, 2)), np.zeros(4), MLPParams(n_in=2))
