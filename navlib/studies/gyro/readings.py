"""The readings of paper C's ambiguous hot-net settings, each a full ``newrb`` design on Table 2.

- input unit and goal: :func:`hot_net_variants`, :func:`target_spread`, :func:`fig2_goal_readings`, and the
  input unit scanned continuously: :func:`input_scale_scan`, :func:`scale_band`;
- width and basis: :func:`width_readings` (MATLAB's ``radbas`` or the paper's eq. 1), :func:`basis_readings`;
- the resolution of any comparison with the printed outputs: :func:`latitude_rounding_effect`.

:func:`latitude_rounding_effect` caches its result per parameter set.
"""

from __future__ import annotations

from functools import lru_cache
from typing import get_args

import numpy as np
import pandas as pd

from navlib.angles import ARCMIN_PER_DEG, ARCSEC_PER_DEG
from navlib.data.gyro_tables import load_hot_test
from navlib.errors import check_param
from navlib.methods.rbf import InputScaler, leave_one_out, newrb

from .measured import _hot_xy, _maxabs, _quantities, _rms, printed_decimals
from .networks import (
    BASIS_FUNCTIONS,
    GOAL_READINGS,
    _hot_loo_errors,
    _table2_net,
    design_hot_net,
    swap_basis,
)
from .parameters import (
    HotNetSettings,
    InputUnit,
    StudyParams,
    WidthReading,
    _check_choice,
    _experiment_children,
    fact,
)


# ---------------------------------------------------------------------------------------- input unit and goal
def hot_net_variants(params: StudyParams = StudyParams()) -> pd.DataFrame:
    """Every reading of paper C's ambiguous network settings, each a full ``newrb`` design on Table 2.

    Input unit ``deg`` or ``arcmin``; goal read as mean (``MSE``) or summed (``SSE``) squared error with the
    printed 0.0003, or as a root-mean-square (``RMS``: MSE < 0.0003^2) or root-sum-square (``RSS``:
    SSE < 0.0003^2) error.  Columns: neurons, training RMS, the three Table 3 outputs, the largest Table 3
    error, and leave-one-out RMS and max over Table 2 (deg/h).

    Parameters
    ----------
    params : StudyParams
        SPREAD and the goal value come from ``params.hot``.

    Returns
    -------
    pandas.DataFrame
        One row per (input, goal reading).
    """
    x2, y2, x3, y3 = _hot_xy()
    rows = []
    for unit in ("deg", "arcmin"):
        for reading, (kind, squared) in GOAL_READINGS.items():
            g = params.hot.goal**2 if squared else params.hot.goal
            hot = HotNetSettings(spread=params.hot.spread, goal=g, goal_kind=kind, input_unit=unit)
            net = design_hot_net(x2, y2, hot)
            loo = leave_one_out(x2, y2, lambda x, y, hot=hot: design_hot_net(x, y, hot))
            p3 = net.predict(x3)
            row = {
                "input": unit,
                "goal": reading,
                "neurons": net.n_neurons,
                "train RMS (deg/h)": float(np.sqrt(net.perf_mse[-1])),
            }
            row.update({f"T3 #{i + 1} (deg/h)": float(p3[i]) for i in range(len(p3))})
            row.update(
                {
                    "max |T3 err| (deg/h)": _maxabs(y3 - p3),
                    "LOO RMS (deg/h)": _rms(y2 - loo),
                    "LOO max (deg/h)": _maxabs(y2 - loo),
                }
            )
            rows.append(row)
    return pd.DataFrame(rows)


def target_spread() -> pd.DataFrame:
    """Variance and sum of squares about the mean of Table 2's drifts ((deg/h)^2): why the printed goal
    0.0003 stops ``newrb`` at its second neuron under both MSE and SSE.

    Returns
    -------
    pandas.DataFrame
        ``quantity`` -> ``value``, ``unit``.
    """
    _, y2, _, _ = _hot_xy()
    return _quantities(
        [
            ("variance of Table 2 drifts", float(np.var(y2)), "(deg/h)^2"),
            ("sum of squares about the mean", float(np.sum((y2 - y2.mean()) ** 2)), "(deg/h)^2"),
            ("goal as printed", fact("training_goal"), "as printed"),
        ]
    )


def input_scale_scan(params: StudyParams = StudyParams(), n_scales: int = 121) -> pd.DataFrame:
    """Table 3 against the unit the latitude error enters the network in, scanned continuously: the input is
    ``dL (deg) * scale`` with ``scale`` log-spaced from 1 (deg) through 60 (arcmin) to 3600 (arcsec) input units
    per deg; SPREAD, goal and goal reading from ``params.hot``, both width readings.  At each scale: neurons, the
    largest ``|ours - printed output|`` and the largest ``|true - ours|`` over Table 3's rows (deg/h).

    Parameters
    ----------
    params : StudyParams
    n_scales : int
        Grid points (the three named units are always included).

    Returns
    -------
    pandas.DataFrame
        Columns scale (input units per deg), width, neurons, ``max |ours - printed| (deg/h)``,
        ``max |T3 err| (deg/h)``.
    """
    check_param("n_scales", n_scales, lo=3, hi=2000, integer=True)
    x2, y2, x3, y3 = _hot_xy()
    printed = load_hot_test()["paper_rbf_drift_deg_h"].to_numpy(float)
    scales = np.unique(np.r_[np.geomspace(1.0, ARCSEC_PER_DEG, int(n_scales)), ARCMIN_PER_DEG])
    rows = []
    for w in get_args(WidthReading):
        hot = HotNetSettings(
            spread=params.hot.spread, goal=params.hot.goal, goal_kind=params.hot.goal_kind, width=w
        )
        for sc in scales:
            net = newrb(
                x2,
                y2,
                goal=hot.goal,
                spread=hot.matlab_spread,
                goal_kind=hot.goal_kind,
                scaler=InputScaler.affine(0.0, 1.0 / sc),
            )
            p3 = net.predict(x3)
            rows.append(
                {
                    "scale": float(sc),
                    "width": w,
                    "neurons": net.n_neurons,
                    "max |ours - printed| (deg/h)": _maxabs(p3 - printed),
                    "max |T3 err| (deg/h)": _maxabs(y3 - p3),
                }
            )
    return pd.DataFrame(rows)


def scale_band(scan: pd.DataFrame, width: str = "matlab") -> pd.DataFrame:
    """The input scales of :func:`input_scale_scan` at which Table 3's outputs are reproduced to the printed
    precision (``max |ours - printed|`` below half a unit of the coarsest printed decimal) and at which Table 3's
    accuracy claim holds (``max |T3 err|`` below ``claimed_accuracy``): lowest and highest such scale.

    Parameters
    ----------
    scan : pandas.DataFrame
        From :func:`input_scale_scan`.
    width : {"matlab", "gaussian"}

    Returns
    -------
    pandas.DataFrame
        ``condition`` -> lowest and highest scale (input units per deg), grid points, share of the grid.
    """
    _check_choice("width", width, get_args(WidthReading))
    s = scan[scan["width"] == width]
    bound = 0.5 * 10.0 ** -int(printed_decimals(3, "paper_rbf_drift_deg_h").min())
    conds = {
        "outputs reproduced to the printed decimal": s["max |ours - printed| (deg/h)"] < bound,
        f"Table 3 error below {fact('claimed_accuracy'):g} deg/h": s["max |T3 err| (deg/h)"]
        < fact("claimed_accuracy"),
    }
    rows = []
    for name, ok in conds.items():
        sc = s.loc[ok.to_numpy(), "scale"]
        rows.append(
            {
                "condition": name,
                "lowest scale": float(sc.min()) if len(sc) else np.nan,
                "highest scale": float(sc.max()) if len(sc) else np.nan,
                "grid points": int(ok.sum()),
                "share of the grid": float(ok.mean()),
            }
        )
    return pd.DataFrame(rows).set_index("condition")


def fig2_goal_readings(params: StudyParams = StudyParams()) -> pd.DataFrame:
    """Fig 2's tension in numbers: where each reading of the printed goal stops ``newrb`` on Table 2 (input unit
    and SPREAD from ``params.hot``), how long the whole orthogonal-least-squares path is, and how much of the
    training MSE's total fall along that path is left after the stop.  A long, slowly converging curve (the
    paper's Fig 2) needs a goal that is reached only late on the path.

    Parameters
    ----------
    params : StudyParams

    Returns
    -------
    pandas.DataFrame
        One row per goal reading (MSE, SSE, RMS, RSS): goal ((deg/h)^2), neurons at the stop, neurons of the full
        path, training MSE at the stop, share of the path's fall in MSE still to come.
    """
    x2, y2, _, _ = _hot_xy()
    h = params.hot
    full = design_hot_net(
        x2,
        y2,
        HotNetSettings(
            spread=h.spread, goal=0.0, goal_kind="mse", input_unit=h.input_unit, width=h.width
        ),
    )
    mse = full.perf_mse
    rows = []
    for reading, (kind, squared) in GOAL_READINGS.items():
        g = h.goal**2 if squared else h.goal
        net = design_hot_net(
            x2,
            y2,
            HotNetSettings(
                spread=h.spread, goal=g, goal_kind=kind, input_unit=h.input_unit, width=h.width
            ),
        )
        stop = float(net.perf_mse[-1])
        rows.append(
            {
                "goal": reading,
                "goal ((deg/h)^2)": g,
                "neurons at stop": net.n_neurons,
                "neurons of the full path": full.n_neurons,
                "training MSE at stop ((deg/h)^2)": stop,
                "share of the fall still to come": float((stop - mse[-1]) / (mse[0] - mse[-1])),
            }
        )
    return pd.DataFrame(rows)


# -------------------------------------------------------------------------------------------- width and basis
def width_readings(params: StudyParams = StudyParams()) -> pd.DataFrame:
    """The hot net under MATLAB's ``radbas`` width (``b = 0.8326 / SPREAD``) and under the paper's own
    Gaussian ``exp(-u^2 / delta^2)`` with ``delta`` = SPREAD (``b = 1 / SPREAD``), input unit and goal from
    ``params.hot``: neurons, width ``b``, the three Table 3 outputs, the largest ``|ours - printed|`` and
    ``|true - ours|`` over Table 3, leave-one-out RMS over Table 2 (deg/h).

    Parameters
    ----------
    params : StudyParams

    Returns
    -------
    pandas.DataFrame
        One row per width reading.
    """
    x2, y2, x3, y3 = _hot_xy()
    printed = load_hot_test()["paper_rbf_drift_deg_h"].to_numpy(float)
    rows = []
    for w in get_args(WidthReading):
        hot = HotNetSettings(
            spread=params.hot.spread,
            goal=params.hot.goal,
            goal_kind=params.hot.goal_kind,
            input_unit=params.hot.input_unit,
            width=w,
        )
        net = design_hot_net(x2, y2, hot)
        p3 = net.predict(x3)
        row = {"width": w, "neurons": net.n_neurons, "b (per input unit)": net.b}
        row.update({f"T3 #{i + 1} (deg/h)": float(p3[i]) for i in range(len(p3))})
        row.update(
            {
                "max |ours - printed| (deg/h)": _maxabs(p3 - printed),
                "max |T3 err| (deg/h)": _maxabs(y3 - p3),
                "LOO RMS (deg/h)": _rms(_hot_loo_errors(hot)),
            }
        )
        rows.append(row)
    return pd.DataFrame(rows)


def basis_readings(params: StudyParams = StudyParams()) -> pd.DataFrame:
    """The hot net (``params.hot``) with each basis function of :data:`~navlib.studies.gyro.networks.BASIS_FUNCTIONS` in
    place of the Gaussian at the same centres and width: Table 3 outputs, the largest ``|output - Gaussian output|``
    over Table 3, the largest ``|true - output|`` over Table 3, and the leave-one-out RMS over Table 2 (each fold:
    ``newrb`` picks the centres, then the basis is swapped), deg/h.  The first row is the Gaussian itself.

    Parameters
    ----------
    params : StudyParams

    Returns
    -------
    pandas.DataFrame
        One row per basis function.
    """
    x2, y2, x3, y3 = _hot_xy()
    net = _table2_net(params.hot)
    ref = net.predict(x3)
    rows = []
    for basis in ("gaussian", *BASIS_FUNCTIONS):
        p3 = swap_basis(net, x2, y2, basis)(x3)
        loo = y2 - leave_one_out(
            x2, y2, lambda x, y, b=basis: swap_basis(design_hot_net(x, y, params.hot), x, y, b)
        )
        row = {"basis": basis}
        row.update({f"T3 #{i + 1} (deg/h)": float(p3[i]) for i in range(len(p3))})
        row.update(
            {
                "max |output - Gaussian| (deg/h)": _maxabs(p3 - ref),
                "max |T3 err| (deg/h)": _maxabs(y3 - p3),
                "LOO RMS (deg/h)": _rms(loo),
            }
        )
        rows.append(row)
    return pd.DataFrame(rows)


# ------------------------------------------------------------------------------------------ latitude rounding
@lru_cache(maxsize=8)
def latitude_rounding_effect(
    params: StudyParams = StudyParams(), input_unit: InputUnit = "arcmin", n_draws: int = 200
) -> float:
    """How far our hot net's Table 3 outputs move when the printed latitudes move within their rounding: the
    resolution of any comparison of our outputs with the paper's printed ones.

    Every latitude of Tables 2 and 3 is redrawn uniformly within half a unit of its printed last decimal
    (:func:`~navlib.studies.gyro.measured.printed_decimals`), the net (``params.hot`` with ``input_unit``) is designed
    on the redrawn Table 2 and applied to the redrawn Table 3; the result is the 95th percentile over ``n_draws`` draws
    of the largest ``|output change|`` over the three rows (seeds
    :func:`~navlib.studies.gyro.parameters.experiment_seeds` ``"rounding"``).

    Parameters
    ----------
    params : StudyParams
    input_unit : {"deg", "arcmin", "arcsec"}
    n_draws : int

    Returns
    -------
    float
        deg/h.
    """
    check_param("n_draws", n_draws, lo=20, integer=True)
    hot = HotNetSettings(
        spread=params.hot.spread,
        goal=params.hot.goal,
        goal_kind=params.hot.goal_kind,
        input_unit=input_unit,
    )
    x2, y2, x3, _ = _hot_xy()
    h2 = 0.5 * 10.0 ** -printed_decimals(2, "latitude_deg")
    h3 = 0.5 * 10.0 ** -printed_decimals(3, "latitude_deg")
    ref = design_hot_net(x2, y2, hot).predict(x3)
    rng = np.random.default_rng(_experiment_children(params.sim.seed, "rounding", 1)[0])
    moved = []
    for _ in range(int(n_draws)):
        a2, a3 = x2 + rng.uniform(-h2, h2), x3 + rng.uniform(-h3, h3)
        moved.append(_maxabs(design_hot_net(a2, y2, hot).predict(a3) - ref))
    return float(np.quantile(moved, 0.95))
