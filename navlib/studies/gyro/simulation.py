"""The gyro chapter's experiments in the static-base error simulator (:mod:`navlib.sensors.ins`).

- Table 1's closed forms against the simulator: :func:`table1_vs_simulator`;
- Fig 1's simulated identification runs: :func:`fig1_simulated_tests`;
- the 16 simulated hot tests and what they tell: :func:`reference_gap` (how well the paper's 72 h-optimal
  "true" drift knows the actual drift) and :func:`position_requirement` (0.0005 deg/h for 1 nmi/72 h);
- the printed position errors read through the simulator's gain: :func:`implied_drift_error`,
  :func:`table3_other_error`, :func:`before_identification`.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np
import pandas as pd

from navlib.angles import ARCSEC, ARCSEC_PER_DEG, to_arcmin
from navlib.data.gyro_tables import load_hot_test
from navlib.errors import check_param
from navlib.sensors import ins

from .measured import _hot_xy, _maxabs, _quantities, _rms, printed_decimals
from .parameters import StudyParams, experiment_seeds, fact


# ---------------------------------------------------------------------------------------------------- Table 1
@dataclass(frozen=True)
class Table1Comparison:
    """``summary``: per error source, the simulator's and Table 1's 12 h latitude error (arcsec) and the
    largest difference over 48 h relative to the simulator's peak; ``curves``: tidy (case, t_h,
    simulator_arcsec, table1_arcsec); ``quantities``: the Table 1 gain and the level-error bound."""

    summary: pd.DataFrame
    curves: pd.DataFrame
    quantities: pd.DataFrame


def table1_vs_simulator(duration_h: float = 48.0, step_s: float = 60.0) -> Table1Comparison:
    """Paper C's Table 1 closed forms against the full static-base error model, one error source at a time.

    Table 1 (in the book's sign convention, velocity term with ``R w_s``)::

        dL = (cos L / W)(1 - cos W t) eps + acc_N (cos w_s t - cos W t) / (R (W^2 - w_s^2))
             - phi_U cos L (sin W t + (W / w_s) sin w_s t) + dV_N sin(w_s t) / (R w_s)

    (:func:`navlib.sensors.ins.table1_latitude_error`), against :func:`navlib.sensors.ins.simulate` without
    rotation.  Also: the 12 h gain ``2 cos L / W`` and its inverse, the 12 h latitude error left by 1 arcsec
    of east tilt (not in Table 1) read as axial drift, and the scatter of Table 2 about a straight line
    expressed as that tilt (a bound on the real system's alignment level errors).

    Parameters
    ----------
    duration_h : float
        Length of each run, h.
    step_s : float
        Simulator step, s.

    Returns
    -------
    Table1Comparison
    """
    check_param("duration_h", duration_h, lo=13.0, hi=200.0)
    earth = ins.Earth(latitude_deg=ins.LOCAL_LATITUDE_DEG)
    tilt_for_bias = -20.0 * ins.UG / earth.g / ARCSEC
    cases = [
        (
            "axial drift 0.001 deg/h",
            dict(imu=ins.ImuErrors(axial_drift_deg_h=0.001)),
            dict(axial_drift_deg_h=0.001),
        ),
        (
            "azimuth error 60 arcsec",
            dict(initial=ins.InitialErrors(azimuth_arcsec=60.0)),
            dict(azimuth_error_arcsec=60.0),
        ),
        (
            "north velocity error 0.1 m/s",
            dict(initial=ins.InitialErrors(vel_north_m_s=0.1)),
            dict(north_velocity_error_m_s=0.1),
        ),
        (
            "north accel bias 20 ug (level at t=0)",
            dict(imu=ins.ImuErrors(accel_bias_y_ug=20.0)),
            dict(north_accel_bias_ug=20.0),
        ),
        (
            "north accel bias 20 ug (tilt absorbs it)",
            dict(
                imu=ins.ImuErrors(accel_bias_y_ug=20.0),
                initial=ins.InitialErrors(tilt_east_arcsec=tilt_for_bias),
            ),
            dict(north_accel_bias_ug=20.0),
        ),
    ]
    no_rot = ins.Rotation(kind="none")
    rows, curves = [], []
    for label, sim_kw, t1_kw in cases:
        run = ins.simulate(duration_h, earth=earth, rotation=no_rot, step_s=step_s, **sim_kw)
        cf = ins.table1_latitude_error(run.t_h, earth=earth, **t1_kw)
        peak = _maxabs(run.latitude_error_deg)
        rows.append(
            {
                "source": label,
                "simulator at 12 h (arcsec)": run.at(12.0)[5] / ARCSEC,
                "Table 1 at 12 h (arcsec)": float(
                    ins.table1_latitude_error(12.0, earth=earth, **t1_kw)
                )
                * ARCSEC_PER_DEG,
                "max |sim - Table 1| / peak": _maxabs(run.latitude_error_deg - cf) / peak,
            }
        )
        curves.append(
            pd.DataFrame(
                {
                    "case": label,
                    "t_h": run.t_h,
                    "simulator_arcsec": run.latitude_error_deg * ARCSEC_PER_DEG,
                    "table1_arcsec": cf * ARCSEC_PER_DEG,
                }
            )
        )
    identify_h = fact("identify_h")
    gain = ins.latitude_error_per_drift(identify_h, earth)
    tilt_run = ins.simulate(
        identify_h, earth=earth, initial=ins.InitialErrors(tilt_east_arcsec=1.0), step_s=step_s
    )
    tilt_lat = float(tilt_run.latitude_error_deg[-1])
    tilt_drift = float(ins.drift_from_latitude_error(tilt_lat, identify_h, earth))
    x2, y2, _, _ = _hot_xy()
    scatter = _rms(y2 - np.polyval(np.polyfit(x2, y2, 1), x2))
    q = _quantities(
        [
            ("Table 1 gain at 12 h", gain, "deg per deg/h"),
            ("Table 1 inverse slope", 1.0 / gain, "(deg/h) per deg"),
            ("12 h latitude error from 1 arcsec east tilt", tilt_lat * ARCSEC_PER_DEG, "arcsec"),
            ("the same read as axial drift", tilt_drift, "deg/h"),
            ("Table 2 scatter about a straight line (RMS)", scatter, "deg/h"),
            ("Table 2 scatter as east tilt", scatter / abs(tilt_drift), "arcsec"),
        ]
    )
    return Table1Comparison(pd.DataFrame(rows), pd.concat(curves, ignore_index=True), q)


# ------------------------------------------------------------------------------------------------------ Fig 1
@dataclass(frozen=True)
class Fig1:
    """``curves``: tidy (test, axial_drift_deg_h, t_h, latitude_error_arcmin, longitude_error_arcmin) over
    the 12 h identification run; ``table``: per test the drift, 12 h errors, Table 1 inverse and the
    72 h-optimal "true" drift (the paper's definition of the reference)."""

    curves: pd.DataFrame
    table: pd.DataFrame


def fig1_simulated_tests(params: StudyParams = StudyParams()) -> Fig1:
    """Fig 1 analogue: latitude and longitude error over the 12 h identification run of simulated tests.

    Axial drifts at ``n_tests`` quantiles of Table 2's drifts; each test draws its own residual horizontal
    sensor errors, alignment errors and gyro noise (:func:`navlib.sensors.ins.simulated_tests`, seeds from
    :func:`~navlib.studies.gyro.parameters.experiment_seeds` ``"fig1"``).  The "true" drift is the compensation
    minimising the worst 72 h position error (paper C Sec. 2.2).

    Parameters
    ----------
    params : StudyParams

    Returns
    -------
    Fig1
    """
    _, y2, _, _ = _hot_xy()
    s = params.sim
    drifts = np.quantile(y2, np.linspace(0, 1, s.n_tests))
    seed = experiment_seeds(s.seed, "fig1", 1)[0]
    tests = ins.simulated_tests(
        drifts, seed=seed, earth=params.earth, procedure=s.procedure(), **s.error_sd()
    )
    curves = pd.concat(
        [
            pd.DataFrame(
                {
                    "test": i + 1,
                    "axial_drift_deg_h": r.final_drift_deg_h,
                    "t_h": r.identify_run.t_h,
                    "latitude_error_arcmin": to_arcmin(r.identify_run.latitude_error_deg),
                    "longitude_error_arcmin": to_arcmin(r.identify_run.longitude_error_deg),
                }
            )
            for i, r in enumerate(tests)
        ],
        ignore_index=True,
    )
    table = pd.DataFrame(
        {
            "test": np.arange(1, len(tests) + 1),
            "axial drift (deg/h)": [r.final_drift_deg_h for r in tests],
            "dL 12 h (arcmin)": [float(to_arcmin(r.latitude_error_12h_deg)) for r in tests],
            "dlon 12 h (arcmin)": [
                float(to_arcmin(r.identify_run.longitude_error_deg[-1])) for r in tests
            ],
            "Table 1 inverse (deg/h)": [r.identified_drift_deg_h for r in tests],
            "72 h-optimal 'true' drift (deg/h)": [r.best_drift_deg_h for r in tests],
        }
    )
    return Fig1(curves, table)


# ---------------------------------------------------------------------------------------- simulated hot tests
@lru_cache(maxsize=4)
def _simulated_hot_tests(params: StudyParams) -> list:
    """16 simulated hot tests with Table 2's drifts (seeds :func:`~navlib.studies.gyro.parameters.experiment_seeds`
    ``"hot_reference"``)."""
    _, y2, _, _ = _hot_xy()
    s = params.sim
    return ins.simulated_tests(
        y2,
        seed=experiment_seeds(s.seed, "hot_reference", 1)[0],
        earth=params.earth,
        procedure=s.procedure(),
        **s.error_sd(),
    )


def reference_gap(params: StudyParams = StudyParams()) -> pd.DataFrame:
    """How well the paper's "true" drift (the compensation minimising the worst 72 h position error) knows
    the actual drift: 16 simulated hot tests with Table 2's drifts (seeds
    :func:`~navlib.studies.gyro.parameters.experiment_seeds` ``"hot_reference"``, the same tests that train
    :func:`~navlib.studies.gyro.cold_state.table5_simulation`'s hot net).

    Parameters
    ----------
    params : StudyParams

    Returns
    -------
    pandas.DataFrame
        test, actual drift, 72 h-optimal drift, gap = optimal - actual (deg/h).
    """
    sim_hot = _simulated_hot_tests(params)
    return pd.DataFrame(
        {
            "test": np.arange(1, len(sim_hot) + 1),
            "actual drift (deg/h)": [r.final_drift_deg_h for r in sim_hot],
            "72 h-optimal drift (deg/h)": [r.best_drift_deg_h for r in sim_hot],
            "gap (deg/h)": [r.best_drift_deg_h - r.final_drift_deg_h for r in sim_hot],
        }
    )


# --------------------------------------------------------------------------------------- position requirement
@lru_cache(maxsize=4)
def _unit_position_gain(params: StudyParams) -> float:
    """Worst 72 h position error (nmi) per deg/h of uncompensated axial drift, no other error (the navigation
    stage of :func:`navlib.sensors.ins.run_procedure`)."""
    proc = params.sim.procedure()
    run = ins.simulate(
        proc.navigate_h,
        earth=params.earth,
        imu=ins.ImuErrors(axial_drift_deg_h=1.0),
        initial=np.zeros(7),
        step_s=proc.step_s,
        t0_s=(proc.align_h + proc.identify_h) * 3600.0,
        seed=None,
    )
    return float(run.position_error_nmi.max())


def position_requirement(params: StudyParams = StudyParams()) -> pd.DataFrame:
    """What "0.0005 deg/h is needed for 1 nmi/72 h" (paper C Sec. 2.2) means in the simulator: the worst 72 h
    position error per deg/h of residual axial drift alone, the drift error that alone reaches the position
    goal, and, on the 16 simulated hot tests (:func:`reference_gap`'s runs, residual errors drawn), the worst
    72 h error left by a compensation off by +-``required_accuracy`` (the worse sign per run).

    Parameters
    ----------
    params : StudyParams

    Returns
    -------
    pandas.DataFrame
        ``quantity`` -> ``value``, ``unit``.
    """
    g = _unit_position_gain(params)
    req, goal = fact("required_accuracy"), fact("position_goal")
    runs = _simulated_hot_tests(params)
    with_res = _residual_required(params)
    return _quantities(
        [
            ("worst 72 h error per deg/h of axial drift", g, "nmi per deg/h"),
            (f"worst 72 h error from {req:g} deg/h alone", g * req, "nmi"),
            (f"drift error that alone reaches {goal:g} nmi", goal / g, "deg/h"),
            (
                f"median over {len(runs)} simulated tests, drift error +-{req:g} deg/h",
                float(np.median(with_res)),
                "nmi",
            ),
        ]
    )


def _residual_required(params: StudyParams) -> np.ndarray:
    req = fact("required_accuracy")
    return np.array(
        [
            max(
                float(r.position_error_nmi_for(r.final_drift_deg_h + sg * req).max())
                for sg in (-1.0, 1.0)
            )
            for r in _simulated_hot_tests(params)
        ]
    )


# ------------------------------------------------------------------------------------ printed position errors
def implied_drift_error(
    position_nmi, gain_nmi_per_deg_h: float, other_nmi: float = 0.0
) -> np.ndarray:
    """The residual axial drift (deg/h) that alone leaves the worst 72 h position error ``position_nmi``,
    ``(position - other) / gain``: the whole error charged to the drift (``other_nmi`` = 0), or what is left
    after ``other_nmi`` of error from other sources is set aside (clipped at 0).

    Parameters
    ----------
    position_nmi : array_like
        Worst 72 h position errors (nmi).
    gain_nmi_per_deg_h : float
        Worst 72 h error per deg/h of axial drift (:func:`position_requirement`).
    other_nmi : float
        Position error set aside for other sources (nmi).

    Returns
    -------
    numpy.ndarray
        deg/h.
    """
    check_param("gain_nmi_per_deg_h", gain_nmi_per_deg_h, lo=0, lo_open=True)
    check_param("other_nmi", other_nmi, lo=0)
    p = np.asarray(position_nmi, dtype=float)
    return np.clip(p - other_nmi, 0.0, None) / gain_nmi_per_deg_h


def table3_other_error(gain_nmi_per_deg_h: float) -> np.ndarray:
    """Per Table 3 test, the part of the printed 72 h error after identification that the printed
    identification error does not explain: ``after - gain |printed error|`` (nmi), the other error sources
    of the paper's own hot tests."""
    t3 = load_hot_test()
    return t3["paper_pos_error_after_nmi_72h"].to_numpy(float) - gain_nmi_per_deg_h * np.abs(
        t3["paper_error_deg_h"].to_numpy(float)
    )


def before_identification(gain_nmi_per_deg_h: float) -> pd.DataFrame:
    """Table 3's printed 72 h position error before identification against the worst 72 h error that each
    test's uncompensated "true" drift leaves alone (``gain |true drift|``): per test the printed value, ours,
    ``|printed - ours| / printed`` and the printed value's rounding relative to it (half a unit of its last
    printed digit / printed value, :func:`~navlib.studies.gyro.measured.printed_decimals`).

    Parameters
    ----------
    gain_nmi_per_deg_h : float
        Worst 72 h error per deg/h of axial drift.

    Returns
    -------
    pandas.DataFrame
    """
    check_param("gain_nmi_per_deg_h", gain_nmi_per_deg_h, lo=0, lo_open=True)
    t3 = load_hot_test()
    printed = t3["paper_pos_error_before_nmi_72h"].to_numpy(float)
    ours = gain_nmi_per_deg_h * np.abs(t3["true_drift_deg_h"].to_numpy(float))
    half = 0.5 * 10.0 ** -printed_decimals(3, "paper_pos_error_before_nmi_72h")
    return pd.DataFrame(
        {
            "test": t3["test"].to_numpy(),
            "printed (nmi)": printed,
            "drift alone (nmi)": ours,
            "relative gap": np.abs(printed - ours) / printed,
            "printed rounding (relative)": half / printed,
        }
    )
