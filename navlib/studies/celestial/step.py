"""The cost of the BPKF's network step at one filter epoch (paper E Sec. 2.1: QR "raises the computational
efficiency of the navigation algorithm"): the running filter, at each star-sensor epoch, turns the epoch's
15x3 gain into the network's inputs and runs one forward pass, then subtracts the output from its attitude.

Two steps, same arithmetic but for the inputs::

    45 raw gains:  x = vec(K_k)  (45 inputs),  y = net_45(x)
    6 QR features: K_k = Q R,  x = [R11 R12 R13 R22 R23 R33]  (diag R >= 0),
                   y = net_6(x)
    net(x) = W2 logsig(W1 (x - mu_x) / s_x + b1) + b2,  scaled back: y s_y + mu_y

(:class:`StepNet`, :func:`step`).  :func:`step_timings` times both on the gains of one filtered run, epoch
by epoch as the running filter does it and vectorised over the run's epochs, in paired repetitions (both
steps in each, alternating which goes first).  numpy, float64, one thread; the paper's implementation
(MATLAB) is not stated.  :func:`step_flops` counts the step's floating-point operations instead, what a
compiled step would cost without an interpreter's overhead per call.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from ...errors import InputError
from ...methods import kalman as km
from ...methods.mlp import MLP

#: The upper triangle of the 3x3 ``R`` in the order of :func:`navlib.methods.kalman.qr_features`.
_IU = np.triu_indices(3)
#: The two timing readings: one epoch at a time (the running filter) and vectorised over a run's epochs.
STEP_READINGS = ("epoch", "batch")


@dataclass(frozen=True)
class StepNet:
    """A trained BP net as plain arrays for one epoch's forward pass: weights ``W1`` (hidden x inputs),
    ``b1``, ``W2`` (3 x hidden), ``b2``, the input scaling ``x_offset``, ``x_scale`` and the output
    scaling ``y_offset``, ``y_scale`` (the net's logsig hidden layer, purelin output)."""

    W1: np.ndarray
    b1: np.ndarray
    W2: np.ndarray
    b2: np.ndarray
    x_offset: np.ndarray
    x_scale: np.ndarray
    y_offset: np.ndarray
    y_scale: np.ndarray

    @classmethod
    def from_mlp(cls, net: MLP) -> StepNet:
        """The arrays of a trained :class:`navlib.methods.mlp.MLP` (logsig hidden layer)."""
        if net.params.hidden != "logsig":
            raise InputError(f"StepNet: a logsig hidden layer, got {net.params.hidden!r}")
        w = {k: np.ascontiguousarray(np.asarray(v, float)) for k, v in net.weights.items()}
        return cls(
            w["W1"],
            w["b1"],
            w["W2"],
            w["b2"],
            np.asarray(net.x_scale.offset, float),
            np.asarray(net.x_scale.scale, float),
            np.asarray(net.y_scale.offset, float),
            np.asarray(net.y_scale.scale, float),
        )

    @property
    def n_in(self) -> int:
        return int(self.W1.shape[1])


def _forward(x: np.ndarray, net: StepNet) -> np.ndarray:
    """``net(x)`` for the inputs of one epoch (n_in,) or of many (n, n_in)."""
    z = ((x - net.x_offset) / net.x_scale) @ net.W1.T + net.b1
    return (1.0 / (1.0 + np.exp(-z))) @ net.W2.T + net.b2


def _features(K: np.ndarray, n_in: int) -> np.ndarray:
    """The inputs from the gain of one epoch (15, 3) or of many (n, 15, 3): its 45 entries, or the 6
    entries of ``R`` with a non-negative diagonal."""
    if n_in == 45:
        return K.reshape(K.shape[:-2] + (45,))
    r = np.linalg.qr(K, mode="r")
    sign = np.where(np.diagonal(r, axis1=-2, axis2=-1) < 0, -1.0, 1.0)
    return (r * sign[..., :, None])[..., _IU[0], _IU[1]]


def step(K: np.ndarray, net: StepNet) -> np.ndarray:
    """The network step of one filter epoch (or of many at once): the attitude correction (arcsec,
    pitch, roll, yaw) the net predicts from the epoch's 15x3 gain ``K`` (base states), with the 45 raw
    entries as inputs when ``net`` has 45, the 6 QR features when it has 6 (see the module docstring).

    Parameters
    ----------
    K : numpy.ndarray
        The gain (15, 3), or a stack (n, 15, 3).
    net : StepNet
        The trained net (45 or 6 inputs).

    Returns
    -------
    numpy.ndarray
        The net's output in target units, (3,) or (n, 3).
    """
    if net.n_in not in (45, 6):
        raise InputError(f"step: a net with 45 or 6 inputs, got {net.n_in}")
    y = _forward(_features(K, net.n_in), net)
    return y * net.y_scale + net.y_offset


def _time_epochs(K: np.ndarray, net: StepNet) -> float:
    """Seconds per epoch of the step run epoch by epoch over the gains ``K`` (n, 15, 3)."""
    t0 = time.perf_counter()
    for k in range(K.shape[0]):
        step(K[k], net)
    return (time.perf_counter() - t0) / K.shape[0]


def _time_batch(K: np.ndarray, net: StepNet) -> float:
    """Seconds per epoch of the step vectorised over all the epochs of ``K`` (n, 15, 3)."""
    t0 = time.perf_counter()
    step(K, net)
    return (time.perf_counter() - t0) / K.shape[0]


def step_flops(n_in: int, n_hidden: int = 10, n_out: int = 3, n_states: int = km.N_BASE) -> int:
    """Floating-point operations of one epoch's network step (additions, multiplications, divisions,
    one each for ``exp`` and ``sqrt``)::

        inputs    45 raw: 0 (the gain's entries)
                  6 QR: Householder QR of the n_states x 3 gain, R only,
                  2 n^2 (m - n/3), m = n_states, n = 3 (Golub & Van Loan,
                  Alg. 5.2.1)
        scaling   2 n_in;  hidden layer 2 n_hidden n_in;  logsig 3 n_hidden
        output    2 n_out n_hidden;  scaling back 2 n_out

    Parameters
    ----------
    n_in : int
        45 (raw gains) or 6 (QR features).
    n_hidden, n_out, n_states : int
        The net's hidden and output units, the gain's rows.

    Returns
    -------
    int
        Operations per epoch.
    """
    if n_in not in (45, 6):
        raise InputError(f"step_flops: 45 or 6 inputs, got {n_in}")
    qr = 0 if n_in == 45 else round(2 * 3**2 * (n_states - 3 / 3))
    return int(
        qr + 2 * n_in + 2 * n_hidden * n_in + 3 * n_hidden + 2 * n_out * n_hidden + 2 * n_out
    )


def step_timings(
    K: np.ndarray, nets: dict[int, StepNet], n_timings: int, n_epochs: int = 300
) -> list[dict]:
    """Paired timings of the 45-input and the 6-input network step on the gains ``K`` (epochs, 15, 3) of
    one filtered run (``n_epochs`` of them, evenly spaced): in each of ``n_timings`` repetitions both steps
    (alternating which goes first) epoch by epoch (reading ``"epoch"``) and vectorised over those epochs
    (``"batch"``), after one untimed warm-up of each.  Rows: ``timing``, ``reading``, ``n_in``,
    ``seconds_per_epoch``."""
    K = np.asarray(K, float)
    if K.ndim != 3 or K.shape[1:] != (km.N_BASE, 3):
        raise InputError(f"step_timings: gains of shape (n_epochs, {km.N_BASE}, 3), got {K.shape}")
    pick = np.unique(np.linspace(0, K.shape[0] - 1, min(n_epochs, K.shape[0])).round().astype(int))
    K = np.ascontiguousarray(K[pick])
    if sorted(nets) != [6, 45]:
        raise InputError(f"step_timings: nets with 45 and 6 inputs, got {sorted(nets)}")
    for n_in, net in nets.items():
        if net.n_in != n_in:
            raise InputError(f"step_timings: the {n_in}-input net has {net.n_in} inputs")
        _time_epochs(K[:20], net)
        _time_batch(K, net)
    rows = []
    for j in range(n_timings):
        for n_in in (45, 6) if j % 2 == 0 else (6, 45):
            for reading, fn in zip(STEP_READINGS, (_time_epochs, _time_batch)):
                rows.append(
                    {
                        "timing": j,
                        "reading": reading,
                        "n_in": n_in,
                        "seconds_per_epoch": fn(K, nets[n_in]),
                    }
                )
    return rows
