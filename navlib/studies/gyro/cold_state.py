"""The gyro chapter's cold start (paper C Sec. 2.3): Table 4 by leave-one-out, Table 5 and Fig 4 in simulation.

- the hot net on Table 4: :func:`table4_hot_net`;
- the cold net and the rate-corrected hot net, leave-one-out on Table 4: :func:`cold_leave_one_out`;
- Table 5 and Fig 4 in a simulated world with the drift rate term from Table 4: :func:`table5_simulation`
  (cached per parameter set; treat returned frames as read-only).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from typing import get_args

import numpy as np
import pandas as pd

from navlib.angles import to_arcmin
from navlib.data.gyro_tables import load_cold_test, load_cold_train
from navlib.methods.rbf import leave_one_out
from navlib.sensors import ins

from .measured import _hot_xy, _maxabs, _quantities, _rms
from .networks import (
    _cold_net_inputs,
    _table2_net,
    design_cold_net,
    design_hot_net,
    rate_coefficient,
)
from .parameters import ColdDtColumn, StudyParams, experiment_seeds, fact
from .simulation import _simulated_hot_tests


# ---------------------------------------------------------------------------------------------------- Table 4
def table4_hot_net(params: StudyParams = StudyParams()) -> pd.DataFrame:
    """The hot net on the cold-start Table 4, beside the paper's hot-net column (error = true - output).

    Parameters
    ----------
    params : StudyParams

    Returns
    -------
    pandas.DataFrame
        sample, dL (arcmin), calibration-window temperature change (C), true, paper hot RBF, our hot RBF,
        and the two errors (deg/h).
    """
    t4 = load_cold_train()
    net = _table2_net(params.hot)
    x4, y4 = t4["latitude_error_deg"].to_numpy(float), t4["true_drift_deg_h"].to_numpy(float)
    ours = net.predict(x4)
    paper = t4["paper_hot_rbf_drift_deg_h"].to_numpy(float)
    return pd.DataFrame(
        {
            "sample": t4["sample"],
            "dL (arcmin)": to_arcmin(x4),
            "calib dT (C)": t4["calib_temp_change_c"].to_numpy(float),
            "true": y4,
            "paper hot RBF": paper,
            "our hot RBF": ours,
            "err paper": y4 - paper,
            "err ours": y4 - ours,
        }
    )


@dataclass(frozen=True)
class ColdLoo:
    """``rows``: per Table 4 row the predictions and errors (deg/h) of the cold net (LOO), the hot net and
    the hot net plus a rate correction (LOO); ``summary``: RMS and max per method; ``grid``: the cold net
    under other temperature-change inputs and SPREADs; ``quantities``: ``k_R`` on all six rows and the
    correlation of the hot-net error with the rate."""

    rows: pd.DataFrame
    summary: pd.DataFrame
    grid: pd.DataFrame
    quantities: pd.DataFrame


COLD_METHODS = ("cold net (LOO)", "hot net (no refit)", "hot + rate correction (LOO)")


def cold_leave_one_out(params: StudyParams = StudyParams()) -> ColdLoo:
    """The cold-state network of paper C Sec. 2.3 scored by leave-one-out on Table 4 (Table 5 prints no
    latitudes, so its rows cannot be used).

    Cold net: ``newrb`` on (dL in arcmin, end-of-alignment temperature, temperature change), inputs z-scored
    on each fold's training rows.  Baselines: the hot net unchanged, and the hot net minus
    ``k_R * calib dT / 12 h`` with ``k_R`` (:func:`~navlib.studies.gyro.networks.rate_coefficient`) fitted on the other
    five rows.

    Parameters
    ----------
    params : StudyParams

    Returns
    -------
    ColdLoo
    """
    t4 = load_cold_train()
    hot = _table2_net(params.hot)
    x4, y4 = t4["latitude_error_deg"].to_numpy(float), t4["true_drift_deg_h"].to_numpy(float)
    hot4 = hot.predict(x4)
    rate4 = t4["calib_temp_change_c"].to_numpy(float) / fact("identify_h")
    X4 = _cold_net_inputs(t4, params.cold.dt_column)
    cold_loo = leave_one_out(X4, y4, lambda x, y: design_cold_net(x, y, params))
    n = len(y4)
    rate_loo = np.array(
        [
            hot4[i]
            - rate_coefficient(
                hot4[np.arange(n) != i] - y4[np.arange(n) != i], rate4[np.arange(n) != i]
            )
            * rate4[i]
            for i in range(n)
        ]
    )
    pred = dict(zip(COLD_METHODS, (cold_loo, hot4, rate_loo)))
    rows = pd.DataFrame({"sample": t4["sample"], "true": y4})
    for k, p in pred.items():
        rows[k.split(" (")[0]] = p
    for k, p in pred.items():
        rows[f"err {k.split(' (')[0]}"] = y4 - p
    summary = pd.DataFrame(
        {
            "method": list(pred),
            "RMS (deg/h)": [_rms(y4 - p) for p in pred.values()],
            "max |err| (deg/h)": [_maxabs(y4 - p) for p in pred.values()],
        }
    )
    grid = []
    for col in get_args(ColdDtColumn):
        Xg = _cold_net_inputs(t4, col)
        for sp in (1.0, 2.0, 4.0):
            p = leave_one_out(
                Xg, y4, lambda x, y, sp=sp: design_cold_net(x, y, params, spread_sd=sp)
            )
            grid.append(
                {
                    "temperature change": col,
                    "SPREAD (sd units)": sp,
                    "LOO RMS (deg/h)": _rms(y4 - p),
                    "LOO max (deg/h)": _maxabs(y4 - p),
                }
            )
    q = _quantities(
        [
            ("k_R from Table 4", rate_coefficient(hot4 - y4, rate4), "(deg/h) per (C/h)"),
            (
                "correlation of hot-net error with rate",
                float(np.corrcoef(rate4, hot4 - y4)[0, 1]),
                "",
            ),
        ]
    )
    return ColdLoo(rows, summary, pd.DataFrame(grid), q)


# ------------------------------------------------------------------------------------------ Table 5 and Fig 4
@dataclass(frozen=True)
class Table5:
    """``table``: per Table 5 test, the paper's 72 h position errors with the hot and cold nets and ours
    (mean over draws of the worst 72 h error, nmi) with the mean ``|true - identified|`` drift (deg/h) per
    method; ``fig4``: tidy (method, compensation_deg_h, t_h, position_error_nmi) for test 1, first draw;
    ``quantities``: ``k_R``, neurons of the simulated nets, the drift actually simulated in ``fig4``;
    ``runs``: one row per simulated run (test, draw, final drift, and per method the worst 72 h position
    error, nmi), the same runs for every method."""

    table: pd.DataFrame
    fig4: pd.DataFrame
    quantities: pd.DataFrame
    runs: pd.DataFrame


TABLE5_METHODS = ("hot net", "cold net", "hot + rate corr.")


def _cold_history(row, k_rate: float, proc: ins.Procedure) -> ins.ColdStart:
    return ins.ColdStart(
        align_temp_min_c=row.align_temp_min_c,
        calib_temp_min_c=row.calib_temp_min_c,
        calib_temp_max_c=row.calib_temp_max_c,
        drift_per_c_h_deg_h=k_rate,
        align_h=proc.align_h,
        identify_h=proc.identify_h,
    )


@lru_cache(maxsize=4)
def table5_simulation(params: StudyParams = StudyParams()) -> Table5:
    """Table 5 and Fig 4 analogues: the cold-start study repeated in a simulated world.

    The axial drift follows the temperature history through the 16 h (piecewise linear through Table 4/5's
    printed ranges, :class:`navlib.sensors.ins.ColdStart`): ``eps(t) = eps_final + k_R dT/dt`` with ``k_R``
    from the real Table 4 (:func:`cold_leave_one_out`).  A hot net is trained on 16 simulated hot tests
    (Table 2's drifts), a cold net on 6 simulated cold tests (Table 4's histories and drifts); both, and the
    hot net with the rate correction, identify the drift of ``n_seeds`` simulated runs of each Table 5
    history with final drifts uniform in +-``cold_drift_half_range_deg_h``.  Each compensation's 72 h error
    comes from :meth:`navlib.sensors.ins.ProcedureResult.position_error_nmi_for` (exact: the errors are
    affine in the residual drift).

    Parameters
    ----------
    params : StudyParams

    Returns
    -------
    Table5
    """
    s, proc, earth = params.sim, params.sim.procedure(), params.earth
    t4, t5 = load_cold_train(), load_cold_test()
    _, y2, _, _ = _hot_xy()
    y4 = t4["true_drift_deg_h"].to_numpy(float)
    k_rate = float(cold_leave_one_out(params).quantities.loc["k_R from Table 4", "value"])
    sim_hot = _simulated_hot_tests(params)
    sim_hot_net = design_hot_net([r.latitude_error_12h_deg for r in sim_hot], y2, params.hot)
    sim_cold = ins.simulated_tests(
        y4,
        seed=experiment_seeds(s.seed, "cold_training", 1)[0],
        cold=[_cold_history(r, k_rate, proc) for r in t4.itertuples()],
        earth=earth,
        procedure=proc,
        **s.error_sd(),
    )
    t4_sim = t4.copy()
    t4_sim["latitude_error_deg"] = [r.latitude_error_12h_deg for r in sim_cold]
    sim_cold_net = design_cold_net(_cold_net_inputs(t4_sim, params.cold.dt_column), y4, params)
    seeds = experiment_seeds(s.seed, "table5", len(t5))
    draw_seeds = experiment_seeds(s.seed, "table5_drifts", len(t5))
    rows, per_run, fig4, q_drift = [], [], None, np.nan
    for j, row in enumerate(t5.itertuples()):
        half = s.cold_drift_half_range_deg_h
        drifts = np.random.default_rng(draw_seeds[j]).uniform(-half, half, s.n_seeds)
        runs = ins.simulated_tests(
            drifts,
            seed=seeds[j],
            cold=[_cold_history(row, k_rate, proc)] * s.n_seeds,
            earth=earth,
            procedure=proc,
            **s.error_sd(),
        )
        lat = np.array([r.latitude_error_12h_deg for r in runs])
        rows5 = pd.DataFrame(
            {
                "latitude_error_deg": lat,
                "calib_temp_max_c": row.calib_temp_max_c,
                "calib_temp_change_c": row.calib_temp_change_c,
                "align_temp_change_c": row.align_temp_change_c,
            }
        )
        hot_est = sim_hot_net.predict(lat)
        est = {
            "hot net": hot_est,
            "cold net": sim_cold_net.predict(_cold_net_inputs(rows5, params.cold.dt_column)),
            "hot + rate corr.": hot_est - k_rate * row.calib_temp_change_c / proc.identify_h,
        }
        out = {
            "test": int(row.test),
            "calib dT (C)": float(row.calib_temp_change_c),
            "paper hot net": float(row.paper_pos_error_hot_net_nmi_72h),
            "paper cold net": float(row.paper_pos_error_cold_net_nmi_72h),
        }
        worst = {
            name: np.array([r.position_error_nmi_for(c).max() for r, c in zip(runs, e)])
            for name, e in est.items()
        }
        per_run.append(
            pd.DataFrame(
                {
                    "test": int(row.test),
                    "draw": np.arange(1, len(runs) + 1),
                    "final drift (deg/h)": drifts,
                }
                | {f"{name} (nmi)": w for name, w in worst.items()}
            )
        )
        for name, w in worst.items():
            out[f"ours {name}"] = float(np.mean(w))
        for name, e in est.items():
            out[f"|drift err| {name}"] = float(np.mean(np.abs(drifts - e)))
        rows.append(out)
        if j == 0:
            r0 = runs[0]
            q_drift = r0.final_drift_deg_h
            fig4 = pd.concat(
                [
                    pd.DataFrame(
                        {
                            "method": name,
                            "compensation_deg_h": float(e[0]),
                            "t_h": r0.after.t_h,
                            "position_error_nmi": r0.position_error_nmi_for(float(e[0])),
                        }
                    )
                    for name, e in est.items()
                ],
                ignore_index=True,
            )
    q = _quantities(
        [
            ("k_R", k_rate, "(deg/h) per (C/h)"),
            ("simulated hot net neurons", sim_hot_net.n_neurons, ""),
            ("simulated cold net neurons", sim_cold_net.n_neurons, ""),
            ("paper Fig 4 run: simulated final drift", q_drift, "deg/h"),
        ]
    )
    return Table5(pd.DataFrame(rows), fig4, q, pd.concat(per_run, ignore_index=True))
