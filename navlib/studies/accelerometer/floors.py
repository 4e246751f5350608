"""The noise floors of the chapter's statistics (ug): what the exact model shows against the *measured*
55 degC target, on held-out and training readings (:func:`rmse_floor_ug`) and as the largest error on a
tumble data set (:func:`max_error_floor_ug`)."""

from __future__ import annotations

import numpy as np

from scipy import optimize, stats

from ...errors import check_param
from .parameters import PaperDParams


def rmse_floor_ug(noise_ug: float, reference_share: float = 0.0) -> float:
    """Noise floor of the RMSE against the *measured* 55 degC target (ug): the RMSE of the exact model.

    Its error on a reading is the noise of that reading minus the noise of the 55 degC reading of the same
    position, :math:`e = n_1 - n_2`, so :math:`\\mathrm{RMSE} = \\sqrt{2}\\,\\sigma` on readings the
    model has not seen.  The 55 degC readings are their own targets (:math:`e = 0`): on a set where they are
    a share ``reference_share`` of the readings (the training set), the exact model's RMSE is
    :math:`\\sqrt{2}\\,\\sigma\\,\\sqrt{1 - s}` with :math:`s` = ``reference_share``.

    Parameters
    ----------
    noise_ug : float
        Noise per reading (1 sigma), ug.
    reference_share : float
        Share of the set's readings taken at the reference temperature (0 for held-out temperatures).

    Returns
    -------
    float
        The floor, ug.
    """
    check_param("reference_share", reference_share, lo=0, hi=1)
    return float(np.sqrt(2.0 * (1.0 - reference_share)) * noise_ug)


def max_error_floor_ug(noise_ug: float, n_temperatures: int, n_positions: int) -> float:
    """Noise floor of the largest error (ug) of a perfect model on a tumble data set: the median of
    :math:`\\max_{i,j} |n_{ij} - m_j|` over ``n_temperatures`` non-reference temperatures ``i`` and
    ``n_positions`` positions ``j``, where :math:`m_j` is the noise of position ``j``'s reference reading
    (the target) and all noises are :math:`N(0, \\sigma^2)`:

    .. math::

        P(\\max \\le x) = \\Bigl(E_m\\bigl[(\\Phi((x + m)/\\sigma) - \\Phi((m - x)/\\sigma))^{n_T}\\bigr]
        \\Bigr)^{n_P} = \\tfrac12,

    the expectation over :math:`m` by Gauss-Hermite quadrature.  It scales with ``noise_ug``.

    Parameters
    ----------
    noise_ug : float
        Noise per reading (1 sigma), ug.
    n_temperatures, n_positions : int
        Non-reference temperatures and positions of the data set.

    Returns
    -------
    float
        The median largest error of a perfect model, ug.
    """
    check_param("noise_ug", noise_ug, lo=0)
    check_param("n_temperatures", n_temperatures, lo=1, integer=True)
    check_param("n_positions", n_positions, lo=1, integer=True)
    if noise_ug == 0:
        return 0.0
    z, w = np.polynomial.hermite_e.hermegauss(80)  # nodes for E[f(m)], m ~ N(0, 1)
    w = w / w.sum()

    def cdf(x):  # in units of the noise
        inner = (stats.norm.cdf(x + z) - stats.norm.cdf(z - x)) ** n_temperatures
        return float(np.dot(w, inner)) ** n_positions - 0.5

    return float(noise_ug * optimize.brentq(cdf, 1e-6, 20.0, xtol=1e-10))


def _floors(params: PaperDParams) -> dict:
    """The floors of :func:`~navlib.studies.accelerometer.tables.noise_floor` from the experiment's shape: held-out,
    training (the reference temperature is one of the training temperatures) and unit B's largest error."""
    exp = params.experiment
    sigma = exp.noise_ug
    n_sp = exp.set_points_c.size
    n_train = n_sp - len(params.held_out_c) - len(params.check_c)
    return {
        "test": rmse_floor_ug(sigma),
        "train": rmse_floor_ug(sigma, 1.0 / n_train),
        "train_share": 1.0 / n_train,
        "unit B max": max_error_floor_ug(sigma, n_sp - 1, exp.positions_deg.size),
        "unit B shape": (n_sp - 1, exp.positions_deg.size),
    }


def _test_floor(params: PaperDParams) -> float:
    """The held-out RMSE floor of a reading: ``sqrt(2) noise``; under the random split the 55 degC readings
    among the test readings are their own targets (expected share 1/23), :func:`rmse_floor_ug`."""
    share = 1.0 / params.experiment.set_points_c.size if params.split_mode == "random" else 0.0
    return rmse_floor_ug(params.experiment.noise_ug, share)
