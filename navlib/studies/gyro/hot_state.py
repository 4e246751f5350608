"""The gyro chapter's hot state (paper C Sec. 2.2): the hot net on Tables 2 and 3, Figs 2 and 3.

- the network and Table 3: :func:`hot_network`, :func:`table3_identification`;
- Fig 2's training path: :func:`fig2_training_path`; Fig 3's position errors: :func:`fig3_position_errors`;
- Table 1 against the measured tables: :func:`slopes_table`, :func:`drift_against_latitude`;
- generalisation beyond three rows: :func:`hot_leave_one_out`.

:func:`fig3_position_errors` caches its result per parameter set; treat returned frames as read-only.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np
import pandas as pd

from navlib.angles import to_arcmin
from navlib.data.gyro_tables import load_cold_train, load_hot_test, load_hot_train
from navlib.errors import check_param
from navlib.methods.rbf import RBFNet, leave_one_out
from navlib.sensors import ins

from .measured import _hot_xy, _maxabs, _quantities, _rms
from .networks import _poly_fit, _table2_net, design_hot_net
from .parameters import HotNetSettings, StudyParams, experiment_seeds, fact


# ------------------------------------------------------------------------------------------------ hot network
@dataclass(frozen=True)
class HotNet:
    """``net``: the designed network; ``neurons``: centre (in the input unit) and weight of each neuron;
    ``quantities``: neurons, width, training RMS, bias (the stop reason is ``net.stop_reason``)."""

    net: RBFNet
    neurons: pd.DataFrame
    quantities: pd.DataFrame


def hot_network(params: StudyParams = StudyParams()) -> HotNet:
    """The hot-state network of paper C Sec. 2.2, designed on Table 2 by ``newrb``
    (:func:`~navlib.studies.gyro.networks.design_hot_net`).

    Parameters
    ----------
    params : StudyParams

    Returns
    -------
    HotNet
    """
    net = _table2_net(params.hot)
    unit = params.hot.input_unit
    neurons = pd.DataFrame(
        {
            "neuron": np.arange(1, net.n_neurons + 1),
            "training sample": net.center_index + 1,
            f"centre ({unit})": net.centers[:, 0],
            "weight (deg/h)": net.weights[:, 0],
        }
    )
    q = _quantities(
        [
            ("neurons", net.n_neurons, ""),
            ("width b", net.b, f"per {unit}"),
            ("training RMS", float(np.sqrt(net.perf_mse[-1])), "deg/h"),
            ("bias", float(net.bias[0]), "deg/h"),
        ]
    )
    return HotNet(net, neurons, q)


@dataclass(frozen=True)
class Table3:
    """``outputs``: per Table 3 test the 12 h latitude error (arcmin), the true drift and each method's
    identified drift (deg/h); ``errors``: true - identified per method (deg/h), the paper's printed error
    beside ours."""

    outputs: pd.DataFrame
    errors: pd.DataFrame


TABLE3_METHODS = ("paper RBF", "our RBF", "Table 1 inverse", "straight line")


def table3_identification(params: StudyParams = StudyParams()) -> Table3:
    """Table 3 analogue: identified axial drift on the paper's three hot test rows.

    Methods: the paper's printed RBF output, our hot net (:func:`hot_network`), the Table 1 inverse
    ``eps = dL(12 h) W / (2 cos L)`` (no training), and a straight line fitted to Table 2.
    Error = true - identified (the paper's sign).

    Parameters
    ----------
    params : StudyParams

    Returns
    -------
    Table3
    """
    t3 = load_hot_test()
    x2, y2, x3, y3 = _hot_xy()
    net = _table2_net(params.hot)
    line = np.polyfit(x2, y2, 1)
    out = pd.DataFrame(
        {
            "test": t3["test"],
            "dL (arcmin)": to_arcmin(x3),
            "true (deg/h)": y3,
            "paper RBF": t3["paper_rbf_drift_deg_h"].to_numpy(float),
            "our RBF": net.predict(x3),
            "Table 1 inverse": ins.drift_from_latitude_error(x3, fact("identify_h"), params.earth),
            "straight line": np.polyval(line, x3),
        }
    )
    err = pd.DataFrame(
        {"test": t3["test"], "paper's printed error": t3["paper_error_deg_h"].to_numpy(float)}
    )
    for m in TABLE3_METHODS:
        err[f"err {m}"] = y3 - out[m].to_numpy()
    return Table3(out, err)


@dataclass(frozen=True)
class Fig2:
    """``path``: training MSE and SSE ((deg/h)^2) by number of neurons along the full OLS path;
    ``full_neurons``/``stop_reason`` of that path; ``our_neurons``: where the goal stops the design."""

    path: pd.DataFrame
    full_neurons: int
    stop_reason: str
    our_neurons: int


def fig2_training_path(params: StudyParams = StudyParams()) -> Fig2:
    """Fig 2 analogue: ``newrb``'s training error against the number of neurons on Table 2 (goal 0, so the
    whole orthogonal-least-squares path until the candidates become numerically dependent).

    Parameters
    ----------
    params : StudyParams

    Returns
    -------
    Fig2
    """
    x2, y2, _, _ = _hot_xy()
    h = params.hot
    full = design_hot_net(
        x2, y2, HotNetSettings(spread=h.spread, goal=0.0, goal_kind="mse", input_unit=h.input_unit)
    )
    ours = _table2_net(h)
    path = pd.DataFrame(
        {
            "neurons": np.arange(full.perf_mse.size),
            "MSE ((deg/h)^2)": full.perf_mse,
            "SSE ((deg/h)^2)": full.perf_sse,
        }
    )
    return Fig2(path, full.n_neurons, full.stop_reason, ours.n_neurons)


# ------------------------------------------------------------------------------------------------------ Fig 3
@dataclass(frozen=True)
class Fig3:
    """``table``: per Table 3 test, the paper's 72 h position errors before/after and ours (mean, min, max
    over the draws, nmi); ``curves``: tidy (test, t_h, before_nmi, after_nmi) of each test's first draw;
    ``runs``: one row per simulated run (test, draw, worst 72 h error before and after identification, and
    ``best_nmi``, the worst 72 h error left by the best possible compensation of that run: the floor that
    the residual errors other than the axial drift set)."""

    table: pd.DataFrame
    curves: pd.DataFrame
    runs: pd.DataFrame


@lru_cache(maxsize=4)
def fig3_position_errors(params: StudyParams = StudyParams()) -> Fig3:
    """Fig 3 analogue: 72 h position error before and after subtracting our hot net's drift.

    Each Table 3 test is replayed ``n_seeds`` times in the simulator (its true drift as the axial drift,
    residual errors drawn per draw, seeds :func:`~navlib.studies.gyro.parameters.experiment_seeds` ``"fig3"``); after
    the 12 h the drift our network identifies from the row's *measured* latitude is subtracted.  "Before": no axial
    compensation. Position error ``R sqrt(dL^2 + (cos L dlon)^2)``, worst over the 72 h.

    Parameters
    ----------
    params : StudyParams

    Returns
    -------
    Fig3
    """
    t3 = load_hot_test()
    s = params.sim
    tab = table3_identification(params).outputs
    seeds = experiment_seeds(s.seed, "fig3", len(t3))
    rows, curves, per_run = [], [], []
    for i in range(len(t3)):
        est = float(tab["our RBF"].iloc[i])
        true = float(tab["true (deg/h)"].iloc[i])
        runs = ins.simulated_tests(
            np.full(s.n_seeds, true),
            seed=seeds[i],
            identify=lambda lat, est=est: est,
            earth=params.earth,
            procedure=s.procedure(),
            **s.error_sd(),
        )
        before = np.array([r.max_error_before_nmi for r in runs])
        after = np.array([r.max_error_after_nmi for r in runs])
        best = np.array([float(r.position_error_nmi_for(r.best_drift_deg_h).max()) for r in runs])
        per_run.append(
            pd.DataFrame(
                {
                    "test": int(t3["test"].iloc[i]),
                    "draw": np.arange(1, len(runs) + 1),
                    "before_nmi": before,
                    "after_nmi": after,
                    "best_nmi": best,
                }
            )
        )
        rows.append(
            {
                "test": int(t3["test"].iloc[i]),
                "true drift (deg/h)": true,
                "our RBF (deg/h)": est,
                "paper before": float(t3["paper_pos_error_before_nmi_72h"].iloc[i]),
                "ours before": before.mean(),
                "ours before min": before.min(),
                "ours before max": before.max(),
                "paper after": float(t3["paper_pos_error_after_nmi_72h"].iloc[i]),
                "ours after": after.mean(),
                "ours after min": after.min(),
                "ours after max": after.max(),
            }
        )
        r0 = runs[0]
        curves.append(
            pd.DataFrame(
                {
                    "test": int(t3["test"].iloc[i]),
                    "t_h": r0.after.t_h,
                    "before_nmi": r0.before.position_error_nmi,
                    "after_nmi": r0.after.position_error_nmi,
                }
            )
        )
    return Fig3(
        pd.DataFrame(rows),
        pd.concat(curves, ignore_index=True),
        pd.concat(per_run, ignore_index=True),
    )


# ----------------------------------------------------------------------------------- Table 1 against the data
@dataclass(frozen=True)
class Slopes:
    """``slopes``: straight-line fits of drift on latitude error (and the inverse regression) against the
    Table 1 slope, (deg/h) per deg; ``loo``: leave-one-out RMS on Table 2 of a straight line and a
    quadratic (deg/h)."""

    slopes: pd.DataFrame
    loo: pd.DataFrame


def slopes_table() -> Slopes:
    """Table 1 against the measured tables: if Table 1 held, drift = dL(12 h) W / (2 cos L) exactly.

    Fits drift on latitude error and latitude error on drift (the truth lies between when both carry
    noise) on Table 2 and on every real row (Tables 2, 3, 4); ratio = fitted / Table 1 slope.

    Returns
    -------
    Slopes
    """
    x2, y2, x3, y3 = _hot_xy()
    t4 = load_cold_train()
    x_all = np.r_[x2, x3, t4["latitude_error_deg"]]
    y_all = np.r_[y2, y3, t4["true_drift_deg_h"]]
    slope_t1 = 1.0 / ins.latitude_error_per_drift(fact("identify_h"), ins.Earth())
    rows = []
    for name, xx, yy in (("Table 2", x2, y2), ("Tables 2+3+4", x_all, y_all)):
        b1, b0 = np.polyfit(xx, yy, 1)
        c1, _ = np.polyfit(yy, xx, 1)
        rows.append(
            {
                "rows": name,
                "n": len(xx),
                "drift on dL": b1,
                "1 / (dL on drift)": 1 / c1,
                "Table 1": slope_t1,
                "ratio drift on dL": b1 / slope_t1,
                "ratio 1 / (dL on drift)": 1 / c1 / slope_t1,
                "intercept (deg/h)": b0,
                "residual RMS (deg/h)": _rms(yy - np.polyval([b1, b0], xx)),
            }
        )
    loo = pd.DataFrame(
        {
            "model": ["straight line", "quadratic"],
            "LOO RMS (deg/h)": [_rms(y2 - leave_one_out(x2, y2, _poly_fit(d))) for d in (1, 2)],
        }
    )
    return Slopes(pd.DataFrame(rows), loo)


@dataclass(frozen=True)
class DriftLatitude:
    """``points``: measured (table, dL_arcmin, drift_deg_h); ``lines``: (model, dL_arcmin, drift_deg_h)."""

    points: pd.DataFrame
    lines: pd.DataFrame


def drift_against_latitude(params: StudyParams = StudyParams(), n_grid: int = 301) -> DriftLatitude:
    """The measured drifts against the 12 h latitude error, with our RBF, the Table 1 inverse and a straight
    line fitted to Table 2 on a grid over +-0.03 deg (+-1.8 arcmin).

    Parameters
    ----------
    params : StudyParams
    n_grid : int

    Returns
    -------
    DriftLatitude
    """
    check_param("n_grid", n_grid, lo=2, integer=True)
    x2, y2, x3, y3 = _hot_xy()
    t4 = load_cold_train()
    points = pd.concat(
        [
            pd.DataFrame(
                {"table": "Table 2 (training)", "dL_arcmin": to_arcmin(x2), "drift_deg_h": y2}
            ),
            pd.DataFrame(
                {"table": "Table 3 (hot tests)", "dL_arcmin": to_arcmin(x3), "drift_deg_h": y3}
            ),
            pd.DataFrame(
                {
                    "table": "Table 4 (cold start)",
                    "dL_arcmin": to_arcmin(t4["latitude_error_deg"]),
                    "drift_deg_h": t4["true_drift_deg_h"].to_numpy(float),
                }
            ),
        ],
        ignore_index=True,
    )
    xs = np.linspace(-0.03, 0.03, int(n_grid))
    net = _table2_net(params.hot)
    models = {
        f"our RBF ({net.n_neurons} neurons)": net.predict(xs),
        "Table 1 inverse": ins.drift_from_latitude_error(xs, fact("identify_h"), params.earth),
        "straight line fit to Table 2": np.polyval(np.polyfit(x2, y2, 1), xs),
    }
    lines = pd.concat(
        [
            pd.DataFrame({"model": k, "dL_arcmin": to_arcmin(xs), "drift_deg_h": v})
            for k, v in models.items()
        ],
        ignore_index=True,
    )
    return DriftLatitude(points, lines)


# ------------------------------------------------------------------------------------------ hot leave-one-out
@dataclass(frozen=True)
class HotLoo:
    """``summary``: per method RMS, max ``|error|`` and rows beyond the claimed accuracy under leave-one-out
    on Table 2; ``rows``: per-row errors (true - predicted, deg/h) of each method."""

    summary: pd.DataFrame
    rows: pd.DataFrame


HOT_LOO_METHODS = ("our RBF (LOO)", "straight line (LOO)", "Table 1 inverse (no fit)")


def hot_leave_one_out(params: StudyParams = StudyParams()) -> HotLoo:
    """Leave-one-out over Table 2's 16 rows: our hot net, a straight line (both refitted without the held-out
    row) and the Table 1 inverse (no fit).  Three test rows cannot support an accuracy bound; this can.

    Parameters
    ----------
    params : StudyParams

    Returns
    -------
    HotLoo
    """
    t2 = load_hot_train()
    x2, y2, _, _ = _hot_xy()
    pred = {
        HOT_LOO_METHODS[0]: leave_one_out(x2, y2, lambda x, y: design_hot_net(x, y, params.hot)),
        HOT_LOO_METHODS[1]: leave_one_out(x2, y2, _poly_fit(1)),
        HOT_LOO_METHODS[2]: ins.drift_from_latitude_error(x2, fact("identify_h"), params.earth),
    }
    lim = fact("claimed_accuracy")
    summary = pd.DataFrame(
        {
            "method": list(pred),
            "RMS (deg/h)": [_rms(y2 - p) for p in pred.values()],
            "max |err| (deg/h)": [_maxabs(y2 - p) for p in pred.values()],
            "rows beyond claim": [int(np.sum(np.abs(y2 - p) > lim)) for p in pred.values()],
            "rows": len(y2),
        }
    )
    rows = pd.DataFrame({"sample": t2["sample"], "dL (arcmin)": to_arcmin(x2), "drift (deg/h)": y2})
    for k, p in pred.items():
        rows[f"err {k.split(' (')[0]}"] = y2 - p
    return HotLoo(summary, rows)
